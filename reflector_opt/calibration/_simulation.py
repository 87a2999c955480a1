"""Simulated calibration of one unit: the paper's protocol run on the forward model.

Osman et al. (2024, §4.1) move each unit over a grid of poses, ±15° pitch and roll in 0.1°
steps, record both sensor voltages with an IMU as ground truth, and fit Eq 6. Here the
voltages come from :func:`reflector_opt.model._forward.voltages` with the design's noise (additive
RMS noise, ADC quantisation; :mod:`reflector_opt.model._noise`) and optional per-sensor gain and
offset mismatch. The fitted model is then validated on independent poses drawn uniformly over
the workspace with fresh noise.

Error statistics (degrees, per angle, estimate minus truth over the validation poses):
RMS, maximum absolute error, and the **percent error, defined here as 100 × RMS error /
angle span** (the span is the workspace range of that angle; 30° for ±15°). The paper's
Table I gives a "% error" without defining it, so its figures are not directly comparable.

To separate causes, the model is also fitted to the noise-free calibration voltages and
validated on noise-free voltages: that error is the calibration model's own **misfit**. The
**noise** part is the difference between the two estimates at the same poses (everything the
recorded voltages add: noise, quantisation, mismatch, drift).
"""

from dataclasses import dataclass

import numpy as np

from reflector_opt.calibration._models import make_model, recorded_params
from reflector_opt.model._forward import voltages
from reflector_opt.model._noise import measure
from reflector_opt.util._display import Summarised, fmt
from reflector_opt.util._errors import InputError
from reflector_opt.util._limits import MAX_POSES, check_count


@dataclass(frozen=True)
class Samples:
    """Poses and the voltages at them.

    Attributes
    ----------
    angles_deg : numpy.ndarray
        Shape (n, 2): true pitch, roll, degrees.
    volts_true : numpy.ndarray
        Shape (n, 2): noise-free sensor voltages, V.
    volts : numpy.ndarray
        Shape (n, 2): recorded voltages (mismatch, noise, ADC), V.
    """

    angles_deg: np.ndarray
    volts_true: np.ndarray
    volts: np.ndarray


def record(design, angles_deg, rng, mismatch=None):
    """Voltages a logger records at the given poses.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
        Its ``noise`` (sigma_v, adc_bits, vref) is applied.
    angles_deg : array_like
        Shape (n, 2): pitch, roll, degrees.
    rng : numpy.random.Generator
    mismatch : reflector_opt.model._noise.Mismatch, optional
        Per-sensor gain and offset.

    Returns
    -------
    Samples
    """
    angles = np.asarray(angles_deg, dtype=float)
    true = voltages(design, angles[:, 0], angles[:, 1])
    return Samples(angles, true, measure_with_design_noise(design, true, rng, mismatch))


def rig_record(volts, design, angles_deg, rng, reference_sigma_deg):
    """What a calibration rig logs of a unit: its voltages with noise, the reference's angles.

    The unit's noise-free voltages at the true poses, the design's voltage noise and ADC
    added (:func:`measure_with_design_noise`; the unit's gain and offset are already in
    ``volts``), then the angle reference's own Gaussian noise on the angles, drawn in that
    order from ``rng``. The one record of a simulated unit, built or made by the model.

    Parameters
    ----------
    volts : callable
        ``volts(pitch_deg, roll_deg)`` → noise-free output voltages, shape ``P + (n,)``, V.
    design : reflector_opt.design._design.Design
        Its ``noise`` (sigma_v, adc_bits, vref) is applied.
    angles_deg : array_like
        Shape (n, 2): the true pitch and roll, degrees.
    rng : numpy.random.Generator
    reference_sigma_deg : float
        RMS noise of the angle reference, degrees (0 for the true angles).

    Returns
    -------
    Samples
        ``angles_deg`` as the reference reads them, ``volts_true`` the noise-free voltages,
        ``volts`` the recorded ones.
    """
    angles = np.asarray(angles_deg, dtype=float)
    true = volts(angles[:, 0], angles[:, 1])
    recorded = measure_with_design_noise(design, true, rng)
    read = angles + rng.normal(0.0, reference_sigma_deg, angles.shape)
    return Samples(read, true, recorded)


def measure_with_design_noise(design, volts, rng, mismatch=None):
    """Apply mismatch, the design's noise and its ADC to voltages (:func:`noise.measure`).

    Parameters
    ----------
    design : reflector_opt.design._design.Design
        Its ``noise`` (sigma_v, adc_bits, vref) is applied.
    volts : array_like
        Shape (n, 2): voltages reaching the read-out, V.
    rng : numpy.random.Generator
    mismatch : reflector_opt.model._noise.Mismatch, optional
        Per-sensor gain and offset.

    Returns
    -------
    numpy.ndarray
        The recorded voltages, V.
    """
    noise = design.noise
    return measure(
        volts,
        rng,
        sigma_v=noise.sigma_v,
        adc_bits=noise.adc_bits,
        vref=noise.vref,
        mismatch=mismatch,
    )


@dataclass(frozen=True)
class Protocol:
    """Calibration and validation samples of one simulated unit.

    Attributes
    ----------
    calibration : Samples
        The calibration plan (the paper's: the workspace grid).
    validation : Samples
        Independent uniformly random poses.
    span_deg : numpy.ndarray
        Pitch and roll spans of the workspace, degrees.
    step_deg : float
        Grid step, degrees (NaN when the plan is not a grid).
    seed : int or sequence of int
        The seed of the protocol's draws.
    """

    calibration: Samples
    validation: Samples
    span_deg: np.ndarray
    step_deg: float
    seed: int


def simulate_protocol(
    recorder, workspace, calibration_poses, n_validation, rng, *, step_deg=np.nan, seed=0
):
    """The simulated calibration protocol: record a plan, then independent validation poses.

    The one sequence every simulated calibration follows — the unit is recorded at the
    calibration poses, then ``n_validation`` poses are drawn uniformly over the workspace
    (:meth:`~reflector_opt.design._components.Workspace.sample`) and recorded in use — with one
    random generator drawing, in this order, the calibration noise, the validation poses and
    the validation noise. What a unit is (the forward model, a built unit, an as-built
    read-out) is the recorder's business; the fit and its validation are :func:`assess`'s.

    Parameters
    ----------
    recorder : callable
        ``recorder(angles_deg, rng, in_use)`` → :class:`Samples`: the unit recorded at poses of
        shape (n, 2), degrees; ``in_use`` is False for the calibration, True for the
        validation (a drift or ambient light after calibration applies there alone).
    workspace : reflector_opt.design._components.Workspace
        Its box bounds the validation poses and gives the spans.
    calibration_poses : array_like
        Shape (n, 2): pitch, roll of the calibration plan, degrees.
    n_validation : int
        Validation poses.
    rng : numpy.random.Generator
        The one source of every draw.
    step_deg : float
        Grid step of the plan, degrees (NaN when the plan is not a grid).
    seed : int or sequence of int
        Recorded in the result (the seed the generator came from).

    Returns
    -------
    Protocol
    """
    n_validation = check_count(n_validation, "n_validation", 1, MAX_POSES)
    calibration = recorder(calibration_poses, rng, False)
    validation = recorder(workspace.sample(rng, n_validation), rng, True)
    lo, hi = workspace.bounds()
    return Protocol(calibration, validation, hi - lo, float(step_deg), seed)


def run_protocol(design, *, step_deg=None, n_validation=20000, seed=0, mismatch=None, drift=None):
    """Simulate the paper's calibration protocol and an independent validation set.

    The forward model's unit recorded on the workspace grid (:func:`simulate_protocol`).

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    step_deg : float, optional
        Grid step, degrees; default the workspace's (0.1° gives 301 × 301 = 90,601 poses).
    n_validation : int
        Number of validation poses, uniform over the workspace.
    seed : int
        Seed of every random draw (poses, noise).
    mismatch : reflector_opt.model._noise.Mismatch, optional
        The unit's per-sensor gain and offset, present in calibration and validation.
    drift : reflector_opt.model._noise.Mismatch, optional
        A further gain and offset change after calibration (validation only).

    Returns
    -------
    Protocol
    """
    workspace = design.workspace
    step = workspace.step_deg if step_deg is None else step_deg
    if not step > 0:
        raise InputError(f"step_deg: must be positive, got {step}")
    workspace.check_step(step, "step_deg")

    def recorder(angles_deg, rng, in_use):
        samples = record(design, angles_deg, rng, mismatch)
        if in_use and drift is not None:
            return Samples(samples.angles_deg, samples.volts_true, drift.apply(samples.volts))
        return samples

    return simulate_protocol(
        recorder,
        workspace,
        workspace.poses(step),
        n_validation,
        np.random.default_rng(seed),
        step_deg=step,
        seed=seed,
    )


@dataclass(frozen=True)
class ErrorStats:
    """Estimation error over a set of poses, per angle (pitch, roll).

    Attributes
    ----------
    rms_deg, max_deg : numpy.ndarray
        RMS and maximum absolute error, degrees.
    percent : numpy.ndarray
        100 × RMS error / angle span.
    """

    rms_deg: np.ndarray
    max_deg: np.ndarray
    percent: np.ndarray

    @classmethod
    def of(cls, error_deg, span_deg):
        """Statistics of errors of shape (n, 2) over angle spans (2,), degrees."""
        rms = np.sqrt(np.mean(np.square(error_deg), axis=0))
        return cls(rms, np.abs(error_deg).max(axis=0), 100.0 * rms / np.asarray(span_deg))

    def to_dict(self):
        """JSON-ready: ``{rms_deg, max_deg, percent_error}`` each ``{pitch, roll}``."""
        named = {"rms_deg": self.rms_deg, "max_deg": self.max_deg, "percent_error": self.percent}
        return {key: {"pitch": float(v[0]), "roll": float(v[1])} for key, v in named.items()}


@dataclass(frozen=True, repr=False)
class CalibrationResult(Summarised):
    """Predicted performance of one calibration model on one simulated unit.

    Attributes
    ----------
    model
        The model fitted to the recorded calibration voltages.
    total : ErrorStats
        Error of that model on the recorded validation voltages.
    misfit : ErrorStats
        Error of the model fitted and validated without noise: the model's own misfit.
    noise : ErrorStats
        Difference between the two estimates at the validation poses.
    protocol : Protocol
    """

    model: object
    total: ErrorStats
    misfit: ErrorStats
    noise: ErrorStats
    protocol: Protocol

    def estimate(self, volts):
        """Pitch and roll from voltages with the fitted model, degrees."""
        return self.model.predict(volts)

    def to_dict(self):
        """JSON-ready summary (the ``evaluate --json`` ``calibration.<model>`` block)."""
        protocol = self.protocol
        return {
            "model": self.model.name,
            "params": recorded_params(self.model),
            **self.total.to_dict(),
            "misfit_rms_deg": self.misfit.to_dict()["rms_deg"],
            "noise_rms_deg": self.noise.to_dict()["rms_deg"],
            "n_calibration": len(protocol.calibration.angles_deg),
            "n_validation": len(protocol.validation.angles_deg),
        }

    # -- display (equality is the dataclass's, field by field) --

    def _summary(self):
        """Title and (label, value) rows of a :class:`CalibrationResult`, units included."""
        protocol, total = self.protocol, self.total
        name = getattr(self.model, "name", type(self.model).__name__)
        n_cal, n_val = len(protocol.calibration.angles_deg), len(protocol.validation.angles_deg)
        title = f"CalibrationResult: {name}, RMS error {_pair(total.rms_deg)}"
        rows = [
            ("max error", _pair(total.max_deg)),
            ("% error", f"{_pair(total.percent, unit='%')} (100 × RMS / span)"),
            ("model misfit", f"RMS {_pair(self.misfit.rms_deg)} (noise-free)"),
            ("noise", f"RMS {_pair(self.noise.rms_deg)} (what the recorded voltages add)"),
            (
                "protocol",
                f"{n_cal:,} calibration poses on a {fmt(protocol.step_deg, unit='°')} grid, "
                f"{n_val:,} validation poses, spans {_pair(protocol.span_deg)}, "
                f"seed {protocol.seed}",
            ),
        ]
        return title, rows


def _pair(values, digits=3, unit="°"):
    """``pitch X, roll Y`` of a per-angle pair."""
    return f"pitch {fmt(values[0], digits, unit)}, roll {fmt(values[1], digits, unit)}"


def validation_error(model, protocol):
    """Fit a calibration model to a protocol's recorded data and measure its validation error.

    Parameters
    ----------
    model : calibration model
        Unfitted template (cloned, not modified).
    protocol : Protocol

    Returns
    -------
    (model, ErrorStats)
        The fitted model and its error on the recorded validation voltages, degrees.
    """
    fitted, estimate = _fit_and_estimate(model, protocol)
    return fitted, ErrorStats.of(estimate - protocol.validation.angles_deg, protocol.span_deg)


def _fit_and_estimate(model, protocol):
    """The model fitted to the recorded calibration data and its validation estimates."""
    cal = protocol.calibration
    fitted = model.clone().fit(cal.volts, cal.angles_deg)
    return fitted, fitted.predict(protocol.validation.volts)


def assess(model, protocol):
    """Fit a calibration model to a protocol's data and measure its validation error.

    The error of the fit to the recorded data (:func:`validation_error`), the model's own
    misfit (fitted and validated without noise) and the difference of the two.

    Parameters
    ----------
    model : Eq5, Eq6 or Polynomial
        Unfitted template (cloned, not modified).
    protocol : Protocol

    Returns
    -------
    CalibrationResult
    """
    cal, val, span = protocol.calibration, protocol.validation, protocol.span_deg
    fitted, estimate = _fit_and_estimate(model, protocol)
    clean = model.clone().fit(cal.volts_true, cal.angles_deg)
    clean_estimate = clean.predict(val.volts_true)
    return CalibrationResult(
        model=fitted,
        total=ErrorStats.of(estimate - val.angles_deg, span),
        misfit=ErrorStats.of(clean_estimate - val.angles_deg, span),
        noise=ErrorStats.of(estimate - clean_estimate, span),
        protocol=protocol,
    )


def simulate_calibration(design, model="eq6", fit="lsq", **protocol_options):
    """Simulate calibrating one unit of ``design`` and predict its estimation error.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    model : str or calibration model
        ``"eq5"``, ``"eq6"``, ``"polyN"``, or an unfitted model instance (then ``fit`` is
        ignored).
    fit : {"lsq", "huber", "minimax"}
    **protocol_options
        ``step_deg``, ``n_validation``, ``seed``, ``mismatch``, ``drift``
        (see :func:`run_protocol`).

    Returns
    -------
    CalibrationResult
    """
    template = make_model(model, fit) if isinstance(model, str) else model
    return assess(template, run_protocol(design, **protocol_options))
