"""The as-built parameters of a batch of units: names, priors, and the unit each describes.

A printed unit differs from its design in its geometry (the reflecting sphere's radius and
centre, each sensor's seat: position and optical-axis tilt) and its read-out (each sensor's
gain and offset); the units printed together share one surface (reflectance ρ and specular
fraction f). Every parameter is kept as its **deviation from the design**, with a zero-mean
normal prior whose standard deviation comes from the tolerance model
(:class:`reflector_opt.tolerance._tolerances.Tolerances`; a uniform spread of half-width h has
σ = h/√3) or, for the surface, from :data:`SURFACE_PRIOR_STD`.

Sensor seats are described in each sensor's own frame, so the names say what moved:

* ``standoff`` — along the optical axis a, positive away from the reflector (a larger gap);
* ``shift_led_detector`` — across the axis, along the LED-to-detector line e;
* ``shift_sideways`` — across the axis and across that line (c = a × e);
* ``tilt_led_detector`` — the axis tipped towards e (a rotation about c): this moves the
  returning spot along the LED–detector line and changes the detected light at first order;
* ``tilt_sideways`` — the axis tipped towards c (second order in the light).

A tolerance model draws isotropic position errors, so the priors are the same in this frame
as in the unit frame.

**The angle reference.** The calibration poses are what a reference (an IMU, an encoder rig)
reads, not the truth. Each unit's calibration session may carry the reference's own errors
as three more parameters of that unit (:data:`REFERENCE_NAMES`, with
:attr:`ParameterLayout.reference_std`): its zero offsets in pitch and roll and the twist κ of its
axes about the backbone. The reference reads (γ', α') = (γ, α)·R(κ) + z with
R(κ) = [[cos κ, sin κ], [−sin κ, cos κ]] (the convention of
``reflector_opt.analysis._budget``), so the true pose of a reading is
(γ, α) = ((γ', α') − z)·R(κ)ᵀ (:meth:`ParameterLayout.true_angles`). They are per unit because each
unit is mounted on the rig on its own: its zero and twist are those of that mounting.

**The physics beyond the fast model.** Two more kinds of parameter take it up where the fit
can (docs/asbuilt.md §1): the sub-surface spread length ℓ of the batch's resin
(``subsurface_mm``, shared, with :attr:`ParameterLayout.subsurface_std`; its nominal
:data:`SUBSURFACE_NOMINAL_MM`), and, per unit and sensor, the amplitude of each model-form
signature (:attr:`ParameterLayout.model_form_names`, a unit-normal prior each:
:mod:`reflector_opt.asbuilt._model_form_terms`), after the unit's reference parameters.
"""

import math
from dataclasses import dataclass, replace

import numpy as np

from reflector_opt.model._geometry import unit
from reflector_opt.model._noise import Mismatch
from reflector_opt.tolerance._tolerances import Tolerances
from reflector_opt.util._errors import InputError

#: Prior standard deviation of the batch's surface, absolute: reflectance ρ and specular
#: fraction f. Assumptions (docs/asbuilt.md): a white SLA resin's ρ is known from its
#: data to about ±0.05, its f from a flat-target measurement or the material preset to
#: about ±0.05.
SURFACE_PRIOR_STD = {"reflectance": 0.05, "specular_fraction": 0.05}

#: Prior standard deviation of each sensor's emitter: its beam divergence θ (the 1/e
#: half-angle, degrees) and its source radius ω0 (mm). The part-to-part spread of an LED's
#: beam, and the freedom the model needs to take up an emitter pattern or a surface that is
#: not quite the model's (docs/asbuilt.md): without it, that misfit goes into the geometry.
#: Assumptions; a flat-target curve measured before assembly pins both.
EMITTER_PRIOR_STD = {"divergence_deg": 2.0, "source_radius_mm": 0.03}

#: The batch's sub-surface spread length ℓ the fit starts from and its prior is centred on,
#: mm: the transport length of a white pigmented photopolymer, "tens of µm to about 0.1 mm"
#: (docs/model.md §9), the built units' default (``ModelForm().subsurface_mm``).
SUBSURFACE_NOMINAL_MM = 0.1

#: Prior std of ℓ, mm: with the nominal 0.1 mm, ±2σ spans the "tens to a few hundred µm" of
#: docs/model.md (0 to 0.3 mm; the model takes ℓ below 0 as 0).
SUBSURFACE_PRIOR_STD_MM = 0.1

#: The angle reference's parameters of one calibration session, in vector order: its zero
#: offsets (pitch, roll) and the twist of its axes about the backbone, degrees.
REFERENCE_NAMES = ("reference_pitch_zero_deg", "reference_roll_zero_deg", "reference_twist_deg")

#: Default prior std of the reference's parameters, degrees (docs/asbuilt.md §1). A zero
#: offset of 1.5°: an IMU's static accuracy (the paper's LPMS-B: < 0.5°) plus its mounting on
#: a printed unit, which a fixture holds to about a degree; wide enough that a 2° offset (a
#: mounting gone wrong) is a 1.3σ event that moves no geometry estimate by more than its std.
#: A twist of 0.5°: the same mounting about the backbone, where only the fixture's flats act.
REFERENCE_PRIOR_STD = {
    "reference_pitch_zero_deg": 1.5,
    "reference_roll_zero_deg": 1.5,
    "reference_twist_deg": 0.5,
}

#: Smallest prior std of a reference parameter taken from a conditions file, degrees: a
#: conditions file's 0 means "not measured", not "exact"; below this the reference's effect
#: on the geometry (under a micrometre) is beneath every other.
REFERENCE_STD_FLOOR_DEG = 0.02

#: The geometry parameters of the reflector: (name, tolerance) in vector order.
_REFLECTOR = (
    ("reflector_radius_mm", "reflector_radius_mm"),
    ("reflector_centre_x_mm", "centre_offset_mm"),
    ("reflector_centre_y_mm", "centre_offset_mm"),
    ("reflector_centre_z_mm", "centre_offset_mm"),
)

#: The parameters of each sensor: (suffix, tolerance) in vector order.
_SENSOR = (
    ("standoff_mm", "sensor_position_mm"),
    ("shift_led_detector_mm", "sensor_position_mm"),
    ("shift_sideways_mm", "sensor_position_mm"),
    ("tilt_led_detector_deg", "sensor_tilt_deg"),
    ("tilt_sideways_deg", "sensor_tilt_deg"),
    ("gain", "gain"),
    ("offset_v", "offset_v"),
    ("divergence_deg", None),
    ("source_radius_mm", None),
)

#: The sensor parameters a flat-target curve depends on.
_CURVE_KINDS = ("gain", "offset_v", "divergence_deg", "source_radius_mm")

#: Plain words for each parameter kind, used to name determined combinations.
_WORDS = {
    "reflector_radius_mm": "reflector radius",
    "reflector_centre_x_mm": "reflector centre x",
    "reflector_centre_y_mm": "reflector centre y",
    "reflector_centre_z_mm": "reflector centre z",
    "standoff_mm": "standoff",
    "shift_led_detector_mm": "shift along its LED–detector line",
    "shift_sideways_mm": "sideways shift",
    "tilt_led_detector_deg": "tilt towards its detector",
    "tilt_sideways_deg": "sideways tilt",
    "gain": "gain",
    "offset_v": "offset",
    "divergence_deg": "beam divergence",
    "source_radius_mm": "emitter size",
    "reflectance": "surface reflectance",
    "specular_fraction": "surface specular fraction",
    "subsurface_mm": "surface sub-surface spread",
    "reference_pitch_zero_deg": "reference pitch zero",
    "reference_roll_zero_deg": "reference roll zero",
    "reference_twist_deg": "reference twist",
}

#: Finite-difference step of each parameter kind (central differences), in its unit.
_STEPS = {"mm": 2e-4, "deg": 2e-3, "gain": 1e-4, "offset_v": 1e-4, "surface": 1e-4, "form": 0.01}


def sensor_frame(placement):
    """A sensor's own frame: optical axis a, LED-to-detector direction e, c = a × e.

    Parameters
    ----------
    placement : reflector_opt.design._components.SensorPlacement

    Returns
    -------
    numpy.ndarray
        Shape (3, 3): rows a, e, c (unit vectors).
    """
    a = unit(np.asarray(placement.axis, dtype=float))
    e = placement.in_plane_detector_direction
    return np.stack([a, e, np.cross(a, e)])


def _std(spread):
    """Standard deviation of a :class:`~reflector_opt.tolerance._tolerances.Spread`."""
    return spread.scale if spread.kind == "normal" else spread.scale / math.sqrt(3.0)


def reference_std_of(conditions):
    """The prior std of the reference's parameters from operating conditions.

    σ of each zero offset is the magnitude of the conditions' reference zero
    (:meth:`~reflector_opt.design._conditions.Conditions.reference_zero`: the given
    ``reference_zero_deg``, else the class of its ``angle_reference``), σ of
    the twist the magnitude of ``reference_twist_deg``, each at least
    :data:`REFERENCE_STD_FLOOR_DEG`.

    Parameters
    ----------
    conditions : reflector_opt.design._conditions.Conditions

    Returns
    -------
    dict
        ``{name: σ}`` in degrees, by :data:`REFERENCE_NAMES`.
    """
    zero = conditions.reference_zero()
    values = (abs(zero[0]), abs(zero[1]), abs(conditions.reference_twist_deg))
    return {
        name: max(float(v), REFERENCE_STD_FLOOR_DEG)
        for name, v in zip(REFERENCE_NAMES, values, strict=True)
    }


def true_pose(pitch_deg, roll_deg, reference_deg):
    """The true pose of an angle reference's reading.

    The reference reads (γ', α') = (γ, α)·R(κ) + (z_γ, z_α), R(κ) = [[cos κ, sin κ],
    [−sin κ, cos κ]] (module notes); so (γ, α) = ((γ', α') − z)·R(κ)ᵀ.

    Parameters
    ----------
    pitch_deg, roll_deg : array_like
        The reference's readings γ', α', degrees (broadcast together).
    reference_deg : sequence of float
        (z_γ, z_α, κ): its pitch and roll zero offsets and its twist, degrees.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        γ, α in degrees.
    """
    pitch_zero, roll_zero, twist = (float(v) for v in reference_deg)
    c, s = math.cos(math.radians(twist)), math.sin(math.radians(twist))
    pitch = np.asarray(pitch_deg, dtype=float) - pitch_zero
    roll = np.asarray(roll_deg, dtype=float) - roll_zero
    return c * pitch + s * roll, c * roll - s * pitch


def _checked_reference_std(reference_std):
    """A reference prior as {name: σ} (degrees, 0 to 20) or None; InputError naming the key."""
    if reference_std is None:
        return None
    if not isinstance(reference_std, dict) or set(reference_std) != set(REFERENCE_NAMES):
        raise InputError(
            f"reference_std: expected a σ in degrees for each of {', '.join(REFERENCE_NAMES)}, "
            f"or None (the reference taken as exact); got {reference_std!r}"
        )
    for name in REFERENCE_NAMES:
        value = reference_std[name]
        if not (isinstance(value, (int, float)) and math.isfinite(value) and 0 <= value <= 20):
            raise InputError(f"reference_std.{name}: expected 0 to 20°, got {value!r}")
    return {name: float(reference_std[name]) for name in REFERENCE_NAMES}


@dataclass(frozen=True)
class ParameterLayout:
    """Where each as-built parameter of a batch sits in the parameter vector.

    The vector is the shared surface (ρ, f, and with ``subsurface_std`` its spread ℓ)
    followed by each unit's block: the reflector's four parameters, then nine per sensor,
    then, with ``reference_std``, its angle reference's three (:data:`REFERENCE_NAMES`),
    then its model-form amplitudes (``model_form_names``). All entries are deviations from the
    design (gain: the factor minus 1; the reference: from an exact reference).

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    n_units : int
    tolerances : reflector_opt.tolerance._tolerances.Tolerances, optional
        The prior of the geometry and read-out (default: the tolerance model's defaults).
    surface_std : dict, optional
        Prior std of ``reflectance`` and ``specular_fraction`` (default
        :data:`SURFACE_PRIOR_STD`).
    reference_std : dict, optional
        Prior std of each of :data:`REFERENCE_NAMES`, degrees (0 fixes one). Default None: no
        reference parameters, the reference's readings are the true poses.
    subsurface_std : float, optional
        Prior std of the batch's sub-surface spread ℓ, mm (a shared parameter
        ``subsurface_mm`` about :data:`SUBSURFACE_NOMINAL_MM`). Default None: no spread, the
        fast model's opaque surface.
    model_form_names : tuple of str, optional
        Names of each unit's model-form amplitudes (``form_<effect>_sensor_<k>``), unit-normal
        priors, after its reference parameters. Default: none.
    """

    design: object
    n_units: int
    tolerances: Tolerances = None
    surface_std: dict = None
    reference_std: dict = None
    subsurface_std: float = None
    model_form_names: tuple = ()

    def __post_init__(self):
        if self.tolerances is None:
            object.__setattr__(self, "tolerances", Tolerances())
        if self.surface_std is None:
            object.__setattr__(self, "surface_std", dict(SURFACE_PRIOR_STD))
        object.__setattr__(self, "reference_std", _checked_reference_std(self.reference_std))
        object.__setattr__(self, "model_form_names", tuple(self.model_form_names))
        if self.subsurface_std is not None and not (
            math.isfinite(self.subsurface_std) and 0 <= self.subsurface_std <= 1
        ):
            raise InputError(f"subsurface_std: expected 0 to 1 mm, got {self.subsurface_std!r}")
        if self.n_units < 1:
            raise InputError("identification: no unit to identify")

    # -- names and sizes --

    @property
    def n_sensors(self):
        """Sensors per unit."""
        return len(self.design.sensors)

    @property
    def shared_names(self):
        """Names of the shared parameters: the surface (and its spread, when fitted)."""
        spread = () if self.subsurface_std is None else ("subsurface_mm",)
        return ("reflectance", "specular_fraction", *spread)

    @property
    def unit_names(self):
        """Names of one unit's parameters, in block order."""
        names = [name for name, _ in _REFLECTOR]
        for k in range(self.n_sensors):
            names += [f"sensor_{k + 1}_{suffix}" for suffix, _ in _SENSOR]
        return tuple(names)

    @property
    def reference_names(self):
        """Names of one unit's reference parameters (empty: the reference is exact)."""
        return () if self.reference_std is None else REFERENCE_NAMES

    @property
    def block_size(self):
        """Parameters per unit of its print and read-out (its reference's not counted)."""
        return len(_REFLECTOR) + len(_SENSOR) * self.n_sensors

    @property
    def _stride(self):
        return self.block_size + len(self.reference_names) + len(self.model_form_names)

    @property
    def size(self):
        """Length of the whole parameter vector."""
        return len(self.shared_names) + self.n_units * self._stride

    def unit_slice(self, u):
        """Slice of unit ``u``'s block (print and read-out) in the parameter vector."""
        start = len(self.shared_names) + u * self._stride
        return slice(start, start + self.block_size)

    def reference_slice(self, u):
        """Slice of unit ``u``'s reference parameters (empty without them)."""
        start = self.unit_slice(u).stop
        return slice(start, start + len(self.reference_names))

    def model_form_slice(self, u):
        """Slice of unit ``u``'s model-form amplitudes (empty without them)."""
        start = self.reference_slice(u).stop
        return slice(start, start + len(self.model_form_names))

    def unit_indices(self, u):
        """Indices of the parameters unit ``u``'s data depend on: shared, its block, its
        reference, its model-form amplitudes."""
        start = self.unit_slice(u).start
        return np.r_[np.arange(len(self.shared_names)), np.arange(start, start + self._stride)]

    def curve_indices(self, u, sensors):
        """Indices of the parameters the flat-target curves of unit ``u``'s ``sensors``
        depend on: the surface, and each sensor's gain, offset, emitter and model-form
        amplitudes."""
        block = self.unit_slice(u)
        out = set(range(len(self.shared_names)))
        for k in set(sensors):
            first = block.start + len(_REFLECTOR) + len(_SENSOR) * k
            out.update(first + i for i, (name, _) in enumerate(_SENSOR) if name in _CURVE_KINDS)
            form = self.model_form_slice(u).start
            out.update(
                form + i
                for i, name in enumerate(self.model_form_names)
                if name.endswith(f"_sensor_{k + 1}")
            )
        return out

    # -- priors, steps, words --

    def prior_std(self):
        """Prior standard deviation of every parameter, in vector order."""
        shared = [self.surface_std[name] for name in self.shared_names[:2]]
        block = [_std(getattr(self.tolerances, t)) for _, t in _REFLECTOR]
        for _ in range(self.n_sensors):
            block += [
                EMITTER_PRIOR_STD[name] if t is None else _std(getattr(self.tolerances, t))
                for name, t in _SENSOR
            ]
        block += [self.reference_std[name] for name in self.reference_names]
        block += [1.0] * len(self.model_form_names)
        if self.subsurface_std is not None:
            shared.append(self.subsurface_std)
        return np.array(shared + block * self.n_units, dtype=float)

    def nominal(self):
        """The design's absolute values of the shared parameters and of one unit's block.

        Geometry deviations are reported against 0, except the radius (the design's radius)
        and the gain (1).
        """
        reflector = self.design.reflector
        shared = np.array([reflector.reflectance, reflector.specular_fraction])
        if self.subsurface_std is not None:
            shared = np.r_[shared, SUBSURFACE_NOMINAL_MM]
        block = np.zeros(self._stride)
        block[0] = reflector.radius_mm
        for k in range(self.n_sensors):
            block[len(_REFLECTOR) + len(_SENSOR) * k + 5] = 1.0
        return np.r_[shared, np.tile(block, self.n_units)]

    def steps(self):
        """Central-difference step of every parameter, in vector order."""
        block = [_STEPS["mm"]] * len(_REFLECTOR)
        for _ in range(self.n_sensors):
            block += [_STEPS["mm"]] * 3 + [_STEPS["deg"]] * 2
            block += [_STEPS["gain"], _STEPS["offset_v"], _STEPS["deg"], _STEPS["mm"]]
        block += [_STEPS["deg"]] * len(self.reference_names)
        block += [_STEPS["form"]] * len(self.model_form_names)
        shared = [_STEPS["surface"]] * 2 + [_STEPS["mm"]] * (len(self.shared_names) - 2)
        return np.array(shared + block * self.n_units)

    def names(self, unit_labels=None):
        """Every parameter's name, unit blocks prefixed with ``unit LABEL:``."""
        labels = unit_labels or [str(u + 1) for u in range(self.n_units)]
        out = list(self.shared_names)
        for label in labels:
            own = (*self.unit_names, *self.reference_names, *self.model_form_names)
            out += [f"unit {label}: {name}" for name in own]
        return out

    def words(self, name):
        """A parameter's name in plain words (``sensor_1_standoff_mm`` → sensor 1 standoff)."""
        key = name.split(": ")[-1]
        if key.startswith("form_"):
            effect, k = key.removeprefix("form_").rsplit("_sensor_", 1)
            return f"sensor {k} model form ({effect.replace('_', ' ')})"
        if key.startswith("sensor_"):
            _, k, suffix = key.split("_", 2)
            return f"sensor {k} {_WORDS[suffix]}"
        return _WORDS[key]

    # -- the unit a parameter vector describes --

    def true_angles(self, x, u, angles_deg):
        """The true poses of unit ``u``'s reference readings for parameter vector ``x``.

        (γ, α) = ((γ', α') − z)·R(κ)ᵀ, the inverse of the reference's reading
        (γ', α') = (γ, α)·R(κ) + z (module notes); the readings as given without reference
        parameters.

        Parameters
        ----------
        x : numpy.ndarray
        u : int
        angles_deg : numpy.ndarray
            Shape (n, 2): the reference's pitch and roll readings, degrees.

        Returns
        -------
        numpy.ndarray
            Shape (n, 2), degrees.
        """
        if not self.reference_names:
            return angles_deg
        pitch, roll = true_pose(angles_deg[:, 0], angles_deg[:, 1], x[self.reference_slice(u)])
        return np.stack([pitch, roll], axis=-1)

    def bounds(self, width=6.0):
        """Bounds of the profile intervals: ±``width`` prior std about the design; ρ in
        (0, 1], f in [0, 1]."""
        std = self.prior_std()
        lower, upper = -width * std, width * std
        nominal = self.nominal()
        lower[0] = max(lower[0], 1e-3 - nominal[0])
        upper[0] = min(upper[0], 1.0 - nominal[0])
        lower[1] = max(lower[1], -nominal[1])
        upper[1] = min(upper[1], 1.0 - nominal[1])
        if self.subsurface_std is not None:
            lower[2] = max(lower[2], -nominal[2])
        return lower, upper

    def subsurface_mm(self, x):
        """The sub-surface spread ℓ of parameter vector ``x``, mm, taken into [0, 1] as the
        model uses it; None when the layout has no spread."""
        if self.subsurface_std is None:
            return None
        return float(np.clip(SUBSURFACE_NOMINAL_MM + x[2], 0.0, 1.0))

    def unit_design(self, x, u, working=None):
        """The geometry and surface of unit ``u`` for parameter vector ``x``.

        Parameters
        ----------
        x : numpy.ndarray
            The whole parameter vector (deviations).
        u : int
        working : Design, optional
            The design to perturb (default: the layout's); its workspace is kept.

        Returns
        -------
        (Design, reflector_opt.model._noise.Mismatch)
        """
        design = self.design if working is None else working
        block = x[self.unit_slice(u)]
        reflector = design.reflector
        reflector = replace(
            reflector,
            radius_mm=reflector.radius_mm + float(block[0]),
            centre_mm=tuple((np.asarray(reflector.centre_mm) + block[1:4]).tolist()),
            reflectance=float(np.clip(reflector.reflectance + x[0], 1e-3, 1.0)),
            specular_fraction=float(np.clip(reflector.specular_fraction + x[1], 0.0, 1.0)),
        )
        sensors, gains, offsets, models = [], [], [], dict(design.sensor_models)
        for k, placement in enumerate(design.sensors):
            s = block[len(_REFLECTOR) + len(_SENSOR) * k :][: len(_SENSOR)]
            moved, model = _built_sensor(design, placement, s)
            if model is not None:
                models[model.name] = model
            sensors.append(moved)
            gains.append(1.0 + float(s[5]))
            offsets.append(float(s[6]))
        built = design.replace(reflector=reflector, sensors=tuple(sensors), sensor_models=models)
        return built, Mismatch(tuple(gains), tuple(offsets))


#: The smallest beam divergence (degrees) and source radius (mm) a trial unit is given: a
#: fit's step beyond them (many prior std away) is taken to them, as ρ and f to their range.
MIN_EMITTER = (1.0, 0.001)


def _built_sensor(design, placement, s):
    """A sensor's placement moved by its block ``s`` of deviations (seat and tilts), and its
    emitter's model changed by them (at least :data:`MIN_EMITTER`), or None if its emitter is
    the design's."""
    a, e, c = sensor_frame(placement)
    position = np.asarray(placement.position_mm) - s[0] * a + s[1] * e + s[2] * c
    t = np.tan(np.deg2rad(s[3:5]))
    axis = a + t[0] * e + t[1] * c
    model, changed = design.model_of(placement), None
    if s[7] != 0.0 or s[8] != 0.0:
        model = changed = model.with_(
            name=f"{model.name} ({placement.name})",
            divergence_deg=max(model.divergence_deg + float(s[7]), MIN_EMITTER[0]),
            source_radius_mm=max(model.source_radius_mm + float(s[8]), MIN_EMITTER[1]),
        )
    built = replace(
        placement,
        model=model.name,
        position_mm=tuple(position.tolist()),
        axis=tuple(axis.tolist()),
    )
    return built, changed


def true_deviations(design, built, mismatch):
    """The block of a unit's parameters that turns ``design`` into ``built`` exactly.

    The inverse of :meth:`ParameterLayout.unit_design` for one unit: used to score an identification
    against a simulated built unit (``reflector_opt.tolerance._builtunit``).

    Parameters
    ----------
    design, built : reflector_opt.design._design.Design
        The nominal design and the unit as built (same sensors, in order).
    mismatch : reflector_opt.model._noise.Mismatch
        The unit's gains and offsets.

    Returns
    -------
    numpy.ndarray
        One unit's block (see :class:`ParameterLayout`).
    """
    block = [built.reflector.radius_mm - design.reflector.radius_mm]
    block += list(np.asarray(built.reflector.centre_mm) - np.asarray(design.reflector.centre_mm))
    for k, (nominal, real) in enumerate(zip(design.sensors, built.sensors, strict=True)):
        a, e, c = sensor_frame(nominal)
        move = np.asarray(real.position_mm) - np.asarray(nominal.position_mm)
        axis = np.asarray(real.axis, dtype=float)
        tilt = np.rad2deg(np.arctan2([axis @ e, axis @ c], axis @ a))
        block += [-(move @ a), move @ e, move @ c, *tilt]
        block += [mismatch.gain[k] - 1.0, mismatch.offset_v[k]]
        block += [built.model_of(real).divergence_deg - design.model_of(nominal).divergence_deg]
        block += [built.model_of(real).source_radius_mm - design.model_of(nominal).source_radius_mm]
    return np.array(block, dtype=float)
