"""A catalogue part's model from its datasheet figures, and the figures a model predicts.

Datasheets of reflective sensors publish a few figures measured against a flat target: the
distance of the output's peak, the range over which the output stays above a share of that
peak (Vishay: > 20 %), and the output current at a test condition (LED current, distance,
target). :func:`predicted_figures` computes the same figures from a
:class:`~reflector_opt.model._sensors.SensorModel` with the flat-target model
(:func:`~reflector_opt.model._optics.flat_target_coupling`, docs/model.md §2), and
:func:`fit_part` fits the model's source radius ω0, divergence θ, current gain G and — where the
datasheet does not state it — its emitter–detector offset e to them by least squares.

The figures fix the model only up to one direction: scaling e, ω0 and tan θ by k and G by k²
leaves a flat-target curve (nearly) unchanged (docs/model.md §5), and a part with only a peak
distance and a test current states two figures for four parameters. The fit therefore carries
weak priors, each a residual ``ln(x / x_prior) / ln 2``: on ω0 (:data:`SOURCE_RADIUS_PRIOR_MM`,
the NJL5901R-2 preset's LED die), on tan θ (:data:`DIVERGENCE_PRIOR_DEG`, the preset's) and on
e (the part's assumed spacing). Where the figures determine a parameter the prior hardly moves
it; where they do not, it decides.

A part's circuit is the paper's (3.3 V, V_F = 1.2 V, R1 = 680 Ω, V_CE(sat) = 0.2 V: the
NJL5901R-2 preset's) with the load R2 chosen by :func:`matched_load_ohm` so that the part's
flat-mirror peak gives the same output as the preset's: every part then spans the same
voltage range, and the comparison between parts is one of the shape of their response, not
of a resistor.
"""

import math
from dataclasses import dataclass
from itertools import compress

import numpy as np

from reflector_opt.util._display import Summarised, fmt
from reflector_opt.util._errors import InputError

#: Flat targets of datasheet tests: name -> (reflectance ρ, specular fraction f).
#: ``white-card``: the Kodak neutral test card's white side (90 % diffuse), the usual reference
#: of Vishay, onsemi and ams OSRAM; ``aluminium``: an evaporated aluminium mirror (Omron), ρ of
#: aluminium near 940 nm about 0.9; ``mirror``: an ideal mirror.
TARGETS = {"white-card": (0.9, 0.0), "aluminium": (0.9, 1.0), "mirror": (1.0, 1.0)}
#: Centre of the prior on the LED's 1/e source radius ω0, mm (the NJL5901R-2 preset's die).
SOURCE_RADIUS_PRIOR_MM = 0.15
#: Centre of the prior on the beam's 1/e half-angle θ, degrees (the NJL5901R-2 preset's); the
#: prior is on tan θ.
DIVERGENCE_PRIOR_DEG = 30.8
#: Width of each prior, in the log of the parameter: a factor of 2 is one standard deviation.
PRIOR_LOG_WIDTH = math.log(2.0)
#: The figures a part's model must reproduce within their tolerance
#: (:func:`reflector_opt.model._catalogue.check_part`); the range's ends are fitted, not checked.
CHECKED = ("peak_distance_mm", "output_current_a")
#: Weight of a checked figure's error in the fit, per tolerance: the fit lands well inside it
#: where the figures and the priors pull apart.
CHECKED_WEIGHT = 3.0
#: The parameters a fit may move, and their bounds: ω0 (mm), θ (degrees), G, e (mm).
_FITTED = ("source_radius_mm", "divergence_deg", "current_gain", "emitter_detector_mm")
_LOWER = (0.01, 3.0, 1e-4, 0.05)
_UPPER = (2.0, 75.0, 1e5, 10.0)
#: Nearest distance the flat-target curve is evaluated at, mm.
_NEAREST_MM = 0.01


def _coupling(model, distance_mm, target):
    """Flat-target coupling η at the distances (mm), on the named target."""
    reflectance, fraction = TARGETS[target]
    return model.flat_coupling(
        np.atleast_1d(np.asarray(distance_mm, dtype=float)), reflectance, fraction
    )


def flat_peak(model, target="white-card", far_mm=None):
    """Distance and coupling of the peak of a sensor's flat-target curve.

    A log-spaced scan of 120 distances from 0.01 mm to ``far_mm`` brackets the peak; bounded
    golden-section search (``scipy.optimize.minimize_scalar``) refines it to 1 µm.

    Parameters
    ----------
    model : reflector_opt.model._sensors.SensorModel
    target : str, optional
        A key of :data:`TARGETS`.
    far_mm : float, optional
        Farthest distance scanned, mm (default 20 e, at least 5 mm).

    Returns
    -------
    (float, float)
        The peak's distance (mm) and coupling (dimensionless).
    """
    from scipy.optimize import minimize_scalar  # slow to import; only here

    far = far_mm or max(5.0, 20.0 * model.emitter_detector_mm)
    d = np.geomspace(_NEAREST_MM, far, 120)
    eta = _coupling(model, d, target)
    i = int(np.argmax(eta))
    lo, hi = d[max(i - 1, 0)], d[min(i + 1, d.size - 1)]
    if hi <= lo:
        return float(d[i]), float(eta[i])
    found = minimize_scalar(
        lambda x: -float(_coupling(model, x, target)[0]),
        bounds=(lo, hi),
        method="bounded",
        options={"xatol": 1e-3},
    )
    best = float(found.x) if -found.fun >= eta[i] else float(d[i])
    return best, float(_coupling(model, best, target)[0])


def level_distances(model, level, target="white-card", peak=None):
    """Distances at which a flat-target curve is ``level`` times its peak, below and above it.

    Parameters
    ----------
    model : reflector_opt.model._sensors.SensorModel
    level : float
        Relative output, in (0, 1) (0.2 for Vishay's "relative I_out > 20 %").
    target : str, optional
        A key of :data:`TARGETS`.
    peak : (float, float), optional
        :func:`flat_peak` of the model, if already computed.

    Returns
    -------
    (float, float)
        Near and far distance, mm; the near one is 0 when the curve is above ``level`` down to
        0.01 mm.
    """
    from scipy.optimize import brentq  # slow to import; only here

    d_peak, eta_peak = peak or flat_peak(model, target)

    def excess(x):
        return float(_coupling(model, x, target)[0]) / eta_peak - level

    near = brentq(excess, _NEAREST_MM, d_peak, xtol=1e-4) if excess(_NEAREST_MM) < 0 else 0.0
    far = d_peak
    while excess(far) > 0:
        if far > 1e3:
            raise InputError(
                f"sensor {model.name!r}: its flat-target output never falls to {level:g}"
            )
        far *= 1.25
    return float(near), float(brentq(excess, max(d_peak, far / 1.25), far, xtol=1e-4))


def predicted_figures(model, figures):
    """The datasheet figures a sensor model predicts, for those the datasheet states.

    Parameters
    ----------
    model : reflector_opt.model._sensors.SensorModel
    figures : mapping
        The part's figures by name, each with a ``value`` (``peak_distance_mm``, ``range_mm``
        with its ``level``, ``output_current_a``, ``test_led_current_a``,
        ``test_distance_mm``, ``test_target``); absent ones are not predicted.

    Returns
    -------
    dict
        ``peak_distance_mm`` (mm), ``range_mm`` ([near, far] at the range's level, mm) and
        ``output_current_a`` (G · I_F · η at the test distance and target, A), for those
        stated.
    """
    target = _value(figures, "test_target") or "white-card"
    peak = flat_peak(model, target)
    out = {"peak_distance_mm": peak[0]}
    if "range_mm" in figures:
        out["range_mm"] = list(level_distances(model, figures["range_mm"].level, target, peak))
    current = _value(figures, "output_current_a")
    if current is not None:
        led = _value(figures, "test_led_current_a")
        eta = _coupling(model, _value(figures, "test_distance_mm"), target)[0]
        out["output_current_a"] = float(model.current_gain * led * eta)
    return out


def _value(figures, name):
    figure = figures.get(name)
    return None if figure is None else figure.value


def matched_load_ohm(model, reference):
    """Load R2 that gives a part the reference part's output swing, Ω.

    The collector current at the flat-mirror peak, G · I_F · η_peak, times R2 is the output's
    largest drop below the supply; R2 = R2_ref · (G_ref η_ref) / (G η) makes it the reference
    part's (the same LED current in the same circuit).

    Parameters
    ----------
    model : reflector_opt.model._sensors.SensorModel
        The part, with its fitted gain.
    reference : reflector_opt.model._sensors.SensorModel
        The part whose swing is matched (the NJL5901R-2 preset).

    Returns
    -------
    float
    """
    eta = flat_peak(model, "mirror")[1]
    eta_ref = flat_peak(reference, "mirror")[1]
    gain = (reference.current_gain * reference.led_current_a * eta_ref) / (
        model.current_gain * model.led_current_a * eta
    )
    return float(reference.load_resistor_ohm * gain)


@dataclass(frozen=True, repr=False)
class FitResult(Summarised):
    """Result of :func:`fit_part`.

    Attributes
    ----------
    model : reflector_opt.model._sensors.SensorModel
        The fitted model (its load resistor not yet matched: :func:`matched_load_ohm`).
    predicted : dict
        :func:`predicted_figures` of the fitted model.
    residuals : dict
        Each residual of the fit in units of its tolerance (or prior width), by name.
    fitted : tuple of str
        The parameters fitted.
    """

    model: object
    predicted: dict
    residuals: dict
    fitted: tuple

    def _summary(self):
        """Title and (label, value) rows of :class:`FitResult`."""
        rows = [(name, fmt(getattr(self.model, name))) for name in self.fitted]
        worst = max(self.residuals, key=lambda k: abs(self.residuals[k]), default=None)
        rows.append(
            (
                "largest residual",
                "n/a" if worst is None else f"{worst}: {fmt(self.residuals[worst])} tolerances",
            )
        )
        rows.append(("residuals", str(len(self.residuals))))
        return f"FitResult: {self.model.name}, {len(self.fitted)} parameters fitted", rows


def _residuals(model, figures, e_prior, priors=None):
    """Residuals (name -> value over tolerance) of a model against the figures and priors."""
    w0_prior, theta_prior = priors or (SOURCE_RADIUS_PRIOR_MM, DIVERGENCE_PRIOR_DEG)
    predicted = predicted_figures(model, figures)
    out = {}
    for name in CHECKED:
        if name in predicted:
            figure = figures[name]
            out[name] = CHECKED_WEIGHT * (predicted[name] - figure.value) / figure.tolerance
    if "range_mm" in predicted:
        figure = figures["range_mm"]
        for i, end in enumerate(("near", "far")):
            out[f"range_mm.{end}"] = (predicted["range_mm"][i] - figure.value[i]) / figure.tolerance
    out["prior.source_radius_mm"] = math.log(model.source_radius_mm / w0_prior) / PRIOR_LOG_WIDTH
    slope = math.tan(math.radians(model.divergence_deg))
    out["prior.divergence_deg"] = (
        math.log(slope / math.tan(math.radians(theta_prior))) / PRIOR_LOG_WIDTH
    )
    if e_prior is not None:
        out["prior.emitter_detector_mm"] = (
            math.log(model.emitter_detector_mm / e_prior) / PRIOR_LOG_WIDTH
        )
    return predicted, out


def fit_part(figures, base, *, fit_spacing=True, divergence_prior_deg=DIVERGENCE_PRIOR_DEG):
    """Fit a sensor model's ω0, θ, G (and e) to a part's datasheet figures by least squares.

    Minimises the sum of squares of each stated figure's error over its tolerance (the peak
    distance and the output current at the test condition weighted by :data:`CHECKED_WEIGHT`,
    the range's ends; each through the flat-target model on the test target) and of the
    priors on ω0, tan θ and e, in the logs of the parameters (``scipy.optimize.least_squares``,
    trust-region reflective within bounds).

    Parameters
    ----------
    figures : mapping
        The part's figures (objects with ``value``, ``tolerance`` and, for ``range_mm``,
        ``level``): ``peak_distance_mm`` is required; ``range_mm`` and ``output_current_a``
        (with ``test_led_current_a``, ``test_distance_mm``, ``test_target``) are used when
        present, and ``emitter_detector_mm`` is the prior on e.
    base : reflector_opt.model._sensors.SensorModel
        Starting point and source of the parameters not fitted (detector area, circuit).
    fit_spacing : bool, optional
        Fit e too (with its prior); False holds it at ``figures["emitter_detector_mm"]``
        (a published or measured spacing). G is fitted only with an output current (else it
        is ``base``'s).
    divergence_prior_deg : float, optional
        Centre of the prior on θ, degrees (the assumed emitter angle).

    Returns
    -------
    FitResult
    """
    from scipy.optimize import least_squares  # slow to import; only here

    e_value = figures["emitter_detector_mm"].value
    names = tuple(compress(_FITTED, (True, True, "output_current_a" in figures, fit_spacing)))
    start = base.with_(emitter_detector_mm=e_value)
    lower, upper = (np.log([bound[_FITTED.index(n)] for n in names]) for bound in (_LOWER, _UPPER))
    x0 = np.clip(np.log([getattr(start, n) for n in names]), lower + 1e-9, upper - 1e-9)

    def model_at(x):
        return start.with_(**dict(zip(names, np.exp(x).tolist(), strict=True)))

    priors = (SOURCE_RADIUS_PRIOR_MM, divergence_prior_deg)
    e_prior = e_value if fit_spacing else None

    def residual(x):
        return np.array(list(_residuals(model_at(x), figures, e_prior, priors)[1].values()))

    found = least_squares(residual, x0, bounds=(lower, upper), diff_step=1e-3, x_scale=1.0)
    model = model_at(found.x)
    predicted, residuals = _residuals(model, figures, e_prior, priors)
    return FitResult(model, predicted, residuals, names)
