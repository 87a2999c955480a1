"""Each long command's progress, as the command line shows it, recorded call by call on small
inputs: it never runs backwards, starts near 0 %, ends at 100 %, and no single step leaves
most of the work without a report (issue 37: ``optimise`` went from 100 % to 24 %,
``--pareto`` sat at 100 %, ``identify`` at 10 %, ``--sensor auto`` said nothing at all)."""

import dataclasses

import numpy as np
import pytest

import reflector_opt.cli._output as output
from reflector_opt.cli import main
from tests.searchsettings import SMALL_SEARCH, write_settings

#: The largest share of the work one step may cover without a report in between.
LARGEST_SILENT_SHARE = 0.5


#: The calls of the last command's progress, (fraction, message).
CALLS = []


class Recorder:
    """Stands in for :class:`~reflector_opt.util._progress.Progress`: keeps every call."""

    def __init__(self, enabled=True, **_):
        CALLS.clear()

    def __call__(self, fraction, message):
        CALLS.append((float(fraction), message))

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


@pytest.fixture
def recorded(monkeypatch):
    monkeypatch.setattr(output, "Progress", Recorder)
    return CALLS


def _honest(calls):
    """The checks every command's progress passes; the calls' fractions."""
    fractions = [f for f, _ in calls]
    assert fractions, "no progress at all"
    assert fractions[0] <= 0.05
    assert fractions[-1] == 1.0
    steps = np.diff(fractions)
    assert np.all(steps >= 0), f"backwards: {calls}"
    assert steps.max(initial=0.0) <= LARGEST_SILENT_SHARE, calls
    return fractions


def _messages(calls, word):
    return [m for _, m in calls if word in m]


def _one_unit(design, folder):
    one = design.replace(mechanics=dataclasses.replace(design.mechanics, n_units=1))
    one.save(folder / "design.json")
    return str(folder / "design.json")


def test_optimise_with_a_pareto_front_covers_search_verification_and_front(recorded, tmp_path):
    settings = write_settings(tmp_path, SMALL_SEARCH + "[pareto]\nmargins_mm = [0.2, 0.1]\n")
    argv = ["optimise", "--config", settings, "--pareto", "--no-report", "-q"]
    assert main([*argv, "-o", str(tmp_path / "out")]) == 0
    calls = recorded
    fractions = _honest(calls)
    assert len(_messages(calls, "search generation")) >= 3 * 3  # the search and two levels
    verify = [f for f, m in calls if "verifying" in m and "margin" not in m]
    front = [f for f, m in calls if m.startswith("margin")]
    assert verify and front and max(verify) < min(front) < 1.0  # the front after the search
    assert fractions.index(max(verify)) < len(fractions) - len(front)


@pytest.mark.slow
def test_report_covers_parts_prediction_and_report(recorded, design, tmp_path):
    path = _one_unit(design, tmp_path)
    assert main(["report", path, "-o", str(tmp_path / "out"), "-q"]) == 0
    calls = recorded
    _honest(calls)
    for step in ("parts:", "calibrating built unit 1 of 1", "segment", "writing the report"):
        assert _messages(calls, step), step


def test_evaluate_reports_each_unit_it_calibrates(recorded, design, tmp_path):
    path = _one_unit(design, tmp_path)
    assert main(["evaluate", path, "-q"]) == 0
    calls = recorded
    _honest(calls)
    assert _messages(calls, "calibrating built unit 1 of 1")


def test_sweep_reports_its_batches_from_the_start(recorded, design, tmp_path):
    path = _one_unit(design, tmp_path)
    argv = ["sweep", path, "--vary", "reflector.radius_mm=6.5:7.5:3", "-q"]
    assert main([*argv, "-o", str(tmp_path / "out")]) == 0
    calls = recorded
    _honest(calls)
    assert calls[0][0] == 0.0
