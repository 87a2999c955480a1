"""The package's size as issue 47 counts it: lines of code and public names.

Run from the repository root: ``python benchmarks/code_size.py``.

Lines of code are physical lines holding a statement's tokens, without docstrings, comments
or blank lines. Public names are summed over the package's public modules (a module's
``__all__``, or its public top-level definitions where it has none); a module under a
leading-underscore name is not counted (tests/test_architecture.py holds the same count).
"""

from __future__ import annotations

import ast
import io
import sys
import tokenize
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

SKIPPED = {tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT}


def code_lines(path):
    """The lines of ``path`` that hold a statement's tokens, docstrings left out."""
    source = path.read_text(encoding="utf-8")
    docstrings = set()
    for node in ast.walk(ast.parse(source)):
        body = getattr(node, "body", None)
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
            first = body[0] if body else None
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
                if isinstance(first.value.value, str):
                    docstrings.update(range(first.lineno, first.end_lineno + 1))
    lines = set()
    for token in tokenize.generate_tokens(io.StringIO(source).readline):
        if token.type not in SKIPPED and token.type != tokenize.ENDMARKER:
            lines.update(range(token.start[0], token.end[0] + 1))
    return len(lines - docstrings)


def main():
    from test_architecture import _public_modules, _public_names

    package = ROOT / "reflector_opt"
    total = sum(code_lines(path) for path in package.rglob("*.py"))
    public = sum(len(_public_names(module, path)) for module, path in _public_modules())
    print(f"lines of code: {total:,}")
    print(f"public names: {public}")


if __name__ == "__main__":
    main()
