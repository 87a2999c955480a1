"""The bearing catalogue: spherical bearings that exist, as data, and the tilt they permit.

A catalogue file (TOML, format ``reflector-opt/bearing-catalogue@1``; the shipped one is
``reflector_opt/data/bearing_catalogue.toml``) lists bearings, each with its figures — bore
d, outside diameter D, inner-ring width B, outer-ring width C, ball diameter dk and
permissible tilt α — every figure a table ``{value, kind, source}`` whose ``kind`` says
whether it was read (``published``), computed from the others (``derived``) or is an
``assumed`` value, as in the sensor catalogue (:mod:`reflector_opt.model._catalogue`).

A design names a bearing by ``mechanics.bearing`` (:class:`~reflector_opt.design._components.
Mechanics`), or describes its own joint by ``mechanics.joint`` (:data:`JOINT_KEYS`: the five
dimensions in mm, the radial clearance in µm, optionally the tilt stop in degrees), which
becomes a :class:`Bearing` of figures ``stated`` by the user (:func:`described_bearing`; its
rated tilt and, unless stated, its stop derived by the catalogue's formulas). The design's
bearing (:func:`design_bearing`) is what every consumer reads: its bore and outside diameter
become the mechanics', its widths and ball diameter the CAD parameters' unless these give
their own (:func:`bearing_cad_parameters`, through
:func:`reflector_opt.design._parts.design_parameters`, which every layout of the parts goes
through), its tilt limits the workspace (:func:`check_tilt`) and its clearance is the joint's
play (:func:`reflector_opt.design._joint.clearance_um`).

Two tilts are told apart. The catalogue's α is the *rated* tilt: up to it the outer ring
rests on the ball across its whole width (:func:`ring_tilt_deg`); beyond it the rings carry
the load on less of their width, which a lightly loaded joint bears, so a workspace past it
is accepted with a warning. The *mechanical stop* is where the outer ring's bore edge meets a
shaft of the bore's diameter, acos(d/dk) − asin(C/dk) (:func:`stop_tilt_deg`; GE 6 E 29.5°,
GE 4 E 38.0°); a workspace past it is refused. A design that names no bearing is checked
against the GE 6 E, whose dimensions its parts take (:data:`DEFAULT_BEARING`).

Each bearing also states its radial internal clearance per ISO 12240-1 class (C2, normal,
C3, each a range of µm): the joint's play in use (docs/conditions.md, "The joint").

The tilt a workspace asks of the bearing is the largest angle between the unit's axis and
the next unit's, over the workspace: with R = Rx(α)·Ry(γ) (paper Eq 1) the rotated z axis has
z component cos α cos γ, so the tilt is arccos(cos α cos γ), largest at the corner of the
pitch and roll ranges (:func:`workspace_tilt_deg`); a ±15° × ±15° workspace asks 21.1°.
"""

import functools
import logging
import math
from dataclasses import dataclass, replace
from typing import Annotated, Literal

import msgspec
from msgspec import Meta

from reflector_opt.design._validation import check_length, check_number, reject_unknown, require_key
from reflector_opt.util import _schema as schema
from reflector_opt.util._catalogues import find_named, read_catalogue
from reflector_opt.util._errors import InputError
from reflector_opt.util._limits import MAX_LENGTH_MM

logger = logging.getLogger(__name__)

FORMAT = "reflector-opt/bearing-catalogue@1"
#: The catalogue shipped with the package (a resource of :mod:`reflector_opt`).
SHIPPED = "data/bearing_catalogue.toml"
#: The bearing whose dimensions a design that names none takes (the paper's).
DEFAULT_BEARING = "GE6E"
#: The clearance classes of ISO 12240-1 a bearing states, by their figure's name.
CLEARANCE_CLASSES = {
    "C2": "clearance_c2_um",
    "normal": "clearance_normal_um",
    "C3": "clearance_c3_um",
}

#: Below this a described dimension reads as metres given for millimetres, mm (the smallest
#: spherical plain bearings have rings a few millimetres wide).
SMALLEST_MM = 0.5

_Kind = Literal["published", "derived", "assumed"]
_Source = Annotated[str, Meta(min_length=1, description="datasheet and place, or the basis")]


class LengthFigure(schema.Table):
    """A dimension, mm."""

    value: Annotated[float, Meta(gt=0, le=MAX_LENGTH_MM, description="mm")]
    kind: _Kind
    source: _Source


class TiltFigure(schema.Table):
    """The permissible tilt, degrees."""

    value: Annotated[float, Meta(gt=0, lt=90, description="degrees")]
    kind: _Kind
    source: _Source


class ClearanceFigure(schema.Table):
    """A radial internal clearance class, [min, max] µm."""

    value: Annotated[
        list[Annotated[float, Meta(ge=0, le=1000, description="µm")]],
        Meta(min_length=2, max_length=2),
    ]
    kind: _Kind
    source: _Source


class FiguresDocument(schema.Table):
    """The figures of one bearing."""

    bore_mm: LengthFigure
    outer_diameter_mm: LengthFigure
    inner_width_mm: LengthFigure
    outer_width_mm: LengthFigure
    ball_diameter_mm: LengthFigure
    tilt_deg: TiltFigure
    clearance_c2_um: ClearanceFigure
    clearance_normal_um: ClearanceFigure
    clearance_c3_um: ClearanceFigure


#: The figures every bearing states, in the order of a record.
FIGURES = FiguresDocument.__struct_fields__
#: The keys of a joint a design describes (``mechanics.joint``): d, D, B, C and dk in mm (the
#: first five figures), the radial internal clearance in µm and, optional, the tilt stop in
#: degrees.
JOINT_KEYS = (*FIGURES[:5], "clearance_um", "stop_deg")


class BearingDocument(schema.Table):
    """One ``[[bearing]]`` entry."""

    name: Annotated[str, Meta(min_length=1, pattern=r"^\S+$", description="key, no spaces")]
    designation: Annotated[str, Meta(min_length=1)]
    maker: Annotated[str, Meta(min_length=1)]
    kind: Annotated[str, Meta(min_length=1)]
    datasheet: _Source
    figures: FiguresDocument


class CatalogueDocument(schema.Table):
    """A bearing catalogue file (TOML)."""

    format: Literal["reflector-opt/bearing-catalogue@1"]
    bearing: Annotated[list[BearingDocument], Meta(min_length=1)]


@dataclass(frozen=True)
class Bearing:
    """One bearing of the catalogue; every length in mm, the tilt in degrees.

    Attributes
    ----------
    name : str
        The key a design names it by (``mechanics.bearing``), e.g. ``"GE4E"``.
    designation, maker, kind, datasheet : str
        The maker's designation, the maker, the kind of bearing and the source.
    figures : dict
        ``{figure: {"value", "kind", "source"}}`` for each of :data:`FIGURES`.
    origin : str
        The catalogue file (``"shipped"`` for the package's own).
    """

    name: str
    designation: str
    maker: str
    kind: str
    datasheet: str
    figures: dict
    origin: str = "shipped"

    def value(self, figure):
        """The value of one of :data:`FIGURES` but the clearances (mm, or degrees for
        ``tilt_deg``)."""
        return float(self.figures[figure]["value"])

    def clearance_um(self, grade="normal"):
        """The radial internal clearance of a class (``"C2"``, ``"normal"``, ``"C3"``),
        ``(min, max)`` µm."""
        low, high = self.figures[CLEARANCE_CLASSES[grade]]["value"]
        return float(low), float(high)

    @property
    def stop_deg(self):
        """The mechanical stop of the tilt, degrees: a described joint's stated ``stop_deg``,
        else :func:`stop_tilt_deg` of its figures."""
        if "stop_deg" in self.figures:
            return self.value("stop_deg")
        return stop_tilt_deg(
            self.bore_mm, self.value("outer_width_mm"), self.value("ball_diameter_mm")
        )

    @property
    def bore_mm(self):
        """Bore diameter d, mm."""
        return self.value("bore_mm")

    @property
    def outer_diameter_mm(self):
        """Outside diameter D, mm."""
        return self.value("outer_diameter_mm")

    @property
    def tilt_deg(self):
        """Rated tilt α, degrees: the outer ring on the ball across its whole width."""
        return self.value("tilt_deg")

    def record(self):
        """The bearing as a JSON-ready dict (what a design records of it)."""
        return {
            "name": self.name,
            "designation": self.designation,
            "maker": self.maker,
            "kind": self.kind,
            "datasheet": self.datasheet,
            "origin": self.origin,
            "figures": {k: dict(v) for k, v in self.figures.items()},
        }


def ring_tilt_deg(inner_width_mm, outer_width_mm, ball_diameter_mm):
    """Tilt at which the inner ring's edge reaches the outer ring's face, degrees.

    α = asin(B/dk) − asin(C/dk): the inner ring's edge lies at the angle asin(B/dk) from the
    ring's mid-plane, seen from the ball's centre, the outer ring's face at asin(C/dk); tilting
    the inner ring by α brings its edge to the outer ring's face. A geometric bound:
    catalogues state it rounded down (GE 4 E: 16.7° by the formula, 16° published).

    Parameters
    ----------
    inner_width_mm, outer_width_mm, ball_diameter_mm : float
        B, C and dk, mm (C < B ≤ dk).

    Returns
    -------
    float
    """
    b, c, dk = (float(v) for v in (inner_width_mm, outer_width_mm, ball_diameter_mm))
    if not 0 < c < b <= dk:
        raise InputError(f"bearing: needs 0 < C < B ≤ dk, got C {c:g}, B {b:g}, dk {dk:g} mm")
    return math.degrees(math.asin(b / dk) - math.asin(c / dk))


def stop_tilt_deg(bore_mm, outer_width_mm, ball_diameter_mm):
    """Tilt at which the outer ring's bore edge meets a shaft of the bore's diameter, degrees.

    acos(d/dk) − asin(C/dk) (derived): seen from the ball's centre the outer ring's bore
    edge lies asin(C/dk) from the ring's mid-plane on the sphere of diameter dk, and a shaft
    of diameter d leaves that sphere at acos(d/dk) from the bore's axis; tilting the ring by
    the difference brings its edge onto the shaft. The unit's printed parts may stop it
    sooner; the CAD export proves their clearance at every pose (docs/cad.md).

    Parameters
    ----------
    bore_mm, outer_width_mm, ball_diameter_mm : float
        d, C and dk, mm (d, C < dk).

    Returns
    -------
    float
    """
    d, c, dk = (float(v) for v in (bore_mm, outer_width_mm, ball_diameter_mm))
    if not (0 < d < dk and 0 < c < dk):
        raise InputError(f"bearing: needs d, C < dk, got d {d:g}, C {c:g}, dk {dk:g} mm")
    return math.degrees(math.acos(d / dk) - math.asin(c / dk))


def workspace_tilt_deg(pitch_deg, roll_deg):
    """The largest tilt of the next unit's axis over a workspace, degrees.

    arccos(cos α · cos γ) at the corner of the ranges (module notes).

    Parameters
    ----------
    pitch_deg, roll_deg : (float, float)
        The workspace's ranges, degrees.

    Returns
    -------
    float
    """
    gamma = math.radians(max(abs(v) for v in pitch_deg))
    alpha = math.radians(max(abs(v) for v in roll_deg))
    return math.degrees(math.acos(min(1.0, math.cos(alpha) * math.cos(gamma))))


def square_workspace_deg(tilt_deg):
    """The largest square workspace ±w × ±w a tilt permits, degrees.

    The inverse of :func:`workspace_tilt_deg` on a square: cos² w = cos α, so
    w = arccos(√cos α) (GE 4 E, α = 16°: 11.35°).

    Parameters
    ----------
    tilt_deg : float
        The bearing's permissible tilt α, degrees, in (0, 90).

    Returns
    -------
    float
    """
    return math.degrees(math.acos(math.sqrt(math.cos(math.radians(float(tilt_deg))))))


def check_tilt(workspace, mechanics):
    """Refuse a workspace past the bearing's mechanical stop; warn past its rated tilt.

    Parameters
    ----------
    workspace : reflector_opt.design._components.Workspace
    mechanics : reflector_opt.design._components.Mechanics
        Its bearing (:func:`design_bearing`: described, named, else :data:`DEFAULT_BEARING`,
        whose dimensions the parts then take).

    Returns
    -------
    float
        The workspace's tilt, degrees. Raises :class:`~reflector_opt.util._errors.InputError`
        naming the workspace, its tilt and the bearing's stop; logs a warning past the rated
        tilt of a named or described bearing (the GE 6 E's rated 13° is derived from assumed
        widths, and the paper ran it through ±15° × ±15°: a design naming none is not warned).
    """
    bearing = design_bearing(mechanics)
    described = bearing.origin == "mechanics.joint"
    called = (
        "the joint described in mechanics.joint" if described else f"the bearing {bearing.name}"
    )
    tilt = workspace_tilt_deg(workspace.pitch_deg, workspace.roll_deg)
    where = f"pitch {list(workspace.pitch_deg)}° and roll {list(workspace.roll_deg)}°"
    if tilt > bearing.stop_deg + 1e-9:
        raise InputError(
            f"workspace: {where} tilt the unit by up to {tilt:.1f}° (at the corner), beyond "
            f"the {bearing.stop_deg:.1f}° mechanical stop of {called}"
            + ("" if described else " (mechanics.bearing)")
        )
    chosen = getattr(mechanics, "bearing", None) or getattr(mechanics, "joint", None)
    if tilt > bearing.tilt_deg + 1e-9 and chosen is not None:
        _warn_past_rated_tilt(where, round(tilt, 1), bearing.tilt_deg, called)
    return tilt


@functools.cache
def _warn_past_rated_tilt(where, tilt, rated, called):
    """Log, once a process for each workspace and bearing, a tilt past the rated one."""
    logger.warning(
        "workspace: %s tilt the unit by up to %.1f° (at the corner), beyond the %.3g° rated "
        "tilt of %s: past it the outer ring carries the load on less than its "
        'full width (docs/smallest.md, "The bearing catalogue")',
        where,
        tilt,
        rated,
        called,
    )


def bearing_cad_parameters(params, bearing):
    """The CAD parameters with a bearing's widths and ball diameter where they are not given.

    Parameters
    ----------
    params : reflector_opt.design._parts.CadParameters
    bearing : Bearing
        The design's bearing (:func:`design_bearing`).

    Returns
    -------
    CadParameters
        ``bearing_inner_width_mm``, ``bearing_outer_width_mm`` and
        ``bearing_ball_diameter_mm`` left as None in ``params`` set to the bearing's B, C and
        dk; a value given explicitly is kept.
    """
    figures = {
        "bearing_inner_width_mm": "inner_width_mm",
        "bearing_outer_width_mm": "outer_width_mm",
        "bearing_ball_diameter_mm": "ball_diameter_mm",
    }
    unset = {k: bearing.value(v) for k, v in figures.items() if getattr(params, k) is None}
    return replace(params, **unset)


def described_bearing(joint, where="mechanics.joint"):
    """The :class:`Bearing` of a joint the user describes (``mechanics.joint``).

    Parameters
    ----------
    joint : dict
        :data:`JOINT_KEYS`: ``bore_mm`` d, ``outer_diameter_mm`` D, ``inner_width_mm`` B,
        ``outer_width_mm`` C and ``ball_diameter_mm`` dk, mm (d < dk < D, C < B ≤ dk);
        ``clearance_um``, the radial internal clearance, µm (0 to 500); ``stop_deg``, the
        tilt stop, degrees in (0, 90), optional (absent or None: :func:`stop_tilt_deg`).
    where : str
        The key the joint came from, for the messages.

    Returns
    -------
    Bearing
        Named ``"described"``, its origin ``where``; the figures given are of kind
        ``stated`` (source the user's description), the clearance stands as the normal class
        [c, c] (the one the joint's play reads), the rated tilt is :func:`ring_tilt_deg` of
        B, C and dk (``derived``), and a stated stop is the figure ``stop_deg``. Raises
        :class:`~reflector_opt.util._errors.InputError` naming the key at fault: a value not
        finite, negative or out of its range (a dimension under :data:`SMALLEST_MM` reads as
        metres, a clearance under 0.5 µm as millimetres), or dimensions that do not make a
        bearing.
    """
    if not isinstance(joint, dict):
        raise InputError(f"{where}: expected a table of {', '.join(JOINT_KEYS)}")
    reject_unknown(joint, JOINT_KEYS, where)
    values = {}
    for key in JOINT_KEYS[:5]:
        given = require_key(joint, key, f"{where}.")[0]
        value = check_length(given, f"{where}.{key}", positive=True)
        if value < SMALLEST_MM:
            raise InputError(
                f"{where}.{key}: {value:g} mm (below {SMALLEST_MM:g} mm) looks like metres; "
                "give millimetres"
            )
        values[key] = value
    given = require_key(joint, "clearance_um", f"{where}.")[0]
    c = check_number(given, f"{where}.clearance_um", nonnegative=True, bound=500.0, unit="µm")
    if 0.0 < c < 0.5:
        raise InputError(
            f"{where}.clearance_um: {c:g} µm (below 0.5 µm) looks like millimetres; give "
            "micrometres"
        )
    d, big_d, b, c_ring, dk = values.values()
    for key, fails, what in (
        ("bore_mm", d >= big_d, f"smaller than outer_diameter_mm ({big_d:g} mm)"),
        ("ball_diameter_mm", not d < dk < big_d, f"between the bore and D ({d:g}, {big_d:g} mm)"),
        ("inner_width_mm", b > dk, f"at most ball_diameter_mm ({dk:g} mm)"),
        ("outer_width_mm", c_ring >= b, f"narrower than inner_width_mm ({b:g} mm)"),
    ):
        if fails:
            raise InputError(f"{where}.{key}: {values[key]:g} mm must be {what}")
    stated = {"kind": "stated", "source": f"the user's description ({where})"}
    figures = {k: {"value": v, **stated} for k, v in values.items()}
    figures["clearance_normal_um"] = {"value": [c, c], **stated}
    figures["tilt_deg"] = {
        "value": ring_tilt_deg(b, c_ring, dk),
        "kind": "derived",
        "source": "asin(B/dk) - asin(C/dk) of the described rings (ring_tilt_deg)",
    }
    stop = joint.get("stop_deg")
    if stop is not None:
        stop = check_number(stop, f"{where}.stop_deg")
        if not 0.0 < stop < 90.0:
            raise InputError(f"{where}.stop_deg: must lie in (0, 90)°, got {stop:g}")
        figures["stop_deg"] = {"value": stop, **stated}
    return Bearing(
        name="described",
        designation="the joint described in " + where,
        maker="the user",
        kind="a described joint",
        datasheet="the user's description",
        figures=figures,
        origin=where,
    )


def design_bearing(mechanics):
    """The bearing a design's mechanics turn on.

    Parameters
    ----------
    mechanics : reflector_opt.design._components.Mechanics

    Returns
    -------
    Bearing
        Its described joint (:func:`described_bearing` of ``mechanics.joint``), else the
        catalogue bearing ``mechanics.bearing`` names, else :data:`DEFAULT_BEARING`.
    """
    joint = getattr(mechanics, "joint", None)
    if joint is not None:
        return described_bearing(joint)
    return get_bearing(getattr(mechanics, "bearing", None) or DEFAULT_BEARING)


def _bearing(entry, origin, where):
    """A :class:`Bearing` from a checked entry, its figures consistent (one line if not)."""
    figures = {k: msgspec.structs.asdict(getattr(entry.figures, k)) for k in FIGURES}
    values = {k: v["value"] for k, v in figures.items()}
    for key in CLEARANCE_CLASSES.values():
        low, high = values[key]
        if low > high:
            raise InputError(f"{where}.figures.{key}: [min, max] µm, got [{low:g}, {high:g}]")
    if values["bore_mm"] >= values["outer_diameter_mm"]:
        raise InputError(f"{where}.figures.bore_mm: must be smaller than outer_diameter_mm")
    if not values["bore_mm"] < values["ball_diameter_mm"] < values["outer_diameter_mm"]:
        raise InputError(f"{where}.figures.ball_diameter_mm: must lie between the bore and D")
    bound = ring_tilt_deg(
        values["inner_width_mm"], values["outer_width_mm"], values["ball_diameter_mm"]
    )
    if values["tilt_deg"] > bound + 1e-9:
        raise InputError(
            f"{where}.figures.tilt_deg: {values['tilt_deg']:g}° exceeds the {bound:.1f}° the "
            "rings' widths allow (ring_tilt_deg)"
        )
    keys = ("name", "designation", "maker", "kind", "datasheet")
    return Bearing(**{k: getattr(entry, k) for k in keys}, figures=figures, origin=origin)


def load_bearings(path=None):
    """Read and check a bearing catalogue file.

    Parameters
    ----------
    path : str or pathlib.Path, optional
        A catalogue file (TOML); default the shipped catalogue.

    Returns
    -------
    tuple of Bearing
        In the file's order. Raises :class:`~reflector_opt.util._errors.InputError` with one
        line naming the file and the key at fault (a figure out of range, a tilt beyond the
        rings' geometric bound, a name twice).
    """
    return read_catalogue(path, SHIPPED, CatalogueDocument, "bearing", _bearing)


@functools.cache
def shipped_bearings():
    """The shipped catalogue, read once.

    Returns
    -------
    tuple of Bearing
    """
    return load_bearings()


def get_bearing(name):
    """A bearing of the shipped catalogue by name.

    Parameters
    ----------
    name : str

    Returns
    -------
    Bearing
        Raises :class:`~reflector_opt.util._errors.InputError` naming the known bearings.
    """
    return find_named(shipped_bearings(), name, "bearing", key="mechanics.bearing")
