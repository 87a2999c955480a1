"""reflector-opt smallest: options refused before any work, in one line, nothing written; a
segment's choices of units and the design of the one chosen; a point's design exported and
reported from its design.json alone."""

import csv
import itertools
import json

import pytest

from reflector_opt.cli import main
from reflector_opt.design import Mechanics, Reflector, SensorPlacement, Workspace, default_design
from reflector_opt.design._bearings import workspace_tilt_deg
from reflector_opt.design._conditions import Conditions
from reflector_opt.design._design import load_design
from reflector_opt.design._layout import plan_layout
from reflector_opt.design._parts import CadParameters
from reflector_opt.util._errors import InputError
from reflector_opt.workflow import SmallestOptions, export, report, smallest
from reflector_opt.workflow._smallest import SmallestRun, _study


@pytest.mark.parametrize(
    ("options", "fragment"),
    [
        (
            SmallestOptions(target_deg=float("nan")),
            "--target-deg: expected a number > 0 and < 90°, got nan",
        ),
        (
            SmallestOptions(target_deg=-0.1),
            "--target-deg: expected a number > 0 and < 90°, got -0.1",
        ),
        (SmallestOptions(target_deg=0.1, workspace_deg=30), "tilts the unit by up to 41.4°"),
        (SmallestOptions(target_deg=0.1, segment_range_deg=120), "no number of units"),
        (SmallestOptions(target_deg=0.1, segment_range_deg=90, link_mm=8), "units would overlap"),
        (SmallestOptions(target_deg=0.1, workspace_deg=11, link_mm=20), "only with --segment"),
        (
            SmallestOptions(target_deg=0.1, workspace_deg=11, segment_range_deg=90),
            "--workspace-deg: not with --segment-range-deg",
        ),
        (SmallestOptions(target_deg=0.1, workspace_deg=11, segment_choices=0), "--segment-ch"),
        (SmallestOptions(target_deg=0.1, workspace_deg=11, sensor="NOPE"), "unknown sensor part"),
        (SmallestOptions(target_deg=0.1, workspace_deg=11, largest_mm=12), "not inside a 12 mm"),
        (
            SmallestOptions(target_deg=2, workspace_deg=11, objective="x"),
            "--objective: expected one of 'in-use', 'resolution', got 'x'",
        ),
        (
            SmallestOptions(target_deg=0.1, workspace_deg=0.2),
            "^search.grid_step_deg: expected less than twice the pitch range (0.8°)",  # at once
        ),
    ],
)
def test_bad_options_are_refused_before_any_work(tmp_path, options, fragment):
    with pytest.raises(InputError, match=fragment.replace("(", r"\(").replace(")", r"\)")):
        smallest(options)
    assert not (tmp_path / "out").exists()


def test_the_command_refuses_a_workspace_no_bearing_permits_with_exit_2(tmp_path, capsys):
    """Past every bearing's mechanical stop (the GE 4 E's 38.0°): the paper's ±15° × ±15°
    (21.1°) is within it, ±30° (41.4°) is not."""
    out = tmp_path / "out"
    assert main(["smallest", "--target-deg", "0.1", "--workspace-deg", "30", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "the workspace, pitch [-30.0, 30.0]° and roll [-30.0, 30.0]°" in err
    assert "beyond the 38.0° mechanical stop of the bearing that tilts most (GE4E)" in err
    assert "give --workspace-deg 27.3 or less" in err and len(err.splitlines()) == 1
    assert not out.exists()
    # the workspace the message offers is accepted as far as the frontier (the bearing fits)
    assert workspace_tilt_deg((-27.3, 27.3), (-27.3, 27.3)) <= 37.976


def test_a_target_below_the_in_use_floor_gets_one_line_naming_it_and_what_lowers_it(
    tmp_path, capsys
):
    """In the default conditions every in-use figure stands on the imu-lpms-b's assumed 1°
    zero: 0.5° is refused before any search (exit 2, nothing written), and the line names
    the better references and the white-noise objective."""
    out = tmp_path / "out"
    args = ["smallest", "--target-deg", "0.5", "--workspace-deg", "11", "-o", str(out)]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and "below the in-use floor of 1° " in err
    assert '"imu-lpms-b2"' in err and '"encoder"' in err and "--objective resolution" in err
    assert not out.exists()


def test_the_search_judges_in_use_by_default_and_in_white_noise_with_objective_resolution(
    tmp_path,
):
    """The frontier's problem: the default conditions without --conditions, the stated ones
    with them, none with --objective resolution (today's white-noise frontier)."""
    base = {"target_deg": 0.1, "workspace_deg": 11.0}
    study = _study(SmallestOptions(**base | {"target_deg": 1.5}))[0]
    assert study.problem.conditions == Conditions()
    stated = tmp_path / "cond.toml"
    stated.write_text('[conditions]\nangle_reference = "encoder"\n')
    study = _study(SmallestOptions(**base, conditions=str(stated)))[0]
    assert study.problem.conditions.angle_reference == "encoder"
    plain = _study(SmallestOptions(**base, objective="resolution", conditions=str(stated)))[0]
    assert plain.problem.conditions is None and plain.target_deg == 0.1
    assert plain.reported_in.angle_reference == "encoder"  # its points reported in them
    row = {
        "part": "VCNT2020",
        "bearing": "GE4E",
        "unit_diameter_mm": 20.0,
        "objective": "resolution",
    }
    row |= {"objective_deg": 0.0812, "worst_case_deg": 0.5321, "white_noise_deg": 0.0799}
    text = repr(SmallestRun(row, None, (row,)))
    assert (
        "at 20 mm, objective 0.0812°, in-use worst case 0.5321° (white-noise floor 0.0799°)" in text
    )
    text = repr(SmallestRun(row | {"objective": "in-use"}, None, (row,)))
    assert "at 20 mm, in-use worst case 0.5321° (white-noise floor" in text


TINY = """
[workspace]
pitch_deg = [-11.0, 11.0]
roll_deg = [-11.0, 11.0]
step_deg = 0.5
[search]
popsize = 5
maxiter = 8
workers = 1
"""


@pytest.mark.slow
def test_a_segment_of_twenty_degrees_its_choices_and_the_design_of_the_one_chosen(tmp_path):
    config = tmp_path / "tiny.toml"
    config.write_text(TINY)
    options = SmallestOptions(
        target_deg=0.2,
        sensor="VCNT2020",
        config=str(config),
        segment_range_deg=20,
        link_mm=20,
        segment_choices=2,
        resolution_mm=2.0,
        starts=1,  # one search a size: the frontier's shape, not its robustness, is tested
        objective="resolution",  # the white-noise search: a third of the in-use one's work
    )
    run = smallest(options).write(tmp_path / "out")
    # ±20° on the GE 4 E (square ±11.35°): 2 units of ±10°, then 3 of ±6.67°
    choices = run.segment["choices"]
    assert [c["n_units"] for c in choices] == [2, 3]
    assert [c["unit_workspace_deg"] for c in choices] == pytest.approx([10.0, 20 / 3])
    assert [c["segment_length_mm"] for c in choices] == [40.0, 60.0]
    chosen = run.segment["chosen"]
    keys = ("orientation_rms_deg", "position_rms_mm")
    fewer = [c for c in choices if c["n_units"] < chosen["n_units"]]
    assert all(all(chosen[k] < c[k] for k in keys) for c in fewer)
    # the design written is the chosen segment's unit: its count, link and share of the range
    design = load_design(tmp_path / "out" / "design.json")
    n = chosen["n_units"]
    assert (design.mechanics.n_units, design.mechanics.link_length_mm) == (n, 20.0)
    assert design.workspace.pitch_deg == pytest.approx((-20 / n, 20 / n))
    assert design.mechanics.unit_diameter_mm == chosen["unit_diameter_mm"]
    saved = json.loads((tmp_path / "out" / "design.json").read_text())["predicted"]
    assert saved["segment_choice"]["chosen"]["n_units"] == n
    assert saved["size_frontier"]["chosen"]["unit_diameter_mm"] == run.chosen["unit_diameter_mm"]
    # its parts are laid out from design.json alone: the GE 4 E's widths (SKF: B 5, C 3,
    # dk 8) and the tendon circle 1.2 mm inside the rim, as the paper's 9.8 mm in 11
    assert not (tmp_path / "out" / "cad.toml").exists()
    cad = plan_layout(design).params
    assert (cad.bearing_inner_width_mm, cad.bearing_outer_width_mm) == (5.0, 3.0)
    assert cad.bearing_ball_diameter_mm == 8.0
    assert cad.tendon_radius_mm == pytest.approx(chosen["unit_diameter_mm"] / 2 - 1.2)
    with open(tmp_path / "out" / "segment.csv", newline="") as f:
        table = list(csv.DictReader(f))
    assert [int(r["n_units"]) for r in table] == [2, 3]
    paper = run.segment["errors"]["paper_motion"]["pitch"]
    assert paper["paper"]["rms_deg"] == 2.45 and paper["amplitude_deg"] == 20.0
    # the frontier never rises with the diameter
    feasible = sorted(
        (r["unit_diameter_mm"], r["objective_deg"]) for r in run.rows if r["status"] == "feasible"
    )
    assert all(a[1] >= b[1] for a, b in itertools.pairwise(feasible))
    # the smallest size that fits, and what fails at the next size tried below it
    (limit,) = run.limits
    assert limit["smallest_mm"] == feasible[0][0]
    failed = [r for r in run.rows if r["unit_diameter_mm"] == limit["fails_at_mm"]]
    assert failed and failed[0]["status"] == "infeasible" and limit["fails_at_mm"] < feasible[0][0]
    assert limit["binding"] == failed[0]["binding"] and limit["reason"] == failed[0]["reason"]
    _the_parts_are_those_export_writes(run, tmp_path)


def _the_parts_are_those_export_writes(run, tmp_path):
    """The chosen design's parts in the folder, proved as ``export`` proves them: the same
    files and the same checks as an export of the folder's design.json."""
    out = tmp_path / "out"
    assert all(path.exists() for path in run.files)
    for name in ("reflector.stl", "body.stl", "assembly.3mf", "view.html"):
        assert out / name in run.files
    report = run.parts.report
    for part in report["printability"].values():
        assert part["ok"] and part["thinnest_wall_mm"] >= 0.8 - 1e-6
    assert report["collision"]["collision_free"]
    assert report["ray_check"]["max_error_mm"] <= report["ray_check"]["tolerance_mm"]
    again = export(out / "design.json").write(tmp_path / "again")
    assert {p.name for p in again.files} == {p.name for p in run.parts.files}
    for name, part in again.report["printability"].items():
        assert part["thinnest_wall_mm"] == pytest.approx(
            report["printability"][name]["thinnest_wall_mm"]
        )
    assert again.report["collision"] == report["collision"]


#: The point ``reflector-opt smallest --target-deg 0.1 --sensor VCNT2020 --workspace-deg 11``
#: chooses (20 mm on the GE 4 E), rounded; its sensors 0.3 µm lower, off the window's limit.
POINT_20MM = default_design().replace(
    reflector=Reflector(7.38, (0.7594, 0.0, 0.8404), 6.5, 0.9, 0.05),
    sensors=tuple(
        SensorPlacement(
            name, "VCNT2020", (6.3757, s * 6.0655, -0.12), (-0.7069, -s * 0.6725, 0.2189)
        )
        for name, s in (("S1", -1.0), ("S2", 1.0))
    ),
    workspace=Workspace((-11.0, 11.0), (-11.0, 11.0), 0.5),
    mechanics=Mechanics(unit_diameter_mm=20.0, bearing="GE4E"),
)


def test_a_point_on_the_ge4e_exports_and_reports_from_its_design_alone(tmp_path):
    path = tmp_path / "design.json"
    POINT_20MM.save(path)
    # the GE 6 E's widths would not clear the bearing: C = 4 puts the outer ring's corner at
    # hypot(6, 2) + 0.2 = 6.52 mm from O, beyond the 6.5 mm inner radius
    with pytest.raises(InputError, match="does not clear the bearing's outer ring"):
        plan_layout(POINT_20MM, CadParameters(bearing_outer_width_mm=4.0))
    run = export(path, chord_tolerance_mm=0.05, preview=False).write(tmp_path / "parts")
    params = run.report["layout"]["cad_parameters"]
    assert params["bearing_outer_width_mm"] == 3.0  # the GE 4 E's C
    assert params["tendon_radius_mm"] == pytest.approx(10.0 - 1.2)
    for part in run.report["printability"].values():
        assert part["ok"] and part["thinnest_wall_mm"] >= 0.8 - 1e-6
    written = report(path).write(tmp_path / "report")
    assert written.cad.error is None and written.cad.report is not None
    assert (tmp_path / "report" / "reflector.stl").exists()
