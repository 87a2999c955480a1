"""Where no design exists, one answer names the constraint and the smallest change found,
and running that change gives a design."""

import re
import tomllib

import pytest

from reflector_opt.model._catalogue import shipped_catalogue
from reflector_opt.util._errors import NoDesignError
from reflector_opt.workflow import optimise
from reflector_opt.workflow._options import OptimiseOptions
from reflector_opt.workflow._remedy import candidate_changes

#: Sensors 10.1–10.2 mm out with 1 mm backing: past the 22 mm unit's 11 mm radius.
TOO_WIDE = """
[bounds]
sensor_radius_mm = [10.1, 10.2]
[workspace]
step_deg = 0.5
[search]
popsize = 4
maxiter = 6
polish_maxiter = 20
workers = 1
"""

#: The 18 mm unit with a VCNT2020 at ±12° (16.9° of tilt at the corner) on the GE 4 E, with
#: a 0.6 mm wall.
UNIT_18 = """
[workspace]
pitch_deg = [-12.0, 12.0]
roll_deg = [-12.0, 12.0]
[mechanics]
unit_diameter_mm = 18.0
bearing = "GE4E"
min_wall_mm = 0.6
[search]
workers = 1
"""


def test_the_changes_grow_round_by_round():
    document = tomllib.loads(UNIT_18)
    changes = candidate_changes(document, "VCNT2020", rounds=2)
    others = [p.name for p in shipped_catalogue() if p.name != "VCNT2020"]
    # by hand from 18 mm, ±12°, 0.6 mm wall, the default clearances 0.5 and 0.2 mm
    first = [
        {("mechanics", "unit_diameter_mm"): 18.5},
        {("workspace", "pitch_deg"): [-11.0, 11.0], ("workspace", "roll_deg"): [-11.0, 11.0]},
        {("mechanics", "min_wall_mm"): 0.55},
        {("constraints", "bearing_clearance_mm"): 0.4},
        {("cad", "clearance_mm"): 0.15},
    ]
    second = [
        {("mechanics", "unit_diameter_mm"): 19.0},
        {("workspace", "pitch_deg"): [-10.0, 10.0], ("workspace", "roll_deg"): [-10.0, 10.0]},
        {("mechanics", "min_wall_mm"): 0.5},
        {("constraints", "bearing_clearance_mm"): 0.3},
        {("cad", "clearance_mm"): 0.1},
    ]
    assert [c[1] for c in changes] == [*first, *[{}] * len(others), *second]
    assert [c[2] for c in changes[5 : 5 + len(others)]] == others
    assert changes[0][0] == "[mechanics] unit_diameter_mm = 18.5"
    assert changes[5][0] == f"--sensor {others[0]}"


def _config(folder, text):
    path = folder / "c.toml"
    path.write_text(text, encoding="utf-8")
    return path


def _answer_and_rerun(tmp_path, text, sensor=None):
    """The refusal's message, and the run with the change it names (its design written)."""
    with pytest.raises(NoDesignError) as refused:
        optimise(OptimiseOptions(config=_config(tmp_path, text), sensor=sensor, report=False))
    message = str(refused.value)
    assert not (tmp_path / "none").exists()
    section, key, value = re.search(
        r"found that gives a design .*?: \[(\w+)\] (\w+) = ([\d.]+)", message
    ).groups()
    changed = tomllib.loads(text)
    changed.setdefault(section, {})[key] = float(value)
    lines = [
        f"[{s}]\n" + "".join(f"{k} = {v!r}\n" for k, v in t.items()) for s, t in changed.items()
    ]
    config = _config(tmp_path, "".join(lines).replace("'", '"'))
    run = optimise(  # the answer's search is in the stated read-out; the run chooses its own
        OptimiseOptions(config=config, sensor=sensor, report=False, read_out="stated")
    ).write(tmp_path / "design")
    assert run.result.evaluation.feasible
    assert (tmp_path / "design" / "design.json").exists()
    objective = float(re.search(r"\(objective ([\d.]+)°\)", message).group(1))
    assert run.result.evaluation.objective == pytest.approx(objective, rel=1e-3)
    return message, (section, key, float(value))


def test_no_design_names_the_constraint_and_the_change_that_gives_one(tmp_path):
    message, change = _answer_and_rerun(tmp_path, TOO_WIDE)
    assert message.count("\n") == 0
    assert "sensor envelope: sensor_radius_mm ≥ 10.1 mm plus 1.0 mm backing" in message
    # 22.5 mm gives 11.25 mm of radius: 10.2 + 1 fits (by hand); the first change tried
    assert change == ("mechanics", "unit_diameter_mm", 22.5)
    assert "`reflector-opt smallest --sensor NJL5901R-2 --workspace-deg 15" in message


@pytest.mark.slow
def test_the_18_mm_unit_with_a_vcnt2020_is_answered_and_the_answer_gives_a_design(tmp_path):
    message, change = _answer_and_rerun(tmp_path, UNIT_18, sensor="VCNT2020")
    assert "must be at least 0.6 mm" in message  # the binding constraint, named
    assert change[:2] == ("mechanics", "unit_diameter_mm") and change[2] > 18.0
    assert "reflector-opt smallest --sensor VCNT2020 --workspace-deg 12" in message
