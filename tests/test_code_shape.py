"""The size limits of the code: functions of at most 60 lines, classes of at most 120.

A unit may be longer when its docstring says why, in a sentence that begins "Long because"
(a dataclass whose length is its documented fields, one linear numerical recipe). The limits
cover every module of the package; a unit's length is from its first decorator to its last
line.
"""

import ast
import re
from pathlib import Path

import reflector_opt

PACKAGE = Path(reflector_opt.__file__).parent
MAX_FUNCTION_LINES = 60
MAX_CLASS_LINES = 120
EXCUSE = re.compile(r"(^|[.!?]\s+|\n\s*)Long because\b")


def _units(tree):
    """Yield (kind, qualified name, node) of every function and class, nested ones too."""
    stack = [("", node) for node in tree.body]
    while stack:
        prefix, node = stack.pop()
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            name = f"{prefix}{node.name}"
            kind = "class" if isinstance(node, ast.ClassDef) else "function"
            yield kind, name, node
            stack.extend((f"{name}.", child) for child in node.body)
        else:
            stack.extend((prefix, child) for child in ast.iter_child_nodes(node))


def _length(node):
    """Lines from the first decorator (or the definition) to the unit's last line."""
    first = min([node.lineno] + [d.lineno for d in node.decorator_list])
    return node.end_lineno - first + 1


def long_units(source, path="<string>"):
    """The units of ``source`` over the limits whose docstring gives no "Long because" reason.

    Returns a list of ``"path:line kind name (n lines > limit)"`` strings.
    """
    found = []
    for kind, name, node in _units(ast.parse(source)):
        limit = MAX_CLASS_LINES if kind == "class" else MAX_FUNCTION_LINES
        length = _length(node)
        if length > limit and not EXCUSE.search(ast.get_docstring(node) or ""):
            found.append(f"{path}:{node.lineno} {kind} {name} ({length} lines > {limit})")
    return found


def test_units_within_size_limits():
    modules = sorted(PACKAGE.rglob("*.py"))
    assert len(modules) > 100  # the whole package, not an empty folder
    found = []
    for module in modules:
        found += long_units(module.read_text(), module.relative_to(PACKAGE.parent))
    assert not found, "too long and no 'Long because' in the docstring:\n" + "\n".join(found)


def _function(lines, docstring=None):
    body = [f"    x{i} = {i}" for i in range(lines - 1 - (docstring is not None))]
    head = [f'    """{docstring}"""'] if docstring is not None else []
    return "\n".join(["def f():", *head, *body]) + "\n"


def test_checker_flags_a_long_function_and_accepts_a_short_one():
    assert long_units(_function(60)) == []
    assert long_units(_function(61)) == ["<string>:1 function f (61 lines > 60)"]


def test_checker_accepts_a_long_because_reason_and_only_that():
    assert long_units(_function(80, "Sum. Long because one recipe.")) == []
    assert long_units(_function(80, "Not long because of anything.")) != []
    assert long_units(_function(80, "Sum of terms.")) != []


def test_checker_measures_methods_nested_functions_and_classes():
    method = "\n".join("    " + line for line in _function(61).splitlines())
    source = "class C:\n" + method + "\n" + "".join(f"    y{i} = {i}\n" for i in range(60))
    found = long_units(source)
    assert "<string>:2 function C.f (61 lines > 60)" in found
    assert "<string>:1 class C (122 lines > 120)" in found
    nested = "def outer():\n" + "\n".join("    " + ln for ln in _function(61).splitlines())
    assert "<string>:2 function outer.f (61 lines > 60)" in long_units(nested)
