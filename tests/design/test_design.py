"""The design object: validation that names the field."""

import pytest

from reflector_opt.design._defaults import default_design
from reflector_opt.design._design import Design
from reflector_opt.util._errors import InputError


def _document(**changes):
    data = default_design().to_dict()
    for path, value in changes.items():
        keys = path.split(".")
        target = data
        for key in keys[:-1]:
            target = target[int(key)] if isinstance(target, list) else target[key]
        last = keys[-1]
        if value is KeyError:
            del target[last]
        elif isinstance(target, list):
            target[int(last)] = value
        else:
            target[last] = value
    return data


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        (
            {"reflector.radius_mm": 0},
            r"reflector\.radius_mm: expected a number > 0 and ≤ 1000 mm, got 0$",
        ),
        (
            {"reflector.radius_mm": -3.0},
            r"reflector\.radius_mm: expected a number > 0.*, got -3\.0",
        ),
        (
            {"reflector.centre_mm": [0, float("nan"), 0]},
            r"reflector\.centre_mm\[1\]: expected a number from -1000 to 1000 mm, got nan",
        ),
        ({"reflector.centre_mm": [0, 0]}, r"reflector\.centre_mm: expected a list of 3"),
        ({"reflector.radius_mm": KeyError}, r"reflector\.radius_mm: missing key"),
        ({"sensors.0.position_mm": KeyError}, r"sensors\[0\]\.position_mm: missing key"),
        ({"sensors.1.model": "NOPE-1"}, r"sensor 'S2'\.model: unknown sensor preset 'NOPE-1'"),
        ({"sensors.0.position_mm": [8.0, 0, 0]}, r"S1 would lie inside the reflector sphere"),
        # O outside the sphere: report --no-cad and tolerance once ran on it (the report
        # ended in an internal error drawing the sensor sections)
        (
            {"reflector.centre_mm": [0, 0, -9.5]},
            r"reflector\.centre_mm: the rotation centre must lie inside the sphere: the centre "
            r"is 9\.5 mm from it, reflector\.radius_mm is 9 mm",
        ),
        ({"sensors.0.axis": [0, 0, 0]}, r"axis: must not be the zero vector"),
        ({"workspace.pitch_deg": [15, -15]}, r"workspace\.pitch_deg: min must be below max"),
        (
            {"workspace.step_deg": 0},
            r"workspace\.step_deg: expected a number > 0 and < 180°, got 0",
        ),
        # a grid of one pose: the prediction failed naming neither the design nor the key
        (
            {"workspace.step_deg": 60},
            r"workspace\.step_deg: expected less than twice the pitch range \(60°\), got 60",
        ),
        (
            {"noise.sigma_v": -1e-3},
            r"noise\.sigma_v: expected a number from 0 to 1000 V, got -0\.001",
        ),
        (
            {"noise.adc_bits": 10.5},
            r"noise\.adc_bits: expected a whole number from 1 to 32, got 10\.5",
        ),
        ({"mechanics.bearing_bore_mm": 20}, r"bearing_bore_mm: must be smaller"),
        ({"reflector.colour": "white"}, r"reflector: unknown key\(s\) colour"),
        ({"format": "reflector-opt/design@9"}, r"format: expected"),
        ({"sensors": []}, r"sensors: a unit needs at least two sensors"),
    ],
)
def test_bad_designs_name_the_field(changes, message):
    with pytest.raises(InputError, match=message):
        Design.from_dict(_document(**changes))


def test_predicted_is_typed_and_its_json_is_the_files_own():
    """``design.predicted`` is read by attribute; a file of an earlier release loads and gives
    back its ``predicted`` block with the same keys in the same order, a key this release
    does not write kept (at the end) and a wrong type refused naming the key."""
    import json
    from pathlib import Path

    from msgspec import UNSET

    path = Path(__file__).resolve().parents[1] / "data" / "design_6c47a9f.json"
    data = json.loads(path.read_text())
    design = Design.from_dict(data)
    written = design.to_dict()["predicted"]
    assert written == data["predicted"] and list(written) == list(data["predicted"])
    assert design.predicted.objective_deg == data["predicted"]["objective_deg"]
    assert design.predicted.metrics == data["predicted"]["metrics"]
    assert design.predicted.conditions is UNSET and not design.predicted.robust
    old = {"note": {"rows": [1.0]}, "objective_deg": 0.5}
    kept = Design.from_dict({**data, "predicted": old}).predicted
    assert kept.others == {"note": {"rows": [1.0]}}
    assert kept.to_dict() == {"objective_deg": 0.5, "note": {"rows": [1.0]}}
    assert design.replace(predicted=kept).predicted == kept  # a typed block is kept as given
    with pytest.raises(InputError, match=r"^predicted\.metrics: expected a table, got 'x'$"):
        Design.from_dict({**data, "predicted": {"metrics": "x"}})


def test_the_figures_in_use_are_typed_and_keep_what_an_earlier_release_wrote():
    """``predicted.conditions`` is an InUse read by attribute, its baseline one too; the
    example's block is written back key for key; a key this release does not write is kept
    at its own level; a wrong type is refused naming its path; the dict reading still
    works for a release, with a warning naming the attribute."""
    import json
    from pathlib import Path

    from reflector_opt.design._in_use import InUse, InUseBaseline

    path = Path(__file__).resolve().parents[2] / "examples" / "data" / "design.json"
    data = json.loads(path.read_text())
    block = Design.from_dict(data).predicted.conditions
    assert isinstance(block, InUse) and isinstance(block.baseline, InUseBaseline)
    written = block.to_dict()
    assert written == data["predicted"]["conditions"]
    assert list(written) == list(data["predicted"]["conditions"])
    assert block.worst_case_deg == data["predicted"]["conditions"]["worst_case_deg"]
    assert block.improvement == pytest.approx(
        block.baseline.worst_case_deg / block.worst_case_deg, rel=1e-12
    )
    old = json.loads(json.dumps(data))
    old["predicted"]["conditions"]["note"] = 1.0
    old["predicted"]["conditions"]["baseline"]["margin_deg"] = 2.0
    del old["predicted"]["conditions"]["rms_deg"]  # an earlier release wrote none
    kept = Design.from_dict(old).predicted.conditions
    assert kept.others == {"note": 1.0} and kept.baseline.others == {"margin_deg": 2.0}
    assert kept.to_dict()["baseline"]["margin_deg"] == 2.0 and "rms_deg" not in kept.to_dict()
    assert Design.from_dict(old).to_dict()["predicted"] == old["predicted"]
    old["predicted"]["conditions"]["baseline"]["median_deg"] = "x"
    with pytest.raises(
        InputError, match=r"^predicted\.conditions\.baseline\.median_deg: expected a number"
    ):
        Design.from_dict(old)
    with pytest.warns(DeprecationWarning, match=r"block\.worst_case_deg"):
        assert block["worst_case_deg"] == block.worst_case_deg
    with pytest.warns(DeprecationWarning), pytest.raises(KeyError):
        kept["rms_deg"]
