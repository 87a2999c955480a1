"""The main job in a notebook with the top-level names: each run computed in memory, nothing
written before its ``write``, and what ``write`` writes is what the commands write."""

import json
import warnings
from pathlib import Path

import pytest

import reflector_opt as ro
from reflector_opt.optimiser._config import load_config
from tests.searchsettings import write_settings

DATA = Path(__file__).resolve().parents[2] / "examples" / "data"
CONDITIONS = Path(__file__).resolve().parents[2] / "examples" / "conditions.toml"


def _tree(folder):
    """Every path under ``folder`` with its size and modification time."""
    return {p: (p.stat().st_size, p.stat().st_mtime_ns) for p in sorted(Path(folder).rglob("*"))}


@pytest.mark.slow
def test_the_main_job_writes_nothing_before_write(tmp_path, monkeypatch):
    settings = load_config(write_settings(tmp_path))
    (tmp_path / "settings.toml").unlink()
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    examples = _tree(DATA)

    # the main job, line by line as a notebook has it
    run = ro.optimise(
        ro.OptimiseOptions(config=settings, sensor="NJL5901R-2", conditions=CONDITIONS)
    )
    evaluated = ro.evaluate(run.design, conditions=CONDITIONS, predict=False)
    parts = ro.export(run.design, part="reflector", preview=False)
    calibration = ro.calibrate(DATA / "data.csv")
    angles = ro.estimate(calibration, DATA / "log.csv")

    assert angles.shape.angles_deg.shape[-1] == 2  # estimated in memory
    assert list(work.iterdir()) == [] and list(tmp_path.iterdir()) == [work]
    assert _tree(DATA) == examples
    assert run.files == () and run.out is None and parts.files == () and calibration.files == ()
    # the figures a user reads, typed and in use
    in_use = evaluated.summary.in_use
    assert 0 < in_use.white_noise_floor_deg < in_use.worst_case_deg < 5
    assert run.design.predicted.conditions.worst_case_deg > 0
    assert parts.report["printability"]["reflector"]["ok"]

    written = run.write(work / "design")
    assert written.files[0] == work / "design" / "design.json" and written.predicted is not None
    assert (
        json.loads(written.files[0].read_text())["reflector"] == run.design.to_dict()["reflector"]
    )
    assert {p.name for p in parts.write(work / "parts").files} >= {"reflector.stl", "reflector.3mf"}
    assert calibration.write(work / "coef.json").files == (work / "coef.json",)
    angles = angles.write(work / "angles.csv")
    assert (work / "angles.csv").read_text().count("\n") == angles.instants + 1  # and a header


def test_estimate_streams_into_its_file_when_the_angles_are_not_in_memory(tmp_path):
    """Written straight from the log (bounded memory) or from the angles in memory: the same
    file."""
    calibration = ro.calibrate(DATA / "data.csv", model="poly5", folds=0)
    streamed = ro.estimate(calibration, DATA / "log.csv").write(tmp_path / "a.csv")
    in_memory = ro.estimate(calibration, DATA / "log.csv")
    assert in_memory.shape.tip_angles_deg is not None
    in_memory = in_memory.write(tmp_path / "b.csv")
    assert (tmp_path / "a.csv").read_bytes() == (tmp_path / "b.csv").read_bytes()
    assert streamed.counts == in_memory.counts and streamed.text() == in_memory.text()


@pytest.mark.parametrize(
    ("alias", "call"),
    [
        (
            "calibrate_run",
            lambda w, out: w.calibrate_run(DATA / "data.csv", out / "c.json", folds=0),
        ),
        ("evaluate_run", lambda w, out: w.evaluate_run(DATA / "design.json", predict=False)),
    ],
)
def test_the_earlier_names_warn_and_still_work(alias, call, tmp_path):
    from reflector_opt import workflow

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        run = call(workflow, tmp_path)
    assert any(
        issubclass(w.category, DeprecationWarning) and alias in str(w.message) for w in caught
    )
    assert run.text()


@pytest.mark.slow
def test_readmes_main_job_runs_as_written(tmp_path, monkeypatch):
    """README's main job, run from a copy of the repository's root: it writes only where it
    says, and only by ``write``."""
    readme = (DATA.parents[1] / "README.md").read_text(encoding="utf-8")
    code = readme.split("<!-- main-job -->", 1)[1].split("```python\n", 1)[1].split("```", 1)[0]
    assert len(code.strip().splitlines()) <= 8
    (tmp_path / "examples").symlink_to(DATA.parent)
    monkeypatch.chdir(tmp_path)
    namespace = {}
    exec(compile(code, "README.md", "exec"), namespace)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cad_out", "examples"]
    assert [p.name for p in (tmp_path / "cad_out").iterdir()] == ["parts"]
    assert (tmp_path / "cad_out" / "parts" / "body.stl").exists()
    assert namespace["angles"].tip_angles_deg.shape[1] >= 2
