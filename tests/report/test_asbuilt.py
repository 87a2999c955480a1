"""The report's as-built section: the print beside the design, what each deviation costs in
resolution, the determinable combinations; a file of another design refused; the report
without an as-built file unchanged."""

import json
from dataclasses import replace

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reflector_opt import default_design
from reflector_opt.analysis._metrics import evaluate_metrics
from reflector_opt.asbuilt import identify, load_as_built
from reflector_opt.calibration._plans import make_plan
from reflector_opt.cli import main
from reflector_opt.design import Workspace
from reflector_opt.model._noise import Mismatch
from reflector_opt.report._asbuilt import (
    AS_BUILT_SECTION,
    check_same_design,
    deviation_records,
    resolution_costs,
    unit_resolution,
)
from reflector_opt.report._render import render_markdown
from reflector_opt.report._report import report_blocks
from reflector_opt.tolerance._builtunit import build_unit, built_unit_protocol
from reflector_opt.tolerance._prediction import predicted_performance
from reflector_opt.util._errors import InputError

#: Half-width of a normal 90 % interval, in standard deviations.
Z90 = 1.6448536269514722


@pytest.fixture(scope="module")
def coarse():
    """The default design on a 1° grid, so that the report runs in seconds."""
    return default_design().replace(workspace=Workspace(step_deg=1.0))


@pytest.fixture(scope="module")
def as_built_path(coarse, tmp_path_factory):
    """AS_BUILT.json of one simulated unit of the coarse design, and the design file."""
    folder = tmp_path_factory.mktemp("asbuilt")
    unit = build_unit(coarse, 0, seed=1)
    plan = make_plan(coarse.workspace, "sobol", 200)
    data = built_unit_protocol(unit, plan, n_validation=10, seed=0).calibration
    # the reference anchored (exact, as the data's is): the print's reflector is determined
    result = identify(coarse, {"U1": (data.volts, data.angles_deg)}, reference_std=None)
    result.save(folder / "AS_BUILT.json", source="cal.csv")
    coarse.save(folder / "design.json")
    # and with the reference's zeros and twist fitted, its readings 2° off in pitch
    read = data.angles_deg + np.array([2.0, 0.0])
    free = identify(coarse, {"U1": (data.volts, read)}, profiles=False, model_form=None)
    free.save(folder / "AS_BUILT_reference.json", source="cal.csv")
    return folder / "AS_BUILT.json"


@pytest.mark.slow
def test_the_reference_found_is_reported_with_what_it_trades_with(coarse, as_built_path):
    anchored = _section(report_blocks(coarse, step_deg=3.0, as_built=as_built_path)[0])
    start = anchored.index(("h3", "Angle reference of unit U1"))
    assert "Taken as exact" in anchored[start + 1][1]
    path = as_built_path.parent / "AS_BUILT_reference.json"
    section = _section(report_blocks(coarse, step_deg=3.0, as_built=path)[0])
    rows = {row[0]: row for row in _tables(section, "Angle reference of unit U1")}
    found = json.loads(path.read_text(encoding="utf-8"))["units"][0]["reference"]
    assert set(rows) == {"reference pitch zero", "reference roll zero", "reference twist"}
    pitch = found["reference_pitch_zero_deg"]
    assert rows["reference pitch zero"][1] == f"{pitch['estimate']:+.3f} ± {pitch['std']:.3f}"
    assert rows["reference pitch zero"][4].startswith("reflector centre x (-0.")
    assert rows["reference pitch zero"][5] == pitch["combination"]


@pytest.fixture(scope="module")
def predicted(coarse):
    return predicted_performance(coarse, seed=0)


@pytest.fixture(scope="module")
def with_section(coarse, as_built_path, predicted):
    return report_blocks(coarse, predicted=predicted, as_built=as_built_path)


def _section(blocks):
    """The blocks of the as-built section."""
    start = blocks.index(("h2", AS_BUILT_SECTION))
    end = next(k for k in range(start + 1, len(blocks)) if blocks[k][0] == "h2")
    return blocks[start:end]


def _tables(section, heading):
    """The rows of the tables under an h3 heading of the section."""
    start = section.index(("h3", heading))
    rows = []
    for block in section[start + 1 :]:
        if block[0] == "h3":
            break
        if block[0] == "table":
            rows += block[2]
    return rows


def _expected_row(row):
    """Deviation ± std and the 90 % interval of a parameter, straight from the file."""
    deviation = row["estimate"] - row["design"]
    if "interval_90" in row:
        low = row["interval_90"]["low"] - row["design"]
        high = row["interval_90"]["high"] - row["design"]
        mark = "" if row["interval_90"]["closed"] else " (open)"
    else:
        low, high, mark = deviation - Z90 * row["std"], deviation + Z90 * row["std"], " (normal)"
    return (
        f"{deviation:+.4f} ± {row['std']:.4f}",
        f"{low:+.4f} to {high:+.4f}{mark}",
        f"{row['prior_std']:.4f}",
        "**yes**" if row["identifiable"] else "no",
    )


@pytest.mark.slow
def test_section_holds_each_parameter_beside_the_design(with_section, as_built_path):
    blocks, figures = with_section
    document = json.loads(as_built_path.read_text(encoding="utf-8"))
    section = _section(blocks)
    by_key = {row[-1].strip("`"): row for row in _tables(section, "Unit U1")}
    parameters = document["units"][0]["parameters"]
    assert set(by_key) == set(parameters)
    # the radius carries a profile-likelihood interval, the gain the normal one
    assert "interval_90" in parameters["reflector_radius_mm"]
    assert "interval_90" not in parameters["sensor_1_gain"]
    for key in ("reflector_radius_mm", "sensor_1_gain", "reflector_centre_x_mm"):
        row = by_key[key]
        assert (row[3], row[4], row[5], row[7]) == _expected_row(parameters[key])
    assert by_key["reflector_radius_mm"][:3] == ("reflector radius", "mm", "9.0000")
    assert by_key["sensor_1_gain"][1:3] == ("–", "1.0000")
    surface = {row[-1].strip("`"): row for row in _tables(section, "Batch surface")}
    row = surface["reflectance"]
    assert (row[3], row[4], row[5], row[7]) == _expected_row(document["shared"]["reflectance"])
    # the figure: every parameter once, the batch's surface and the unit as two series
    assert "as_built_deviations.png" in figures
    assert ("img", "as_built_deviations.png") in [b[:2] for b in section]
    combinations = _tables(section, "Determinable combinations")
    names = [c["name"] for c in document["units"][0]["determined"]]
    assert [row[1] for row in combinations] == names and names


@pytest.mark.slow
def test_section_sits_after_the_prediction_and_in_the_contents(with_section):
    blocks, _ = with_section
    headings = [b[1] for b in blocks if b[0] == "h2"]
    at = headings.index(AS_BUILT_SECTION)
    # the units as built follow the prediction, and what a unit meets in use follows them
    assert headings[at - 1 : at + 2] == ["Predicted performance", AS_BUILT_SECTION, "In use"]
    assert "[As built](#as-built)" in _contents(blocks)[1]


def test_resolution_is_the_reports_cramer_rao_bound(coarse):
    metrics = evaluate_metrics(coarse)
    nominal = unit_resolution(coarse)
    assert nominal["worst_pitch_deg"] == pytest.approx(metrics.worst_pitch_deg, rel=1e-12)
    assert nominal["worst_roll_deg"] == pytest.approx(metrics.worst_roll_deg, rel=1e-12)
    rms = np.sqrt(np.mean(metrics.resolution_pitch_deg**2))
    assert nominal["rms_pitch_deg"] == pytest.approx(rms, rel=1e-12)
    # offsets shift the voltages and leave their slopes; a gain of 2 halves every bound
    shifted = unit_resolution(coarse, Mismatch((1.0, 1.0), (0.3, -0.2)))
    assert shifted == pytest.approx(nominal, rel=1e-12)
    doubled = unit_resolution(coarse, Mismatch((2.0, 2.0), (0.0, 0.0)))
    assert_allclose(list(doubled.values()), 0.5 * np.array(list(nominal.values())), rtol=1e-12)


#: Reflector deviations and the field of the design each moves.
_BY_HAND = {
    "reflectance": None,
    "specular_fraction": None,
    "reflector_radius_mm": None,
    "reflector_centre_x_mm": 0,
    "reflector_centre_y_mm": 1,
    "reflector_centre_z_mm": 2,
}


def _by_hand(design, name, deviation):
    """The design with one reflector deviation, written out without the as-built layout."""
    reflector = design.reflector
    if _BY_HAND[name] is None:
        field = "radius_mm" if name == "reflector_radius_mm" else name
        moved = replace(reflector, **{field: getattr(reflector, field) + deviation})
    else:
        centre = list(reflector.centre_mm)
        centre[_BY_HAND[name]] += deviation
        moved = replace(reflector, centre_mm=tuple(centre))
    return design.replace(reflector=moved)


@pytest.mark.slow
def test_deviation_costs_are_ranked_and_each_is_the_deviation_alone(coarse, as_built_path):
    as_built = load_as_built(as_built_path)
    costs = resolution_costs(as_built, coarse)
    nominal = evaluate_metrics(coarse).worst_resolution_deg
    assert costs["nominal"]["worst_deg"] == pytest.approx(nominal, rel=1e-12)
    unit = costs["units"][0]
    determined = [
        r["name"]
        for r in deviation_records({**as_built.shared, **as_built.units[0]["parameters"]})
        if r["determined"]
    ]
    assert sorted(c["name"] for c in unit["costs"]) == sorted(determined)
    sizes = [abs(c["change_deg"]) for c in unit["costs"]]
    assert sizes == sorted(sizes, reverse=True)
    # a deviation of the reflector alone, applied by hand to the design
    reflector = [c for c in unit["costs"] if c["name"] in _BY_HAND]
    assert reflector, "the fixture's unit should have a determined reflector deviation"
    for cost in reflector:
        alone = evaluate_metrics(_by_hand(coarse, cost["name"], cost["deviation"]))
        assert cost["worst_deg"] == pytest.approx(alone.worst_resolution_deg, rel=1e-12)
        change = alone.worst_resolution_deg - nominal
        assert cost["change_deg"] == pytest.approx(change, rel=1e-9, abs=1e-15)
    # the unit as built: its own design and gains
    built = as_built.units[0]
    gains = np.asarray(built["read_out"].gain)
    assert unit["resolution"]["worst_deg"] == pytest.approx(
        unit_resolution(built["as_built"], Mismatch(tuple(gains), (0.0,) * len(gains)))["worst_deg"]
    )


@pytest.mark.slow
def test_a_deviation_switched_off_costs_nothing(coarse, as_built_path, tmp_path):
    document = json.loads(as_built_path.read_text(encoding="utf-8"))
    before = resolution_costs(load_as_built(as_built_path), coarse)["units"][0]["costs"]
    top = before[0]["name"]
    assert top in document["units"][0]["parameters"] or top in document["shared"]
    table = document["units"][0]["parameters"]
    row = table[top] if top in table else document["shared"][top]
    row["estimate"] = row["design"]
    row.pop("interval_90", None)
    path = tmp_path / "off.json"
    path.write_text(json.dumps(document), encoding="utf-8")
    after = resolution_costs(load_as_built(path), coarse)["units"][0]["costs"]
    switched = [c for c in after if c["name"] == top]
    assert switched[0]["deviation"] == 0.0
    assert switched[0]["change_deg"] == pytest.approx(0.0, abs=1e-12)
    assert after[-1]["name"] == top or abs(after[-1]["change_deg"]) < 1e-12
    # every other deviation costs what it cost before
    rest = {c["name"]: c["change_deg"] for c in after if c["name"] != top}
    assert rest == {c["name"]: c["change_deg"] for c in before if c["name"] != top}


@pytest.mark.slow
def test_another_design_is_refused(coarse, as_built_path, tmp_path, capsys):
    other = coarse.replace(reflector=replace(coarse.reflector, radius_mm=8.9))
    with pytest.raises(InputError, match=r"reflector\.radius_mm is 9\.0 there, 8\.9") as info:
        report_blocks(other, step_deg=3.0, as_built=as_built_path)
    assert "\n" not in str(info.value)
    # the grid step and the predicted block do not make another design
    check_same_design(
        load_as_built(as_built_path),
        coarse.replace(workspace=Workspace(step_deg=0.5), predicted={"objective_deg": 1.0}),
    )
    path = tmp_path / "other.json"
    other.save(path)
    out = tmp_path / "report"
    code = main(["report", str(path), "--as-built", str(as_built_path), "-o", str(out), "-q"])
    assert code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "identified for another design" in err
    assert str(as_built_path) in err and not out.exists()


@pytest.mark.slow
def _contents(blocks):
    """The report's contents line."""
    return next(b for b in blocks if b[0] == "p" and b[1].startswith("Contents: "))


def test_report_without_as_built_is_unchanged(coarse, predicted, with_section):
    blocks, figures = report_blocks(coarse, predicted=predicted)
    assert ("h2", AS_BUILT_SECTION) not in blocks
    with_blocks, with_figures = with_section
    section = _section(with_blocks)
    start = with_blocks.index(section[0])
    rest = with_blocks[:start] + with_blocks[start + len(section) :]
    at = rest.index(_contents(rest))  # the contents line, after the headline in use
    assert rest[:at] == blocks[:at] and rest[at + 1 :] == blocks[at + 1 :]
    assert rest[at][1].replace(" · [As built](#as-built)", "") == blocks[at][1]
    assert set(with_figures) - set(figures) == {"as_built_deviations.png"}
    assert "As built" not in render_markdown(blocks)


@pytest.mark.slow
def test_report_command_with_as_built(as_built_path, tmp_path):
    design = as_built_path.parent / "design.json"
    folder = tmp_path / "with"
    args = ["report", str(design), "--as-built", str(as_built_path), "--no-cad", "-q"]
    assert main([*args, "-o", str(folder)]) == 0
    md = (folder / "report.md").read_text(encoding="utf-8")
    assert f"\n## {AS_BUILT_SECTION}\n" in md and "### Which deviations cost resolution" in md
    assert (folder / "as_built_deviations.png").stat().st_size > 1000
    html = (folder / "report.html").read_text(encoding="utf-8")
    assert '<h2 id="as-built">As built</h2>' in html
