"""Shared fixtures, the property tests' settings, and how pytest-xdist shares out the tests."""

import os

import matplotlib
import pytest
from hypothesis import settings

matplotlib.use("Agg")

from reflector_opt import default_design

#: The property tests draw the same examples on every run ("repeatable", the default), so a
#: run of the suite is reproducible; ``HYPOTHESIS_PROFILE=explore`` draws new ones each run.
settings.register_profile("repeatable", derandomize=True)
settings.register_profile("explore", derandomize=False)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repeatable"))


def pytest_addoption(parser):
    parser.addoption(
        "--regenerate-golden",
        action="store_true",
        help="tests/test_outputs_unchanged.py: write the documented commands' outputs as the "
        "new golden copies instead of comparing them (only for an intended output change)",
    )


@pytest.fixture(scope="session")
def design():
    """The built-in default design."""
    return default_design()


@pytest.fixture(scope="session")
def documented_runs(tmp_path_factory):
    """The documented commands run so far (``tests/test_documented_commands.py``), so each runs
    once a session, whichever test needs it first: the scratch folder (``done``), the printed
    text (``printed``) and the files written (``written``) of each, by command line."""
    root = tmp_path_factory.mktemp("documented")
    return {"root": root, "done": {}, "printed": {}, "written": {}}


#: Test modules that share one session's runs, so pytest-xdist keeps each set on one worker
#: and no run is made twice: the documented commands' runs (the ``documented_runs`` fixture)
#: and the print loop's batches (tests/asbuilt/printloop.py's cached ``printed`` and
#: ``model_form``). tests/test_work_groups.py checks that every module reading them is listed.
SHARED_RUNS = {
    "documented_runs": ("tests/test_documented_commands.py", "tests/test_outputs_unchanged.py"),
    "printloop": (
        "tests/asbuilt/test_asbuiltfile.py",
        "tests/asbuilt/test_batch.py",
        "tests/asbuilt/test_batchforecast.py",
        "tests/asbuilt/test_correction.py",
        "tests/asbuilt/test_estimator.py",
        "tests/asbuilt/test_model_form_bias.py",
        "tests/asbuilt/test_result.py",
        "tests/cli/test_correct.py",
        "tests/workflow/test_correct.py",
    ),
}

#: The set of :data:`SHARED_RUNS` each module belongs to.
WORK_GROUP = {module: group for group, modules in SHARED_RUNS.items() for module in modules}


def work_group(nodeid):
    """The tests one pytest-xdist worker runs together: a test module's, or a set of
    :data:`SHARED_RUNS` (so a module's fixtures and a session's shared runs are made once)."""
    module = nodeid.split("::")[0]
    return WORK_GROUP.get(module, module)


class WorkGroupScheduling:
    """pytest-xdist's scheduler of :func:`work_group`, registered when xdist is installed."""

    @staticmethod
    def pytest_xdist_make_scheduler(config, log):
        """Under ``pytest -n N`` (its default ``--dist load``), schedule by :func:`work_group`:
        xdist's ``loadscope`` with the scope of a test being its work group. Its scopes go out
        largest first (``--loadscope-reorder``), so the long sets start early."""
        if config.getoption("dist") != "load":
            return None
        from xdist.scheduler import LoadScopeScheduling

        class ByWorkGroup(LoadScopeScheduling):
            def _split_scope(self, nodeid):
                return work_group(nodeid)

        return ByWorkGroup(config, log)


def pytest_configure(config):
    if config.pluginmanager.hasplugin("xdist"):
        config.pluginmanager.register(WorkGroupScheduling(), "work-group-scheduling")
