"""A design's angle-error budget in use: what each operating condition costs, and in total.

Every source is carried to the angles through the voltage Jacobian J = ∂V/∂(γ, α) of the fast
model (:func:`reflector_opt.analysis._jacobian.voltage_jacobian`): a change δV of the outputs
that the calibration did not see moves the estimate by the least-squares

    δθ = (JᵀJ)⁻¹ Jᵀ δV                                            (J⁻¹ δV for two sensors)

at each pose of a grid over the workspace. The sources (docs/conditions.md):

``noise``
    The white-noise floor, the Cramér–Rao bound σ_V·sqrt((JᵀJ)⁻¹) with the drive's noise
    factor (:mod:`reflector_opt.analysis._resolution`); random, its "max" is 3σ at the worst
    pose.
``form``
    The calibration form's misfit, given by the caller (``form_error_deg``; it needs the
    calibration layer above this one).
``temperature``
    The junction temperature ±``temperature_range_k`` from calibration, through the light path
    of :mod:`reflector_opt.model._temperature` (its dark-current part cancelled under
    ``modulated`` drive); with ``temperature_compensated``, what a temperature-aware
    calibration cannot see: the thermometer's error (offset and lag at the rate of change),
    the strip's gradient and the curvature a linear compensation leaves.
``expansion``
    The printed reflector and the sensor strip at the temperature change of ``temperature``
    (with ``temperature_compensated``, the thermometer's error), each expanding by its own
    coefficient (``resin_cte_ppm_per_k``, ``strip_cte_ppm_per_k``), through the forward model.
``ambient``
    A constant change of ``ambient_mv`` on each output alone and on all together (none under
    ``modulated``), with the mains flicker met at each sensor's read instant, the drive's
    residue of it left: RMS over the flicker's phase, amplitude as its max.
``crosstalk``
    ``neighbour_crosstalk`` of a neighbouring unit's photocurrent on each detector, the
    neighbour calibrated straight and used at its workspace's corners and edges (none when
    the LEDs are lit one at a time).
``reference``
    The angle reference's zero offset (the class of ``angle_reference``, or
    ``reference_zero_deg`` where given) and axis twist, both signs: the calibration learns
    the reference's frame.
``latency``
    The reference's lag ω·τ at the calibration's angular speed, on each angle.
``play``
    The sphere's centre shifted by what of the bearing's clearance the calibration does not
    learn (:func:`reflector_opt.design._joint.joint_shifts`: ±c/2 along each axis for a free
    joint or a load that reverses, the friction cone's ±(c/2)·sin φ across the load of a
    seated one), through the forward model, with ± half the joint's hysteresis on each angle.
``supply``
    The supply changed by ±``supply_change_mv`` since calibration, read against a fixed or a
    ratiometric ADC reference.
``ageing``
    The LEDs' output lower by :data:`LED_AGEING_PER_1000H` per 1000 h of
    ``hours_since_calibration``, common to the sensors.
``self_heating``
    With ``cold_start``, the LED junctions' rise from switch-on
    (:func:`~reflector_opt.model._temperature.self_heating_k`, the drive's duty).

Every voltage change is the voltage pipeline's (:mod:`reflector_opt.model._operating`): the
grid's outputs at calibration taken to the state that differs by that source alone.

A systematic source is a set of scenarios; its RMS is the largest over scenarios of the RMS
over the workspace, its max the largest error over scenarios and poses. The total's RMS is the
root-sum-square of the sources' (independent sources), its max the sum of their maxes (a
bound: every source at its worst at once).
"""

import itertools
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np

from reflector_opt.analysis._jacobian import values_and_jacobian
from reflector_opt.analysis._resolution import crlb_deg
from reflector_opt.design._joint import FRICTION, joint_shifts
from reflector_opt.model._drive import drive_effects
from reflector_opt.model._forward import voltages
from reflector_opt.model._operating import OperatingState, apply_state, photocurrent_v, readings
from reflector_opt.model._settling import LOAD_EXPONENT, time_constants_s
from reflector_opt.model._temperature import ThermalCoefficients, self_heating_k
from reflector_opt.util._display import Summarised

#: Grid step of the budget over the workspace, degrees (31 × 31 poses for ±15°).
BUDGET_STEP_DEG = 1.0
#: The budget's sources, in the order they are reported.
SOURCES = (
    "noise",
    "form",
    "temperature",
    "expansion",
    "ambient",
    "crosstalk",
    "reference",
    "latency",
    "play",
    "supply",
    "ageing",
    "self_heating",
)
#: Relative loss of an IR LED's output per 1000 h lit, with its kind and source.
LED_AGEING_PER_1000H = {
    "value": 0.03,
    "kind": "assumed",
    "range": [0.005, 0.03],
    "source": "no loss per 1000 h found in Vishay, Osram or Everlight documents; Everlight's "
    "qualification of the ITR8307 (DRX-083-121 rev. 2, p. 7) passes a unit that lost up to "
    "20 % in 1000 h at 20 mA, an upper bound; 0.5-3 % per 1000 h at a few mA is plausible, "
    "3 % the unfavourable end",
}
#: Phases of the flicker over a frame the budget takes, evenly over a period.
FLICKER_PHASES = 12
#: Peak over RMS of a random error's "max".
_RANDOM_PEAK = 3.0


@dataclass(frozen=True)
class AngleError:
    """RMS and maximum of an angle error over the workspace, per angle, degrees."""

    pitch_rms_deg: float
    roll_rms_deg: float
    pitch_max_deg: float
    roll_max_deg: float

    @classmethod
    def zero(cls):
        """No error."""
        return cls(0.0, 0.0, 0.0, 0.0)

    @classmethod
    def of_scenarios(cls, errors_deg):
        """From errors of shape (scenarios, poses, 2): worst scenario's RMS, worst max."""
        e = np.abs(np.asarray(errors_deg, dtype=float))
        rms = np.sqrt(np.mean(e**2, axis=1)).max(axis=0)
        peak = e.max(axis=(0, 1))
        return cls(float(rms[0]), float(rms[1]), float(peak[0]), float(peak[1]))

    @classmethod
    def total(cls, errors):
        """Root-sum-square of the RMS values, sum of the maxes."""
        rows = np.array(
            [[e.pitch_rms_deg, e.roll_rms_deg, e.pitch_max_deg, e.roll_max_deg] for e in errors]
        )
        rms = np.sqrt(np.sum(rows[:, :2] ** 2, axis=0))
        peak = rows[:, 2:].sum(axis=0)
        return cls(float(rms[0]), float(rms[1]), float(peak[0]), float(peak[1]))

    def to_dict(self):
        """``{pitch_rms_deg, roll_rms_deg, pitch_max_deg, roll_max_deg}``."""
        return dict(self.__dict__)


@dataclass(frozen=True)
class _Linearisation:
    """The outputs as the drive reads them, and their Jacobian, on a grid of poses (flattened).

    Under a switched drive a detector has settled to ``settled`` of its own LED's light when it
    is read (:func:`~reflector_opt.model._settling.settled_share`): the calibration learns that
    smaller response, while what does not follow the LED (ambient light, the dark current, the
    supply at the collector, the noise) passes whole. A ``differenced`` read-out (LED on less
    LED off, ``modulated``) takes off whatever changes both reads alike."""

    design: object
    settled: float
    differenced: bool
    pitch_deg: np.ndarray
    roll_deg: np.ndarray
    shape: tuple
    volts: np.ndarray
    jacobian: np.ndarray

    @classmethod
    def of(cls, design, step_deg, settled=1.0, differenced=False):
        pitch, roll = np.meshgrid(*design.workspace.axes(step_deg), indexing="ij")
        v, jac = values_and_jacobian(
            lambda p, r: _read(design, settled, voltages(design, p, r)), pitch.ravel(), roll.ravel()
        )
        return cls(design, settled, differenced, pitch.ravel(), roll.ravel(), pitch.shape, v, jac)

    def shift(self, delta_v):
        """Angle errors (…, poses, 2) of voltage changes (…, poses, n)."""
        return angle_shift_deg(self.jacobian, delta_v)

    def change(self, lit_only=False, **state):
        """The readings' change (poses, n) in the state that differs from calibration by
        ``state`` (:class:`~reflector_opt.model._operating.OperatingState` fields), V.

        A differenced read-out's reading is the lit output less the dark one (no photocurrent),
        so the dark output's change is taken off — unless ``lit_only``: a change that differs
        between the two reads (the flicker's residue, a neighbour's light left in one)."""
        models = self.design.models
        state = OperatingState(**state)
        lit = apply_state(self.volts, models, state) - self.volts
        if not self.differenced or lit_only:
            return lit
        dark = readings(np.zeros((1, len(models))), models)  # no photocurrent
        return lit - (apply_state(dark, models, state) - dark)

    @cached_property
    def reread(self):
        """The forward model's outputs at the grid's poses, in one call, as the drive reads
        them, V: the base the terms that move the geometry (:meth:`outputs`) subtract, so
        that the interpolated coupling's error cancels."""
        return self.outputs()

    def outputs(self, design=None, **forward):
        """The forward model's outputs of ``design`` (default the grid's) at the grid's poses,
        as the drive reads them, V; ``forward``: :func:`~reflector_opt.model._forward.voltages`'s
        keywords."""
        design = self.design if design is None else design
        volts = voltages(design, self.pitch_deg, self.roll_deg, **forward)
        return _read(design, self.settled, volts)


def _read(design, settled, volts):
    """Outputs of the forward model as a drive whose detectors settle to ``settled`` reads them."""
    if settled == 1.0:
        return volts
    return apply_state(volts, design.models, OperatingState(settled_share=settled))


def angle_shift_deg(jacobian, delta_v):
    """The estimate's shift from an unseen change of the outputs, δθ = (JᵀJ)⁻¹ Jᵀ δV, degrees.

    Parameters
    ----------
    jacobian : array_like, shape P + (n, 2 + m)
        ∂V/∂(γ, α), V/deg, then ∂V/∂ of ``m`` nuisance parameters the estimator fits beside
        the angles (a common gain a reference sensor reads, a shift of the joint): the shifts
        are then the first two components of the least-squares solution.
    delta_v : array_like, shape (…,) + P + (n,)
        Output changes, V, broadcast against the poses.

    Returns
    -------
    numpy.ndarray
        Shape ``(…,) + P + (2,)``: pitch and roll shifts, degrees (inf where J is singular or
        nearly so, as :func:`~reflector_opt.analysis._resolution.crlb_deg`).
    """
    jac = np.asarray(jacobian, dtype=float)
    dv = np.asarray(delta_v, dtype=float)
    normal = np.einsum("...ki,...kj->...ij", jac, jac)
    rhs = np.einsum("...ki,...k->...i", jac, dv)
    if jac.shape[-1] > 2:
        return np.linalg.solve(normal, rhs[..., None])[..., :2, 0]
    a, b, c = normal[..., 0, 0], normal[..., 0, 1], normal[..., 1, 1]
    det = a * c - b * b
    ok = det > 1e-12 * (a * c)  # as the Cramér–Rao bound: no estimate where J is singular
    det = np.where(ok, det, 1.0)
    shift = np.stack(
        [(c * rhs[..., 0] - b * rhs[..., 1]) / det, (a * rhs[..., 1] - b * rhs[..., 0]) / det],
        axis=-1,
    )
    return np.where(ok[..., None], shift, np.inf)


def _shipped_part_names():
    """The names of the shipped catalogue's parts (a model outside it takes generic figures)."""
    from reflector_opt.model import _catalogue as catalogue

    return {part.name for part in catalogue.shipped_catalogue()}


def thermal_coefficients_of(models):
    """Each sensor's temperature coefficients: its catalogue part's, else the generic ones.

    Parameters
    ----------
    models : sequence of reflector_opt.model._sensors.SensorModel

    Returns
    -------
    tuple of ThermalCoefficients
    """
    from reflector_opt.model import _catalogue as catalogue

    names = _shipped_part_names()
    return tuple(
        catalogue.thermal_coefficients(m.name) if m.name in names else ThermalCoefficients()
        for m in models
    )


def detector_time_constants_s(models):
    """Each sensor's detector time constants, rising and falling, at its circuit's load, s: its
    catalogue part's switching times, else the generic ones (:data:`~reflector_opt.model.
    catalogue.GENERIC_SWITCHING`), through :func:`~reflector_opt.model._settling.time_constants_s`.

    Parameters
    ----------
    models : sequence of reflector_opt.model._sensors.SensorModel

    Returns
    -------
    tuple of (float, float)
    """
    from reflector_opt.model import _catalogue as catalogue

    names = _shipped_part_names()
    taus = []
    for m in models:
        found = catalogue.switching_times(m.name) if m.name in names else None
        rise, fall, load, _ = found or (*catalogue.GENERIC_SWITCHING, True)
        taus.append(time_constants_s(rise, fall, load, m.load_resistor_ohm))
    return tuple(taus)


def drift_sensitivity(design, *, change=0.01, step_deg=BUDGET_STEP_DEG):
    """Angle error from a change of the light path, common to all sensors and each alone.

    A relative change ``change`` of the photocurrent (LED output, drive or detector gain) moves
    each output by −change · R2 · I_photo; the shift of the estimate is linearised through J.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    change : float, optional
        Relative change of the light path (0.01: 1 %).
    step_deg : float, optional
        Grid step over the workspace, degrees.

    Returns
    -------
    dict
        ``{"common": AngleError, <sensor name>: AngleError, …}``.
    """
    grid = _Linearisation.of(design, step_deg)
    n = len(design.sensors)
    masks = {"common": np.ones(n)} | {s.name: np.eye(n)[k] for k, s in enumerate(design.sensors)}
    return {
        name: AngleError.of_scenarios(grid.shift(grid.change(light_change=change * mask))[None])
        for name, mask in masks.items()
    }


@dataclass(frozen=True, repr=False)
class ErrorBudget(Summarised):
    """A design's predicted angle error in use, per source and in total.

    Attributes
    ----------
    sources : dict
        Source name (:data:`SOURCES`) → :class:`AngleError`.
    total : AngleError
        RMS: root-sum-square of the sources'; max: the sum of their maxes.
    conditions : reflector_opt.design._conditions.Conditions
    drive : reflector_opt.model._drive.DriveEffects
    self_heating_k : tuple of float
        Each LED junction's steady rise over the ambient under the drive, K.
    pitch_deg, roll_deg : numpy.ndarray
        The grid of the maps, shape (n_pitch, n_roll).
    maps : dict
        Source name → worst-scenario absolute error, shape (n_pitch, n_roll, 2), degrees
        (the noise's 1σ): where in the workspace each source costs most.
    scenarios : dict
        Systematic source name → its signed errors, shape (scenarios, n_pitch · n_roll, 2)
        (pitch-major), degrees: each scenario's error pose by pose (the order each term's
        function documents; ``ambient``: each output alone, all together, then the flicker
        at :data:`FLICKER_PHASES` phases, the one lowering the outputs most on average first).
    joint : reflector_opt.design._joint.JointShifts
        What of the joint's clearance the calibration learns and what stays.
    assumed : tuple of dict
        Every assumed figure the budget used (``{"figure", "value", "range", "source"}``):
        the outputs that lean on them say so.
    """

    sources: dict
    total: AngleError
    conditions: object
    drive: object
    self_heating_k: tuple
    pitch_deg: np.ndarray = field(repr=False)
    roll_deg: np.ndarray = field(repr=False)
    maps: dict = field(repr=False)
    scenarios: dict = field(default_factory=dict, repr=False)
    joint: object = None
    assumed: tuple = ()

    @property
    def worst_case_deg(self):
        """The worst-case total error: the largest over poses and angles of the root-sum-square
        of every source's worst-scenario error there (the noise's 1σ), degrees.

        With every condition at zero it is the worst-case Cramér–Rao 1σ resolution, the
        white-noise objective of ``optimise``.
        """
        stacked = np.stack(list(self.maps.values()))
        return float(np.sqrt(np.sum(stacked**2, axis=0)).max())

    def to_dict(self):
        """``{SOURCE: {pitch_rms_deg, …}, …, "total": {…}}``."""
        return {name: e.to_dict() for name, e in self.sources.items()} | {
            "total": self.total.to_dict()
        }

    def _summary(self):
        rows = [
            (
                name,
                f"pitch {e.pitch_rms_deg:.3f}° RMS ({e.pitch_max_deg:.3f}° max), "
                f"roll {e.roll_rms_deg:.3f}° RMS ({e.roll_max_deg:.3f}° max)",
            )
            for name, e in {**self.sources, "total": self.total}.items()
        ]
        return f"ErrorBudget ({self.drive.scheme} drive)", rows


def _temperature(grid, design, conditions, drive, thermal):
    """Scenarios of the junctions' temperature change from calibration, degrees.

    Uncompensated: ΔT = +R and −R on every sensor. Temperature-compensated
    (:func:`compensated_changes_k`): what the compensation cannot see, then the curvature a
    compensation linear in T leaves at ΔT = R and at 0: fitted at T0 − R, T0 and T0 + R by a
    line in T, it leaves of a relative output κ·ΔT² the residue κ·(ΔT² − 2R²/3), κR²/3 at the
    ends, −2κR²/3 at T0."""
    state = {"thermal": thermal, "dark_current_changes": not drive.dark_current_cancelled}

    def change(delta_t_k):
        return grid.change(delta_t_k=delta_t_k, **state)

    r = conditions.temperature_range_k
    if not conditions.temperature_compensated:
        return grid.shift(np.stack([change(r), change(-r)]))
    changes = [change(dt) for dt in compensated_changes_k(conditions, len(design.models))]
    kappa = np.array([t.output_per_k2 for t in thermal])
    changes += [grid.change(light_change=kappa * (dt**2 - 2.0 * r**2 / 3.0)) for dt in (r, 0.0)]
    return grid.shift(np.stack(changes))


def compensated_changes_k(conditions, n):
    """Each sensor's temperature change that a temperature-aware calibration does not see,
    per scenario, K: the thermometer's error e = offset + lag · rate (both signs) with the
    strip's gradient g, sensor k at g·(k/(n − 1) − 1/2) from the strip's mean (both signs):
    four scenarios of n changes."""
    e = _thermometer_error_k(conditions)
    along = np.linspace(-0.5, 0.5, n) if n > 1 else np.zeros(1)
    g = conditions.strip_gradient_k * along
    return [tuple(float(v) for v in se * e + sg * g) for se in (1, -1) for sg in (1, -1)]


def _thermometer_error_k(conditions):
    """The thermometer's error against what it measures, offset + lag · rate, K."""
    lag = conditions.thermometer_lag_s * conditions.temperature_rate_k_per_min / 60.0
    return conditions.thermometer_offset_k + lag


def _expansion(grid, design, conditions):
    """Scenarios: the parts at ΔT = +R and −R from calibration (compensated: ± the
    thermometer's error e, as a compensation linear in T learns the rest), the reflector's
    radius and centre scaled by 1 + α_resin·ΔT, the sensors' positions by 1 + α_strip·ΔT,
    both about the joint's centre, through the forward model."""
    compensated = conditions.temperature_compensated
    dt = _thermometer_error_k(conditions) if compensated else conditions.temperature_range_k
    resin, strip = 1e-6 * conditions.resin_cte_ppm_per_k, 1e-6 * conditions.strip_cte_ppm_per_k
    # the changed design's own checks on a 0.5° grid at most: the forward model checks these
    workspace = replace(design.workspace, step_deg=max(design.workspace.step_deg, 0.5))
    warm = grid.outputs(expanded_design(design, resin * dt, strip * dt, workspace=workspace))
    change = warm - grid.reread  # odd in ΔT to first order (strains of 1e-4): −ΔT gives −change
    return grid.shift(np.stack([change, -change]))


def expanded_design(design, reflector_strain, sensor_strain, *, workspace=None):
    """The design with its reflector and its sensors' places expanded about the joint's centre.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    reflector_strain, sensor_strain : float
        Relative changes of length, α ΔT: the reflector's radii and centre scale by
        1 + ``reflector_strain``, the sensors' positions by 1 + ``sensor_strain`` (their axes
        and the sensor parts themselves unchanged).
    workspace : reflector_opt.design._components.Workspace, optional
        The changed design's workspace; default the design's.

    Returns
    -------
    reflector_opt.design._design.Design
    """
    r, k = design.reflector, 1.0 + reflector_strain
    reflector = replace(
        r,
        radius_mm=r.radius_mm * k,
        inner_radius_mm=r.inner_radius_mm * k,
        centre_mm=tuple(float(c) * k for c in r.centre_mm),
    )
    sensors = tuple(
        replace(s, position_mm=tuple(float(p) * (1.0 + sensor_strain) for p in s.position_mm))
        for s in design.sensors
    )
    return design.replace(
        reflector=reflector, sensors=sensors, workspace=workspace or design.workspace
    )


def _ambient(grid, design, conditions, drive):
    """A constant change on each output alone and on all together, and the flicker at
    :data:`FLICKER_PHASES` phases of a frame, the one it lowers the outputs most on average
    first: sensor k, read k · ``drive.read_interval_s`` into the frame, meets its drop
    A·cos(θ + 2π f k Δt)."""
    n = grid.volts.shape[-1]
    masks = np.vstack([np.eye(n), np.ones((1, n))])
    constant = 1e-3 * conditions.ambient_mv * drive.ambient_dc * masks
    amplitude = 1e-3 * conditions.ambient_flicker_mv * drive.flicker
    phases = 2.0 * np.pi * conditions.flicker_hz * drive.read_interval_s * np.arange(n)
    lowest = -np.angle(np.sum(np.exp(1j * phases)))
    thetas = lowest + 2.0 * np.pi * np.arange(FLICKER_PHASES) / FLICKER_PHASES
    waves = [
        grid.change(lit_only=True, flicker_v=amplitude * np.cos(theta + phases)) for theta in thetas
    ]
    return (
        grid.shift(np.stack([grid.change(ambient_v=tuple(m)) for m in constant])),
        grid.shift(np.stack(waves)),
    )


def _crosstalk(grid, design, conditions, drive):
    """The neighbour calibrated straight, used at its workspace's corners and edge middles."""
    photo = photocurrent_v(grid.volts, design.models).reshape((*grid.shape, -1))
    i, j = (grid.shape[0] - 1, grid.shape[1] - 1)
    picks = [(0, 0), (0, j), (i, 0), (i, j), (i // 2, 0), (i // 2, j), (0, j // 2), (i, j // 2)]
    straight = photo[i // 2, j // 2]
    share = conditions.neighbour_crosstalk * drive.crosstalk
    changes = [
        grid.change(lit_only=True, crosstalk_v=share * (photo[a, b] - straight)) for a, b in picks
    ]
    return grid.shift(np.stack(changes))


def _reference(grid, conditions):
    """Every sign of the zero offset (:meth:`~reflector_opt.design._conditions.Conditions.
    reference_zero`) on each angle and of the twist: eight scenarios."""
    kappa = np.deg2rad(conditions.reference_twist_deg)
    angles = np.stack([grid.pitch_deg, grid.roll_deg], axis=-1)
    errors = []
    for sp, sr, sk in itertools.product((1.0, -1.0), repeat=3):  # every sign of each error
        c, s = np.cos(kappa), sk * np.sin(kappa)
        twisted = angles @ np.array([[c, s], [-s, c]])
        zero = np.array(conditions.reference_zero()) * (sp, sr)
        errors.append(twisted - angles + zero)
    return np.stack(errors)


def _play(grid, design, joint, conditions):
    """Scenarios: the centre at +x, +y, +z, −x, −y, −z by what stays of the joint's shift
    (``joint.stays_um``), each with the hysteresis's + or − half on both angles.

    The outputs' change is odd in the shift to first order (tens of µm against a millimetre
    of |OC|: the second order is a few per cent of it), so −δ is taken as the change of +δ
    negated: three forward-model calls, not six."""
    stays_mm = 1e-3 * np.asarray(joint.stays_um, dtype=float)
    plus = np.stack(
        [grid.outputs(reflector_shift_mm=stays_mm * axis) - grid.reread for axis in np.eye(3)]
    )
    half = 0.5 * conditions.joint_hysteresis_deg
    return (
        grid.shift(np.concatenate([plus, -plus]))
        + half * np.array([[1.0, 1.0], [-1.0, -1.0]]).repeat(3, axis=0)[:, None, :]
    )


def _supply(grid, design, conditions):
    """Scenarios: the supply at +δ and −δ since calibration, read by the ADC."""
    delta_v = 1e-3 * conditions.supply_change_mv
    changes = [
        grid.change(supply_change_v=sign * delta_v, adc_reference=conditions.adc_reference)
        for sign in (1.0, -1.0)
    ]
    return grid.shift(np.stack(changes))


def _noise(grid, design, drive):
    sigma_v = drive.noise_factor * design.noise.total_sigma_v
    jac = grid.jacobian
    if jac.shape[-1] > 2:  # the angles' share of σ_V² (JᵀJ)⁻¹ with the nuisance fitted
        inverse = np.linalg.inv(np.einsum("...ki,...kj->...ij", jac, jac))
        sigma = sigma_v * np.sqrt(np.diagonal(inverse, axis1=-2, axis2=-1)[..., :2])
    else:
        sigma = np.stack(crlb_deg(jac, sigma_v), axis=-1)
    rms = np.sqrt(np.mean(sigma**2, axis=0))
    peak = _RANDOM_PEAK * sigma.max(axis=0)
    return AngleError(*rms, *peak), sigma


def _self_heating(grid, design, conditions, drive, thermal):
    rises = tuple(
        self_heating_k(m, t, drive.duty) for m, t in zip(design.models, thermal, strict=True)
    )
    if not conditions.cold_start:
        return rises, None
    led_only = tuple(replace(t, detector_gain_per_k=0.0, dark_current_a=0.0) for t in thermal)
    cold = grid.change(delta_t_k=tuple(-r for r in rises), thermal=led_only)
    return rises, grid.shift(cold)[None]


def _systematic_errors(grid, design, conditions, drive, thermal, joint):
    """Source name → scenario errors (scenarios, poses, 2), degrees."""
    lag = 1e-3 * conditions.angular_speed_deg_s * conditions.reference_latency_ms
    # ageing, one scenario: every LED's output lower by the ageing since calibration
    loss = LED_AGEING_PER_1000H["value"] * conditions.hours_since_calibration / 1000.0
    return {
        "temperature": _temperature(grid, design, conditions, drive, thermal),
        "expansion": _expansion(grid, design, conditions),
        "crosstalk": _crosstalk(grid, design, conditions, drive),
        "reference": _reference(grid, conditions),
        "latency": np.broadcast_to(
            lag * np.array([[1.0, 1.0], [-1.0, -1.0]])[:, None, :], (2, grid.pitch_deg.size, 2)
        ),
        "play": _play(grid, design, joint, conditions),
        "supply": _supply(grid, design, conditions),
        "ageing": grid.shift(grid.change(light_change=-loss)[None]),
    }


def error_budget(
    design, conditions, *, form_error_deg=None, step_deg=BUDGET_STEP_DEG, nuisance=None
):
    """The predicted angle error of a calibrated unit of ``design`` in ``conditions``.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    conditions : reflector_opt.design._conditions.Conditions
    form_error_deg : array_like, optional
        The calibration form's error at the budget's grid poses, shape
        (n_pitch · n_roll, 2) (pitch-major), degrees; None leaves the ``form`` source at zero.
    step_deg : float, optional
        Grid step over the workspace, degrees.
    nuisance : callable, optional
        ``nuisance(grid) -> (poses, n, m)``: ∂V/∂ of ``m`` parameters an estimator fits beside
        the angles from the outputs of the grid (:class:`_Linearisation`), in its units
        (benchmarks/third_sensor.py: the common gain a reference sensor reads, the joint's
        shift). Every term is then the angles' part of the least-squares solution for all
        of them (:func:`angle_shift_deg`), the noise its share of σ_V² (JᵀJ)⁻¹.

    Returns
    -------
    ErrorBudget
    """
    drive = drive_effects(
        conditions.drive,
        len(design.sensors),
        conditions.sample_rate_hz,
        conditions.flicker_hz,
        tau_s=tuple(np.max(detector_time_constants_s(design.models), axis=0)),
    )
    grid = _Linearisation.of(
        design, step_deg, settled=drive.settled_share, differenced=drive.dark_current_cancelled
    )
    if nuisance is not None:
        grid = replace(grid, jacobian=np.concatenate([grid.jacobian, nuisance(grid)], axis=-1))
    thermal = thermal_coefficients_of(design.models)
    joint = joint_shifts(conditions, design.mechanics)
    errors = _systematic_errors(grid, design, conditions, drive, thermal, joint)
    if form_error_deg is not None:
        errors["form"] = np.asarray(form_error_deg, dtype=float).reshape(1, -1, 2)
    rises, heating = _self_heating(grid, design, conditions, drive, thermal)
    if heating is not None:
        errors["self_heating"] = heating
    sources = {name: AngleError.of_scenarios(e) for name, e in errors.items()}
    maps = {name: np.abs(e).max(axis=0) for name, e in errors.items()}
    sources["noise"], maps["noise"] = _noise(grid, design, drive)
    constant, flicker = _ambient(grid, design, conditions, drive)
    errors["ambient"] = np.concatenate([constant, flicker])  # in scenarios only
    sources["ambient"] = _ambient_error(constant, flicker)
    maps["ambient"] = np.abs(constant).max(axis=0) + np.abs(flicker).max(axis=0)
    ordered = {name: sources.get(name, AngleError.zero()) for name in SOURCES}
    shape = (*grid.shape, 2)
    return ErrorBudget(
        sources=ordered,
        total=AngleError.total(ordered.values()),
        conditions=conditions,
        drive=drive,
        self_heating_k=rises,
        pitch_deg=grid.pitch_deg.reshape(grid.shape),
        roll_deg=grid.roll_deg.reshape(grid.shape),
        maps={name: maps.get(name, np.zeros(shape)).reshape(shape) for name in SOURCES},
        scenarios=errors,
        joint=joint,
        assumed=assumed_figures(design, conditions, joint),
    )


def assumed_figures(design, conditions, joint):
    """The assumed figures a budget of ``design`` in ``conditions`` leans on.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    conditions : reflector_opt.design._conditions.Conditions
    joint : reflector_opt.design._joint.JointShifts

    Returns
    -------
    tuple of dict
        ``{"figure", "value", "range", "source"}`` each: the sensors' assumed temperature
        figures (their catalogue part's, or the generic defaults of a part not in it), the
        bearing's clearance row and the friction where the joint term uses them, the LED
        ageing where hours are given, the angle reference's class where it sets the zero and
        is assumed, the conditions' own assumed defaults where left so.
    """
    from reflector_opt.design._bearings import design_bearing
    from reflector_opt.design._conditions import DEFAULT_BASIS, Conditions
    from reflector_opt.model import _catalogue as catalogue

    found = []

    def add(figure, value, source):  # a figure stated without a range
        found.append({"figure": figure, "value": value, "range": None, "source": source})

    names = _shipped_part_names()
    for model in dict.fromkeys(m.name for m in design.models):
        if model in names:
            figures = catalogue.assumed_temperature_figures(model)
        else:
            figures = {
                k: {"value": v, "range": None, "source": "the generic default"}
                for k, v in ThermalCoefficients().__dict__.items()
                if v is not None
            }
        found += [{"figure": f"{model}: {k}", **v} for k, v in figures.items()]
    if conditions.joint_clearance_um is None and joint.clearance_um > 0.0:
        bearing = design_bearing(design.mechanics)
        row = bearing.figures["clearance_normal_um"]
        if row["kind"] == "assumed":
            add(f"{bearing.name}: clearance_normal_um", row["value"], row["source"])
    if conditions.drive != "dc":
        for model in dict.fromkeys(m.name for m in design.models):
            if model not in names or catalogue.switching_times(model)[3]:
                add(f"{model}: rise_time_s, fall_time_s", None, "assumed (the catalogue's source)")
        found.append({"figure": "detector load exponent", **_without_kind(LOAD_EXPONENT)})
    if joint.seated and joint.clearance_um > 0.0:
        found.append({"figure": "joint friction coefficient", **_without_kind(FRICTION)})
    if conditions.hours_since_calibration > 0.0:
        found.append({"figure": "LED ageing per 1000 h", **_without_kind(LED_AGEING_PER_1000H)})
    reference = conditions.reference_figure()
    if reference is not None and reference["kind"] == "assumed":
        name = reference.pop("name")
        found.append({"figure": f"angle reference {name}", **_without_kind(reference)})
    defaults = Conditions()
    for key, (kind, source) in DEFAULT_BASIS.items():
        if kind == "assumed" and getattr(conditions, key) == getattr(defaults, key):
            add(f"conditions.{key} (the default value)", getattr(conditions, key), source)
    return tuple(found)


def _without_kind(figure):
    return {k: v for k, v in figure.items() if k != "kind"}


def _ambient_error(constant, flicker):
    """A constant change (scenarios) and the flicker (phases evenly over a period: RMS over
    the phases and the poses, its largest as max)."""
    steady = AngleError.of_scenarios(constant)
    rms = np.hypot(
        [steady.pitch_rms_deg, steady.roll_rms_deg], np.sqrt(np.mean(flicker**2, (0, 1)))
    )
    peak = np.add([steady.pitch_max_deg, steady.roll_max_deg], np.abs(flicker).max(axis=(0, 1)))
    return AngleError(*rms.tolist(), *peak.tolist())
