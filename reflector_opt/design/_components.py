"""The parts of a design: reflector, sensor placements, workspace, mechanics and noise.

Each part checks its fields on construction against its block of ``design.json``, declared
once in :mod:`reflector_opt.design._schema` (types, ranges, units), and then what the block
cannot state (relations between fields); ``to_dict`` / ``from_dict`` write and read the block
(see :mod:`reflector_opt.design._designfile`). Errors name the field.
"""

import dataclasses
import math
from dataclasses import dataclass

import msgspec
import numpy as np

from reflector_opt.design._schema import (
    MechanicsBlock,
    NoiseBlock,
    ReflectorBlock,
    SensorBlock,
    WorkspaceBlock,
)
from reflector_opt.design._validation import check_range
from reflector_opt.model._surface import DEFAULT_MATERIAL, MATERIALS
from reflector_opt.util import _schema as schema
from reflector_opt.util._errors import InputError
from reflector_opt.util._fileio import json_record
from reflector_opt.util._limits import MAX_POSES, check_size, grid_poses


def _check(part, block, where, *skip):
    """Check a part's fields (but ``skip``) against its block's declaration."""
    fields = {k: v for k, v in dataclasses.asdict(part).items() if k not in skip}
    schema.convert(fields, block, where=where)


def _read(data, block, where):
    """A block of a document, checked against its declaration, as a part's keyword
    arguments: the defaults filled in, lists as tuples."""
    fields = msgspec.to_builtins(schema.convert(data, block, where=where))
    return {k: tuple(v) if isinstance(v, list) else v for k, v in fields.items()}


class _Block:
    """A part that writes its block of ``design.json`` as its fields."""

    def to_dict(self):
        """JSON-ready dict."""
        return json_record(self)


@dataclass(frozen=True)
class Reflector(_Block):
    """The convex spherical reflector.

    Parameters
    ----------
    radius_mm : float
        Reflecting sphere radius r_s, mm.
    centre_mm : tuple of float
        Sphere centre s0 at zero pose in the unit frame, mm.
    inner_radius_mm : float
        Radius of the inner surface, concentric with the rotation centre O, mm.
    reflectance : float
        Total reflectance ρ of the printed surface (0–1).
    specular_fraction : float
        Share f of ρ that is reflected like a mirror; the rest, 1 − f, is Lambertian
        (:mod:`reflector_opt.model._surface`). The defaults are the ``white-sla-resin``
        material (ρ = 0.9, f = 0.05).
    """

    radius_mm: float = 9.0
    centre_mm: tuple[float, float, float] = (0.0, 0.0, -1.4)
    inner_radius_mm: float = 7.5
    reflectance: float = MATERIALS[DEFAULT_MATERIAL].reflectance
    specular_fraction: float = MATERIALS[DEFAULT_MATERIAL].specular_fraction

    def __post_init__(self):
        _check(self, ReflectorBlock, "reflector")

    @classmethod
    def from_dict(cls, data, where="reflector"):
        """Build from a ``design.json`` ``reflector`` block.

        A block without ``specular_fraction`` was written when the model took every
        reflector for a mirror: it is read as f = 1, the surface it was designed for. The
        warning that says so is the whole design's, given once the design is accepted
        (:func:`~reflector_opt.design._designfile.warn_of_assumptions`).
        """
        return cls(**_read(data, ReflectorBlock, where))


@dataclass(frozen=True)
class SensorPlacement(_Block):
    """One sensor on the flexible strip.

    Parameters
    ----------
    name : str
        Label, e.g. ``"S1"``.
    model : str
        Sensor part: a preset name or a key of the design's ``sensor_models``.
    position_mm : tuple of float
        Emitter position f in the unit frame, mm.
    axis : tuple of float
        Optical axis a (pointing at the reflector); normalised on use.
    detector_direction : tuple of float
        Direction from the LED to the phototransistor in the sensor plane; its component
        along the axis is removed. Two sensors with differently oriented pairs respond
        differently to pitch and roll (the paper's Fig. 2g).
    """

    name: str
    model: str
    position_mm: tuple[float, float, float]
    axis: tuple[float, float, float]
    detector_direction: tuple[float, float, float] = (0.0, 0.0, 1.0)

    def __post_init__(self):
        where = f"sensor {self.name!r}"
        _check(self, SensorBlock, where)
        a, e = np.asarray(self.axis, dtype=float), np.asarray(self.detector_direction, dtype=float)
        if np.linalg.norm(a) < 1e-9:
            raise InputError(f"{where}.axis: must not be the zero vector")
        a = a / np.linalg.norm(a)
        if np.linalg.norm(e - (e @ a) * a) < 1e-6:
            raise InputError(f"{where}.detector_direction: must not be parallel to the axis")

    @property
    def in_plane_detector_direction(self):
        """Unit LED-to-detector direction, projected into the sensor plane."""
        from reflector_opt.model._geometry import unit  # the geometry loads the numba kernel

        a = unit(self.axis)
        e = np.asarray(self.detector_direction, dtype=float)
        return unit(e - (e @ a) * a)

    @classmethod
    def from_dict(cls, data, where):
        """Build from one entry of ``design.json`` ``sensors``."""
        fields = _read(data, SensorBlock, where)
        return cls(**{**fields, "name": where if fields["name"] is None else fields["name"]})


@dataclass(frozen=True)
class Workspace(_Block):
    """The poses one unit must sense.

    Parameters
    ----------
    pitch_deg, roll_deg : tuple of float
        (min, max) pitch γ and roll α, degrees.
    step_deg : float
        Grid step of the calibration protocol, degrees (the paper's 0.1°).
    """

    pitch_deg: tuple[float, float] = (-15.0, 15.0)
    roll_deg: tuple[float, float] = (-15.0, 15.0)
    step_deg: float = 0.1

    def __post_init__(self):
        _check(self, WorkspaceBlock, "workspace")
        check_range(self.pitch_deg, "workspace.pitch_deg")
        check_range(self.roll_deg, "workspace.roll_deg")
        self.check_step(self.step_deg, "workspace.step_deg")

    def check_step(self, step_deg, where):
        """Refuse a grid step whose pose grid over this workspace would be too large, or
        would not reach the upper end of the pitch or roll range (a step of twice the range
        or more: the grid would hold one angle).

        Parameters
        ----------
        step_deg : float
            A grid step, degrees (positive).
        where : str
            The parameter that sets it, for the message.

        Returns
        -------
        int
            The number of poses of the grid (at most :data:`~.limits.MAX_POSES`).
        """
        for key in ("pitch_deg", "roll_deg"):
            lo, hi = getattr(self, key)
            if (hi - lo) / step_deg <= 0.5:  # axes() would make round(span / step) + 1 = 1
                raise InputError(
                    f"{where}: expected less than twice the {key[:-4]} range "
                    f"({2 * (hi - lo):g}°), got {step_deg:g}: the grid would not reach "
                    f"workspace.{key}[1]"
                )
        return self._grid_size(step_deg, where)

    def _grid_size(self, step_deg, where):
        """The poses of the grid at ``step_deg``, refused above :data:`~.limits.MAX_POSES`."""
        spans = (self.pitch_deg[1] - self.pitch_deg[0], self.roll_deg[1] - self.roll_deg[0])
        return check_size(
            grid_poses(spans, step_deg), f"{where} = {step_deg:g}°", MAX_POSES, "grid poses"
        )

    def axes(self, step_deg=None):
        """Pitch and roll sample values, both ends included.

        Parameters
        ----------
        step_deg : float, optional
            Grid step, degrees; defaults to the workspace's own.

        Returns
        -------
        (numpy.ndarray, numpy.ndarray)
            1-D pitch and roll values, degrees.
        """
        step = self.step_deg if step_deg is None else step_deg
        if not step > 0:
            raise InputError(f"step_deg: must be positive, got {step}")
        self._grid_size(step, "step_deg")  # the parameters' steps are checked in full
        return tuple(
            np.linspace(lo, hi, round((hi - lo) / step) + 1)
            for lo, hi in (self.pitch_deg, self.roll_deg)
        )

    def grid(self, step_deg=None):
        """Pitch and roll as broadcastable columns: shapes (n_pitch, 1) and (1, n_roll).

        Parameters
        ----------
        step_deg : float, optional
            Grid step, degrees; defaults to the workspace's own.

        Returns
        -------
        (numpy.ndarray, numpy.ndarray)
            Broadcasting them gives the full (n_pitch, n_roll) pose grid.
        """
        pitch, roll = self.axes(step_deg)
        return pitch[:, None], roll[None, :]

    def poses(self, step_deg=None):
        """The pose grid as a list of poses, pitch-major (the paper's raster order).

        Parameters
        ----------
        step_deg : float, optional
            Grid step, degrees; defaults to the workspace's own.

        Returns
        -------
        numpy.ndarray
            Shape (n_pitch · n_roll, 2): pitch, roll, degrees.
        """
        pitch, roll = np.meshgrid(*self.axes(step_deg), indexing="ij")
        return np.column_stack([pitch.ravel(), roll.ravel()])

    def bounds(self, margin_deg=0.0):
        """The workspace as a box: its lower and upper (pitch, roll) corners.

        Parameters
        ----------
        margin_deg : float, optional
            Widening on every side, degrees.

        Returns
        -------
        (numpy.ndarray, numpy.ndarray)
            Shape (2,) each: (pitch, roll) of the lower and the upper corner, degrees.
        """
        lo, hi = np.array([self.pitch_deg, self.roll_deg], dtype=float).T
        return lo - margin_deg, hi + margin_deg

    def sample(self, rng, n):
        """Poses drawn uniformly over the workspace.

        Parameters
        ----------
        rng : numpy.random.Generator
        n : int
            Number of poses.

        Returns
        -------
        numpy.ndarray
            Shape (n, 2): pitch and roll, degrees.
        """
        lo, hi = self.bounds()
        return rng.uniform(lo, hi, size=(int(n), 2))

    @classmethod
    def from_dict(cls, data, where="workspace"):
        """Build from a ``design.json`` ``workspace`` block."""
        return cls(**_read(data, WorkspaceBlock, where))


@dataclass(frozen=True)
class Mechanics:
    """Mechanical envelope of one unit; the defaults are the paper's prototype.

    Parameters
    ----------
    unit_diameter_mm, unit_height_mm : float
        Outer diameter and height of a rotational unit, mm (22 and 12).
    bearing_bore_mm, bearing_od_mm : float
        Spherical bearing bore and outer diameter, mm (GE6: 6 and 14).
    link_length_mm : float
        Distance between the rotation centres of consecutive units, mm (12 mm unit plus the
        6 mm springs: 18).
    n_units : int
        Units in one segment (4).
    min_wall_mm : float
        Thinnest printable wall, mm (0.8).
    bearing : str or None
        A bearing of the bearing catalogue (:mod:`reflector_opt.design._bearings`, e.g.
        ``"GE4E"``): its bore and outside diameter replace ``bearing_bore_mm`` and
        ``bearing_od_mm``, and its permissible tilt limits the workspace; None (default) for
        the dimensions as given.
    joint : dict or None
        A joint the user describes instead of naming one, ``{key: value}`` of
        :data:`~reflector_opt.design._bearings.JOINT_KEYS` (lengths mm, ``clearance_um`` µm,
        optional ``stop_deg`` degrees): a bearing as a named one is
        (:func:`~reflector_opt.design._bearings.described_bearing`); not with ``bearing``.
    """

    unit_diameter_mm: float = 22.0
    unit_height_mm: float = 12.0
    bearing_bore_mm: float = 6.0
    bearing_od_mm: float = 14.0
    link_length_mm: float = 18.0
    n_units: int = 4
    min_wall_mm: float = 0.8
    bearing: str | None = None
    joint: dict | None = None

    def __post_init__(self):
        object.__setattr__(self, "n_units", _whole(self.n_units))
        _check(self, MechanicsBlock, "mechanics", "joint")  # the joint: described_bearing
        if self.bearing is not None or self.joint is not None:
            _take_bearing(self)
        if self.bearing_bore_mm >= self.bearing_od_mm:
            raise InputError("mechanics.bearing_bore_mm: must be smaller than bearing_od_mm")
        if self.bearing_od_mm >= self.unit_diameter_mm:
            raise InputError("mechanics.bearing_od_mm: must be smaller than unit_diameter_mm")

    def to_dict(self):
        """JSON-ready dict (``bearing`` None when no catalogue bearing is named, ``joint``
        only when one is described)."""
        keys = [k for k in self.__dataclass_fields__ if k != "joint" or self.joint is not None]
        return {k: dict(self.joint) if k == "joint" else getattr(self, k) for k in keys}

    @classmethod
    def from_dict(cls, data, where="mechanics"):
        """Build from a ``design.json`` ``mechanics`` block."""
        if isinstance(data, dict) and "n_units" in data:
            data = {**data, "n_units": _whole(data["n_units"])}
        return cls(**_read(data, MechanicsBlock, where))


def _whole(value):
    """A float with a whole value (a JSON or TOML number) as an int; anything else as is."""
    return int(value) if isinstance(value, float) and value.is_integer() else value


def _take_bearing(mechanics):
    """Set a Mechanics' bore and outside diameter from its named or described bearing."""
    from reflector_opt.design._bearings import described_bearing, get_bearing

    if mechanics.joint is None:
        bearing = get_bearing(mechanics.bearing)
    elif mechanics.bearing is not None:
        raise InputError(
            "mechanics.joint: a joint is described and a bearing named (mechanics.bearing); "
            "give one of them"
        )
    else:
        bearing = described_bearing(mechanics.joint)
        joint = {k: float(v) for k, v in mechanics.joint.items() if v is not None}
        object.__setattr__(mechanics, "joint", joint)
    object.__setattr__(mechanics, "bearing_bore_mm", bearing.bore_mm)
    object.__setattr__(mechanics, "bearing_od_mm", bearing.outer_diameter_mm)


@dataclass(frozen=True)
class Noise(_Block):
    """Measurement noise of the read-out.

    Parameters
    ----------
    sigma_v : float
        Additive RMS voltage noise, V.
    adc_bits : int
        ADC resolution, bits.
    vref : float
        ADC reference (full-scale) voltage, V.
    """

    sigma_v: float = 0.002
    adc_bits: int = 12
    vref: float = 3.3

    def __post_init__(self):
        _check(self, NoiseBlock, "noise")

    @property
    def lsb_v(self):
        """ADC step, V."""
        return self.vref / 2**self.adc_bits

    @property
    def total_sigma_v(self):
        """RMS of noise and quantisation together, sqrt(σ² + LSB²/12), V."""
        return math.sqrt(self.sigma_v**2 + self.lsb_v**2 / 12.0)

    @classmethod
    def from_dict(cls, data, where="noise"):
        """Build from a ``design.json`` ``noise`` block."""
        return cls(**_read(data, NoiseBlock, where))
