"""The tolerance model: how an as-built unit differs from its design, and random draws of it.

Every tolerance is a zero-centred :class:`Spread` — a normal distribution with standard
deviation ``scale`` or a uniform one on ±``scale`` — in the unit its name carries. Two of them
are one-sided (crosstalk and ambient light can only add light): their draws are the absolute
values, a half-normal or a uniform distribution on [0, scale].

A draw of one unit is kept as *standard* values (standard normal, or uniform on [−1, 1]) per
tolerance, scaled only when the unit is built (:func:`as_built`). Every tolerance is drawn for
every sample even when its scale is zero, from a generator seeded by ``(seed, sample index)``:
a sample's draw therefore depends on nothing but the seed and its index — not on the
executor, the number of workers, the batch it travels in, or the other tolerances' scales.

Defaults (documented assumptions, docs/tolerance.md): an SLA print places surfaces within
about ±50 µm (σ 25 µm on radii and on each component of the sphere centre); hand or
pick-and-place assembly on the flexible strip places each sensor within σ 50 µm per axis and
tilts its optical axis by σ 1° about each of the two axes across it; gain σ 2 % and offset
σ 10 mV per sensor (component tolerances; the paper saw a gain difference between the two
sensors of a unit); optical crosstalk up to 1 % of the neighbour's photocurrent (removed by
time-multiplexed driving); a change of ambient light between calibration and use of up to
1 µA of collector current; electrical noise and the ADC as in the design's ``noise``.
"""

import math
from dataclasses import asdict, dataclass, field, fields, replace
from typing import Annotated, Literal

import msgspec
import numpy as np
from msgspec import Meta

from reflector_opt.design import Reflector
from reflector_opt.model._geometry import tilted_axis
from reflector_opt.model._noise import Mismatch
from reflector_opt.util import _schema as schema
from reflector_opt.util._errors import InputError
from reflector_opt.util._limits import MAX_ANGLE_DEG, MAX_LENGTH_MM
from reflector_opt.util._seeds import stream_rng

_KINDS = ("normal", "uniform")


@dataclass(frozen=True)
class Spread:
    """A zero-centred distribution of one tolerance.

    Parameters
    ----------
    scale : float
        Standard deviation (``kind="normal"``) or half-width (``kind="uniform"``), in the
        unit of the tolerance it belongs to; 0 switches the tolerance off.
    kind : {"normal", "uniform"}
    """

    scale: float = 0.0
    kind: str = "normal"

    def __post_init__(self):
        if self.kind not in _KINDS:
            raise InputError(
                f"distribution: expected one of {', '.join(_KINDS)}, got {self.kind!r}"
            )
        if isinstance(self.scale, bool) or not isinstance(self.scale, int | float):
            raise InputError(f"distribution scale: expected a number, got {self.scale!r}")
        if not math.isfinite(self.scale) or self.scale < 0:
            what = "standard deviation" if self.kind == "normal" else "half-width"
            raise InputError(f"{what}: must be a finite number ≥ 0, got {self.scale}")

    def standard(self, rng, size):
        """Standard draws: N(0, 1) for ``normal``, U(−1, 1) for ``uniform``; shape ``size``."""
        return rng.standard_normal(size) if self.kind == "normal" else rng.uniform(-1.0, 1.0, size)


#: Tolerances whose draws are absolute values (they can only add light).
ONE_SIDED = ("crosstalk_fraction", "ambient_current_ua")


@dataclass(frozen=True)
class Tolerances:
    """Distributions of the manufacturing and operating errors of one unit.

    Parameters
    ----------
    reflector_radius_mm : Spread
        Error of the reflecting sphere's radius r_s, mm.
    centre_offset_mm : Spread
        Error of each component (x, y, z) of the sphere centre s0, mm.
    inner_radius_mm : Spread
        Error of the inner surface radius, mm (changes the shell wall only).
    sensor_position_mm : Spread
        Error of each component of each sensor's position f, mm.
    sensor_tilt_deg : Spread
        Tilt of each sensor's optical axis about each of two axes across it, degrees.
    gain : Spread
        Relative error of each sensor's output gain (0.02 = 2 %), applied as
        :class:`reflector_opt.model._noise.Mismatch`.
    offset_v : Spread
        Error of each sensor's output offset, V.
    crosstalk_fraction : Spread
        One-sided: fraction of each other sensor's light-induced collector current that
        reaches a sensor's phototransistor (its LED's light leaking across).
    ambient_current_ua : Spread
        One-sided: extra collector current from ambient light in use that was not present
        during calibration, µA.
    multiplexed : bool
        Sensors driven in turn (time-multiplexed through a demultiplexer): no crosstalk.
    """

    reflector_radius_mm: Spread = field(default_factory=lambda: Spread(0.025))
    centre_offset_mm: Spread = field(default_factory=lambda: Spread(0.025))
    inner_radius_mm: Spread = field(default_factory=lambda: Spread(0.025))
    sensor_position_mm: Spread = field(default_factory=lambda: Spread(0.05))
    sensor_tilt_deg: Spread = field(default_factory=lambda: Spread(1.0))
    gain: Spread = field(default_factory=lambda: Spread(0.02))
    offset_v: Spread = field(default_factory=lambda: Spread(0.01))
    crosstalk_fraction: Spread = field(default_factory=lambda: Spread(0.01, "uniform"))
    ambient_current_ua: Spread = field(default_factory=lambda: Spread(1.0, "uniform"))
    multiplexed: bool = False

    def __post_init__(self):
        for name in self.names():
            if not isinstance(getattr(self, name), Spread):
                raise InputError(f"tolerance {name}: expected a Spread")
        if not isinstance(self.multiplexed, bool):
            raise InputError(f"multiplexed: expected true or false, got {self.multiplexed!r}")

    @staticmethod
    def names():
        """Tolerance names in their fixed draw order."""
        return tuple(f.name for f in fields(Tolerances) if f.name != "multiplexed")

    @classmethod
    def zero(cls, multiplexed=False):
        """Every tolerance switched off (default kinds kept): each sample is the nominal design."""
        defaults = cls()
        return cls(
            **{name: replace(getattr(defaults, name), scale=0.0) for name in cls.names()},
            multiplexed=multiplexed,
        )

    def only(self, name):
        """Copy in which every tolerance but ``name`` is switched off."""
        if name not in self.names():
            raise InputError(f"unknown tolerance {name!r}; known: {', '.join(self.names())}")
        return replace(
            self,
            **{
                other: replace(getattr(self, other), scale=0.0)
                for other in self.names()
                if other != name
            },
        )

    def active(self):
        """Names of the tolerances with a non-zero scale (crosstalk off when multiplexed)."""
        return tuple(
            name
            for name in self.names()
            if getattr(self, name).scale > 0
            and not (name == "crosstalk_fraction" and self.multiplexed)
        )

    def to_dict(self):
        """JSON-ready ``{name: {"scale": ..., "kind": ...}, "multiplexed": ...}``."""
        spreads = {name: asdict(getattr(self, name)) for name in self.names()}
        return {**spreads, "multiplexed": self.multiplexed}

    @classmethod
    def from_dict(cls, data, where="tolerances"):
        """Build from a dict like :meth:`to_dict`'s, checked against :data:`TolerancesTable`.

        Omitted tolerances keep their defaults; a tolerance may also be given as a bare
        number: its scale, with the default kind.

        Parameters
        ----------
        data : dict
        where : str, optional
            The table's place, for messages.
        """
        return cls.from_table(schema.convert(data, TolerancesTable, toml=True, where=where))

    @classmethod
    def from_table(cls, table):
        """Build from a checked :data:`TolerancesTable`."""
        nominal, values = cls(), {}
        for name in cls.names():
            value, default = getattr(table, name), getattr(nominal, name)
            if not isinstance(value, SpreadTable):  # a bare number: the scale
                value = SpreadTable(scale=value)
            scale = default.scale if value.scale is None else value.scale
            values[name] = Spread(scale, value.kind or default.kind)
        return cls(**values, multiplexed=table.multiplexed)


class SpreadTable(schema.Table):
    """One tolerance as a table: its scale and its distribution (absent: the default)."""

    scale: (
        Annotated[float, Meta(ge=0, le=1e3, description="σ or half-width, in the tolerance's unit")]
        | None
    ) = None
    kind: Literal["normal", "uniform"] | None = None


#: Largest scale of a tolerance, by the unit its name ends with.
_SCALE_BOUND = {"_mm": MAX_LENGTH_MM, "_deg": MAX_ANGLE_DEG, "_fraction": 1.0}


def _tolerance_key(name):
    """The declared type of one tolerance: a scale (in its unit, 0: off) or a table."""
    bound = next((b for suffix, b in _SCALE_BOUND.items() if name.endswith(suffix)), 1e3)
    scale = Annotated[float, Meta(ge=0, le=bound, description="σ or half-width (0: off)")]
    return (name, scale | SpreadTable, getattr(Tolerances(), name).scale)


#: The declared schema of a ``[tolerances]`` table: each tolerance as its scale (a number)
#: or a table ``{scale, kind}``, and ``multiplexed``.
TolerancesTable = msgspec.defstruct(
    "TolerancesTable",
    [
        *(_tolerance_key(name) for name in Tolerances.names()),
        ("multiplexed", bool, Tolerances.multiplexed),
    ],
    bases=(schema.Table,),
    module=__name__,
)


def factor_sizes(n_sensors):
    """Number of standard draws of each tolerance for a unit with ``n_sensors`` sensors."""
    per_sensor = {"sensor_position_mm": 3, "sensor_tilt_deg": 2}
    sizes = {"reflector_radius_mm": 1, "centre_offset_mm": 3, "inner_radius_mm": 1}
    for name in Tolerances.names():
        if name not in sizes:
            sizes[name] = n_sensors * per_sensor.get(name, 1)
    return sizes


@dataclass(frozen=True)
class Draw:
    """The random part of one sample: standard draws per tolerance and the noise seed.

    Attributes
    ----------
    index : int
        Sample index (results are keyed by it).
    standard : dict of str to numpy.ndarray
        Standard draws of each tolerance (see :meth:`Spread.standard`), before scaling.
    noise_seed : int
        Seed of the simulated calibration (poses, noise, ADC).
    """

    index: int
    standard: dict
    noise_seed: int


def draw_sample(tolerances, n_sensors, seed, index):
    """The draw of sample ``index``: a function of ``(seed, index)`` alone.

    Its generator is the ``"tolerance_draw"`` stream's child ``index`` of the seed
    (:func:`reflector_opt.util._seeds.stream_rng`).

    Parameters
    ----------
    tolerances : Tolerances
        Only the kinds (normal or uniform) matter here, not the scales.
    n_sensors : int
    seed : int
        Seed of the whole analysis (≥ 0).
    index : int
        Sample index (≥ 0).

    Returns
    -------
    Draw
    """
    rng = stream_rng(seed, "tolerance_draw", index)
    sizes = factor_sizes(n_sensors)
    standard = {
        name: getattr(tolerances, name).standard(rng, sizes[name]) for name in Tolerances.names()
    }
    return Draw(int(index), standard, int(rng.integers(2**63 - 1)))


@dataclass(frozen=True)
class Electrical:
    """The as-built unit's read-out errors (sensors in design order).

    Attributes
    ----------
    mismatch : reflector_opt.model._noise.Mismatch
        Gain and offset of each sensor.
    crosstalk_fraction : numpy.ndarray
        Fraction of every other sensor's light-induced current each sensor picks up.
    ambient_current_ua : numpy.ndarray
        Extra collector current in use (not during calibration), µA.
    """

    mismatch: Mismatch
    crosstalk_fraction: np.ndarray
    ambient_current_ua: np.ndarray


def drawn_errors(tolerances, draw):
    """The errors of one draw in the tolerances' units: ``scale × standard draw``.

    One-sided tolerances take the absolute value; crosstalk is zero when the sensors are
    multiplexed.

    Parameters
    ----------
    tolerances : Tolerances
    draw : Draw

    Returns
    -------
    dict of str to numpy.ndarray
        One array per tolerance, in :meth:`Tolerances.names` order.
    """
    errors = {}
    for name in Tolerances.names():
        x = getattr(tolerances, name).scale * np.asarray(draw.standard[name], dtype=float)
        if name in ONE_SIDED:
            x = np.abs(x)
        if name == "crosstalk_fraction" and tolerances.multiplexed:
            x = np.zeros_like(x)
        errors[name] = x
    return errors


def as_built(design, tolerances, draw):
    """The unit built from ``design`` with the errors of one draw.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    tolerances : Tolerances
    draw : Draw

    Returns
    -------
    tuple of (Design, Electrical)
        The as-built geometry (validated: raises
        :class:`~reflector_opt.util._errors.InputError` if a sensor ends up inside the sphere) and
        its read-out errors. With every scale zero both equal the nominal design exactly.
    """
    n = len(design.sensors)
    errors = drawn_errors(tolerances, draw)
    refl = design.reflector
    reflector = Reflector(
        radius_mm=refl.radius_mm + float(errors["reflector_radius_mm"][0]),
        centre_mm=tuple((np.asarray(refl.centre_mm) + errors["centre_offset_mm"]).tolist()),
        inner_radius_mm=refl.inner_radius_mm + float(errors["inner_radius_mm"][0]),
        reflectance=refl.reflectance,
    )
    moves = errors["sensor_position_mm"].reshape(n, 3)
    tilts = errors["sensor_tilt_deg"].reshape(n, 2)
    sensors = tuple(
        replace(
            s,
            position_mm=tuple((np.asarray(s.position_mm) + moves[i]).tolist()),
            axis=tilted_axis(s.axis, tilts[i]),
        )
        for i, s in enumerate(design.sensors)
    )
    built = design.replace(reflector=reflector, sensors=sensors)
    electrical = Electrical(
        mismatch=Mismatch(
            tuple((1.0 + errors["gain"]).tolist()), tuple(errors["offset_v"].tolist())
        ),
        crosstalk_fraction=errors["crosstalk_fraction"],
        ambient_current_ua=errors["ambient_current_ua"],
    )
    return built, electrical
