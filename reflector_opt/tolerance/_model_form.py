"""The model form: physics a built unit has and the fast model lacks.

The built-unit truth (:mod:`reflector_opt.tolerance._builtunit`) computes a unit's optics with the
exact reference, the fast model's own physics without its approximations. A :class:`ModelForm`
adds, as named options with moderate defaults (docs/model.md, "Physics the fast model leaves
out", gives each basis):

* ``specular_roughness_deg`` — the mirror-like share reflected into a Beckmann microfacet lobe
  of this RMS slope angle instead of a perfect mirror;
* ``subsurface_mm`` — the diffuse share's light leaving the translucent resin around where it
  entered, spread by the kernel exp(−r/ℓ)/(2πℓ²);
* ``emitter_pattern`` — the LED's angular pattern: ``"cosine_power"`` or ``"two_gaussian"``
  of the same nominal width as the model's Gaussian, or ``"gaussian"``;
* ``crosstalk_coupling`` — light that reaches the phototransistor inside the sensor's package
  without leaving it, a constant coupling added to each sensor's;
* ``ambient_current_ua`` — a constant collector current from ambient light, present during
  calibration and use alike.

The optics (the first three) are computed by
:func:`reflector_opt.model._exact_model_form.exact_model_form_design_coupling`; the last two are
constants added to the coupling (the ambient current as the coupling that gives the same collector
current, I_amb / (G · I_F), exact because I_C is linear in η).
"""

import math
from dataclasses import dataclass, fields, replace

from reflector_opt.model._exact_model_form import check_options
from reflector_opt.util._errors import InputError

#: Largest in-package crosstalk coupling accepted (detected over emitted power).
MAX_CROSSTALK_COUPLING = 0.01

#: Largest ambient collector current accepted, µA (a tenth of the default design's signal).
MAX_AMBIENT_CURRENT_UA = 50.0


@dataclass(frozen=True)
class ModelForm:
    """Physics of a built unit beyond the fast model, with moderate defaults.

    ``ModelForm()`` switches every effect on at its default; :meth:`none` switches all off
    (the exact reference's physics, today's built units); :meth:`only` keeps one.

    Parameters
    ----------
    specular_roughness_deg : float
        RMS microfacet slope angle of the specular lobe, degrees (Beckmann's RMS slope is its
        tangent). Default 3° (0.052 rad): a glossy printed surface; 0 is a perfect mirror.
    subsurface_mm : float
        Length ℓ of the sub-surface spread kernel exp(−r/ℓ)/(2πℓ²) of the diffuse share, mm
        (mean lateral displacement 2ℓ). Default 0.1 mm: the transport length of a white,
        pigmented photopolymer is tens to a hundred µm. 0 is an opaque Lambertian surface.
    emitter_pattern : str
        The LED's angular pattern: ``"cosine_power"`` (default), ``"two_gaussian"`` or
        ``"gaussian"`` (the fast model's), each of the model's nominal 1/e width.
    crosstalk_coupling : float
        In-package coupling from the LED to its own phototransistor, added to each sensor's
        coupling independent of the pose (detected over emitted power). Default 1.5e-4, 1.6 %
        of the default design's coupling at the zero pose (0.0096).
    ambient_current_ua : float
        Constant collector current from ambient light, µA, in the calibration data and in
        use. Default 0.5 µA: 5 mV at the 10 kΩ load, 0.7 % of the default design's signal
        current (71 µA at the zero pose).
    """

    specular_roughness_deg: float = 3.0
    subsurface_mm: float = 0.1
    emitter_pattern: str = "cosine_power"
    crosstalk_coupling: float = 1.5e-4
    ambient_current_ua: float = 0.5

    def __post_init__(self):
        check_options(self.specular_roughness_deg, self.subsurface_mm, self.emitter_pattern)
        for name, bound in (
            ("crosstalk_coupling", MAX_CROSSTALK_COUPLING),
            ("ambient_current_ua", MAX_AMBIENT_CURRENT_UA),
        ):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise InputError(f"{name}: expected a number, got {value!r}")
            if not (math.isfinite(value) and 0.0 <= value <= bound):
                raise InputError(f"{name}: expected 0 to {bound:g}, got {value!r}")

    @classmethod
    def none(cls):
        """No form error: the exact reference's physics (a built unit as before)."""
        return cls(0.0, 0.0, "gaussian", 0.0, 0.0)

    @staticmethod
    def names():
        """Names of the options, in order."""
        return tuple(f.name for f in fields(ModelForm))

    def only(self, *names):
        """Copy that keeps the named options and switches every other one off.

        Parameters
        ----------
        *names : str
            Option names (:meth:`names`).

        Returns
        -------
        ModelForm
        """
        unknown = [n for n in names if n not in self.names()]
        if unknown:
            raise InputError(f"unknown form error {unknown[0]!r}; known: {', '.join(self.names())}")
        return replace(ModelForm.none(), **{n: getattr(self, n) for n in names})

    @property
    def has_optics(self):
        """True if an optical option departs from the exact reference's physics."""
        return (
            self.specular_roughness_deg > 0.0
            or self.subsurface_mm > 0.0
            or self.emitter_pattern != "gaussian"
        )

    def optics(self):
        """The optical options, as keyword arguments of
        :func:`~reflector_opt.model._exact_model_form.exact_model_form_coupling`."""
        return {
            "roughness_deg": self.specular_roughness_deg,
            "subsurface_mm": self.subsurface_mm,
            "emitter_pattern": self.emitter_pattern,
        }

    def extra_coupling(self, model):
        """Pose-independent coupling added to a sensor's: crosstalk plus ambient light.

        The ambient current enters as the coupling giving the same collector current,
        ``I_amb / (G · I_F)``.

        Parameters
        ----------
        model : reflector_opt.model._sensors.SensorModel

        Returns
        -------
        float
            Detected over emitted power (dimensionless).
        """
        ambient = self.ambient_current_ua * 1e-6 / (model.current_gain * model.led_current_a)
        return self.crosstalk_coupling + ambient

    def to_dict(self):
        """JSON-ready ``{option: value}``."""
        return {name: getattr(self, name) for name in self.names()}
