"""The design of one sensing unit, its validation and the ``design.json`` round trip.

A :class:`Design` is the reflector (sphere radius and centre, inner radius), the sensors
(part, position, optical axis, LED-to-detector direction), the workspace (pitch and roll
ranges), the mechanical envelope and the noise. ``design.json`` keys
``reflector.radius_mm``, ``reflector.centre_mm``, ``sensors[].position_mm``,
``workspace.pitch_deg`` and ``workspace.roll_deg`` are a public contract (format
``reflector-opt/design@1``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from reflector_opt.model.geometry import sensor_distance, unit
from reflector_opt.model.sensors import SensorModel, get_preset
from reflector_opt.util.errors import InputError
from reflector_opt.util.fileio import read_json, write_json

__all__ = [
    "FORMAT",
    "Design",
    "Mechanics",
    "Noise",
    "Reflector",
    "SensorPlacement",
    "Workspace",
    "default_design",
    "load_design",
]

FORMAT = "reflector-opt/design@1"

# --- reading JSON with messages that name the field -------------------------------------------


def _number(value, where, *, positive=False, nonnegative=False):
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise InputError(f"{where}: expected a number, got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise InputError(f"{where}: must be finite, got {value}")
    if positive and value <= 0:
        raise InputError(f"{where}: must be positive, got {value}")
    if nonnegative and value < 0:
        raise InputError(f"{where}: must not be negative, got {value}")
    return value


def _vector(value, where, length=3):
    if not isinstance(value, list | tuple) or len(value) != length:
        raise InputError(f"{where}: expected a list of {length} numbers, got {value!r}")
    return tuple(_number(v, f"{where}[{i}]") for i, v in enumerate(value))


def _range(value, where):
    lo, hi = _vector(value, where, length=2)
    if not lo < hi:
        raise InputError(f"{where}: min must be below max, got [{lo}, {hi}]")
    return lo, hi


def _section(data, key, where=""):
    path = f"{where}{key}"
    if not isinstance(data, dict):
        raise InputError(f"{where.rstrip('.') or 'design'}: expected an object")
    if key not in data:
        raise InputError(f"{path}: missing key")
    return data[key], path


def _reject_unknown(data, allowed, where):
    unknown = sorted(set(data) - set(allowed))
    if unknown:
        raise InputError(f"{where}: unknown key(s) {', '.join(unknown)}")


# --- the parts of a design ----------------------------------------------------------------------


@dataclass(frozen=True)
class Reflector:
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
        Reflectance ρ of the printed surface (0–1); white SLA resin is assumed 0.9.
    """

    radius_mm: float = 9.0
    centre_mm: tuple[float, float, float] = (0.0, 0.0, -1.5)
    inner_radius_mm: float = 7.5
    reflectance: float = 0.9

    def __post_init__(self):
        _number(self.radius_mm, "reflector.radius_mm", positive=True)
        _vector(self.centre_mm, "reflector.centre_mm")
        _number(self.inner_radius_mm, "reflector.inner_radius_mm", positive=True)
        rho = _number(self.reflectance, "reflector.reflectance", positive=True)
        if rho > 1:
            raise InputError(f"reflector.reflectance: must be at most 1, got {rho}")

    def to_dict(self):
        """JSON-ready dict."""
        return {
            "radius_mm": self.radius_mm,
            "centre_mm": list(self.centre_mm),
            "inner_radius_mm": self.inner_radius_mm,
            "reflectance": self.reflectance,
        }

    @classmethod
    def from_dict(cls, data, where="reflector"):
        """Build from a ``design.json`` ``reflector`` block."""
        _reject_unknown(data, ("radius_mm", "centre_mm", "inner_radius_mm", "reflectance"), where)
        radius, path = _section(data, "radius_mm", f"{where}.")
        centre, cpath = _section(data, "centre_mm", f"{where}.")
        return cls(
            radius_mm=_number(radius, path, positive=True),
            centre_mm=_vector(centre, cpath),
            inner_radius_mm=_number(
                data.get("inner_radius_mm", cls.inner_radius_mm), f"{where}.inner_radius_mm"
            ),
            reflectance=_number(data.get("reflectance", cls.reflectance), f"{where}.reflectance"),
        )


@dataclass(frozen=True)
class SensorPlacement:
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
        _vector(self.position_mm, f"{where}.position_mm")
        a = np.asarray(_vector(self.axis, f"{where}.axis"))
        if np.linalg.norm(a) < 1e-9:
            raise InputError(f"{where}.axis: must not be the zero vector")
        e = np.asarray(_vector(self.detector_direction, f"{where}.detector_direction"))
        a = a / np.linalg.norm(a)
        if np.linalg.norm(e - (e @ a) * a) < 1e-6:
            raise InputError(f"{where}.detector_direction: must not be parallel to the axis")

    @property
    def in_plane_detector_direction(self):
        """Unit LED-to-detector direction, projected into the sensor plane."""
        a = unit(self.axis)
        e = np.asarray(self.detector_direction, dtype=float)
        return unit(e - (e @ a) * a)

    def to_dict(self):
        """JSON-ready dict."""
        return {
            "name": self.name,
            "model": self.model,
            "position_mm": list(self.position_mm),
            "axis": list(self.axis),
            "detector_direction": list(self.detector_direction),
        }

    @classmethod
    def from_dict(cls, data, where):
        """Build from one entry of ``design.json`` ``sensors``."""
        _reject_unknown(data, ("name", "model", "position_mm", "axis", "detector_direction"), where)
        position, ppath = _section(data, "position_mm", f"{where}.")
        axis, apath = _section(data, "axis", f"{where}.")
        model, _ = _section(data, "model", f"{where}.")
        if not isinstance(model, str):
            raise InputError(f"{where}.model: expected a sensor part name")
        return cls(
            name=str(data.get("name", where)),
            model=model,
            position_mm=_vector(position, ppath),
            axis=_vector(axis, apath),
            detector_direction=_vector(
                data.get("detector_direction", cls.detector_direction),
                f"{where}.detector_direction",
            ),
        )


@dataclass(frozen=True)
class Workspace:
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
        _range(self.pitch_deg, "workspace.pitch_deg")
        _range(self.roll_deg, "workspace.roll_deg")
        _number(self.step_deg, "workspace.step_deg", positive=True)
        for key in ("pitch_deg", "roll_deg"):
            if max(abs(v) for v in getattr(self, key)) >= 90:
                raise InputError(f"workspace.{key}: angles must lie within (-90, 90) degrees")

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

    def to_dict(self):
        """JSON-ready dict."""
        return {
            "pitch_deg": list(self.pitch_deg),
            "roll_deg": list(self.roll_deg),
            "step_deg": self.step_deg,
        }

    @classmethod
    def from_dict(cls, data, where="workspace"):
        """Build from a ``design.json`` ``workspace`` block."""
        _reject_unknown(data, ("pitch_deg", "roll_deg", "step_deg"), where)
        pitch, ppath = _section(data, "pitch_deg", f"{where}.")
        roll, rpath = _section(data, "roll_deg", f"{where}.")
        return cls(
            pitch_deg=_range(pitch, ppath),
            roll_deg=_range(roll, rpath),
            step_deg=_number(data.get("step_deg", cls.step_deg), f"{where}.step_deg"),
        )


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
    """

    unit_diameter_mm: float = 22.0
    unit_height_mm: float = 12.0
    bearing_bore_mm: float = 6.0
    bearing_od_mm: float = 14.0
    link_length_mm: float = 18.0
    n_units: int = 4
    min_wall_mm: float = 0.8

    def __post_init__(self):
        for key, value in self.to_dict().items():
            _number(value, f"mechanics.{key}", positive=True)
        if self.bearing_bore_mm >= self.bearing_od_mm:
            raise InputError("mechanics.bearing_bore_mm: must be smaller than bearing_od_mm")
        if self.bearing_od_mm >= self.unit_diameter_mm:
            raise InputError("mechanics.bearing_od_mm: must be smaller than unit_diameter_mm")
        if int(self.n_units) != self.n_units:
            raise InputError("mechanics.n_units: must be a whole number")

    def to_dict(self):
        """JSON-ready dict."""
        return {k: getattr(self, k) for k in self.__dataclass_fields__}

    @classmethod
    def from_dict(cls, data, where="mechanics"):
        """Build from a ``design.json`` ``mechanics`` block."""
        _reject_unknown(data, cls.__dataclass_fields__, where)
        values = {k: _number(v, f"{where}.{k}", positive=True) for k, v in data.items()}
        if "n_units" in values:
            values["n_units"] = int(values["n_units"])
        return cls(**values)


@dataclass(frozen=True)
class Noise:
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
        _number(self.sigma_v, "noise.sigma_v", nonnegative=True)
        _number(self.vref, "noise.vref", positive=True)
        bits = _number(self.adc_bits, "noise.adc_bits", positive=True)
        if int(bits) != bits or bits > 32:
            raise InputError(f"noise.adc_bits: must be a whole number from 1 to 32, got {bits}")

    @property
    def lsb_v(self):
        """ADC step, V."""
        return self.vref / 2**self.adc_bits

    @property
    def total_sigma_v(self):
        """RMS of noise and quantisation together, sqrt(σ² + LSB²/12), V."""
        return math.sqrt(self.sigma_v**2 + self.lsb_v**2 / 12.0)

    def to_dict(self):
        """JSON-ready dict."""
        return {"sigma_v": self.sigma_v, "adc_bits": self.adc_bits, "vref": self.vref}

    @classmethod
    def from_dict(cls, data, where="noise"):
        """Build from a ``design.json`` ``noise`` block."""
        _reject_unknown(data, ("sigma_v", "adc_bits", "vref"), where)
        values = {k: _number(v, f"{where}.{k}") for k, v in data.items()}
        if "adc_bits" in values:
            if int(values["adc_bits"]) != values["adc_bits"]:
                raise InputError(f"{where}.adc_bits: must be a whole number")
            values["adc_bits"] = int(values["adc_bits"])
        return cls(**values)


@dataclass(frozen=True)
class Design:
    """A complete sensing-unit design.

    Parameters
    ----------
    reflector : Reflector
    sensors : tuple of SensorPlacement
        At least two sensors (two voltages for two angles).
    workspace : Workspace
    mechanics : Mechanics
    noise : Noise
    sensor_models : dict of str to SensorModel
        Sensor parts defined in the design itself (e.g. fitted to a measured curve); they
        take precedence over the built-in presets of the same name.
    predicted : dict
        Predicted performance figures written by the analysis commands (free-form JSON).

    Notes
    -----
    Construction validates every field, and that no sensor touches the reflector sphere
    anywhere in the workspace (checked on the workspace grid, at least every 0.5°).
    """

    reflector: Reflector = field(default_factory=Reflector)
    sensors: tuple[SensorPlacement, ...] = ()
    workspace: Workspace = field(default_factory=Workspace)
    mechanics: Mechanics = field(default_factory=Mechanics)
    noise: Noise = field(default_factory=Noise)
    sensor_models: dict = field(default_factory=dict)
    predicted: dict = field(default_factory=dict)

    def __post_init__(self):
        if len(self.sensors) < 2:
            raise InputError("sensors: a unit needs at least two sensors")
        names = [s.name for s in self.sensors]
        if len(set(names)) != len(names):
            raise InputError(f"sensors: names must be unique, got {names}")
        for s in self.sensors:
            self.model_of(s)
        if self.reflector.inner_radius_mm >= self.reflector.radius_mm + np.linalg.norm(
            self.reflector.centre_mm
        ):
            raise InputError("reflector.inner_radius_mm: the inner surface lies outside the sphere")
        pitch, roll = self.workspace.grid(min(self.workspace.step_deg, 0.5))
        d = sensor_distance(
            self.positions_mm,
            self.reflector.centre_mm,
            self.reflector.radius_mm,
            pitch,
            roll,
            on_collision="nan",
        )
        touching = np.isnan(d).any(axis=(0, 1))
        if touching.any():
            bad = [n for n, t in zip(names, touching, strict=True) if t]
            raise InputError(
                f"sensors: {', '.join(bad)} would lie inside the reflector sphere in the workspace"
            )

    # -- derived arrays (sensors along the first axis) --

    @property
    def positions_mm(self):
        """Sensor positions, shape (n_sensors, 3), mm."""
        return np.array([s.position_mm for s in self.sensors], dtype=float)

    @property
    def axes(self):
        """Unit optical axes, shape (n_sensors, 3)."""
        return unit([s.axis for s in self.sensors])

    @property
    def detector_offsets_mm(self):
        """Emitter-to-detector vectors e in each sensor plane, shape (n_sensors, 3), mm."""
        return np.array(
            [
                self.model_of(s).emitter_detector_mm * s.in_plane_detector_direction
                for s in self.sensors
            ]
        )

    @property
    def models(self):
        """Sensor models in sensor order."""
        return [self.model_of(s) for s in self.sensors]

    def model_of(self, sensor):
        """The :class:`SensorModel` of one placement (design-defined first, then presets)."""
        if sensor.model in self.sensor_models:
            return self.sensor_models[sensor.model]
        try:
            return get_preset(sensor.model)
        except InputError as exc:
            raise InputError(f"sensor {sensor.name!r}.model: {exc}") from None

    def with_sensor_model(self, model):
        """Copy in which every sensor uses ``model`` (stored in ``sensor_models``).

        Parameters
        ----------
        model : SensorModel
            E.g. a model fitted to a measured curve.

        Returns
        -------
        Design
        """
        return replace(
            self,
            sensors=tuple(replace(s, model=model.name) for s in self.sensors),
            sensor_models={**self.sensor_models, model.name: model},
        )

    def replace(self, **changes):
        """Copy with top-level parts replaced (validated again)."""
        return replace(self, **changes)

    # -- JSON --

    def to_dict(self):
        """The ``design.json`` document as a dict."""
        out = {
            "format": FORMAT,
            "reflector": self.reflector.to_dict(),
            "sensors": [s.to_dict() for s in self.sensors],
            "workspace": self.workspace.to_dict(),
            "mechanics": self.mechanics.to_dict(),
            "noise": self.noise.to_dict(),
            "predicted": self.predicted,
        }
        if self.sensor_models:
            out["sensor_models"] = {k: m.to_dict() for k, m in self.sensor_models.items()}
        return out

    @classmethod
    def from_dict(cls, data):
        """Build and validate from a ``design.json`` dict; errors name the field."""
        if not isinstance(data, dict):
            raise InputError("design: expected a JSON object")
        allowed = (
            "format",
            "reflector",
            "sensors",
            "workspace",
            "mechanics",
            "noise",
            "sensor_models",
            "predicted",
        )
        _reject_unknown(data, allowed, "design")
        fmt = data.get("format", FORMAT)
        if fmt != FORMAT:
            raise InputError(f"format: expected {FORMAT!r}, got {fmt!r}")
        reflector, _ = _section(data, "reflector")
        sensors, _ = _section(data, "sensors")
        if not isinstance(sensors, list):
            raise InputError("sensors: expected a list")
        for i, s in enumerate(sensors):
            if not isinstance(s, dict):
                raise InputError(f"sensors[{i}]: expected an object")
        workspace, _ = _section(data, "workspace")
        for key, block in (("reflector", reflector), ("workspace", workspace)):
            if not isinstance(block, dict):
                raise InputError(f"{key}: expected an object")
        models = data.get("sensor_models", {})
        if not isinstance(models, dict):
            raise InputError("sensor_models: expected an object")
        return cls(
            reflector=Reflector.from_dict(reflector),
            sensors=tuple(
                SensorPlacement.from_dict(s, f"sensors[{i}]") for i, s in enumerate(sensors)
            ),
            workspace=Workspace.from_dict(workspace),
            mechanics=Mechanics.from_dict(_object(data, "mechanics")),
            noise=Noise.from_dict(_object(data, "noise")),
            sensor_models={
                k: SensorModel.from_dict(v, f"sensor_models.{k}") for k, v in models.items()
            },
            predicted=_object(data, "predicted"),
        )

    def save(self, path):
        """Write ``design.json`` atomically."""
        write_json(path, self.to_dict())


def _object(data, key):
    block = data.get(key, {})
    if not isinstance(block, dict):
        raise InputError(f"{key}: expected an object")
    return block


def load_design(path):
    """Read and validate a ``design.json`` file.

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    Design
        Raises :class:`~reflector_opt.util.errors.InputError` naming the problem.
    """
    return Design.from_dict(read_json(path))


def default_design():
    """The built-in design, resembling the paper's prototype unit.

    A 22 mm unit with the GE6 bearing (6 mm bore, 14 mm outer diameter), two NJL5901R-2
    sensors 90° apart at 10 mm from the rotation centre looking radially inwards, and a
    reflector sphere of radius 9 mm whose centre sits 1.5 mm below the rotation centre;
    the inner surface (7.5 mm) clears the bearing's outer ring. Workspace ±15° pitch and
    roll in 0.1° steps.

    Returns
    -------
    Design
    """
    return Design(
        reflector=Reflector(),
        sensors=(
            SensorPlacement("S1", "NJL5901R-2", (10.0, 0.0, 0.0), (-1.0, 0.0, 0.0)),
            SensorPlacement("S2", "NJL5901R-2", (0.0, 10.0, 0.0), (0.0, -1.0, 0.0)),
        ),
    )
