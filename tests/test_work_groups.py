"""pytest-xdist's work groups (tests/conftest.py) hold every module that shares a session's runs.

A module that reads the documented commands' runs or the print loop's cached batches, and is
missing from ``SHARED_RUNS``, would still pass under ``pytest -n N``, but its worker would make
those runs a second time: the suite would be slower without any test saying so.
"""

from pathlib import Path

import pytest

from tests.asbuilt import printloop
from tests.conftest import SHARED_RUNS, WORK_GROUP, work_group

ROOT = Path(__file__).resolve().parents[1]

#: What each shared set is recognised by in a test: a fixture it requests, or a cached function
#: its module imports.
READS = {
    "documented_runs": lambda item: "documented_runs" in item.fixturenames,
    "printloop": lambda item: any(
        value is cache
        for value in vars(item.module).values()
        for cache in (printloop.printed, printloop.model_form)
    ),
}


class Collected:
    """The items of a collection."""

    items = ()

    def pytest_collection_finish(self, session):
        self.items = [item for item in session.items if hasattr(item, "module")]


def test_every_module_that_reads_shared_runs_is_in_their_group():
    collected = Collected()
    options = ["--collect-only", "-q", "-p", "no:cacheprovider", "-p", "no:xdist"]
    assert pytest.main([*options, str(ROOT / "tests")], plugins=[collected]) == 0
    items = collected.items
    assert len(items) > 1000, len(items)
    for group, reads in READS.items():
        readers = {item.nodeid.split("::")[0] for item in items if reads(item)}
        missing = sorted(module for module in readers if work_group(module) != group)
        assert not missing, f"add to SHARED_RUNS[{group!r}] in tests/conftest.py: {missing}"


def test_every_listed_module_exists_and_is_in_one_group():
    listed = [module for modules in SHARED_RUNS.values() for module in modules]
    assert len(listed) == len(WORK_GROUP), "a module listed in two groups"
    assert all((ROOT / module).is_file() for module in listed), listed
    assert work_group("tests/asbuilt/test_doe.py::test_x[1]") == "tests/asbuilt/test_doe.py"
    assert work_group("tests/test_outputs_unchanged.py::test_y") == "documented_runs"
