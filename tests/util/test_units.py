"""The unit checks of input columns (issue 37, item 2): metres, millivolts, radians, supply."""

import numpy as np
import pytest

from reflector_opt.util._units import (
    UnitsError,
    check_angles_deg,
    check_distances_mm,
    check_millivolts,
    check_supply_v,
)

#: A flat-target curve of the NJL5901R-2, mm (the usable range is 0.5–3 mm).
CURVE_MM = np.array([0.3, 0.5, 1.0, 2.0, 3.0, 4.0])


def test_a_curve_in_millimetres_passes_and_in_metres_or_micrometres_is_named():
    check_distances_mm(CURVE_MM, "c.csv")
    with pytest.raises(
        UnitsError, match=r"^c.csv: column distance_mm spans 0.0003–0.004: .*metres"
    ):
        check_distances_mm(CURVE_MM / 1000, "c.csv")
    with pytest.raises(UnitsError, match="spans 300–4000: that looks like micrometres"):
        check_distances_mm(CURVE_MM * 1000, "c.csv")
    check_distances_mm(CURVE_MM / 1000, "c.csv", accept=True)


def test_millivolts_of_the_supply_are_named_and_volts_pass():
    volts = np.array([[0.2, 3.3], [1.5, 2.4]])  # the clamp V_CE(sat) to Vcc, docs/model.md
    check_millivolts(volts, "d.csv", ("v1", "v2"), 3.3)
    check_supply_v(volts, "d.csv", ("v1", "v2"), 3.3)
    with pytest.raises(
        UnitsError, match=r"column v1 spans 200–1500, beyond the 3.3 V supply: .*millivolts"
    ):
        check_supply_v(volts * 1000, "d.csv", ("v1", "v2"), 3.3)
    check_supply_v(volts * 1000, "d.csv", ("v1", "v2"), 3.3, accept=True)


def test_the_supply_margin_is_five_percent_and_the_first_value_beyond_is_named():
    margin = 0.05 * 3.3  # 0.165 V
    check_supply_v(np.array([[-margin, 3.3 + margin]]), "d.csv", ("v1", "v2"), 3.3)
    volts = np.array([[1.0, 2.0], [1.0, 3.3 + 1.01 * margin], [-1.0, 2.0]])
    rows = ["line 2", "line 3", "line 4"]
    with pytest.raises(UnitsError, match=r"^d.csv: line 3: column v2 is 3.46665, beyond the 3.3 V"):
        check_supply_v(volts, "d.csv", ("v1", "v2"), 3.3, rows=rows)
    # a 5 V bench read as 5 V: not millivolts (below ten times the supply), another circuit
    with pytest.raises(UnitsError, match=r"spans 1–5, beyond .*not a reading of this circuit"):
        check_supply_v(np.array([1.0, 5.0]), "d.csv", ("volts",), 3.3)
    check_supply_v(np.array([1.0, 5.0]), "d.csv", ("volts",), 5.0)


def test_radians_are_named_and_a_degree_span_passes():
    degrees = np.array([[-15.0, 15.0], [0.0, 0.0]])
    check_angles_deg(degrees, "d.csv", ("pitch_deg", "roll_deg"))
    with pytest.raises(UnitsError, match=r"pitch_deg and roll_deg are all within ±0.6 .*radians"):
        check_angles_deg(np.radians(degrees), "d.csv", ("pitch_deg", "roll_deg"))
    check_angles_deg(np.zeros((3, 2)), "d.csv", ("pitch_deg", "roll_deg"))  # one pose, zero
    check_angles_deg(np.radians(degrees), "d.csv", ("pitch_deg", "roll_deg"), accept=True)


def test_every_refusal_is_one_line_naming_the_option():
    with pytest.raises(UnitsError) as refused:
        check_distances_mm(CURVE_MM / 1000, "c.csv")
    assert "\n" not in str(refused.value) and str(refused.value).endswith(
        "or pass --accept-units if they are right"
    )
