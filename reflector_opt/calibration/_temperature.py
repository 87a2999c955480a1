"""Temperature compensation: voltages mapped back to the calibration temperature, then the form.

A unit's light path drifts with temperature (LED output, drive current, detector gain:
:mod:`reflector_opt.model._temperature`): the collector current, Vcc − V, scales with it, and
the dark current adds an offset. To first order in ΔT = T − T0, sensor k reads

    V(T) = Vcc − (Vcc − V(T0)) · (1 + c_k ΔT + q_k ΔT²) − d_k ΔT              (1)

with c_k its relative gain change per kelvin, q_k its curvature per kelvin squared (``degree``
2; 0 with the default ``degree`` 1) and d_k its offset change, V per kelvin. Vcc is
the pivot where no light falls: the sensor's supply (3.3 V in the default circuit,
:mod:`reflector_opt.model._electronics`). A read-out gain g and offset o after the sensor move
the pivot to g·Vcc + o; (1) keeps its form, with g·d_k + (g·Vcc + o − Vcc)·c_k for d_k.
With data at exactly two temperatures, (1) holds there exactly whatever the higher-order
terms, for a calibration form that absorbs an affine change of each voltage (Eq 6, polyN);
a curved light path (the dome-shaped curves of relative output against temperature,
:class:`~reflector_opt.model._temperature.ThermalCoefficients` ``output_per_k2``) between
and beyond them needs q_k, and so data at three temperatures at least (T0 − R, T0, T0 + R).
:func:`compensate` inverts (1) exactly,

    V0 = Vcc − (Vcc − V − d_k ΔT) / (1 + c_k ΔT + q_k ΔT²),                   (2)

and :class:`TemperatureCompensated` applies any calibration form (Eq 5, Eq 6, polyN, or the
one ``auto`` chooses) to V0.

**Fit.** c_k and d_k of every sensor are fitted jointly with the form's coefficients by
variable projection (Golub and Pereyra, SIAM J. Numer. Anal. 10 (1973) 413–432): an outer
nonlinear least squares over the 2 × n_sensors thermal parameters
(:func:`scipy.optimize.least_squares`), whose residual is that of the form's linear least
squares on the compensated voltages (:func:`fit_thermal`). The residual pairs (pitch, roll)
are whitened by their 2 × 2 covariance, estimated from a first pass: the errors of the two
angles come from the same voltage noise and are correlated. Each parameter's standard
deviation is from the Jacobian J of the projected residuals at the solution,
cov = s² (JᵀJ)⁻¹ with s² the residual variance per degree of freedom; projecting out the
form's coefficients accounts for their correlation with the thermal parameters. The
reference temperature T0 is the mean of the calibration temperatures (or given). The form's
own fit (Huber, minimax) is then made on the compensated voltages; the thermal parameters are
always least squares.

The data need two or more temperatures at least :data:`MIN_SPAN_K` apart (three or more
distinct ones for ``degree`` 2). A temperature is one per sample (one thermometer for the
unit) or one per sample and sensor (a thermometer at each sensor: ΔT of (1) is then each
sensor's own, which removes a gradient along the strip that the calibration did not see).
"""

from typing import NamedTuple

import numpy as np

from reflector_opt.calibration._estimators import make_estimator, selected
from reflector_opt.calibration._models import Estimator, check_sample_pairs
from reflector_opt.calibration._physical import PhysicalModel
from reflector_opt.calibration._selection import AutoModel
from reflector_opt.calibration._terms import input_normalisation, monomials
from reflector_opt.util._errors import FitError, InputError

#: The smallest spread of calibration temperatures that determines the thermal parameters, K.
MIN_SPAN_K = 1.0

#: A temperature above this, °C, is taken for kelvin (293 K is 20 °C).
KELVIN_LIKE_C = 150.0

#: The lowest plausible operating temperature, °C.
MIN_TEMPERATURE_C = -60.0

#: The pivot Vcc without a design: the supply of the default circuit, V.
DEFAULT_SUPPLY_V = 3.3

#: Thermal parameters are fitted in these units (per mille per K, mV/K, 10⁻⁵ per K²): of
#: order one.
_UNIT = 1e-3
_UNIT2 = 1e-5

#: Singular values of the Jacobian below this fraction of the largest: not determined.
RANK_RTOL = 1e-8


def check_temperature_c(value, where, given=None):
    """One temperature in °C, refused (InputError naming ``where``) if implausible.

    Parameters
    ----------
    value : float
        °C.
    where : str
        The field, for the message (``"data.csv, line 4: column temperature_c"``).
    given : str, optional
        The value as written, for the message.

    Returns
    -------
    float
    """
    shown = value if given is None else given
    if not np.isfinite(value):
        raise InputError(f"{where}: {shown} is not finite")
    if value > KELVIN_LIKE_C:
        raise InputError(
            f"{where}: {shown} looks like kelvin; give degrees Celsius (at most "
            f"{KELVIN_LIKE_C:g} °C)"
        )
    if value < MIN_TEMPERATURE_C:
        raise InputError(
            f"{where}: {shown} °C is below {MIN_TEMPERATURE_C:g} °C, not an operating temperature"
        )
    return float(value)


def check_temperatures(values, n_samples=None, n_sensors=None):
    """Temperatures (°C) as a float array, each checked by :func:`check_temperature_c`.

    Parameters
    ----------
    values : array_like
        °C.
    n_samples : int, optional
        The number of samples they must match: shape (n_samples,), one per sample, or
        (n_samples, n_sensors), one per sample and sensor.
    n_sensors : int, optional
        The sensors, for the second shape.

    Returns
    -------
    numpy.ndarray
    """
    if values is None:
        raise InputError("temperature_c: missing; a compensated calibration needs the temperatures")
    t = np.asarray(values, dtype=float)
    if n_samples is not None and t.shape not in ((n_samples,), (n_samples, n_sensors)):
        raise InputError(
            f"temperature_c: expected {n_samples} values (or {n_samples} × {n_sensors}, one "
            f"per sensor), got shape {t.shape}"
        )
    bad = ~(np.isfinite(t) & (t <= KELVIN_LIKE_C) & (t >= MIN_TEMPERATURE_C))
    if bad.any():
        i = int(np.flatnonzero(bad.ravel())[0])
        check_temperature_c(t.ravel()[i], f"temperature_c: sample {i}")
    return t


def compensate(volts, delta_t_k, gain_per_k, offset_v_per_k, supply_v, gain_per_k2=0.0):
    """Voltages at the reference temperature from those at T0 + ΔT: Eq (2) of the module notes.

    V0 = Vcc − (Vcc − V − d_k ΔT) / (1 + c_k ΔT + q_k ΔT²), the exact inverse of
    V = Vcc − (Vcc − V0)(1 + c_k ΔT + q_k ΔT²) − d_k ΔT.

    Parameters
    ----------
    volts : array_like
        Shape ``P + (n_sensors,)``, V.
    delta_t_k : array_like
        T − T0, K: shape ``P`` (one for the sensors) or ``P + (n_sensors,)`` (each its own).
    gain_per_k : array_like
        c_k, relative change of each sensor's collector current per K, shape (n_sensors,).
    offset_v_per_k : array_like
        d_k, V/K, shape (n_sensors,).
    supply_v : array_like
        Vcc of each sensor, V.
    gain_per_k2 : array_like
        q_k, 1/K², shape (n_sensors,) (0: linear in ΔT).

    Returns
    -------
    numpy.ndarray
        Shape ``P + (n_sensors,)``, V. Raises InputError naming ``temperature_c`` where
        1 + c_k ΔT + q_k ΔT² ≤ 0 (a temperature far outside the calibration's).
    """
    v = np.asarray(volts, dtype=float)
    dt = np.asarray(delta_t_k, dtype=float)
    dt = dt if dt.shape == v.shape else dt[..., None]
    factor = 1.0 + np.asarray(gain_per_k, dtype=float) * dt + np.asarray(gain_per_k2) * dt**2
    if not np.all(factor > 0.0):
        raise InputError(
            "temperature_c: a temperature so far from the calibration's that the fitted gain "
            "change reverses the light (1 + c·ΔT + q·ΔT² ≤ 0)"
        )
    vcc = np.asarray(supply_v, dtype=float)
    return vcc - (vcc - v - offset_v_per_k * dt) / factor


class ThermalFit(NamedTuple):
    """The thermal parameters of :func:`fit_thermal`, each of shape (n_sensors,)."""

    #: c_k, 1/K, and its standard deviation.
    gain_per_k: np.ndarray
    gain_per_k_std: np.ndarray
    #: d_k, V/K, and its standard deviation.
    offset_v_per_k: np.ndarray
    offset_v_per_k_std: np.ndarray
    #: q_k, 1/K², and its standard deviation (None: linear in ΔT, ``degree`` 1).
    gain_per_k2: np.ndarray | None = None
    gain_per_k2_std: np.ndarray | None = None

    def compensate(self, volts, delta_t_k, supply_v):
        """:func:`compensate` with these parameters."""
        q = 0.0 if self.gain_per_k2 is None else self.gain_per_k2
        return compensate(volts, delta_t_k, self.gain_per_k, self.offset_v_per_k, supply_v, q)


def _thermal_fit(x, std, s):
    """A :class:`ThermalFit` from the fitted (c, d[, q]) in their own units and their std."""
    units = np.r_[np.full(2 * s, _UNIT), np.full(len(x) - 2 * s, _UNIT2)]
    x, std = x * units, std * units
    quadratic = (x[2 * s :], std[2 * s :]) if len(x) > 2 * s else (None, None)
    return ThermalFit(x[:s], std[:s], x[s : 2 * s], std[s : 2 * s], *quadratic)


def _projected(volts, angles, dt, x, form, supply_v):
    """Residuals (n, 2) of the form's least squares on the voltages compensated with ``x``."""
    s = volts.shape[1]
    w = _thermal_fit(x, x, s).compensate(volts, dt, supply_v)
    centre, scale = input_normalisation(w, form.centred)
    design = monomials((w - centre) / scale, form.terms)
    coef = np.linalg.lstsq(design, angles, rcond=None)[0]
    return design @ coef - angles


def _whitener(residuals, dof):
    """The 2 × 2 matrix that decorrelates the residual pairs and scales them to unit variance
    (the identity for residuals without a covariance: a fit to noise-free data)."""
    try:
        return np.linalg.inv(np.linalg.cholesky(residuals.T @ residuals / dof)).T
    except np.linalg.LinAlgError:
        return np.eye(residuals.shape[1])


def _two_passes(volts, angles, delta_t_k, form, supply_v, bounds, dof):
    """The outer least squares, then again whitened by its residuals: the second result."""
    from scipy.optimize import least_squares

    x, white = np.zeros(len(bounds[0])), np.eye(2)
    for _ in range(2):
        result = least_squares(
            lambda x, white=white: (
                _projected(volts, angles, delta_t_k, x, form, supply_v) @ white
            ).ravel(),
            x,
            bounds=bounds,
            diff_step=1e-7,
        )
        x = result.x
        white = _whitener(_projected(volts, angles, delta_t_k, x, form, supply_v), dof)
    return result


def fit_thermal(volts, angles, delta_t_k, form, supply_v, degree=1):
    """Fit each sensor's c_k and d_k (and q_k) jointly with a form's coefficients (module
    notes).

    Parameters
    ----------
    volts, angles : numpy.ndarray
        Shape (n, n_sensors) V and (n, 2) degrees, checked.
    delta_t_k : numpy.ndarray
        Shape (n,) or (n, n_sensors): each sample's T − T0 (each sensor's), K.
    form : Eq5, Eq6 or Polynomial
        The form (its ``terms`` and ``centred``); least squares whatever its ``fit``.
    supply_v : numpy.ndarray
        Vcc of each sensor, V.
    degree : {1, 2}
        The gain change's degree in ΔT (2: with q_k).

    Returns
    -------
    ThermalFit
        Raises FitError naming ``temperature_c`` if the data do not determine them.
    """
    from threadpoolctl import threadpool_limits

    s = volts.shape[1]
    dof = 2 * (len(volts) - len(form.terms)) - (1 + degree) * s
    if dof <= 0:
        raise FitError(f"temperature_c: {len(volts)} samples are too few for {form.name}")
    span = max(np.abs(delta_t_k).max(), 1.0)
    # keeps 1 + c·ΔT + q·ΔT² ≥ 0.5 (each term at most a quarter, or a half alone)
    limit = np.r_[np.full(s, 0.5 / (_UNIT * span)), np.full(s, np.inf)]
    if degree == 2:
        limit = np.r_[limit[:s] / 2, limit[s:], np.full(s, 0.25 / (_UNIT2 * span**2))]
    bounds = (-limit, limit)
    with threadpool_limits(limits=1):  # many small least squares: threads only contend
        result = _two_passes(volts, angles, delta_t_k, form, supply_v, bounds, dof)
    singular = np.linalg.svd(result.jac, compute_uv=False)
    if not np.all(np.isfinite(singular)) or singular[-1] <= RANK_RTOL * singular[0]:
        raise FitError(
            "temperature_c: the samples away from the reference temperature do not determine "
            "each sensor's gain and offset change; record more poses there"
        )
    cov = np.linalg.inv(result.jac.T @ result.jac) * (2.0 * result.cost / dof)
    return _thermal_fit(result.x, np.sqrt(np.diag(cov)), s)


def _template(form):
    """An unfitted form from a name or an estimator; the physical model is refused."""
    if isinstance(form, str):
        if form.strip().lower() == PhysicalModel.name:
            raise InputError("form: temperature compensation takes eq5, eq6, polyN or auto")
        return make_estimator(form)
    if not isinstance(form, AutoModel) and not hasattr(form, "terms"):
        raise InputError(
            f"form: temperature compensation takes eq5, eq6, polyN or auto, not "
            f"{getattr(form, 'name', type(form).__name__)}"
        )
    return form.clone()


def _supply(supply_v, n_sensors):
    """Vcc of each sensor, V: one value for all, or one each."""
    vcc = np.broadcast_to(np.asarray(supply_v, dtype=float), (n_sensors,)).copy()
    if not np.all((vcc > 0.0) & (vcc <= 1e3)):
        raise InputError(f"supply_v: expected positive volts (at most 1000 V), got {supply_v}")
    return vcc


def _spanning(temperature_c, degree):
    """The temperatures, refused unless they span :data:`MIN_SPAN_K` (and, for ``degree`` 2,
    hold three temperatures at least :data:`MIN_SPAN_K` apart)."""
    low, high = temperature_c.min(), temperature_c.max()
    if high - low < MIN_SPAN_K:
        raise InputError(
            f"temperature_c: the samples span {high - low:.3g} K ({low:g} to {high:g} °C); "
            f"compensation needs two or more temperatures at least {MIN_SPAN_K:g} K apart"
        )
    mean = temperature_c.reshape(len(temperature_c), -1).mean(axis=1)
    between = (mean - low >= MIN_SPAN_K) & (high - mean >= MIN_SPAN_K)
    if degree == 2 and not between.any():
        raise InputError(
            f"temperature_c: a gain curved in T (degree 2) needs three temperatures at least "
            f"{MIN_SPAN_K:g} K apart; the samples are at {low:g} and {high:g} °C only"
        )
    return temperature_c


def _fit_form_and_thermal(template, volts, angles, delta_t_k, supply_v, degree):
    """The fitted form on the compensated voltages and the :class:`ThermalFit`.

    The form is first fitted as it is (its own checks of the data; ``auto``'s first choice),
    the thermal parameters with it, ``auto`` chooses again on the compensated voltages and
    the thermal parameters are fitted once more with that choice.
    """
    form = selected(template.clone().fit(volts, angles))
    thermal = fit_thermal(volts, angles, delta_t_k, form, supply_v, degree)
    if isinstance(template, AutoModel):
        w = thermal.compensate(volts, delta_t_k, supply_v)
        form = template.clone().fit(w, angles).selected_
        thermal = fit_thermal(volts, angles, delta_t_k, form, supply_v, degree)
    return form.clone().fit(thermal.compensate(volts, delta_t_k, supply_v), angles), thermal


class TemperatureCompensated(Estimator):
    """A calibration form applied to voltages mapped back to the reference temperature.

    scikit-learn style (module notes for the physics and the fit): ``fit(voltages, angles,
    temperature_c)`` and ``predict(voltages, temperature_c)``.

    Parameters
    ----------
    form : str or estimator
        ``"eq5"``, ``"eq6"``, ``"polyN"`` or ``"auto"``, or such an unfitted model.
    supply_v : float or sequence of float
        Vcc, the pivot of each sensor, V (default the default circuit's 3.3 V).
    reference_temperature_c : float, optional
        T0, °C; default the mean of the calibration temperatures.
    degree : {1, 2}
        The gain change's degree in ΔT: 2 fits each sensor's curvature q_k too (Eq 1; data at
        three temperatures at least).

    Attributes
    ----------
    form_ : Eq5, Eq6 or Polynomial
        The form fitted to the compensated voltages (the one ``auto`` chose).
    reference_temperature_c_ : float
    supply_v_ : numpy.ndarray
    gain_per_k_, gain_per_k_std_ : numpy.ndarray
        c_k per sensor and its standard deviation, 1/K.
    offset_v_per_k_, offset_v_per_k_std_ : numpy.ndarray
        d_k per sensor and its standard deviation, V/K.
    gain_per_k2_ : numpy.ndarray or None
        q_k per sensor, 1/K² (None for ``degree`` 1).
    thermal_ : ThermalFit
        The parameters above together, with the std of q_k.
    temperature_range_c_ : numpy.ndarray
        Lowest and highest calibration temperature, °C.
    n_samples_ : int
    """

    def __init__(
        self, form="eq6", *, supply_v=DEFAULT_SUPPLY_V, reference_temperature_c=None, degree=1
    ):
        self.form = form
        self.supply_v = supply_v
        self.reference_temperature_c = reference_temperature_c
        self.degree = degree

    @property
    def name(self):
        """The form's name (the chosen one once fitted)."""
        if hasattr(self, "form_"):
            return self.form_.name
        return self.form if isinstance(self.form, str) else self.form.name

    def fit(self, voltages, angles, temperature_c):
        """Fit the thermal parameters and the form (module notes).

        Parameters
        ----------
        voltages : array_like
            Shape (n, 2), V.
        angles : array_like
            Shape (n, 2): reference pitch and roll, degrees.
        temperature_c : array_like
            Shape (n,): each sample's temperature, or (n, 2): each sensor's, °C; at least
            :data:`MIN_SPAN_K` apart.

        Returns
        -------
        self
        """
        if self.degree not in (1, 2):
            raise InputError(f"degree: 1 or 2 (the gain change's degree in ΔT), got {self.degree}")
        V, A = check_sample_pairs(voltages, angles, "temperature-compensated fit")
        T = _spanning(check_temperatures(temperature_c, len(V), V.shape[1]), self.degree)
        t0 = self.reference_temperature_c
        t0 = float(T.mean()) if t0 is None else check_temperature_c(t0, "reference_temperature_c")
        supply = _supply(self.supply_v, V.shape[1])
        form, thermal = _fit_form_and_thermal(
            _template(self.form), V, A, T - t0, supply, self.degree
        )
        return self.set_fitted(form, t0, supply, thermal, (T.min(), T.max()))

    def set_fitted(self, form, reference_c, supply_v, thermal, range_c):
        """Set the fitted state (a fit, or a coefficient file): a fitted form, T0 (°C), Vcc
        (V), a :class:`ThermalFit` and the calibration's temperature range (°C)."""
        self.form_, self.n_samples_ = form, form.n_samples_
        self.reference_temperature_c_ = float(reference_c)
        self.supply_v_ = np.asarray(supply_v, dtype=float)
        self.thermal_ = ThermalFit(
            *(None if v is None else np.asarray(v, dtype=float) for v in thermal)
        )
        self.gain_per_k_, self.gain_per_k_std_ = self.thermal_[:2]
        self.offset_v_per_k_, self.offset_v_per_k_std_ = self.thermal_[2:4]
        self.gain_per_k2_ = self.thermal_.gain_per_k2
        self.temperature_range_c_ = np.asarray(range_c, dtype=float)
        return self

    def fixed_form(self):
        """An unfitted copy whose form is the fitted one (the form ``auto`` chose, fixed)."""
        self._check_fitted()
        return type(self)(**{**self.get_params(deep=False), "form": self.form_.clone()})

    def compensated(self, voltages, temperature_c):
        """The voltages mapped back to the reference temperature (Eq 2), V, shape of
        ``voltages`` (``P + (2,)``); ``temperature_c`` (°C) of shape ``P``, or of the
        voltages' shape (each sensor's)."""
        self._check_fitted()
        dt = check_temperatures(temperature_c) - self.reference_temperature_c_
        return self.thermal_.compensate(voltages, dt, self.supply_v_)

    def predict(self, voltages, temperature_c):
        """Pitch and roll, degrees (shape ``P + (2,)``), from voltages (V, ``P + (2,)``) at
        temperatures (°C, shape ``P``, or one for all)."""
        compensated = self.compensated(voltages, temperature_c)  # refused before fit()
        return self.form_.predict(compensated)
