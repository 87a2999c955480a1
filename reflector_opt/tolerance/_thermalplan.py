"""Planning a temperature-compensated calibration: how many poses, at which temperatures.

A unit used at ±K kelvin from its calibration temperature T0 needs, besides its calibration
plan at T0 (the base plan), poses at other temperatures from which the compensation
(:class:`~reflector_opt.calibration._temperature.TemperatureCompensated`) learns each sensor's
gain and offset change. :func:`plan_temperature` simulates it on built units
(:func:`~reflector_opt.tolerance._builtunit.build_unit`: exact optics, as-built geometry, their
read-out gain and offset, the design's noise): each unit records the base plan at T0 and,
for every layout (:data:`LAYOUTS`: N Sobol poses at T0 + K, or the same N at T0 − K and at
T0 + K) and size N (:data:`SIZES`), the extra poses at their temperature
(:class:`~reflector_opt.model._operating.OperatingState`, the generic thermal coefficients of
:class:`~reflector_opt.model._temperature.ThermalCoefficients` unless given); the compensated
form is fitted and validated at fresh poses with the true angles at ΔT = −K, −K/2, 0, K/2
and K. The yardstick of each is the unit's white-noise error with the same poses: the same
form fitted to the base plan and the extra poses all recorded at T0, validated at T0 with the
same noise draws (extra poses improve the form too; the yardstick keeps that out of the
temperature's cost). The base plan's form alone, used at every temperature, shows what
compensation saves. Errors over the units are pooled as the RMS of their RMS.
:func:`recommend_thermal` picks the fewest extra poses whose error at every validation
temperature is within a fraction of their yardstick.

The form of the compensation is the one the base plan's calibration ends with: ``auto``
chooses it per unit on the base plan (and keeps it), any other is used as named.
:func:`plan_to_extend` chooses the base plan from a calibration plan study: the physical form
is not compensated, so a plan of another form near the floor is taken instead.
"""

from dataclasses import dataclass, replace

import numpy as np

from reflector_opt.calibration._estimators import make_estimator, selected
from reflector_opt.calibration._plans import make_plan
from reflector_opt.calibration._temperature import TemperatureCompensated
from reflector_opt.model._operating import OperatingState
from reflector_opt.tolerance._builtunit import REFERENCE_SIGMA_DEG, build_unit
from reflector_opt.tolerance._planning import recommend
from reflector_opt.util._errors import InputError
from reflector_opt.util._progress import no_progress
from reflector_opt.util._seeds import stream_rng

#: Where the extra poses are recorded, as multiples of the use range K.
LAYOUTS = {"warm": (1.0,), "both": (-1.0, 1.0)}

#: Extra poses per temperature tried.
SIZES = (10, 25, 50, 100)

#: Validation temperatures, as multiples of K.
VALIDATION = (-1.0, -0.5, 0.0, 0.5, 1.0)

#: Validation poses per unit and temperature.
N_VALIDATION = 1000

#: The reference temperature of the simulated calibrations, °C (only differences matter).
T0_C = 25.0


@dataclass(frozen=True)
class ThermalPrediction:
    """The compensated calibration's error for one layout and size, pooled over the units.

    Attributes
    ----------
    layout : str
        A key of :data:`LAYOUTS`.
    n_poses : int
        Extra poses at each of the layout's temperatures.
    changes_k : tuple of float
        Their temperature changes from T0, K.
    rms_deg : numpy.ndarray
        Shape (n_validation_temperatures, 2): RMS error (pitch, roll), degrees.
    reference_rms_deg : numpy.ndarray
        (pitch, roll): the yardstick, the form fitted to the same poses all recorded at T0
        and validated there, degrees.
    """

    layout: str
    n_poses: int
    changes_k: tuple
    rms_deg: np.ndarray
    reference_rms_deg: np.ndarray

    @property
    def extra_poses(self):
        """Poses recorded away from T0."""
        return self.n_poses * len(self.changes_k)

    @property
    def ratio(self):
        """Each RMS over the yardstick, shape (n_validation_temperatures, 2)."""
        return self.rms_deg / self.reference_rms_deg

    def to_dict(self):
        """JSON-ready, with the ratio of each RMS to the yardstick (pitch, roll)."""
        return {
            "layout": self.layout,
            "n_poses": self.n_poses,
            "changes_k": list(self.changes_k),
            "extra_poses": self.extra_poses,
            "rms_deg": self.rms_deg.tolist(),
            "reference_rms_deg": self.reference_rms_deg.tolist(),
            "ratio": self.ratio.tolist(),
        }


@dataclass(frozen=True)
class ThermalStudy:
    """Every layout and size tried, beside the yardstick and the uncompensated form.

    Attributes
    ----------
    change_k : float
        The use range K, K.
    form : str
        The form asked for (``auto``: chosen per unit on the base plan).
    pattern : str or None
        The base plan's pattern (a label).
    base_poses : int
    validation_k : numpy.ndarray
        The validation temperature changes, K.
    reference_rms_deg : numpy.ndarray
        (pitch, roll): the base plan's form at T0, degrees (its white-noise error).
    uncompensated_rms_deg : numpy.ndarray
        Shape (n_validation_temperatures, 2): that form at each validation temperature.
    predictions : list of ThermalPrediction
    n_units, seed : int
    """

    change_k: float
    form: str
    pattern: str | None
    base_poses: int
    validation_k: np.ndarray
    reference_rms_deg: np.ndarray
    uncompensated_rms_deg: np.ndarray
    predictions: list
    n_units: int
    seed: int

    def to_dict(self):
        """JSON-ready: the settings, the yardstick, the uncompensated form, every prediction."""
        ref = self.reference_rms_deg
        return {
            "change_k": self.change_k,
            "form": self.form,
            "pattern": self.pattern,
            "base_poses": self.base_poses,
            "n_units": self.n_units,
            "seed": self.seed,
            "validation_k": self.validation_k.tolist(),
            "reference_rms_deg": ref.tolist(),
            "uncompensated_rms_deg": self.uncompensated_rms_deg.tolist(),
            "uncompensated_ratio": (self.uncompensated_rms_deg / ref).tolist(),
            "predictions": [p.to_dict() for p in self.predictions],
        }


def _pooled(errors):
    """RMS over the units of each unit's RMS: ``errors`` (units, …, samples, 2) → (…, 2)."""
    per_unit = np.sqrt(np.mean(np.square(errors), axis=-2))
    return np.sqrt(np.mean(np.square(per_unit), axis=0))


def _state(change_k, thermal):
    return OperatingState(
        delta_t_k=float(change_k), **({} if thermal is None else {"thermal": thermal})
    )


def _validation(unit, changes, seed, n_validation, thermal):
    """Validation poses (true angles) and their voltages at each temperature change, the same
    noise draws at every one."""
    workspace = unit.design.workspace
    truth = workspace.sample(stream_rng(seed, "thermal_truth_poses", unit.index), n_validation)
    volts = [
        unit.record(
            truth, stream_rng(seed, "thermal_truth_noise", unit.index), 0.0, _state(dt, thermal)
        )
        for dt in changes
    ]
    return truth, [v.volts for v in volts]


def _temperatures(n_base, n_poses, changes_k):
    """The temperature of each recorded pose, °C: the base plan's at T0, then the extra poses
    at each change from T0 (K) in turn."""
    return T0_C + np.repeat([0.0, *changes_k], [n_base, *(n_poses,) * len(changes_k)])


def _stacked(samples):
    """Voltages and angles of several recordings, one after the other."""
    return (np.vstack([s.volts for s in samples]), np.vstack([s.angles_deg for s in samples]))


def _unit_errors(unit, base, extras, form, changes, settings):
    """One unit's validation errors (V validation temperatures, P predictions, n poses).

    Returns the base plan's form at every temperature (V, n, 2); each prediction's
    compensated form at every temperature (P, V, n, 2); and the yardstick of each, the form
    fitted to the same poses all recorded at T0, validated at T0 (P, n, 2). ``extras``: per
    prediction, its poses and their temperature changes (K); ``changes``: the validation
    temperature changes (K); ``settings``: (seed, n_validation, thermal).
    """
    seed, n_validation, thermal = settings
    rng = stream_rng(seed, "thermal_plan", unit.index)
    cold = unit.record(base, rng)
    truth, validation = _validation(unit, changes, seed, n_validation, thermal)
    at_t0 = validation[list(changes).index(0.0)]
    plain = selected(make_estimator(form, seed=seed).fit(cold.volts, cold.angles_deg))
    uncompensated = np.stack([plain.predict(v) - truth for v in validation])
    compensated, same_poses = [], []
    for poses, poses_k in extras:
        data = [cold, *(unit.record(poses, rng, state=_state(dt, thermal)) for dt in poses_k)]
        flat = [cold, *(unit.record(poses, rng) for _ in poses_k)]  # the same poses at T0
        temps = _temperatures(len(base), len(poses), poses_k)
        model = TemperatureCompensated(plain.clone(), reference_temperature_c=T0_C)
        model.fit(*_stacked(data), temps)
        compensated.append(
            [
                model.predict(v, np.full(len(truth), T0_C + dt)) - truth
                for v, dt in zip(validation, changes, strict=True)
            ]
        )
        same_poses.append(plain.clone().fit(*_stacked(flat)).predict(at_t0) - truth)
    return uncompensated, np.array(compensated), np.array(same_poses)


def _extras(workspace, layouts, sizes, change_k, seed):
    """(layout, n, poses, changes) of every prediction: N Sobol poses at each temperature."""
    return [
        (
            layout,
            n,
            make_plan(workspace, "sobol", n, seed=seed),
            tuple(f * change_k for f in LAYOUTS[layout]),
        )
        for layout in layouts
        for n in sizes
    ]


def plan_temperature(
    design,
    base_plan,
    *,
    change_k=10.0,
    form="auto",
    pattern=None,
    layouts=tuple(LAYOUTS),
    sizes=SIZES,
    n_units=3,
    seed=0,
    n_validation=N_VALIDATION,
    thermal=None,
    progress=None,
):
    """Simulate compensated calibrations on built units for every layout and size (module notes).

    Parameters
    ----------
    design : reflector_opt.design._design.Design
        Two sensors.
    base_plan : array_like
        Shape (n, 2): the poses recorded at T0 (pitch, roll), degrees.
    change_k : float
        The use range K: the unit is used from T0 − K to T0 + K, K (1 to 60).
    form : str
        ``"auto"`` or a form name (``eq5``, ``eq6``, ``polyN``).
    pattern : str, optional
        The base plan's pattern, for the record.
    layouts : sequence of str
        Keys of :data:`LAYOUTS`.
    sizes : sequence of int
        Extra poses per temperature, each at least 4.
    n_units : int
    seed : int
        Seed of the units, the Sobol points and every noise draw.
    n_validation : int
        Validation poses per unit and temperature.
    thermal : ThermalCoefficients or tuple of them, optional
        The sensors' temperature coefficients (default the generic ones).
    progress : callable, optional
        ``progress(fraction, message)`` as each unit is done.

    Returns
    -------
    ThermalStudy
    """
    progress = no_progress if progress is None else progress
    if len(design.sensors) != 2:
        raise InputError("temperature plan: the design must have exactly two sensors")
    if not 1.0 <= change_k <= 60.0:
        raise InputError(f"temperature change: expected 1 to 60 K, got {change_k}")
    unknown = sorted(set(layouts) - set(LAYOUTS))
    if unknown:
        raise InputError(f"layouts: unknown {', '.join(unknown)}; known: {', '.join(LAYOUTS)}")
    base = np.asarray(base_plan, dtype=float)
    extras = _extras(design.workspace, layouts, sizes, change_k, seed)
    changes = np.array(VALIDATION) * change_k
    settings = (int(seed), int(n_validation), thermal)
    errors = []
    for i in range(int(n_units)):
        progress(i / n_units, f"temperature plan: unit {i + 1} of {n_units}")
        unit = build_unit(design, i, seed=seed)
        errors.append(_unit_errors(unit, base, [e[2:] for e in extras], form, changes, settings))
    uncompensated, rms, same = (_pooled(np.array(e)) for e in zip(*errors, strict=True))
    predictions = [
        ThermalPrediction(layout, n, poses_k, rms[j], same[j])
        for j, (layout, n, _, poses_k) in enumerate(extras)
    ]
    reference = uncompensated[list(VALIDATION).index(0.0)]
    return ThermalStudy(
        float(change_k),
        form,
        pattern,
        len(base),
        changes,
        reference,
        uncompensated,
        predictions,
        int(n_units),
        int(seed),
    )


def recommend_thermal(study, within=0.10):
    """The fewest extra poses whose error at every validation temperature is within
    ``within`` of their yardstick on both angles (ties: the smaller worst ratio).

    Parameters
    ----------
    study : ThermalStudy
    within : float
        Allowed excess over the yardstick (0.10: at most 1.1 ×).

    Returns
    -------
    ThermalPrediction or None
    """
    worst = {id(p): float(np.max(p.ratio)) for p in study.predictions}
    good = [p for p in study.predictions if worst[id(p)] <= 1.0 + within]
    return min(good, key=lambda p: (p.extra_poses, worst[id(p)]), default=None)


def plan_to_extend(study, within=0.10):
    """The calibration plan a temperature plan extends, as ``(form, pattern, n_poses)``.

    The plan :func:`~reflector_opt.tolerance._planning.recommend` chooses, if its form can be
    compensated; the physical form cannot, so then the smallest plan of another form within
    ``within`` of the floor, else ``auto`` on the recommended plan's poses.

    Parameters
    ----------
    study : reflector_opt.tolerance._planning.PlanStudy
    within : float
        Allowed excess over the Cramér–Rao floor.

    Returns
    -------
    tuple or None
        None if no plan comes within ``within`` of the floor.
    """
    best = recommend(study, within)
    if best is None:
        return None
    if best.form != "physical":
        return best.form, best.pattern, best.n_poses
    others = [p for p in study.predictions if p.form != "physical"]
    other = recommend(replace(study, predictions=others), within)
    if other is not None:
        return other.form, other.pattern, other.n_poses
    return "auto", best.pattern, best.n_poses


def thermometer_layout(study, within=0.10):
    """The layout :func:`thermometer_costs` measures: the recommended one of those with poses
    at T0 − K and T0 + K (:func:`recommend_thermal`), else the largest of them; None if the
    study has none."""
    both = [p for p in study.predictions if len(p.changes_k) > 1]
    if not both:
        return None
    pick = recommend_thermal(replace(study, predictions=both), within)
    return pick or max(both, key=lambda p: p.extra_poses)


def thermal_poses(design, prediction, seed=0):
    """The extra poses of a prediction and their temperature changes, in recording order.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    prediction : ThermalPrediction
    seed : int
        The study's seed (its Sobol points).

    Returns
    -------
    numpy.ndarray
        Shape (extra_poses, 3): pitch, roll (degrees) and the temperature change from T0 (K).
    """
    poses = make_plan(design.workspace, "sobol", prediction.n_poses, seed=seed)
    return np.vstack(
        [np.column_stack([poses, np.full(len(poses), dt)]) for dt in prediction.changes_k]
    )


#: What a compensation does not see, each measured alone by :func:`thermometer_costs` (assumed
#: magnitudes, as the error budget's conditions name them: ``thermometer_offset_k``,
#: ``thermometer_lag_s`` at ``temperature_rate_k_per_min``, ``strip_gradient_k``): the
#: thermometer 1 K off the junctions in use only, 30 s behind a change of 0.5 K/min, and S1
#: and S2 1 K apart in use with the thermometer between them.
IMPERFECTIONS = {"offset_k": 1.0, "lag_s": 30.0, "rate_k_per_min": 0.5, "gradient_k": 1.0}

#: The protocol :func:`thermometer_costs` measures: a thermometer at each sensor, on its
#: copper (5 s behind it), logged at calibration after the temperature settles and in use,
#: and a gain change of degree 2 in ΔT fitted on data at T0 − K, T0 and T0 + K.
PROTOCOL = {"per_sensor": True, "logged_at_calibration": True, "lag_s": 5.0, "degree": 2}

#: The compensated error the protocol is to keep, a multiple of the white-noise error.
PROTOCOL_TARGET = 1.5

#: Each row of a :class:`ThermometerStudy`: the imperfection, and what the protocol does.
COST_ROWS = {
    "curvature": ("the parts' curvature of the light path", "a term in ΔT² (three temperatures)"),
    "thermometer_offset": (
        "thermometer 1 K off, in use only",
        "the same thermometer logged at calibration (a constant offset cancels)",
    ),
    "thermometer_lag": (
        "thermometer 30 s behind at 0.5 K/min",
        "a thermometer on the sensors' copper, 5 s behind",
    ),
    "strip_gradient": ("S1 and S2 1 K apart in use", "a thermometer at each sensor"),
    "all": ("all four at once, linear in ΔT", "the whole protocol"),
}


@dataclass(frozen=True)
class ThermometerStudy:
    """What each imperfection of the thermometer and the light path costs a compensated
    calibration, and what the protocol leaves (:func:`thermometer_costs`).

    Attributes
    ----------
    prediction : ThermalPrediction
        The layout measured (poses at T0 − K and T0 + K besides the base plan at T0).
    curvature_per_k2 : tuple of float
        The truth's curvature of each sensor's relative output, 1/K² (``output_per_k2``).
    ratio : dict
        Row name (:data:`COST_ROWS`) → (without, with the protocol): the compensated RMS over
        the same poses' white-noise error at T0, the worse of pitch and roll at the worst
        validation temperature and sign, pooled over the units.
    allowed_error_k : float
        The thermometer error in use (offset's change, plus lag × rate) the protocol's form
        can take within :data:`PROTOCOL_TARGET` × (the systematic term grows as the error).
    n_units, seed : int
    """

    prediction: ThermalPrediction
    curvature_per_k2: tuple
    ratio: dict
    allowed_error_k: float
    n_units: int
    seed: int

    @property
    def settle_rate_k_per_min(self):
        """The rate of change below which calibration data are taken, K/min: the protocol's
        thermometer lag at it costs a tenth of :attr:`allowed_error_k`."""
        return 0.1 * self.allowed_error_k * 60.0 / PROTOCOL["lag_s"]

    def to_dict(self):
        """JSON-ready: the layout, the imperfections' sizes and each row's two ratios."""
        return {
            "changes_k": list(self.prediction.changes_k),
            "n_poses": self.prediction.n_poses,
            "imperfections": dict(IMPERFECTIONS),
            "curvature_per_k2": list(self.curvature_per_k2),
            "protocol": {**PROTOCOL, "target": PROTOCOL_TARGET},
            "rows": [
                {
                    "case": name,
                    "imperfection": COST_ROWS[name][0],
                    "remedy": COST_ROWS[name][1],
                    "ratio": without,
                    "protocol_ratio": with_protocol,
                }
                for name, (without, with_protocol) in self.ratio.items()
            ],
            "allowed_error_k": self.allowed_error_k,
            "settle_rate_k_per_min": self.settle_rate_k_per_min,
            "n_units": self.n_units,
            "seed": self.seed,
        }


def package_truth(thermal):
    """A truth recorded through the package's light path (:func:`apply_state`):
    ``record(unit, poses, rng, reference_sigma_deg, delta_t_k)`` → Samples, ``delta_t_k`` one
    for the sensors or one each (K)."""

    def record(unit, poses, rng, reference_sigma_deg, delta_t_k):
        state = OperatingState(delta_t_k=delta_t_k, thermal=thermal)
        return unit.record(poses, rng, reference_sigma_deg, state)

    return record


def _protocol_errors(unit, base, prediction, form, settings):
    """One unit's validation errors of each row (without, with the protocol), each of shape
    (cases, V, n, 2), and the yardstick (n, 2): see :func:`thermometer_costs`."""
    seed, n_validation, record = settings
    e = IMPERFECTIONS
    lag_k = e["lag_s"] * e["rate_k_per_min"] / 60.0
    fast_k = PROTOCOL["lag_s"] * e["rate_k_per_min"] / 60.0
    rng = stream_rng(seed, "thermal_plan", unit.index)
    poses = make_plan(unit.design.workspace, "sobol", prediction.n_poses, seed=seed)
    data = [record(unit, base, rng, REFERENCE_SIGMA_DEG, 0.0)]
    data += [record(unit, poses, rng, REFERENCE_SIGMA_DEG, dt) for dt in prediction.changes_k]
    flat = [data[0], *(record(unit, poses, rng, REFERENCE_SIGMA_DEG, 0.0) for _ in data[1:])]
    temps = _temperatures(len(base), len(poses), prediction.changes_k)
    truth = unit.design.workspace.sample(
        stream_rng(seed, "thermal_truth_poses", unit.index), n_validation
    )
    changes = np.array(VALIDATION) * max(np.abs(prediction.changes_k))
    half = 0.5 * e["gradient_k"] * np.array([1.0, -1.0])

    def validation(spread):  # (V, n, 2): S1 and S2 at ΔT ± spread from the strip's mean
        noise = stream_rng(seed, "thermal_truth_noise", unit.index)
        return np.stack(
            [record(unit, truth, noise, 0.0, tuple(dt + spread)).volts for dt in changes]
        )

    uniform, apart = validation(0.0 * half), validation(half)
    plain = selected(make_estimator(form, seed=seed).fit(*_stacked(data[:1])))
    yardstick = plain.clone().fit(*_stacked(flat)).predict(uniform[list(VALIDATION).index(0.0)])

    def fitted(degree, offset_k):
        model = TemperatureCompensated(plain.clone(), reference_temperature_c=T0_C, degree=degree)
        return model.fit(*_stacked(data), temps + offset_k)

    def errors(model, volts, read_k):
        """(V, n, 2) at each ΔT, read ``read_k`` off: one thermometer (a number) or one per
        sensor (a pair)."""
        read = T0_C + changes[:, None, None] + np.zeros(volts.shape) + read_k
        read = read if np.ndim(read_k) else read[..., 0]
        return np.stack([model.predict(v, t) for v, t in zip(volts, read, strict=True)]) - truth

    linear, quadratic = fitted(1, 0.0), fitted(2, 0.0)
    logged = fitted(2, e["offset_k"])
    signs = (1.0, -1.0)
    rows = {
        "curvature": ([errors(linear, uniform, 0.0)], [errors(quadratic, uniform, 0.0)]),
        "thermometer_offset": (
            [errors(quadratic, uniform, s * e["offset_k"]) for s in signs],
            [errors(logged, uniform, e["offset_k"])],
        ),
        "thermometer_lag": (
            [errors(quadratic, uniform, s * lag_k) for s in signs],
            [errors(quadratic, uniform, s * fast_k) for s in signs],
        ),
        "strip_gradient": (
            [errors(quadratic, v, 0.0) for v in (apart, validation(-half))],
            [errors(quadratic, apart, half)],
        ),
        "all": (
            [
                errors(linear, v, so * e["offset_k"] + sr * lag_k)
                for v in (apart, validation(-half))
                for so in signs
                for sr in signs
            ],
            [errors(logged, apart, half + e["offset_k"] + sr * fast_k) for sr in signs],
        ),
    }
    return {k: tuple(np.array(v) for v in pair) for k, pair in rows.items()}, yardstick - truth


def thermometer_costs(
    design,
    base_plan,
    prediction,
    *,
    form="auto",
    n_units=3,
    seed=0,
    n_validation=N_VALIDATION,
    thermal=None,
    record=None,
    progress=None,
):
    """What each imperfection a compensation does not see costs, and what the protocol leaves.

    Each built unit records the base plan at T0 and the prediction's poses at T0 ± K through
    the parts' light path (their curvature included), and is validated at
    ΔT = −K … K (:data:`VALIDATION`) with each imperfection of :data:`IMPERFECTIONS` alone,
    both signs, and all together (:data:`COST_ROWS`): compensated as
    :func:`plan_temperature` does (one thermometer read exactly at calibration, linear in
    ΔT; the thermometer's rows with the term in ΔT² so that the curvature is not counted
    twice), and per :data:`PROTOCOL`. The yardstick is :func:`plan_temperature`'s, the same
    poses all recorded at T0.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    base_plan : array_like
        Shape (n, 2), degrees: the poses at T0.
    prediction : ThermalPrediction
        Of the ``both`` layout (three temperatures).
    form : str
        As :func:`plan_temperature`.
    n_units, seed, n_validation : int
    thermal : ThermalCoefficients or tuple of them, optional
        The truth's light path (default each part's catalogue figures,
        :func:`~reflector_opt.analysis._budget.thermal_coefficients_of`).
    record : callable, optional
        Another truth: ``record(unit, poses, rng, reference_sigma_deg, delta_t_k)`` →
        Samples (default :func:`package_truth` of ``thermal``).
    progress : callable, optional

    Returns
    -------
    ThermometerStudy
    """
    from reflector_opt.analysis._budget import thermal_coefficients_of

    if len(design.sensors) != 2:
        raise InputError("thermometer costs: the design must have exactly two sensors")
    if len(prediction.changes_k) < 2:
        raise InputError("thermometer costs: the layout needs poses at T0 − K and T0 + K")
    progress = no_progress if progress is None else progress
    thermal = thermal_coefficients_of(design.models) if thermal is None else thermal
    record = package_truth(thermal) if record is None else record
    base = np.asarray(base_plan, dtype=float)
    settings = (int(seed), int(n_validation), record)
    units = []
    for i in range(int(n_units)):
        progress(i / n_units, f"thermometer costs: unit {i + 1} of {n_units}")
        units.append(
            _protocol_errors(build_unit(design, i, seed=seed), base, prediction, form, settings)
        )
    yardstick = _pooled(np.array([u[1] for u in units]))
    ratio = {
        name: tuple(
            float(np.max(_pooled(np.array([u[0][name][j] for u in units])) / yardstick))
            for j in (0, 1)
        )
        for name in COST_ROWS
    }
    parts = thermal if isinstance(thermal, tuple) else (thermal,) * len(design.sensors)
    return ThermometerStudy(
        prediction,
        tuple(float(t.output_per_k2) for t in parts),
        ratio,
        allowed_error_k(ratio["curvature"][1], ratio["thermometer_offset"][0]),
        int(n_units),
        int(seed),
    )


def allowed_error_k(perfect, offset, offset_k=None, target=PROTOCOL_TARGET):
    """The thermometer error that keeps the compensated error within ``target``, K.

    The error's systematic term is linear in the thermometer's error x and adds to the
    white-noise error in quadrature: r(x)² = r₀² + (x/e)²·(r_e² − r₀²), with r₀ the ratio
    with a perfect thermometer and r_e the ratio with an error e, so
    x = e·√((target² − r₀²)/(r_e² − r₀²)) (0 if r₀ ≥ target; inf if r_e ≤ r₀).

    Parameters
    ----------
    perfect, offset : float
        r₀ and r_e (multiples of the white-noise error).
    offset_k : float, optional
        e, K (default :data:`IMPERFECTIONS` ``offset_k``).
    target : float

    Returns
    -------
    float
    """
    e = IMPERFECTIONS["offset_k"] if offset_k is None else offset_k
    if perfect >= target:
        return 0.0
    if offset <= perfect:
        return float("inf")
    return float(e * np.sqrt((target**2 - perfect**2) / (offset**2 - perfect**2)))
