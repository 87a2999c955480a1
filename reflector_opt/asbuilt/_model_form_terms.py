"""Physics the fast model lacks, in the identification: fitted, subtracted, or carried.

The fast model the identification fits has a Gaussian emitter, a perfect mirror and an
opaque Lambertian surface. A printed unit's LED has its own pattern, white resin spreads the
light it scatters under its surface, and the specular skin is rough
(:class:`reflector_opt.tolerance._model_form.ModelForm`, docs/model.md §9). Left to the
geometry, these move it: 0.2 mm of spread biased the identified centre height by 77 µm with
residuals at the noise. Each kind is handled as what it is (docs/asbuilt.md §3):

* **Fitted** — the sub-surface spread length ℓ of the batch's resin is a parameter
  (``subsurface_mm``, :class:`~reflector_opt.asbuilt._parameters.ParameterLayout`). The diffuse part
  of each sensor's coupling is multiplied by the flat-target ratio
  R(d; ℓ) = η_L(d; ℓ)/η_L(d; 0) at the sensor's Eq 3 distance d
  (:func:`reflector_opt.model._flat_hankel.subsurface_ratio`, exact for a flat target), so
  ``η = ρ [f η_M + (1 − f) η_L R(d; ℓ)]``
  (:func:`~reflector_opt.asbuilt._spread.spread_voltages`). On the default
  design's sphere the exact spread (:mod:`reflector_opt.model._exact_model_form`) lowers the
  diffuse part 0.7–2.5 % more than this at ℓ = 0.2 mm: what is left is carried below.
* **Subtracted** — the fast model's own offset from the exact reference, computed once on
  the nominal unit (no tolerances, the design's surface) at the unit's poses: the bias
  ``V_exact − V_fast`` is added to the model's voltages, not to its variance.
* **Carried** — each remaining effect, per sensor: its signature on the nominal unit
  ``g = V_effect − V_exact`` (for the spread, less the part the fitted ℓ reproduces), only
  in that sensor's column, enters the model as ``c · g`` with an amplitude c of prior
  N(0, 1): the effect at its documented size, of unknown sign, separately for each sensor
  so that S2 − S1 contrasts (part-to-part LED differences) are covered as well as their sum.
  Fitting the amplitudes with the rest puts their uncertainty into the posterior covariance
  itself, so no posterior std exceeds its prior; a flat-target curve of the same sensor
  carries the same amplitude (its signature from the closed-form flat couplings,
  :func:`reflector_opt.model._flat_hankel.flat_couplings`) and pins it.

:func:`reference_units` gives the nominal unit's noise-free data with each effect, for
:mod:`reflector_opt.asbuilt._model_form_bias`.
"""

import json
from dataclasses import dataclass, replace

import numpy as np

from reflector_opt.asbuilt._problem import Curve, UnitData
from reflector_opt.asbuilt._spread import spread_curve_volts, spread_voltages
from reflector_opt.model._flat_hankel import flat_couplings
from reflector_opt.tolerance._builtunit import build_unit
from reflector_opt.tolerance._model_form import ModelForm
from reflector_opt.tolerance._tolerances import Tolerances

#: The name of the reference unit with the exact reference's physics and no effect.
EXACT = "exact_reference"

#: The effects whose shifts enter the covariance. Crosstalk and ambient light are constant
#: couplings, taken up exactly by the offsets.
OPTICAL_EFFECTS = ("specular_roughness_deg", "subsurface_mm", "emitter_pattern")

#: The LED patterns other than the model's Gaussian; each is a signature of its own when a
#: form error's pattern is not Gaussian (the LED's true shape is unknown).
PATTERNS = ("cosine_power", "two_gaussian")


def effects_of(model_form):
    """The signatures' effects of a form error: ``(name, ModelForm with it alone)``.

    The rough lobe and the spread at the form error's sizes, and, if its LED pattern is not
    Gaussian, each of :data:`PATTERNS`; crosstalk and ambient light none (the offsets take
    them up exactly).

    Parameters
    ----------
    model_form : reflector_opt.tolerance._model_form.ModelForm

    Returns
    -------
    list of (str, ModelForm)
    """
    out = []
    if model_form.specular_roughness_deg > 0:
        out.append(("roughness", model_form.only("specular_roughness_deg")))
    if model_form.subsurface_mm > 0:
        out.append(("subsurface", model_form.only("subsurface_mm")))
    if model_form.emitter_pattern != "gaussian":
        out += [(p, replace(ModelForm.none(), emitter_pattern=p)) for p in PATTERNS]
    return out


def model_form_names(model_form, n_sensors):
    """Names of one unit's model-form amplitudes, sensor by sensor: ``form_<effect>_sensor_k``.

    Parameters
    ----------
    model_form : reflector_opt.tolerance._model_form.ModelForm or None
    n_sensors : int

    Returns
    -------
    tuple of str
    """
    if model_form is None:
        return ()
    effects = [name for name, _ in effects_of(model_form)]
    return tuple(f"form_{e}_sensor_{k + 1}" for k in range(n_sensors) for e in effects)


@dataclass(frozen=True)
class ModelFormTerms:
    """The bias and the amplitude signatures of each unit's data (module notes).

    Attributes
    ----------
    design : reflector_opt.design._design.Design
        The nominal design.
    model_form : reflector_opt.tolerance._model_form.ModelForm
        The form error whose effects these are.
    effects : list of (str, ModelForm)
        :func:`effects_of` the form error.
    exact : reflector_opt.tolerance._builtunit.BuiltUnit
        The nominal unit with the exact reference's optics.
    built : list of reflector_opt.tolerance._builtunit.BuiltUnit
        The nominal unit with each effect alone.
    spread_fitted : bool
        Whether the fit has the spread ℓ (the spread's signature is then what the fitted
        model does not reproduce of it).
    bias, signatures : list of numpy.ndarray
        Per unit of the batch, :meth:`at` its poses.
    curve_bias, curve_signatures : list of list of numpy.ndarray
        Per unit and curve, the bias (points,) and signatures (terms, points), V.
    """

    design: object
    model_form: object
    effects: list
    exact: object
    built: list
    spread_fitted: bool
    bias: list
    signatures: list
    curve_bias: list
    curve_signatures: list

    def at(self, pitch_deg, roll_deg):
        """The bias ``V_exact − V_fast`` (n, sensors) and the signatures (terms, n, sensors)
        at poses (n,), V."""
        design = self.design
        base = self.exact.volts(pitch_deg, roll_deg)
        fast = spread_voltages(design, pitch_deg, roll_deg, None)
        columns = []
        for (name, only), unit in zip(self.effects, self.built, strict=True):
            change = unit.volts(pitch_deg, roll_deg) - base
            if name == "subsurface" and self.spread_fitted:
                change -= spread_voltages(design, pitch_deg, roll_deg, only.subsurface_mm) - fast
            columns.append(change)
        return base - fast, _per_sensor(columns, base.shape)

    def extra_volts(self, pitch_deg, roll_deg, amplitudes):
        """What the terms add to a unit's voltages at poses (n,) for its ``amplitudes``, V."""
        bias, signatures = self.at(pitch_deg, roll_deg)
        return bias + np.tensordot(amplitudes, signatures, axes=1)

    def volts(self, u, amplitudes):
        """What the terms add to unit ``u``'s calibration voltages, (n, sensors), V."""
        return self.bias[u] + np.tensordot(amplitudes, self.signatures[u], axes=1)

    def curve_volts(self, u, c, amplitudes):
        """What the terms add to unit ``u``'s curve ``c``, V."""
        return self.curve_bias[u][c] + amplitudes @ self.curve_signatures[u][c]


#: Nominal units built, by design and effects (the benchmark and the tests identify many
#: units of one design; each set costs a few seconds of exact optics).
_BUILT = {}


def _nominal_units(design, effects):
    """The nominal unit built with exact optics and with each effect alone (kept for the
    next call with the same design and effects)."""
    key = json.dumps([design.to_dict(), [o.to_dict() for _, o in effects]], sort_keys=True)
    if key not in _BUILT:
        surface = (design.reflector.reflectance, design.reflector.specular_fraction)
        options = {"tolerances": Tolerances.zero(), "surface": surface}
        exact = build_unit(design, 0, model_form=ModelForm.none(), **options)
        built = [build_unit(design, 0, model_form=only, **options) for _, only in effects]
        if len(_BUILT) >= 4:
            _BUILT.pop(next(iter(_BUILT)))
        _BUILT[key] = (exact, built)
    return _BUILT[key]


def _flat_volts(design, k, distance_mm, pattern="gaussian", subsurface_mm=0.0):
    """Closed-form flat-target voltages of the design's sensor k on its surface, V."""
    model, reflector = design.models[k], design.reflector
    parts = flat_couplings(distance_mm, model, emitter_pattern=pattern, subsurface_mm=subsurface_mm)
    return model.output_voltage(parts.total(reflector.reflectance, reflector.specular_fraction))


def model_form_terms(design, units, model_form, spread_fitted):
    """The bias and signatures of a batch's data (:class:`ModelFormTerms`).

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    units : sequence of reflector_opt.asbuilt._problem.UnitData
    model_form : reflector_opt.tolerance._model_form.ModelForm
        The effects and their sizes (:func:`effects_of`).
    spread_fitted : bool
        Whether the fit has the spread ℓ.

    Returns
    -------
    ModelFormTerms
    """
    effects = effects_of(model_form)
    exact, built = _nominal_units(design, effects)
    out = ModelFormTerms(design, model_form, effects, exact, built, spread_fitted, [], [], [], [])
    for data in units:
        bias, signatures = out.at(data.angles_deg[:, 0], data.angles_deg[:, 1])
        out.bias.append(bias)
        out.signatures.append(signatures)
        found = [_curve_terms(design, c, effects, spread_fitted) for c in data.curves]
        out.curve_bias.append([bias for bias, _ in found])
        out.curve_signatures.append([signature for _, signature in found])
    return out


def _per_sensor(columns, shape):
    """(terms, n, sensors): each effect's change in one sensor's column at a time, sensor by
    sensor (the order of :func:`model_form_names`)."""
    n_sensors = shape[-1]
    out = np.zeros((n_sensors * len(columns), *shape))
    for k in range(n_sensors):
        for e, change in enumerate(columns):
            out[k * len(columns) + e, :, k] = change[:, k]
    return out


def _curve_terms(design, curve, effects, spread_fitted):
    """The bias and (terms, points) signatures of one flat-target curve (the rough lobe has
    no closed form on a flat target and no signature there)."""
    k, d = curve.sensor, curve.distance_mm
    reflector = design.reflector
    surface = (reflector.reflectance, reflector.specular_fraction)
    base = _flat_volts(design, k, d)
    fast = spread_curve_volts(design.models[k], d, *surface, None)
    signature = np.zeros((len(design.models) * len(effects), len(d)))
    for e, (name, only) in enumerate(effects):
        if name == "roughness":
            continue
        change = _flat_volts(design, k, d, only.emitter_pattern, only.subsurface_mm) - base
        if name == "subsurface" and spread_fitted:
            change -= spread_curve_volts(design.models[k], d, *surface, only.subsurface_mm) - fast
        signature[k * len(effects) + e] = change
    return base - fast, signature


def reference_units(design, template, model_form=None):
    """Noise-free data of the nominal unit with each optical effect of ``model_form``.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    template : reflector_opt.asbuilt._problem.UnitData
        A unit of the batch: its poses and its curves' sensors and distances are used.
    model_form : reflector_opt.tolerance._model_form.ModelForm, optional
        The effects and their sizes (default ``ModelForm()``, the documented defaults).

    Returns
    -------
    list of (str, reflector_opt.asbuilt._problem.UnitData)
        The nominal unit's data: first with the exact reference's physics (:data:`EXACT`),
        then with each effect that is switched on, by its name.
    """
    model_form = ModelForm() if model_form is None else model_form
    reflector = design.reflector
    surface = (reflector.reflectance, reflector.specular_fraction)
    pitch, roll = template.angles_deg[:, 0], template.angles_deg[:, 1]
    effects = [(EXACT, ModelForm.none())]
    effects += [(name, model_form.only(name)) for name in OPTICAL_EFFECTS]
    out = []
    for effect, only in effects:
        if effect != EXACT and not only.has_optics:
            continue
        unit = build_unit(design, 0, tolerances=Tolerances.zero(), model_form=only, surface=surface)
        curves = tuple(
            Curve(c.sensor, c.distance_mm, unit.flat_curve(c.sensor, c.distance_mm, None))
            for c in template.curves
        )
        out.append((effect, UnitData(effect, unit.volts(pitch, roll), template.angles_deg, curves)))
    return out
