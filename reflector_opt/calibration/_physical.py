"""Physical calibration: a few parameters of the forward model fitted per unit, then inverted.

Instead of a polynomial from voltages to angles, :class:`PhysicalModel` fits the design's own
forward model (:func:`reflector_opt.model._forward.voltages`) to a unit's calibration data,
freeing the parameters in which built units differ most (:data:`PARAMETERS`): each sensor's
gain and offset, the reflector centre's offset (x, y, z), each sensor's optical-axis tilt
about the two directions across it (:func:`reflector_opt.model._geometry.tilted_axis`) and the
surface's specular fraction. The fit is :func:`scipy.optimize.least_squares` on the voltage
residuals in units of σ_V, started from the nominal design.

Angles are estimated by inverting the fitted model at every sample: Gauss–Newton on
``V(γ, α) = v`` (the 2 × 2 normal equations of every sample solved at once, the Jacobian by
central differences, :func:`reflector_opt.analysis._jacobian.values_and_jacobian`), started
from a cubic polynomial fitted to the same calibration data. Each estimate's covariance is
σ_V² (JᵀJ)⁻¹ at the solution (the Cramér–Rao bound of the fitted model at that pose,
:func:`reflector_opt.analysis._resolution.crlb_deg`).
"""

import functools
from dataclasses import replace

import numpy as np

from reflector_opt.calibration._models import Estimator, check_sample_pairs, make_model
from reflector_opt.model._geometry import tilted_axis
from reflector_opt.util._errors import FitError, InputError

#: Fitted parameters, in vector order, and their nominal values (two sensors).
PARAMETERS = (
    ("gain_1", 1.0),
    ("gain_2", 1.0),
    ("offset_1_v", 0.0),
    ("offset_2_v", 0.0),
    ("centre_x_mm", 0.0),
    ("centre_y_mm", 0.0),
    ("centre_z_mm", 0.0),
    ("tilt_1u_deg", 0.0),
    ("tilt_1w_deg", 0.0),
    ("tilt_2u_deg", 0.0),
    ("tilt_2w_deg", 0.0),
    ("specular_fraction", None),  # nominal: the design's
)

#: Typical sizes of the parameters (``x_scale`` of the fit).
_SCALES = np.array([0.02, 0.02, 0.01, 0.01, 0.05, 0.05, 0.05, 1.0, 1.0, 1.0, 1.0, 0.05])

#: Relative step of the fit's forward differences (least_squares' own for "2-point").
_STEP = float(np.sqrt(np.finfo(float).eps))

#: Gauss–Newton iterations of the inversion and the margin (degrees) the estimates may leave
#: the workspace by.
GAUSS_NEWTON_ITERATIONS = 8
MARGIN_DEG = 2.0

#: Grid step of the clearance check of the fit's trial designs, degrees.
CHECK_STEP_DEG = 5.0

#: The polynomial fitted to the calibration data to start the inversion.
WARM_START = "poly3"


class PhysicalModel(Estimator):
    """A unit's calibration as a fitted forward model, inverted per sample.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
        The nominal design (two sensors).

    Attributes
    ----------
    params_ : dict
        Fitted :data:`PARAMETERS` (after :meth:`fit`).
    warm_start_ : Polynomial
        The polynomial that starts the inversion.
    n_samples_ : int
    training_rms_v_ : numpy.ndarray
        RMS voltage residual of the fit per sensor, V.
    """

    name = "physical"

    def __init__(self, design):
        self.design = design

    def __repr__(self):
        return "PhysicalModel(design=...)"

    def _check_params(self):
        if len(self.design.sensors) != 2:
            raise InputError("physical calibration: the design must have exactly two sensors")

    @property
    def _working(self):
        """The design whose trial variants the fit builds, its workspace on a coarse grid.

        The trial designs are validated on that grid (the step does not enter the voltages;
        the design's own grid check already passed). Kept for the design it was made of:
        ``set_params(design=...)`` makes it anew.
        """
        design, working = getattr(self, "_working_for", (None, None))
        if design is not self.design:
            grid = replace(self.design.workspace, step_deg=CHECK_STEP_DEG)
            working = self.design.replace(workspace=grid)
            self._working_for = (self.design, working)
        return working

    @property
    def nominal(self):
        """The parameter vector of the nominal design."""
        return np.array(
            [self.design.reflector.specular_fraction if v is None else v for _, v in PARAMETERS]
        )

    def unit_design(self, x):
        """The design with parameter vector ``x``'s geometry and surface (not gain/offset).

        Its workspace step is :data:`CHECK_STEP_DEG` (only the clearance check uses it).
        """
        reflector = self._working.reflector
        centre = tuple((np.asarray(reflector.centre_mm) + x[4:7]).tolist())
        sensors = tuple(
            replace(s, axis=tilted_axis(s.axis, x[7 + 2 * i : 9 + 2 * i]))
            for i, s in enumerate(self._working.sensors)
        )
        fraction = float(np.clip(x[11], 0.0, 1.0))
        return self._working.replace(
            reflector=replace(reflector, centre_mm=centre, specular_fraction=fraction),
            sensors=sensors,
        )

    def _volts(self, x, pitch, roll, unit=None):
        from reflector_opt.model._forward import voltages  # numba: imported when first needed

        unit = self.unit_design(x) if unit is None else unit
        return voltages(unit, pitch, roll) * x[0:2] + x[2:4]

    def fit(self, voltages, angles):
        """Fit the physical parameters to calibration samples.

        Parameters
        ----------
        voltages : array_like
            Shape (n_samples, 2), V.
        angles : array_like
            Shape (n_samples, 2): reference pitch and roll, degrees.

        Returns
        -------
        self
        """
        self._check_params()
        V, A = check_sample_pairs(voltages, angles, "physical")
        if 2 * len(V) < 2 * len(PARAMETERS):
            raise InputError(
                f"physical: {len(V)} samples are too few for {len(PARAMETERS)} parameters "
                f"(at least {len(PARAMETERS)})"
            )
        from scipy.optimize import least_squares

        lower = np.full(len(PARAMETERS), -np.inf)
        upper = np.full(len(PARAMETERS), np.inf)
        lower[11], upper[11] = 0.0, 1.0
        start = np.clip(self.nominal, lower, upper)
        residual, jacobian = fit_residual(self, V, A, (lower, upper))
        try:
            result = least_squares(
                residual, start, jac=jacobian, x_scale=_SCALES, bounds=(lower, upper)
            )
        except (ValueError, np.linalg.LinAlgError) as exc:
            raise FitError(f"physical fit failed: {exc}") from None
        if not result.success:
            raise FitError(f"physical fit did not converge: {result.message}")
        self.set_fitted(result.x, make_model(WARM_START).fit(V, A), len(V))
        residuals = self._volts(self.x_, A[:, 0], A[:, 1], self.unit_) - V
        self.training_rms_v_ = np.sqrt(np.mean(residuals**2, axis=0))
        return self

    def set_fitted(self, x, warm_start, n_samples):
        """Set the fitted state: parameter vector, warm-start polynomial, sample count.

        Used by :meth:`fit` and to rebuild a model from its file
        (:mod:`~reflector_opt.calibration._coefficients`).
        """
        self._check_params()
        self.x_ = np.asarray(x, dtype=float)
        self.params_ = {name: float(v) for (name, _), v in zip(PARAMETERS, self.x_, strict=True)}
        self.unit_ = self.unit_design(self.x_)
        self.warm_start_ = warm_start
        self.n_samples_ = int(n_samples)
        return self

    def predict(self, voltages, return_cov=False):
        """Pitch and roll from voltages, by inverting the fitted model at every sample.

        Parameters
        ----------
        voltages : array_like
            Shape ``P + (2,)``, V.
        return_cov : bool
            Also return each estimate's covariance σ_V² (JᵀJ)⁻¹, deg², shape ``P + (2, 2)``.

        Returns
        -------
        numpy.ndarray or (numpy.ndarray, numpy.ndarray)
            Shape ``P + (2,)``: pitch, roll in degrees (and the covariances).
        """
        self._check_fitted()
        model = functools.partial(self._volts, self.x_, unit=self.unit_)  # (pitch, roll) -> V
        sigma_v = self.design.noise.total_sigma_v
        return invert_model(
            model, voltages, self.warm_start_, self.design.workspace, sigma_v, return_cov
        )


def fit_residual(model, V, A, bounds):
    """The residual ``(V(x) − V) / σ_V`` (flattened) of a :class:`PhysicalModel`'s fit and its
    Jacobian, for :func:`scipy.optimize.least_squares`.

    The gains and offsets enter linearly, ``V(x) = g · V₀(x) + o``, so their columns are
    exact: ``V₀ / σ_V`` and ``1 / σ_V``. The other columns are forward differences with
    the step least_squares takes itself (``√ε · max(1, |x|)``, away from a bound it would
    cross), from ``V₀(x)`` kept from the residual just evaluated at the same ``x``: 8
    forward-model runs per Jacobian instead of 12.

    Parameters
    ----------
    model : PhysicalModel
        Gives the trial designs (:meth:`PhysicalModel.unit_design`) and σ_V.
    V, A : numpy.ndarray
        Shape (n, 2) each: the recorded voltages, V, and the reference angles, degrees.
    bounds : (numpy.ndarray, numpy.ndarray)
        Lower and upper bounds of the parameters (:data:`PARAMETERS` order).

    Returns
    -------
    (callable, callable)
        ``residual(x)``, shape (2n,), and ``jacobian(x)``, shape (2n, 12).
    """
    from reflector_opt.model._forward import voltages  # numba: imported when first needed

    sigma = model.design.noise.total_sigma_v
    last = {"x": None}

    def clean(x):
        if last["x"] is None or not np.array_equal(last["x"], x):
            last["x"] = np.array(x)
            last["v0"] = voltages(model.unit_design(x), A[:, 0], A[:, 1])
        return last["v0"]

    def residual(x):
        return ((clean(x) * x[0:2] + x[2:4] - V) / sigma).ravel()

    def jacobian(x):
        v0 = clean(x)
        jac = np.empty((V.size, len(PARAMETERS)))
        for k in range(2):  # rows k, k + 2, …: sensor k's residuals
            jac[:, k] = jac[:, 2 + k] = 0.0
            jac[k::2, k] = v0[:, k] / sigma
            jac[k::2, 2 + k] = 1.0 / sigma
        for j in range(4, len(PARAMETERS)):
            h = _STEP * (1.0 if x[j] >= 0 else -1.0) * max(1.0, abs(x[j]))
            if not bounds[0][j] <= x[j] + h <= bounds[1][j]:
                h = -h
            moved = x.copy()
            moved[j] += h
            step = moved[j] - x[j]  # the step as represented
            v = voltages(model.unit_design(moved), A[:, 0], A[:, 1])
            jac[:, j] = ((v - v0) * x[0:2] / (sigma * step)).ravel()
        return jac

    return residual, jacobian


def invert_model(model, voltages, warm_start, workspace, sigma_v, return_cov=False):
    """Pitch and roll from voltages by inverting a forward model at every sample.

    Gauss–Newton on ``model(γ, α) = v`` (the 2 × 2 normal equations of every sample solved
    at once, the Jacobian by central differences), started from ``warm_start``'s estimate
    and kept within :data:`MARGIN_DEG` of the workspace.

    Parameters
    ----------
    model : callable
        ``model(pitch_deg, roll_deg)`` → voltages with the two sensors on the last axis, V.
    voltages : array_like
        Shape ``P + (2,)``, V.
    warm_start : object
        A fitted calibration model whose ``predict`` gives the starting angles.
    workspace : reflector_opt.design._components.Workspace
    sigma_v : float
        Voltage noise, V (for the covariance).
    return_cov : bool
        Also return each estimate's covariance σ_V² (JᵀJ)⁻¹, deg², shape ``P + (2, 2)``.

    Returns
    -------
    numpy.ndarray or (numpy.ndarray, numpy.ndarray)
        Shape ``P + (2,)``: pitch, roll in degrees (and the covariances).
    """
    from reflector_opt.analysis._jacobian import values_and_jacobian  # numba, when needed

    V = np.asarray(voltages, dtype=float)
    if V.shape[-1:] != (2,):
        raise InputError(f"voltages: the last axis must hold v1, v2, got shape {V.shape}")
    shape = V.shape[:-1]
    v = V.reshape(-1, 2)
    lo, hi = workspace.bounds(MARGIN_DEG)
    theta = np.clip(warm_start.predict(v), lo, hi)
    for _ in range(GAUSS_NEWTON_ITERATIONS):
        values, jac = values_and_jacobian(model, theta[:, 0], theta[:, 1])
        normal = np.einsum("nki,nkj->nij", jac, jac)
        gradient = np.einsum("nki,nk->ni", jac, v - values)
        step = np.linalg.solve(normal, gradient[..., None])[..., 0]
        theta = np.clip(theta + step, lo, hi)
    estimate = theta.reshape((*shape, 2))
    if not return_cov:
        return estimate
    _, jac = values_and_jacobian(model, theta[:, 0], theta[:, 1])
    normal = np.einsum("nki,nkj->nij", jac, jac)
    cov = sigma_v**2 * np.linalg.inv(normal)
    return estimate, cov.reshape((*shape, 2, 2))
