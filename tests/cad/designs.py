"""Designs the optimiser and the tolerance model produce, for the checks that must hold on all.

``data/designs/*.json`` were written by ``reflector-opt optimise`` (seed 0, one start):

=================  =============================================================================
optimised          no options (the built-in defaults)
matte, polished    ``--surface matte``, ``--surface polished``
qre1113            ``[sensor] model = "QRE1113"``
wide-pitch         ``[workspace] pitch_deg = [-20, 20]``, ``roll_deg = [-10, 10]``
centre-below       ``[bounds] centre_z_mm = [-3, -0.5]``
far-range          ``[sensor] range_mm = [1.0, 3.0]``
centre-back        ``[bounds] centre_along_mm = [-2, 0]``, ``sensor_separation_deg = [60, 120]``
=================  =============================================================================

``data/optimised_design.json`` is the optimiser's design of an earlier version. Besides
these: the built-in default design, the printable variant A of docs/cad.md, and units
built from them as the tolerance model draws them
(:func:`~reflector_opt.tolerance._tolerances.as_built` of
:func:`~reflector_opt.tolerance._tolerances.draw_sample`, with the default tolerances and with the
geometric ones four times as large), whose sphere centres and sensors leave the plane of
symmetry.
"""

from dataclasses import replace
from pathlib import Path

from reflector_opt.design import Reflector, SensorPlacement, default_design, load_design
from reflector_opt.tolerance._tolerances import Spread, Tolerances, as_built, draw_sample

DATA = Path(__file__).parent / "data"

#: The printable variant A of docs/cad.md: the default design, its centre 1.2 mm below O.
DESIGN_A = default_design().replace(
    reflector=Reflector(9.0, (0.0, 0.0, -1.2), 7.5),
    sensors=(
        SensorPlacement("S1", "NJL5901R-2", (10.0, 0.0, 0.0), (-1.0, 0.0, 0.0)),
        SensorPlacement("S2", "NJL5901R-2", (0.0, 10.0, 0.0), (0.0, -1.0, 0.0)),
    ),
)

COARSE = 0.05  # chord tolerance of most tests, mm


def printable_design(radius, centre, sensor_radius, inner=7.5):
    """The default design with the given sphere and its two sensors on the x and y axes."""
    return default_design().replace(
        reflector=Reflector(radius, centre, inner),
        sensors=(
            SensorPlacement("S1", "NJL5901R-2", (sensor_radius, 0.0, 0.0), (-1.0, 0.0, 0.0)),
            SensorPlacement("S2", "NJL5901R-2", (0.0, sensor_radius, 0.0), (0.0, -1.0, 0.0)),
        ),
    )


#: A larger sphere than A's with the sensors 0.2 mm further out (printable).
DESIGN_B = printable_design(9.2, (0.0, 0.0, -1.4), 10.2)
#: Off-axis centre: printable or not, its surface must still match Eq 3.
DESIGN_C = printable_design(9.2, (0.2, 0.1, -1.3), 10.2)

#: The default tolerances with the geometric ones four times as large.
COARSE_TOLERANCES = replace(
    Tolerances(),
    reflector_radius_mm=Spread(0.1),
    centre_offset_mm=Spread(0.1),
    inner_radius_mm=Spread(0.0),  # the default inner radius leaves the bearing 0.02 mm
    sensor_position_mm=Spread(0.2),
    sensor_tilt_deg=Spread(4.0),
)

#: Built units: (name, nominal design's file, tolerances, draw index; seed 29).
AS_BUILT = (
    ("optimised, built #0", "optimised", Tolerances(), 0),
    ("optimised, built #1", "optimised", Tolerances(), 1),
    ("qre1113, built coarsely #1", "qre1113", COARSE_TOLERANCES, 1),
    ("centre-back, built coarsely #2", "centre-back", COARSE_TOLERANCES, 2),
)


def _optimised(name):
    return load_design(DATA / "designs" / f"{name}.json")


def _built(base, tolerances, index):
    design = _optimised(base)
    draw = draw_sample(tolerances, len(design.sensors), seed=29, index=index)
    return as_built(design, tolerances, draw)[0]


def designs():
    """Every test design by name.

    Returns
    -------
    dict of str to reflector_opt.design._design.Design
    """
    found = {"default": default_design(), "printable A": DESIGN_A}
    found["optimised, earlier version"] = load_design(DATA / "optimised_design.json")
    found.update(
        {path.stem: load_design(path) for path in sorted((DATA / "designs").glob("*.json"))}
    )
    found.update({name: _built(*how) for name, *how in AS_BUILT})
    return found
