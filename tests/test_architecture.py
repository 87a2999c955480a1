"""The package's layers (docs/architecture.md): every import points down, and no circle."""

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "reflector_opt"

#: Subpackages from the bottom layer to the top; a module may import its own layer and those below.
LAYERS = (
    "util",
    "model",
    "design",
    "analysis",
    "calibration",
    "robot",
    "tolerance",
    "asbuilt",
    "optimiser",
    "cad",
    "report",
    "workflow",
    "cli",
)


def _module_name(path):
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path):
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            if node.module == "reflector_opt":
                found.update(f"reflector_opt.{alias.name}" for alias in node.names)
            else:
                found.add(node.module)
        elif isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
    # ``from reflector_opt import __version__`` reads metadata, not a layer
    return {
        name
        for name in found
        if name.startswith("reflector_opt.") and not name.startswith("reflector_opt.__")
    }


MODULES = {
    _module_name(path): _imports(path)
    for path in sorted(PACKAGE.rglob("*.py"))
    if path.parent != PACKAGE  # the package root re-exports the public API
}


def _layer(module):
    return module.split(".")[1]


def test_every_module_lives_in_a_layer():
    assert {_layer(module) for module in MODULES} <= set(LAYERS)
    root_modules = {p.stem for p in PACKAGE.glob("*.py")}
    assert root_modules == {"__init__", "__main__"}


def test_the_architecture_figure_draws_these_layers_in_this_order():
    """docs/figures/architecture.png is drawn from make_figures.LAYERS: these layers, top down."""
    import importlib.util

    path = PACKAGE.parent / "docs" / "figures" / "make_figures.py"
    spec = importlib.util.spec_from_file_location("make_figures", path)
    figures = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(figures)
    assert [name for name, *_ in figures.LAYERS] == list(reversed(LAYERS))


@pytest.mark.parametrize("module", sorted(MODULES))
def test_imports_point_down_the_layers(module):
    rank = LAYERS.index(_layer(module))
    upward = {name for name in MODULES[module] if LAYERS.index(_layer(name)) > rank}
    assert not upward, f"{module} imports from a layer above it: {sorted(upward)}"


def test_no_import_cycle():
    graph = {
        module: {name for name in imports if name in MODULES and name != module}
        for module, imports in MODULES.items()
    }
    state = {}

    def visit(module, path):
        state[module] = "open"
        for name in graph[module]:
            if state.get(name) == "open":
                cycle = [*path[path.index(name) :], name]
                raise AssertionError("import cycle: " + " -> ".join(cycle))
            if name not in state:
                visit(name, [*path, name])
        state[module] = "done"

    for module in graph:
        if module not in state:
            visit(module, [module])


def _imported_names(path):
    """Every ``reflector_opt`` name a module imports, as ``module.name`` (``import`` of a
    whole module: its name)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found.update(f"{node.module}.{alias.name}" for alias in node.names)
        elif isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
    return {name for name in found if name.startswith("reflector_opt.")}


#: What a command module may import from the library besides ``reflector_opt.workflow`` (its
#: run) and ``reflector_opt.cli`` (the parser's vocabulary and the printer), each for the
#: parser or the printer, from a module light enough for ``--help`` (tests/test_startup.py).
CLI_HELPERS = {
    "reflector_opt.__version__": "``--version``",
    "reflector_opt.util._errors.": "InputError and its kinds: exit code 2, one line",
    "reflector_opt.util._crashlog.": "the crash log of an internal error",
    "reflector_opt.util._interrupts.": "Ctrl-C held through imports that would swallow it",
    "reflector_opt.util._atomic.": "the output folder's checks, named by --out; MANIFEST",
    "reflector_opt.util._limits.": "the parsers' bounds (poses, lengths, units)",
    "reflector_opt.util._units.": "the parsers' unit checks",
    "reflector_opt.util._fileio.json_number": "--json's numbers (NaN as null)",
    "reflector_opt.util._progress.": "the progress display",
    "reflector_opt.util._declared.": "each run's declared options: the parser and the check",
    "reflector_opt.util._fileio.write_text": "docs/cli.md written whole",
    "reflector_opt.optimiser._size.judged_deg": "the figure smallest's table prints per row",
}

CLI_MODULES = {
    _module_name(path): _imported_names(path) for path in sorted((PACKAGE / "cli").glob("*.py"))
}


def _beyond_the_workflow(names):
    return {
        name
        for name in names
        if not name.startswith(("reflector_opt.workflow", "reflector_opt.cli"))
        and not any(name == h or (h.endswith(".") and name.startswith(h)) for h in CLI_HELPERS)
    }


@pytest.mark.parametrize("module", sorted(CLI_MODULES))
def test_a_command_imports_its_workflow_the_parser_and_the_printer(module):
    """docs/architecture.md: a command parses, calls its workflow and prints."""
    beyond = _beyond_the_workflow(CLI_MODULES[module])
    assert not beyond, f"{module} does a workflow's work: imports {sorted(beyond)}"


def _public_modules():
    """The modules whose names are public: none of their path's parts private."""
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        if not any(p.startswith("_") and p not in ("__init__", "__main__") for p in parts):
            yield ".".join(parts[:-1] if parts[-1] == "__init__" else parts), path


def _public_names(module, path):
    """A module's ``__all__``, or its public top-level definitions where it has none."""
    import importlib

    names = getattr(importlib.import_module(module), "__all__", None)
    if names is not None:
        return list(names)
    defined = []
    for node in ast.parse(path.read_text(encoding="utf-8")).body:
        if isinstance(node, ast.FunctionDef | ast.ClassDef):
            defined.append(node.name)
        elif isinstance(node, ast.Assign):
            defined += [target.id for target in node.targets if isinstance(target, ast.Name)]
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            defined.append(node.target.id)
    return [name for name in defined if not name.startswith("_")]


def test_the_public_api_is_at_most_150_names_each_in_the_api_reference():
    """The package's public names, summed over its public modules (the packages' curated
    ``__all__``; every other module is private), number at most 150, and each is in
    docs/api.rst's reference (by its package's page or by name)."""
    counted = {module: _public_names(module, path) for module, path in _public_modules()}
    assert sum(len(names) for names in counted.values()) <= 150, {
        module: len(names) for module, names in counted.items() if names
    }
    api = (PACKAGE.parent / "docs" / "api.rst").read_text(encoding="utf-8")
    missing = [
        f"{module}.{name}"
        for module, names in counted.items()
        for name in names
        if f"{module}.{name}" not in api and f"automodule:: {module}\n" not in api
    ]
    assert not missing, missing


def test_no_module_imports_a_private_name_of_another_module():
    """Only a private module is imported by a private name (``_shapes`` of ``cad``); a
    leading-underscore function, class or constant stays in its module."""
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not (isinstance(node, ast.ImportFrom) and node.level == 0 and node.module):
                continue
            folder = PACKAGE.parent / node.module.replace(".", "/")
            for alias in node.names:
                private = alias.name.startswith("_") and not alias.name.startswith("__")
                module = (folder / f"{alias.name}.py").exists() or (folder / alias.name).is_dir()
                if node.module.startswith("reflector_opt") and private and not module:
                    found.append(f"{path.relative_to(PACKAGE.parent)}: {alias.name}")
    assert not found, found
