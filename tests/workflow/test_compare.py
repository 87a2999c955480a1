"""``compare``: two designs side by side, checked against each design's own evaluation."""

import dataclasses
import json

import numpy as np
import pytest

from reflector_opt.analysis._metrics import evaluate_metrics
from reflector_opt.cli import main
from reflector_opt.design import load_design
from reflector_opt.workflow import compare
from reflector_opt.workflow._compare import COMPARE_STEP_DEG, compared_rows

EXAMPLE = "tests/data/design_6c47a9f.json"  # the white-noise sample design


@pytest.fixture(scope="module")
def compared(tmp_path_factory):
    out = tmp_path_factory.mktemp("compare") / "out"
    return compare(EXAMPLE, None, predict=False).write(out)


def _row(run, quantity):
    return next(r for r in run.rows if r["quantity"] == quantity)


def test_each_figure_is_each_design_s_own_and_the_difference_is_b_minus_a(compared, design):
    example = load_design(EXAMPLE)
    for given, side in ((example, "a"), (design, "b")):  # an independent path: the metrics
        metrics = evaluate_metrics(given, COMPARE_STEP_DEG)
        assert _row(compared, "metrics.worst_pitch_resolution_deg")[side] == pytest.approx(
            metrics.worst_pitch_deg
        )
    row = _row(compared, "sensors.S1.margin_mm")
    assert row["a"] == pytest.approx(0.1, abs=1e-5)  # the example keeps the 0.1 mm margin
    assert row["difference"] == pytest.approx(row["b"] - row["a"])
    assert "calibration.eq6.rms_deg.pitch" not in [r["quantity"] for r in compared.rows]


def test_the_figures_are_written_whole(compared):
    names = sorted(f.name for f in compared.files)
    assert names == ["resolution_difference.png", *(f"resolution_maps_{s}.png" for s in "ab")]
    assert all(f.stat().st_size > 0 for f in compared.files)
    manifest = json.loads((compared.out / "manifest.json").read_text())
    assert manifest


def test_a_figure_only_one_design_has_is_shown_without_a_difference():
    a = {"sensors": [{"name": "S1", "margin_mm": 0.1}], "metrics": {"w_deg": 1.0}}
    b = {"sensors": [{"name": "S9", "margin_mm": 0.3}], "metrics": {"w_deg": 0.5}}
    rows = {r["quantity"]: r for r in compared_rows(a, b)}
    assert rows["metrics.w_deg"]["difference"] == -0.5
    assert rows["sensors.S1.margin_mm"] == {
        "quantity": "sensors.S1.margin_mm",
        "a": 0.1,
        "b": None,
        "difference": None,
    }


def test_the_predicted_calibration_is_compared(tmp_path, design):
    one = dataclasses.replace(design.mechanics, n_units=1)
    run = compare(design.replace(mechanics=one), design.replace(mechanics=one))
    row = _row(run, "calibration.recommended.rms_deg.pitch")
    assert row["a"] == row["b"] > 0 and row["difference"] == 0  # the same seed, the same units
    assert np.isfinite(_row(run, "calibration.floor_rms_deg.pitch")["a"])


def test_the_command_prints_the_rows_as_json(tmp_path, capsys):
    argv = ["compare", EXAMPLE, "--no-predict", "--json", "-q", "-o", str(tmp_path / "c")]
    assert main(argv) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed["a"] == EXAMPLE and printed["b"] == "built-in default, in A's unit"
    assert any(r["quantity"] == "drift_sensitivity.common.pitch_rms_deg" for r in printed["rows"])


def test_a_missing_design_is_one_line_and_exit_2(tmp_path, capsys):
    assert main(["compare", str(tmp_path / "none.json"), "-o", str(tmp_path / "c")]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "none.json" in err
    assert not (tmp_path / "c").exists()


def test_the_two_are_compared_in_use_first_and_ranked(compared):
    """In the default conditions the white-noise sample design's worst case in use is 1.581°,
    the default design's 1.367°: B is the better, said before the figures' rows."""
    quantities = [r["quantity"] for r in compared.rows]
    assert quantities[:4] == [
        "in_use.worst_case_deg",
        "in_use.rms_deg",
        "in_use.median_deg",
        "in_use.white_noise_floor_deg",
    ]
    worst = _row(compared, "in_use.worst_case_deg")
    assert worst["a"] == pytest.approx(1.581, abs=5e-4)
    assert worst["b"] == pytest.approx(1.3665, abs=5e-4)
    assert compared.better_in_use == "b" and compared.to_dict()["in_use"]["better"] == "b"
    a, b = (s["in_use"] for s in compared.summaries)
    assert b.worst_case_deg == pytest.approx(a.baseline.worst_case_deg, rel=1e-12)
    text = compared.text().splitlines()
    assert text[2].startswith("in use in the default conditions (docs/conditions.md)")
    worse, median = worst["b"] / worst["a"], b.median_deg / a.median_deg
    assert (
        text[5]
        == f"  in use B is the better: B's worst case is {worse:.2f}× A's, its median {median:.2f}×"
    )
    assert text.index(next(t for t in text if t.startswith("quantity"))) == 7


def test_a_design_alone_is_compared_with_the_built_in_geometry_in_its_own_unit():
    """``compare A``: B is the default design ``evaluate`` and ``optimise`` compare A with,
    the built-in geometry in A's unit (here the GE 4 E's 20 mm unit), not the paper's 22 mm."""
    from reflector_opt.design._defaults import default_design
    from tests.workflow.test_smallest import POINT_20MM

    run = compare(POINT_20MM, predict=False)
    assert run.designs[1] == default_design(like=POINT_20MM) != default_design()
    assert run.designs[1].mechanics == POINT_20MM.mechanics
    assert run.sources == ("given", "built-in default, in A's unit")
