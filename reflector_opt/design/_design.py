"""The :class:`Design` of one sensing unit: its parts, the checks on the whole, the file.

A :class:`Design` is the reflector (sphere radius and centre, inner radius), the sensors
(part, position, optical axis, LED-to-detector direction), the workspace (pitch and roll
ranges), the mechanical envelope and the noise; the parts are in
:mod:`reflector_opt.design._components`, the ``design.json`` document in
:mod:`reflector_opt.design._designfile`.
"""

from dataclasses import dataclass, field, replace

import msgspec
import numpy as np
from msgspec import UNSET, UnsetType

from reflector_opt.design._bearings import check_tilt
from reflector_opt.design._components import Mechanics, Noise, Reflector, SensorPlacement, Workspace
from reflector_opt.design._designfile import (
    design_fields_from_dict,
    design_to_dict,
    warn_of_assumptions,
)
from reflector_opt.design._in_use import InUse
from reflector_opt.design._validation import check_centre_inside
from reflector_opt.model._geometry import sensor_distance, unit
from reflector_opt.util._display import Summarised, fmt, span, vector
from reflector_opt.util._errors import InputError
from reflector_opt.util._fileio import Kept, read_json, write_json


class Predicted(Kept):
    """What the commands that made a design predicted of it: ``design.json``'s ``predicted``.

    Each block is left out (``msgspec.UNSET``) where no command wrote it; a key this release
    does not write is kept as read, in ``others`` (:class:`~reflector_opt.util._fileio.Kept`).

    Attributes
    ----------
    objective_deg : float or None
        The optimiser's objective (degrees; None where not finite).
    metrics, constraints, optimiser : dict
        The verified metrics, each constraint's value, limit and whether it is met, and the
        search's record (seed, evaluations, budget, variables).
    baseline : dict
        The default geometry judged alike, and ``improvement`` over it (``worst``, …).
    improvement : dict or None
    conditions : reflector_opt.design._in_use.InUse
        The error in use in the conditions the design was optimised in
        (``conditions.worst_case_deg``; the table is ``conditions.conditions``).
    robust, sensor_choice, drift_front, size_frontier, segment_choice : dict
        The records of ``optimise --robust``, ``--sensor``, ``--drift-front`` and
        ``smallest``.
    others : dict
        Keys no command of this release writes, as read.
    """

    objective_deg: float | UnsetType | None = UNSET
    metrics: dict | UnsetType = UNSET
    constraints: dict | UnsetType = UNSET
    optimiser: dict | UnsetType = UNSET
    baseline: dict | UnsetType = UNSET
    improvement: dict | UnsetType | None = UNSET
    conditions: InUse | UnsetType = UNSET
    robust: dict | UnsetType = UNSET
    sensor_choice: dict | UnsetType = UNSET
    drift_front: dict | UnsetType = UNSET
    size_frontier: dict | UnsetType = UNSET
    segment_choice: dict | UnsetType = UNSET

    @classmethod
    def from_dict(cls, data, where="predicted"):
        """The block read from ``design.json``; InputError naming the key that does not fit."""
        return super().from_dict(data, where)

    def replace(self, **blocks):
        """Copy with ``blocks`` written (``sensor_choice=record``)."""
        return msgspec.structs.replace(self, **blocks)


@dataclass(frozen=True, repr=False)
class Design(Summarised):
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
    predicted : Predicted or dict
        Predicted performance figures written by the analysis commands (a dict is read as
        ``design.json``'s block).
    correction : dict
        The print correction this geometry carries (written by ``reflector-opt correct``:
        what was changed, by how much, from which identified units; docs/print-loop.md);
        empty for a design as drawn.

    Notes
    -----
    Construction validates every field, that the rotation centre lies inside the reflector
    sphere, and that no sensor touches the sphere anywhere in the workspace (checked on the
    workspace grid, at least every 0.5°).
    """

    reflector: Reflector = field(default_factory=Reflector)
    sensors: tuple[SensorPlacement, ...] = ()
    workspace: Workspace = field(default_factory=Workspace)
    mechanics: Mechanics = field(default_factory=Mechanics)
    noise: Noise = field(default_factory=Noise)
    sensor_models: dict = field(default_factory=dict)
    predicted: Predicted = field(default_factory=Predicted)
    correction: dict = field(default_factory=dict)

    def __post_init__(self):
        if isinstance(self.predicted, dict):
            object.__setattr__(self, "predicted", Predicted.from_dict(self.predicted))
        _check_design(self)

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
        """The :class:`SensorModel` of one placement: design-defined first, then the presets
        and the parts of the sensor catalogue."""
        if sensor.model in self.sensor_models:
            return self.sensor_models[sensor.model]
        from reflector_opt.model._catalogue import sensor_model  # its data read when needed

        try:
            return sensor_model(sensor.model)
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

    # -- display (equality is the dataclass's, field by field) --

    #: Sensors listed one per line in the short display; more are summarised.
    _SHOWN_SENSORS = 4

    def _summary(self):
        """Title and (label, value) rows of the key figures, units included."""
        r, w, m, n = self.reflector, self.workspace, self.mechanics, self.noise
        rows = [
            (
                "reflector",
                f"sphere radius {r.radius_mm:.3f} mm at {vector(r.centre_mm, unit='mm')}, "
                f"inner radius {r.inner_radius_mm:.3f} mm",
            ),
            (
                "surface",
                f"reflectance {r.reflectance:.3g}, specular fraction {r.specular_fraction:.3g}",
            ),
        ]
        shown = self.sensors if len(self.sensors) <= self._SHOWN_SENSORS else self.sensors[:3]
        rows += [
            (
                f"sensor {s.name}",
                f"{s.model} at {vector(s.position_mm, unit='mm')}, axis {vector(s.axis)}",
            )
            for s in shown
        ]
        if len(shown) < len(self.sensors):
            rest = [s.name for s in self.sensors[len(shown) :]]
            rows.append(("more sensors", ", ".join(rest)))
        rows += [
            (
                "workspace",
                f"pitch {span(*w.pitch_deg, unit='°')}, roll {span(*w.roll_deg, unit='°')}, "
                f"grid {fmt(w.step_deg, unit='°')}",
            ),
            (
                "unit",
                f"diameter {fmt(m.unit_diameter_mm, unit='mm')}, height "
                f"{fmt(m.unit_height_mm, unit='mm')}, bearing {fmt(m.bearing_bore_mm)}/"
                f"{fmt(m.bearing_od_mm, unit='mm')}",
            ),
            (
                "noise",
                f"{fmt(1e3 * n.sigma_v, unit='mV')} RMS, {n.adc_bits}-bit ADC, "
                f"full scale {fmt(n.vref, unit='V')}",
            ),
        ]
        predicted = _predicted_line(self.predicted)
        if predicted:
            rows.append(("predicted", predicted))
        return f"Design: {len(self.sensors)} sensors", rows

    # -- design.json (reflector_opt.design._designfile) --

    def to_dict(self):
        """The ``design.json`` document as a dict."""
        return design_to_dict(self)

    @classmethod
    def from_dict(cls, data):
        """Build and validate from a ``design.json`` dict; errors name the field.

        What reading the dict assumed is logged as a warning once the design is accepted
        (:func:`~reflector_opt.design._designfile.warn_of_assumptions`).
        """
        design = cls(**design_fields_from_dict(data))
        warn_of_assumptions(data)
        return design

    def save(self, path):
        """Write ``design.json`` atomically."""
        write_json(path, self.to_dict())


def _check_design(design):
    """The checks of construction (see :class:`Design`'s notes); InputError on the first."""
    if len(design.sensors) < 2:
        raise InputError("sensors: a unit needs at least two sensors")
    names = [s.name for s in design.sensors]
    if len(set(names)) != len(names):
        raise InputError(f"sensors: names must be unique, got {names}")
    for s in design.sensors:
        design.model_of(s)
    reflector = design.reflector
    if reflector.inner_radius_mm >= reflector.radius_mm + np.linalg.norm(reflector.centre_mm):
        raise InputError("reflector.inner_radius_mm: the inner surface lies outside the sphere")
    check_centre_inside(reflector.radius_mm, reflector.centre_mm)
    _check_clearance(design)
    check_tilt(design.workspace, design.mechanics)


def _predicted_line(predicted):
    """The optimiser's objective and worst resolutions from a ``predicted`` block, or ""."""
    parts = []
    if predicted.objective_deg is not None and predicted.objective_deg is not UNSET:
        parts.append(f"objective {fmt(predicted.objective_deg, unit='°')}")
    resolution = (predicted.metrics or {}).get("resolution_deg")
    for axis in ("pitch", "roll"):
        worst = resolution.get(f"{axis}_worst") if isinstance(resolution, dict) else None
        if isinstance(worst, int | float) and not isinstance(worst, bool):
            parts.append(f"worst {axis} resolution {fmt(worst, unit='°')}")
    blocks = predicted.to_dict()
    if not parts and blocks:
        parts.append(f"{len(blocks)} entries ({', '.join(sorted(blocks)[:4])})")
    return ", ".join(parts)


def _check_clearance(design):
    """Fail if a sensor lies inside the reflector sphere anywhere on the workspace grid."""
    pitch, roll = design.workspace.grid(min(design.workspace.step_deg, 0.5))
    r = design.reflector
    d = sensor_distance(
        design.positions_mm, r.centre_mm, r.radius_mm, pitch, roll, on_collision="nan"
    )
    touching = np.isnan(d).any(axis=(0, 1))
    if touching.any():
        bad = [s.name for s, t in zip(design.sensors, touching, strict=True) if t]
        raise InputError(
            f"sensors: {', '.join(bad)} would lie inside the reflector sphere in the workspace"
        )


def load_design(path):
    """Read and validate a ``design.json`` file.

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    Design
        Raises :class:`~reflector_opt.util._errors.InputError` naming the file and the
        problem, as the other readers do: ``design.json: reflector.radius_mm: expected …``.
    """
    data = read_json(path)
    try:
        return Design.from_dict(data)
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from None
