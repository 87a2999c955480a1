"""Dimensions of the printed parts that the optical design does not fix.

The design (``design.json``) fixes the reflector sphere, the inner surface, the sensor
positions, the workspace and the unit's envelope and bearing
(:class:`~reflector_opt.design._components.Mechanics`).
:class:`CadParameters` holds everything else a printable part needs — fits, clearances,
the spherical bearing's widths, the tendon holes, the sensor package and the flexible strip —
with the paper's prototype (Osman et al. 2024, NJL5901R-2 sensors) as defaults.
They can be read from a TOML file whose keys are the field names.

Some follow the design unless given (:func:`design_parameters`, which every layout goes
through): the bearing's widths and ball diameter are the figures of the joint
``mechanics.joint`` describes or the catalogue bearing ``mechanics.bearing`` names (the
paper's GE 6 E when it names none), the tendon circle lies
:data:`TENDON_INSET_MM` inside the unit's rim, and a sensor part that states its own package
(``SensorModel.package_mm``) sets the package fields (:func:`package_parameters`). A value
given explicitly (a ``--config`` file, the optimiser's ``[cad]`` table) wins over the
design's.
"""

from dataclasses import asdict, dataclass, fields, replace
from typing import Annotated

import msgspec
from msgspec import Meta

from reflector_opt.design._bearings import bearing_cad_parameters, design_bearing
from reflector_opt.design._validation import check_length, check_number
from reflector_opt.util import _schema as schema
from reflector_opt.util._fileio import read_config
from reflector_opt.util._limits import MAX_ANGLE_DEG, MAX_LENGTH_MM

#: How far inside the unit's rim the tendon circle lies unless given, mm: the paper's
#: prototype, 9.8 mm on a 22 mm unit.
TENDON_INSET_MM = 1.2
#: The parameters that follow the design unless given (None): :func:`design_parameters`.
FROM_DESIGN = (
    "bearing_inner_width_mm",
    "bearing_outer_width_mm",
    "bearing_ball_diameter_mm",
    "tendon_radius_mm",
)


@dataclass(frozen=True)
class CadParameters:
    """Printable-part dimensions; every length in mm, every angle in degrees.

    Parameters
    ----------
    clearance_mm : float
        Running clearance kept between the rotating reflector part and anything fixed
        (the body, the bearing's outer ring), mm.
    footprint_factor : float
        The reflecting band extends beyond every point a sensor axis hits by this many 1/e
        radii of the beam footprint there (2: 98 % of the beam power lands on the band).
    band_margin_mm : float
        Extra band margin beyond the beam footprint, mm.
    sweep_margin_deg : float
        Angular safety margin added to the swept region of the reflector when the body's
        cavity is cut, degrees.
    bearing_inner_width_mm, bearing_outer_width_mm : float or None
        Widths B (inner ring) and C (outer ring) of the spherical bearing, mm; ``None``: the
        catalogue's figures of the design's bearing (GE 6 E: 6 and 4; GE 4 E: 5 and 3).
    bearing_ball_diameter_mm : float or None
        Sphere diameter dk of the bearing's inner ring, mm; ``None``: the catalogue's (GE 6 E:
        10; GE 4 E: 8).
    shaft_clearance_mm : float
        Diametral clearance of the shaft in the bearing bore, mm.
    shaft_extension_mm : float
        Length the shaft reaches below the inner ring (for a retaining clip or glue), mm.
    lid_thickness_mm : float
        Wall of the dome above the reflecting band, concentric with the rotation centre, mm.
    neck_radius_mm : float
        Radius of the solid neck joining the dome to the flange, mm.
    flange_thickness_mm : float
        Thickness of the reflector part's top flange (the mounting face of the next unit's
        body), mm.
    body_top_mm : float
        Height of the body's top face above the rotation centre O, mm.
    tendon_hole_diameter_mm : float
        Diameter of the three tendon holes, mm.
    tendon_radius_mm : float or None
        Pitch-circle radius of the tendon holes, mm; ``None``: :data:`TENDON_INSET_MM` inside
        the unit's rim (9.8 mm on the paper's 22 mm unit).
    tendon_azimuth_deg : float or None
        Azimuth of the first tendon hole (the others at +120° and +240°), degrees from +x
        towards +y; ``None`` chooses the azimuth farthest from the reflecting patches.
    sensor_width_mm, sensor_length_mm, sensor_depth_mm : float
        Sensor package across the strip, along the strip and along the optical axis, mm
        (NJL5901R-2: 1.0 × 1.4 × 0.6).
    sensor_pocket_clearance_mm : float
        Clearance around the sensor package in its window, mm.
    strip_width_mm, strip_thickness_mm : float
        Flexible PCB strip, mm; its channel is this wide and at least this deep.
    """

    clearance_mm: float = 0.2
    footprint_factor: float = 1.5
    band_margin_mm: float = 0.2
    sweep_margin_deg: float = 1.0
    bearing_inner_width_mm: float | None = None
    bearing_outer_width_mm: float | None = None
    bearing_ball_diameter_mm: float | None = None
    shaft_clearance_mm: float = 0.05
    shaft_extension_mm: float = 1.0
    lid_thickness_mm: float = 0.9
    neck_radius_mm: float = 4.0
    flange_thickness_mm: float = 1.5
    body_top_mm: float = 2.0
    tendon_hole_diameter_mm: float = 0.7
    tendon_radius_mm: float | None = None
    tendon_azimuth_deg: float | None = None
    sensor_width_mm: float = 1.0
    sensor_length_mm: float = 1.4
    sensor_depth_mm: float = 0.6
    sensor_pocket_clearance_mm: float = 0.1
    strip_width_mm: float = 2.0
    strip_thickness_mm: float = 0.15

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            where = f"cad.{f.name}"
            if value is None and f.name in (*FROM_DESIGN, "tendon_azimuth_deg"):
                continue
            if f.name == "tendon_azimuth_deg":
                check_number(value, where, bound=360.0, unit="degrees")
            elif f.name == "sweep_margin_deg":
                check_number(value, where, nonnegative=True, bound=MAX_ANGLE_DEG, unit="degrees")
            elif f.name == "footprint_factor":
                check_number(value, where, positive=True, bound=100.0)
            else:
                check_length(value, where, positive=f.name not in _MAY_BE_ZERO, nonnegative=True)

    def to_dict(self):
        """JSON/TOML-ready dict (a value left to the design or automatic, None, omitted)."""
        return {k: v for k, v in asdict(self).items() if v is not None}

    @classmethod
    def from_dict(cls, data, where="cad"):
        """Build from a dict of field names, checked against :class:`CadTable`.

        Parameters
        ----------
        data : dict
        where : str, optional
            The key path of the table, for messages.
        """
        return cls.from_table(schema.convert(data, CadTable, toml=True, where=where))

    @classmethod
    def from_table(cls, table):
        """Build from a checked :class:`CadTable`."""
        return cls(**msgspec.structs.asdict(table))


def package_parameters(params, models):
    """The CAD parameters with the sensor package of the parts a design uses.

    A part that states its package (``SensorModel.package_mm``: across the emitter–detector
    line, along it, along the optical axis) sets ``sensor_width_mm``, ``sensor_length_mm``
    and ``sensor_depth_mm``: the body's windows and channels are cut for the part the design
    names, whatever the CAD parameters say. The flexible strip is widened, where it is
    narrower, to the window (the package and its pocket clearance on both sides): a strip
    narrower than the part it carries would leave a ledge of body between its channel and the
    window. With several such parts the window holds the largest of each dimension; parts
    without a package (the presets) leave the parameters'.

    Parameters
    ----------
    params : CadParameters
    models : iterable of reflector_opt.model._sensors.SensorModel
        The design's sensor models (``Design.models``).

    Returns
    -------
    CadParameters
        ``params`` itself when no part states a package.
    """
    packages = [m.package_mm for m in models if getattr(m, "package_mm", None) is not None]
    if not packages:
        return params
    across, along, depth = (max(float(p[i]) for p in packages) for i in range(3))
    strip = max(params.strip_width_mm, across + 2.0 * params.sensor_pocket_clearance_mm)
    return replace(
        params,
        sensor_width_mm=across,
        sensor_length_mm=along,
        sensor_depth_mm=depth,
        strip_width_mm=strip,
    )


def design_parameters(params, design):
    """The CAD parameters a design's parts are laid out with: the given ones, completed by the
    design's.

    A parameter of :data:`FROM_DESIGN` left as None takes the design's value: the bearing's
    widths B, C and ball diameter dk are the figures of the joint ``mechanics.joint``
    describes or the catalogue bearing ``mechanics.bearing`` names, or of
    :data:`~reflector_opt.design._bearings.DEFAULT_BEARING` when it names none
    (:func:`~reflector_opt.design._bearings.bearing_cad_parameters`); the tendon circle's
    radius is the unit's radius less :data:`TENDON_INSET_MM`. A value given explicitly wins.
    The sensor package is the parts' (:func:`package_parameters`).

    Parameters
    ----------
    params : CadParameters or None
        The given parameters; None for the defaults.
    design : reflector_opt.design._design.Design

    Returns
    -------
    CadParameters
        Every field but ``tendon_azimuth_deg`` set.
    """
    mechanics = design.mechanics
    params = package_parameters(params or CadParameters(), design.models)
    params = bearing_cad_parameters(params, design_bearing(mechanics))
    if params.tendon_radius_mm is None:
        radius = round(0.5 * mechanics.unit_diameter_mm - TENDON_INSET_MM, 9)
        params = replace(params, tendon_radius_mm=radius)
    return params


#: Dimensions that may be zero (the others must be positive).
_MAY_BE_ZERO = {"clearance_mm", "band_margin_mm", "sweep_margin_deg", "shaft_clearance_mm"}


def _cad_key(name):
    """The declared type of one CAD parameter: unit and range."""
    if name == "tendon_azimuth_deg":
        return (
            Annotated[float, Meta(ge=-360, le=360, description="degrees; absent: automatic")] | None
        )
    if name == "sweep_margin_deg":
        return Annotated[float, Meta(ge=0, le=MAX_ANGLE_DEG, description="degrees")]
    if name == "footprint_factor":
        return Annotated[float, Meta(gt=0, le=100, description="1/e beam radii")]
    if name in _MAY_BE_ZERO:
        return Annotated[float, Meta(ge=0, le=MAX_LENGTH_MM, description="mm")]
    if name in FROM_DESIGN:
        absent = (
            f"{TENDON_INSET_MM:g} mm inside the unit's rim"
            if name == "tendon_radius_mm"
            else "the figure of the design's bearing (mechanics.joint or .bearing; GE6E if none)"
        )
        meta = Meta(gt=0, le=MAX_LENGTH_MM, description=f"mm; absent: {absent}")
        return Annotated[float, meta] | None
    return Annotated[float, Meta(gt=0, le=MAX_LENGTH_MM, description="mm")]


#: The declared schema of a CAD parameters table (``--cad-params FILE.toml``, ``[cad]`` of the
#: optimiser config): every field of :class:`CadParameters` with its unit, range and default.
CadTable = msgspec.defstruct(
    "CadTable",
    [(f.name, _cad_key(f.name), f.default) for f in fields(CadParameters)],
    bases=(schema.Table,),
    module=__name__,
)


def json_schema():
    """The JSON Schema of a CAD parameters table (``docs/cad-parameters.schema.json``).

    Returns
    -------
    dict
    """
    return schema.json_schema(CadTable, "CAD parameters (TOML)")


def load_cad_parameters(path):
    """Read :class:`CadParameters` from a TOML file (keys are the field names).

    Parameters
    ----------
    path : str or pathlib.Path
        TOML file; its keys may sit at the top level or in a ``[cad]`` table.

    Returns
    -------
    CadParameters
    """
    return read_config(path, _parse_cad_parameters)


def _parse_cad_parameters(data):
    """:class:`CadParameters` from a parsed TOML document, at the top level or in [cad]."""
    in_table = set(data) == {"cad"}  # keys under [cad] are named cad.KEY in messages
    table = data["cad"] if in_table else data
    return CadParameters.from_table(
        schema.convert(table, CadTable, toml=True, where="cad" if in_table else "")
    )
