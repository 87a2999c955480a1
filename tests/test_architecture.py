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
    "tolerance",
    "asbuilt",
    "optimise",
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
    "reflector_opt.util.errors.": "InputError and its kinds: exit code 2, one line",
    "reflector_opt.util.crashlog.": "the crash log of an internal error",
    "reflector_opt.util.interrupts.": "Ctrl-C held through imports that would swallow it",
    "reflector_opt.util.atomic.": "the output folder's checks, named by --out; MANIFEST",
    "reflector_opt.util.limits.": "the parsers' bounds (poses, lengths, units)",
    "reflector_opt.util.units.": "the parsers' unit checks",
    "reflector_opt.util.fileio.json_number": "--json's numbers (NaN as null)",
    "reflector_opt.util.progress.": "the progress display",
    "reflector_opt.calibration.choices.FITS": "--fit's choices",
    "reflector_opt.design.parts.DEFAULT_TOLERANCE_MM": "--chord-tolerance's default",
    "reflector_opt.model.surface.DEFAULT_MATERIAL": "--material's default",
    "reflector_opt.model.surface.MATERIALS": "--material's choices",
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


# --- tests mirror the package --------------------------------------------------------------------

TESTS = Path(__file__).resolve().parent

_COMMAND = "a command (parse, call, print): its runs, parser and text are tested in "
_SCHEMA = "a schema: its published JSON Schema and messages are tested in tests/util/test_schema.py"

#: Modules without their own ``tests/<package>/test_<module>.py`` and where they are tested
#: instead. The list only shrinks: a module that gains its test module must leave it.
MIRROR_ALLOWLIST = {
    "calibration.schema": _SCHEMA,
    "cli.compare": _COMMAND + "tests/workflow/test_compare.py",
    "cli.estimate": _COMMAND + "tests/workflow/test_estimate.py, tests/cli/test_calibrate.py",
    "cli.export": _COMMAND + "tests/workflow/test_export.py",
    "cli.plan_calibration": _COMMAND + "tests/workflow/test_plan_calibration.py",
    "cli.report": _COMMAND + "tests/workflow/test_report.py, tests/report/test_report.py",
    "cli.smallest": _COMMAND + "tests/workflow/test_smallest.py",
    "cli.sweep": _COMMAND + "tests/workflow/test_sweep.py",
    "cli.tolerance": _COMMAND + "tests/workflow/test_tolerance.py",
    "optimise.schema": _SCHEMA,
    "report.plots": "a re-export namespace of reflector_opt.report.figures (tests/report/figures/)",
    "tolerance.schema": _SCHEMA,
}


def _test_modules():
    """Each module of the package (not ``__init__``/``__main__``) and its mirrored test module."""
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE)
        if path.stem in ("__init__", "__main__"):
            continue
        name = ".".join(rel.with_suffix("").parts)
        out[name] = TESTS.joinpath(*rel.parts[:-1], f"test_{rel.name}")
    return out


def test_every_module_has_its_test_module():
    """docs/architecture.md: reflector_opt/<package>/<module>.py is tested in
    tests/<package>/test_<module>.py, or is listed in MIRROR_ALLOWLIST with the reason."""
    missing = {name for name, test in _test_modules().items() if not test.is_file()}
    unlisted = sorted(missing - set(MIRROR_ALLOWLIST))
    assert not unlisted, f"modules without their test module: {unlisted}"


def test_the_mirror_allowlist_only_shrinks():
    """A listed module that gained its test module (or is gone) leaves the list."""
    modules = _test_modules()
    stale = sorted(m for m in MIRROR_ALLOWLIST if m not in modules or modules[m].is_file())
    assert not stale, f"remove from MIRROR_ALLOWLIST: {stale}"
