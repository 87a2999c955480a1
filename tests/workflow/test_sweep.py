"""sweep: the command's sweep as one library call, with what it wrote and said."""

import csv
import json

import pytest

from reflector_opt.cli import main
from reflector_opt.workflow import SweepRun, sweep

VARY = ["reflector.radius_mm=8.35:8.55:2"]


@pytest.fixture(scope="module")
def design_file(tmp_path_factory, design):
    path = tmp_path_factory.mktemp("sweep_run") / "design.json"
    design.save(path)
    return path


@pytest.fixture(scope="module")
def swept(design_file):
    return sweep(design_file, VARY).write(design_file.parent / "out")


def test_each_points_margin_is_its_designs_distance_window(design, swept):
    """Independent path: each point's design evaluated over its workspace
    (:func:`~reflector_opt.workflow._evaluate`); the margin is the least room
    between a sensor's distances and its range, at either end. The near end moves one for one
    with the radius (the nearest pose sees the sphere's surface along its normal)."""
    from dataclasses import replace

    from reflector_opt.workflow import evaluate

    assert isinstance(swept, SweepRun)
    assert [r["reflector.radius_mm"] for r in swept.rows] == [8.35, 8.55]
    near = []
    for row in swept.rows:
        reflector = replace(design.reflector, radius_mm=row["reflector.radius_mm"])
        built = design.replace(reflector=reflector)
        sensors = evaluate(built, predict=False).summary.sensors
        ends = [
            (s.distance_mm.min - s.range_mm[0], s.range_mm[1] - s.distance_mm.max) for s in sensors
        ]
        near.append(min(low for low, _ in ends))
        expected = min(min(pair) for pair in ends)
        assert row["nominal_distance_margin_mm"] == pytest.approx(expected, abs=1e-9)
    assert near[0] - near[1] == pytest.approx(0.2, abs=1e-9)


def test_the_table_is_written_as_it_is_held(swept):
    assert [f.name for f in swept.files] == ["sweep.csv", "sweep.png"]
    with swept.files[0].open() as handle:
        rows = list(csv.DictReader(handle))
    assert [float(r["nominal_rms_pitch_deg"]) for r in rows] == [
        r["nominal_rms_pitch_deg"] for r in swept.rows
    ]
    first = swept.text().splitlines()[0]
    assert first.startswith("reflector.radius_mm=8.35: in-use worst case ")
    assert "°, white-noise worst 1σ pitch/roll " in first
    assert swept.to_dict()["files"] == ["sweep.csv", "sweep.png"]


def test_the_command_prints_the_runs_text_and_summary(design_file, swept, tmp_path, capsys):
    argv = ["sweep", str(design_file), "--vary", VARY[0], "-q", "-o"]
    assert main([*argv, str(tmp_path / "a")]) == 0
    assert capsys.readouterr().out.startswith(swept.text() + "\nwrote 3 files in ")
    assert main([*argv, str(tmp_path / "b"), "--json"]) == 0
    expected = {**swept.to_dict(), "folder": str(tmp_path / "b")}
    assert json.loads(capsys.readouterr().out) == json.loads(json.dumps(expected))


def test_each_points_in_use_worst_case_is_its_designs_budget(design, swept, tmp_path):
    """Independent path: the point's design's error budget in the default conditions, and in
    stated ones (an encoder rig's reference) the sweep judges the points in."""
    from dataclasses import replace

    from reflector_opt.analysis._budget import error_budget
    from reflector_opt.design._conditions import Conditions

    encoder = Conditions().replace(angle_reference="encoder")
    path = tmp_path / "cond.toml"
    path.write_text('[conditions]\nangle_reference = "encoder"\n')
    stated = sweep(design, VARY[:1], conditions=str(path)).write(tmp_path / "out")
    for row, other in zip(swept.rows, stated.rows, strict=True):
        reflector = replace(design.reflector, radius_mm=row["reflector.radius_mm"])
        built = design.replace(reflector=reflector)
        for judged, conditions in ((row, Conditions()), (other, encoder)):
            expected = error_budget(built, conditions).worst_case_deg
            assert judged["nominal_worst_case_deg"] == pytest.approx(expected, rel=1e-9)
        assert other["nominal_worst_case_deg"] < row["nominal_worst_case_deg"]  # no 1° zero
