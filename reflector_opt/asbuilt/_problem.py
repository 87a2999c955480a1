"""The identification problem: weighted residuals of a batch's data and their Jacobian.

For a parameter vector x (:class:`~reflector_opt.asbuilt._parameters.ParameterLayout`) the residuals
are, per unit, the calibration voltages' misfit ``(V_model − V) / σ_eff`` (the design's
forward model, :func:`reflector_opt.model._forward.voltages`, with the unit's gain and
offset), the misfit of each sensor's flat-target curve measured before assembly (if given,
:func:`reflector_opt.model._optics.flat_target_coupling` against a target of the reflector's
material, through the same gain and offset), and the prior ``x / σ_prior``. Minimising
their sum of squares is the MAP estimate under Gaussian noise and priors.

σ_eff of each sample and sensor adds, to the design's voltage noise with quantisation, the
angle reference's noise carried through the unit's slope:
``σ_eff² = σ_V² + σ_ref² (∂V/∂γ² + ∂V/∂α²)`` (errors in the poses, to first order). With
reference parameters the model is evaluated at the true poses of the readings
(:meth:`~reflector_opt.asbuilt._parameters.ParameterLayout.true_angles`). With the batch's spread ℓ
the diffuse part is spread (:func:`~reflector_opt.asbuilt._spread.spread_voltages`); with
model-form terms (:class:`~reflector_opt.asbuilt._model_form_terms.ModelFormTerms`) their bias
and the unit's amplitudes times their signatures are added to the model's voltages.

The Jacobian is by central differences per unit block: a unit's residuals depend only on
the shared surface and its own block, so a batch of U units costs U × (2 × block + 4)
evaluations of the forward model, each about a millisecond for 200 poses. The forward
model's coupling is a Chebyshev interpolant in the pose, smooth in every parameter, so the
differences are accurate to about 1e-6 relative; an analytic Jacobian through the
quadrature of the surface coupling would be a second model to keep in step with the first.
"""

from dataclasses import dataclass, replace

import numpy as np

from reflector_opt.analysis._jacobian import voltage_jacobian
from reflector_opt.asbuilt._spread import spread_curve_volts, spread_voltages
from reflector_opt.util._errors import InputError

#: Grid step of the clearance check of the fit's trial designs, degrees (the voltages do
#: not depend on it; the design itself passed its own check).
CHECK_STEP_DEG = 5.0


@dataclass(frozen=True)
class Curve:
    """A sensor's flat-target curve, measured before assembly.

    Attributes
    ----------
    sensor : int
        Index of the sensor in the design (0-based).
    distance_mm : numpy.ndarray
        Sensor-to-target distances, mm.
    volts : numpy.ndarray
        Output voltages, V.
    """

    sensor: int
    distance_mm: np.ndarray
    volts: np.ndarray


@dataclass(frozen=True)
class UnitData:
    """One unit's calibration samples and optional flat-target curves.

    Attributes
    ----------
    label : str
        The unit's id in the data.
    volts : numpy.ndarray
        Shape (n, n_sensors), V.
    angles_deg : numpy.ndarray
        Shape (n, 2): the reference's pitch and roll, degrees.
    curves : tuple of Curve
    """

    label: str
    volts: np.ndarray
    angles_deg: np.ndarray
    curves: tuple = ()


class IdentificationProblem:
    """Residuals and Jacobian of the MAP identification of a batch.

    Parameters
    ----------
    layout : reflector_opt.asbuilt._parameters.ParameterLayout
    units : sequence of UnitData
    reference_sigma_deg : float
        RMS noise of the angle reference at each calibration pose, degrees.
    terms : reflector_opt.asbuilt._model_form_terms.ModelFormTerms, optional
        The model-form bias and signatures (amplitudes: the layout's ``model_form_names``).
    """

    def __init__(self, layout, units, reference_sigma_deg, terms=None):
        self.layout = layout
        self.units = tuple(units)
        design = layout.design
        self.working = design.replace(workspace=replace(design.workspace, step_deg=CHECK_STEP_DEG))
        self.sigma_v = design.noise.total_sigma_v
        self.prior_std = layout.prior_std()
        self.free = self.prior_std > 0
        self.steps = layout.steps()
        self.reference_sigma_deg = reference_sigma_deg
        self.terms = terms
        self.sigma_eff = [self._effective_sigma(u, reference_sigma_deg) for u in self.units]

    def _effective_sigma(self, data, reference_sigma_deg):
        slope = voltage_jacobian(self.layout.design, data.angles_deg[:, 0], data.angles_deg[:, 1])
        return np.sqrt(self.sigma_v**2 + reference_sigma_deg**2 * np.sum(slope**2, axis=-1))

    @property
    def n_data(self):
        """Number of data residuals (samples × sensors, plus curve points)."""
        return sum(u.volts.size + sum(c.volts.size for c in u.curves) for u in self.units)

    def misfit_v(self, x, u):
        """Model minus measured calibration voltages of unit ``u``, V, shape (n, sensors)."""
        return self._misfit_v(x, *self.layout.unit_design(x, u, self.working), u)

    def calibration_residuals(self, x, u):
        """Weighted misfit of unit ``u``'s calibration samples, flattened."""
        return (self.misfit_v(x, u) / self.sigma_eff[u]).ravel()

    def curve_residuals(self, x, u):
        """Weighted misfit of unit ``u``'s flat-target curves, concatenated (may be empty)."""
        if not self.units[u].curves:
            return np.zeros(0)
        return self._curve_residuals(x, *self.layout.unit_design(x, u, self.working), u)

    def unit_residuals(self, x, u):
        """Weighted data residuals of unit ``u`` (calibration samples, then its curves); the
        trial unit is built once for both."""
        built, mismatch = self.layout.unit_design(x, u, self.working)
        calibration = (self._misfit_v(x, built, mismatch, u) / self.sigma_eff[u]).ravel()
        if not self.units[u].curves:
            return calibration
        return np.r_[calibration, self._curve_residuals(x, built, mismatch, u)]

    def _misfit_v(self, x, built, mismatch, u):
        data = self.units[u]
        angles = self.layout.true_angles(x, u, data.angles_deg)
        spread = self.layout.subsurface_mm(x)
        model = mismatch.apply(spread_voltages(built, angles[:, 0], angles[:, 1], spread))
        if self.terms is not None:
            model = model + self.terms.volts(u, x[self.layout.model_form_slice(u)])
        return model - data.volts

    def _curve_residuals(self, x, built, mismatch, u):
        spread = self.layout.subsurface_mm(x)
        out = []
        for c, curve in enumerate(self.units[u].curves):
            model = _curve_volts(built, mismatch, curve, spread)
            if self.terms is not None:
                model = model + self.terms.curve_volts(u, c, x[self.layout.model_form_slice(u)])
            out.append((model - curve.volts) / self.sigma_v)
        return np.concatenate(out)

    def data_residuals(self, x):
        """Weighted data residuals of every unit, concatenated."""
        return np.concatenate([self.unit_residuals(x, u) for u in range(len(self.units))])

    def prior_residuals(self, x):
        """``x / σ_prior`` of the free parameters."""
        return x[self.free] / self.prior_std[self.free]

    def residuals(self, x):
        """Data residuals followed by the prior's."""
        return np.r_[self.data_residuals(x), self.prior_residuals(x)]

    def data_jacobian(self, x, central=True):
        """∂(data residuals)/∂x by central differences, block by block: (n_data, size).

        A unit's curves depend only on the surface and their sensors' read-out and emitter
        (:meth:`~reflector_opt.asbuilt._parameters.ParameterLayout.curve_indices`); the other
        columns
        of their rows are zero and not computed. Forward differences (``central=False``)
        halve the cost; the fit's iterations use them, the covariance central ones.
        """
        return np.vstack([_unit_jacobian(self, x, u, central) for u in range(len(self.units))])

    def jacobian(self, x, central=True, data_jacobian=None):
        """∂(all residuals)/∂x: the data block (``data_jacobian`` if already computed at x)
        over the prior's diagonal; the columns of fixed parameters are zero."""
        if data_jacobian is None:
            data_jacobian = self.data_jacobian(x, central)
        prior = np.diag(1.0 / np.where(self.free, self.prior_std, np.inf))[self.free]
        return np.vstack([data_jacobian, prior])

    def check_counts(self):
        """Refuse a unit with fewer samples than its parameters (amplitudes not counted)."""
        per_unit = self.free[self.layout.unit_indices(0)].sum() - len(self.layout.model_form_names)
        for data in self.units:
            if data.volts.size < per_unit:
                raise InputError(
                    f"unit {data.label}: {len(data.volts)} samples give {data.volts.size} "
                    f"voltages, fewer than the {per_unit} as-built parameters of a unit; "
                    f"record at least {-(-per_unit // data.volts.shape[1])} poses"
                )


def _curve_volts(built, mismatch, curve, spread):
    """The voltages the built unit's sensor gives on the flat-target curve's distances, V,
    the target's diffuse part spread by ``spread`` (mm, or None)."""
    reflector, sensor = built.reflector, built.models[curve.sensor]
    volts = spread_curve_volts(
        sensor, curve.distance_mm, reflector.reflectance, reflector.specular_fraction, spread
    )
    return mismatch.gain[curve.sensor] * volts + mismatch.offset_v[curve.sensor]


def _difference(residuals, x, u, j, h, base):
    """Difference of ``residuals(x, u)`` in parameter j with step h: central, or forward from
    ``base`` (the residuals at x) when it is given."""
    up = x.copy()
    up[j] += h
    if base is not None:
        return (residuals(up, u) - base) / h
    down = x.copy()
    down[j] -= h
    return (residuals(up, u) - residuals(down, u)) / (2 * h)


def _unit_jacobian(problem, x, u, central):
    """Rows of unit ``u``'s data residuals in :meth:`IdentificationProblem.data_jacobian`."""
    data, layout = problem.units[u], problem.layout
    n_curve = sum(c.volts.size for c in data.curves)
    columns = np.zeros((data.volts.size + n_curve, layout.size))
    curve_columns = layout.curve_indices(u, [c.sensor for c in data.curves])
    base = (None, None)
    if not central:
        base = (problem.calibration_residuals(x, u), problem.curve_residuals(x, u))
    form = layout.model_form_slice(u)
    for j in layout.unit_indices(u):
        if not problem.free[j]:
            continue
        if form.start <= j < form.stop:  # linear in the amplitude: its signature
            columns[:, j] = _form_column(problem, u, j - form.start)
            continue
        h = problem.steps[j]
        columns[: data.volts.size, j] = _difference(
            problem.calibration_residuals, x, u, j, h, base[0]
        )
        if n_curve and j in curve_columns:
            columns[data.volts.size :, j] = _difference(
                problem.curve_residuals, x, u, j, h, base[1]
            )
    return columns


def _form_column(problem, u, t):
    """∂(unit ``u``'s data residuals)/∂(its amplitude t): the signature over the noise."""
    terms, data = problem.terms, problem.units[u]
    calibration = (terms.signatures[u][t] / problem.sigma_eff[u]).ravel()
    curves = [terms.curve_signatures[u][c][t] / problem.sigma_v for c in range(len(data.curves))]
    return np.concatenate([calibration, *curves])
