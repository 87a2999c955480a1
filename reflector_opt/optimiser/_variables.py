"""The design variables of the optimiser, declared in one place with units and bounds.

A point of the search is a mapping ``{name: value}`` over :data:`VARIABLES`; a variable whose
bounds are equal is held fixed. :func:`build_design` turns a point into a
:class:`~reflector_opt.design._design.Design`.

The variables are chosen so that the search sees the problem's structure:

* The two sensors sit at the same radius ρ from the unit's axis and the same height z, at
  azimuths ``β ∓ Δ/2`` (β the pair's mean azimuth from +x towards +y, Δ their separation).
  They look back at the axis with their optical axes tilted by τ out of the horizontal plane
  (positive: towards +z): ``f_i = (ρ cos φ_i, ρ sin φ_i, z)``,
  ``a_i = (−cos φ_i cos τ, −sin φ_i cos τ, sin τ)``. The LED-to-detector direction stays
  vertical (+z), as on the paper's flexible strip.
* The sphere centre's horizontal offset is given along and across the pair's mean azimuth,
  so turning the pair carries the offset with it.
* The sphere radius follows from the nominal gap g, the Eq-3 distance of the sensors at zero
  pose: ``r_s = mean_i |f_i − s0| − g``. The gap is what the distance window constrains, so
  most random candidates are already near the sensor's range.
* The inner radius of the shell is not searched: it does not enter the optics, and a smaller
  one only thickens the wall, so it is the smallest that clears the bearing
  (``bearing_od_mm/2 + bearing_clearance_mm``).

By default the pair is mirror-symmetric about the xz-plane, the plane of pitch (β = 0 and no
offset across it): the sensors straddle +x and respond alike, as the paper recommends for its
next prototype. Give ``sensor_azimuth_deg`` or ``centre_across_mm`` a range to search
asymmetric layouts (``sensor_azimuth_deg`` in [0°, 90°] covers every layout: mirroring in x
or y, or swapping the sensors' names, changes no metric).
"""

import math
from dataclasses import dataclass

import numpy as np

from reflector_opt.design import Design, Reflector, SensorPlacement
from reflector_opt.model._sensors import PRESETS
from reflector_opt.util._errors import InputError


@dataclass(frozen=True)
class Variable:
    """One design variable.

    Parameters
    ----------
    name : str
        Key in configs and results (it carries the unit).
    unit : str
        ``"mm"`` or ``"deg"``.
    description : str
        What it is.
    """

    name: str
    unit: str
    description: str


#: The design variables; their default bounds are :func:`default_bounds`.
VARIABLES = (
    Variable("gap_mm", "mm", "sensor-to-sphere distance g at zero pose (sets the radius r_s)"),
    Variable("centre_along_mm", "mm", "sphere centre offset in xy along the pair's azimuth"),
    Variable("centre_across_mm", "mm", "sphere centre offset in xy across the pair's azimuth"),
    Variable("centre_z_mm", "mm", "sphere centre offset along z"),
    Variable("sensor_radius_mm", "mm", "distance ρ of the sensors from the unit axis"),
    Variable("sensor_height_mm", "mm", "height z of the sensors"),
    Variable("sensor_tilt_deg", "deg", "tilt τ of the optical axes out of the xy-plane (+: up)"),
    Variable("sensor_azimuth_deg", "deg", "mean azimuth β of the sensor pair from +x"),
    Variable("sensor_separation_deg", "deg", "azimuth difference Δ between the sensors"),
)

_NAMES = tuple(v.name for v in VARIABLES)

#: Quantities of a design that follow from the variables, and how to steer them.
DERIVED = {
    "radius_mm": "the sphere radius follows from gap_mm",
    "centre_x_mm": "bound centre_along_mm and centre_across_mm instead",
    "centre_y_mm": "bound centre_along_mm and centre_across_mm instead",
    "azimuth_1_deg": "bound sensor_azimuth_deg and sensor_separation_deg instead",
    "azimuth_2_deg": "bound sensor_azimuth_deg and sensor_separation_deg instead",
    "inner_radius_mm": "it is bearing_od_mm/2 + constraints.bearing_clearance_mm",
}


#: The variables whose bounds must be positive, and what their default bounds come from.
_DEFAULT_SOURCES = {
    "gap_mm": "the sensor's range_mm",
    "sensor_radius_mm": "the unit's radius less the constraints' sensor_backing_mm",
}


def default_bounds(sensor, mechanics, *, sensor_backing_mm, bearing_clearance_mm):
    """Default search bounds, ``{name: (lower, upper)}``.

    The gap spans the sensor's usable range; the sensor radius runs from the smallest that
    leaves room for the shell (inner radius + minimum wall + the sensor's nearest distance) to
    the largest the envelope allows (unit radius − backing). The pair's mean azimuth and the
    across offset are fixed at 0 (a mirror-symmetric pair).

    Parameters
    ----------
    sensor : reflector_opt.model._sensors.SensorModel
    mechanics : reflector_opt.design._components.Mechanics
    sensor_backing_mm, bearing_clearance_mm : float
        Radial room behind a sensor's face, and clearance of the shell over the bearing, mm.

    Returns
    -------
    dict
    """
    lo, hi = sensor.range_mm
    inner = 0.5 * mechanics.bearing_od_mm + bearing_clearance_mm
    rho_max = 0.5 * mechanics.unit_diameter_mm - sensor_backing_mm
    return {
        "gap_mm": (lo, hi),
        "centre_along_mm": (-2.0, 2.0),
        "centre_across_mm": (0.0, 0.0),
        "centre_z_mm": (-3.0, 3.0),
        "sensor_radius_mm": (min(inner + mechanics.min_wall_mm + lo, rho_max), rho_max),
        "sensor_height_mm": (-2.0, 2.0),
        "sensor_tilt_deg": (-25.0, 25.0),
        "sensor_azimuth_deg": (0.0, 0.0),
        "sensor_separation_deg": (20.0, 160.0),
    }


def resolve_bounds(defaults, overrides=None, where="bounds"):
    """Default bounds with some replaced, checked.

    Parameters
    ----------
    defaults : dict
        From :func:`default_bounds`.
    overrides : mapping of str to (float, float), optional
        New (lower, upper) per variable name; lower == upper fixes the variable.
    where : str, optional
        Prefix for error messages (e.g. the config section).

    Returns
    -------
    dict
        ``{name: (lower, upper)}`` for every variable, in :data:`VARIABLES` order.
    """
    bounds = {name: tuple(defaults[name]) for name in _NAMES}
    for name, pair in (overrides or {}).items():
        if name in DERIVED:
            raise InputError(f"{where}.{name}: not a search variable; {DERIVED[name]}")
        if name not in bounds:
            raise InputError(f"{where}.{name}: unknown design variable; known: {', '.join(_NAMES)}")
        try:
            lo, hi = (float(v) for v in pair)
        except (TypeError, ValueError):
            raise InputError(f"{where}.{name}: expected [min, max], got {pair!r}") from None
        if not (math.isfinite(lo) and math.isfinite(hi)):
            raise InputError(f"{where}.{name}: bounds must be finite, got [{lo}, {hi}]")
        if lo > hi:
            raise InputError(f"{where}.{name}: min {lo} is greater than max {hi}")
        bounds[name] = (lo, hi)
    for name, source in _DEFAULT_SOURCES.items():
        if bounds[name][0] <= 0:
            given = name in (overrides or {})
            raise InputError(
                f"{where}.{name}: must be positive, got min {bounds[name][0]}"
                + ("" if given else f" (the default, from {source}; set it, or change that)")
            )
    return bounds


@dataclass(frozen=True)
class _TrialDesign(Design):
    """A :class:`Design` built without its construction checks: a search candidate.

    Candidates come from variables inside their bounds, and the forward model raises
    :class:`~reflector_opt.util._errors.CollisionError` for a sensor inside the sphere at any pose
    it evaluates, so the workspace-wide collision check of ``Design.__post_init__`` (a
    quarter of the cost of evaluating a candidate on a coarse grid) is left out.
    """

    def __post_init__(self):
        pass


def build_design(
    values, *, sensor, workspace, mechanics, noise, inner_radius_mm, surface=None, checked=True
):
    """The design at one point of the search.

    Parameters
    ----------
    values : mapping of str to float
        A value for every name in :data:`VARIABLES` (units in the names).
    sensor : reflector_opt.model._sensors.SensorModel
        The part used for both sensors; embedded in the design if it is not a stock preset.
    workspace, mechanics, noise : reflector_opt.design._components.Workspace, Mechanics, Noise
    inner_radius_mm : float
        Inner radius of the reflector shell, mm.
    surface : reflector_opt.model._surface.Material, optional
        Reflectance and specular fraction of the reflector (default: the ``Reflector``'s).
    checked : bool, optional
        False builds a search candidate without ``Design``'s workspace-wide checks (its
        evaluation still fails on a collision); the default builds a checked ``Design``.

    Returns
    -------
    reflector_opt.design._design.Design
        Raises :class:`~reflector_opt.util._errors.InputError` if the point is not a valid design
        (a sensor inside the sphere, a radius ≤ 0, ...).
    """
    centre, positions, axes, radius = placement(values)
    sensors = tuple(
        SensorPlacement(f"S{i}", sensor.name, tuple(f.tolist()), tuple(a.tolist()))
        for i, (f, a) in enumerate(zip(positions, axes, strict=True), start=1)
    )
    if radius <= 0:
        raise InputError(f"gap_mm: a gap of {values['gap_mm']} mm leaves no sphere (r_s ≤ 0)")
    finish = (
        {}
        if surface is None
        else {"reflectance": surface.reflectance, "specular_fraction": surface.specular_fraction}
    )
    reflector = Reflector(
        radius_mm=radius,
        centre_mm=tuple(centre.tolist()),
        inner_radius_mm=inner_radius_mm,
        **finish,
    )
    return (Design if checked else _TrialDesign)(
        reflector=reflector,
        sensors=sensors,
        workspace=workspace,
        mechanics=mechanics,
        noise=noise,
        sensor_models=embedded_sensor_models(sensor),
    )


def placement(values):
    """Sphere centre, sensor positions and axes, and sphere radius at one point of the search.

    ``f_i = (ρ cos φ_i, ρ sin φ_i, z)``, ``a_i = (−cos φ_i cos τ, −sin φ_i cos τ, sin τ)``
    with ``φ_i = β ∓ Δ/2``; the centre offset turned by β; ``r_s = mean_i |f_i − s0| − g``.

    Parameters
    ----------
    values : mapping of str to float
        A value for every name in :data:`VARIABLES`.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray, numpy.ndarray, float)
        s0 (3,), positions (2, 3) and unit axes (2, 3), mm, and r_s, mm (≤ 0: no sphere).
    """
    rho, z = values["sensor_radius_mm"], values["sensor_height_mm"]
    tilt = math.radians(values["sensor_tilt_deg"])
    beta = math.radians(values["sensor_azimuth_deg"])
    half = 0.5 * math.radians(values["sensor_separation_deg"])
    along, across = values["centre_along_mm"], values["centre_across_mm"]
    centre = np.array(
        [
            along * math.cos(beta) - across * math.sin(beta),
            along * math.sin(beta) + across * math.cos(beta),
            values["centre_z_mm"],
        ]
    )
    phi = np.array([beta - half, beta + half])
    c, s = np.cos(phi), np.sin(phi)
    positions = np.stack([rho * c, rho * s, np.full(2, z)], axis=-1)
    axes = np.stack([-c * math.cos(tilt), -s * math.cos(tilt), np.full(2, math.sin(tilt))], axis=-1)
    radius = float(np.mean(np.linalg.norm(positions - centre, axis=-1))) - values["gap_mm"]
    return centre, positions, axes, radius


def embedded_sensor_models(sensor):
    """``Design.sensor_models`` for a part: empty for a stock preset, else the part itself.

    Parameters
    ----------
    sensor : reflector_opt.model._sensors.SensorModel

    Returns
    -------
    dict
    """
    return {} if PRESETS.get(sensor.name) == sensor else {sensor.name: sensor}


#: Variables that change sign when the unit's geometry is mirrored in its xy-plane (z → −z)
#: with the optical axes' tilt kept. The mirror preserves every Eq-3 distance; the optics
#: differ, since the LED-to-detector direction stays +z (a full mirror would flip it and the
#: tilt), so the image is a similar design, not an equivalent one. The objective therefore
#: has two similar basins, the sphere centre below or above the sensors' plane, and a
#: population settles in one of them; the polish also starts from this image in the other.
Z_MIRRORED = ("centre_z_mm", "sensor_height_mm")


def z_mirror(values):
    """The design variables with the geometry mirrored in the xy-plane, the tilt kept.

    Parameters
    ----------
    values : mapping of str to float

    Returns
    -------
    dict
        ``centre_z_mm`` and ``sensor_height_mm`` negated.
    """
    return {k: (-v if k in Z_MIRRORED else v) for k, v in values.items()}


def symmetric_layout(values):
    """The design variables with the pair made mirror-symmetric about the xz-plane.

    The pair's mean azimuth and the across offset set to 0 (the default layout): a start for
    the polish when they are searched, since that family holds good designs that the larger
    search space makes harder to find.

    Parameters
    ----------
    values : mapping of str to float

    Returns
    -------
    dict
    """
    return {**values, "sensor_azimuth_deg": 0.0, "centre_across_mm": 0.0}


def values_from_vector(names, vector, fixed):
    """``{name: value}`` from the free variables' vector and the fixed values."""
    return dict(fixed) | dict(zip(names, np.asarray(vector, dtype=float).tolist(), strict=True))


def forward_steps(u, step):
    """Forward-difference points of a point of the unit box, one coordinate at a time.

    Parameters
    ----------
    u : numpy.ndarray
        Scaled variables, each in [0, 1].
    step : float
        Step in units of each range; taken backwards where forwards would leave the box.

    Returns
    -------
    (list of float, list of numpy.ndarray)
        Each coordinate's signed step and the point moved by it.
    """
    steps = [step if v + step <= 1.0 else -step for v in u]
    return steps, [u + du * e for du, e in zip(steps, np.eye(u.size), strict=True)]
