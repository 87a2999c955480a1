"""The simulated print process: its systematic part, and units printed through build_unit."""

import numpy as np
import pytest

from reflector_opt.asbuilt._parameters import ParameterLayout
from reflector_opt.asbuilt._printprocess import PrintProcess
from reflector_opt.tolerance._tolerances import Tolerances
from reflector_opt.util._errors import InputError
from tests.asbuilt.printloop import drawn_design


def _block(design, process):
    names = ParameterLayout(design, 1).unit_names
    return dict(zip(names, process.systematic_deviation(design), strict=True))


def test_the_default_systematic_part_is_the_documented_one():
    design = drawn_design()  # sphere radius 9 mm at z = −1.2 mm, sensors 10 mm out
    block = _block(design, PrintProcess())
    expected = {
        "reflector_radius_mm": -0.006 * 9.0,
        "reflector_centre_z_mm": 0.006 * 1.2 + 0.04,
        "sensor_1_standoff_mm": -0.006 * 10.0,  # the seat 60 µm nearer the axis
        "sensor_2_standoff_mm": -0.006 * 10.0,
        "sensor_1_tilt_led_detector_deg": 0.8,
    }
    for name, value in block.items():
        assert value == pytest.approx(expected.get(name, 0.0), abs=1e-9), name


def test_scatter_only_has_no_systematic_part_and_seats_move_along_their_axes():
    design = drawn_design()
    assert np.allclose(PrintProcess.scatter_only().systematic_deviation(design), 0.0)
    process = PrintProcess.scatter_only(tolerances=Tolerances.zero())
    deeper = PrintProcess(0.0, (0.0, 0.0, 0.0), (), (0.1,), Tolerances.zero())
    built = deeper.systematic_design(design)
    assert built.sensors[0].position_mm == pytest.approx((10.1, 0.0, 0.0))
    assert process.systematic_design(design) == design


def test_a_unit_without_scatter_is_the_systematic_geometry_with_the_batch_surface():
    design = drawn_design()
    process = PrintProcess(tolerances=Tolerances.zero(), surface=(0.85, 0.2))
    unit = process.print_unit(design, 0, seed=1)
    expected = process.systematic_design(design)
    assert unit.design.reflector.radius_mm == pytest.approx(expected.reflector.radius_mm)
    assert unit.design.reflector.centre_mm == pytest.approx(expected.reflector.centre_mm)
    assert unit.design.positions_mm == pytest.approx(expected.positions_mm)
    assert unit.design.axes == pytest.approx(expected.axes)
    reflector = unit.design.reflector
    assert (reflector.reflectance, reflector.specular_fraction) == (0.85, 0.2)


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"shrink": 0.5}, "shrink"),
        ({"centre_shift_mm": (0.0, 0.1)}, "centre_shift_mm"),
        ({"seat_tilts_deg": ((45.0, 0.0),)}, "seat_tilts_deg"),
        ({"seat_standoffs_mm": (float("nan"),)}, "seat_standoffs_mm"),
    ],
)
def test_bad_processes_are_refused(options, message):
    with pytest.raises(InputError, match=message):
        PrintProcess(**options)


def test_a_batch_needs_a_unit():
    with pytest.raises(InputError, match="n_units"):
        PrintProcess().print_batch(drawn_design(), 0)
