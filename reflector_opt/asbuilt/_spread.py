"""The fast model with the resin's sub-surface spread: the diffuse part spread by length ℓ.

White resin is translucent: light scattered beneath its surface leaves it up to a few
hundred µm from where it entered (docs/model.md §9), which the fast model's opaque
Lambertian surface lacks. With the spread length ℓ the diffuse part of each coupling is
multiplied by the flat-target ratio ``R(d; ℓ) = η_L(d; ℓ)/η_L(d; 0)``
(:func:`reflector_opt.model._flat_hankel.subsurface_ratio`, exact for a flat target),
``η = ρ [f η_M + (1 − f) η_L R(d; ℓ)]``: at each sensor's Eq 3 distance d for the
reflector (:func:`spread_voltages`; what the sphere's own spread does beyond it,
:mod:`reflector_opt.asbuilt._model_form_terms` carries) and at the target's distance for a
flat-target curve (:func:`spread_curve_volts`).
"""

from dataclasses import replace

import numpy as np

from reflector_opt.model._flat_hankel import subsurface_ratio
from reflector_opt.model._forward import respond
from reflector_opt.model._operating import readings
from reflector_opt.model._optics import flat_target_coupling


def spread_voltages(built, pitch_deg, roll_deg, subsurface_mm):
    """Noise-free voltages of the fast model with the diffuse part spread under the surface.

    ``η = ρ [f η_M + (1 − f) η_L R(d; ℓ)]``, R the flat-target spread ratio at each
    sensor's Eq 3 distance d (module notes); ``ℓ`` None or 0 gives the fast model.

    Parameters
    ----------
    built : reflector_opt.design._design.Design
    pitch_deg, roll_deg : array_like
        Poses, degrees, broadcast to shape P.
    subsurface_mm : float or None
        Spread length ℓ, mm.

    Returns
    -------
    numpy.ndarray
        Shape ``P + (n_sensors,)``, V (no read-out gain or offset).
    """
    full = respond(built, pitch_deg, roll_deg)
    if not subsurface_mm:
        return full.volts
    reflector = built.reflector
    diffuse = respond(
        built.replace(reflector=replace(reflector, specular_fraction=0.0)), pitch_deg, roll_deg
    ).coupling
    ratio = np.stack(
        [_ratio(full.distance_mm[..., k], m, subsurface_mm) for k, m in enumerate(built.models)],
        axis=-1,
    )
    eta = full.coupling + (1.0 - reflector.specular_fraction) * diffuse * (ratio - 1.0)
    return readings(np.maximum(eta, 0.0), built.models)


#: Chebyshev points of the spread ratio over a batch of distances (interpolated between:
#: smooth in d, within 1e-6 of the ratio at every distance of the default design).
RATIO_NODES = 12


def _ratio(distance_mm, model, subsurface_mm):
    """:func:`~reflector_opt.model._flat_hankel.subsurface_ratio` at many distances, from its
    values at :data:`RATIO_NODES` Chebyshev points of their span."""
    d = np.asarray(distance_mm, dtype=float)
    low, high = float(d.min()), float(d.max())
    if d.size <= RATIO_NODES or high - low < 1e-9:
        return subsurface_ratio(d, model, subsurface_mm)
    nodes = np.polynomial.chebyshev.chebpts1(RATIO_NODES)
    at = 0.5 * (low + high) + 0.5 * (high - low) * nodes
    fit = np.polynomial.Chebyshev.fit(
        at, subsurface_ratio(at, model, subsurface_mm), RATIO_NODES - 1, domain=[low, high]
    )
    return fit(d)


def spread_curve_volts(model, distance_mm, reflectance, specular_fraction, subsurface_mm):
    """A sensor's noise-free flat-target curve with the target's diffuse part spread, V.

    ``η = ρ [f η_M + (1 − f) η_L R(d; ℓ)]`` on the fast model's flat-target rules
    (:func:`reflector_opt.model._optics.flat_target_coupling`), R exact for a flat target.

    Parameters
    ----------
    model : reflector_opt.model._sensors.SensorModel
    distance_mm : array_like
        Distances, mm.
    reflectance, specular_fraction : float
        The target's ρ and f.
    subsurface_mm : float or None
        Spread length ℓ, mm (None or 0: none).

    Returns
    -------
    numpy.ndarray
        Voltages (no read-out gain or offset), shape of ``distance_mm``.
    """
    mirror = flat_target_coupling(distance_mm, model, 1.0, 1.0)
    diffuse = flat_target_coupling(distance_mm, model, 1.0, 0.0)
    if subsurface_mm:
        diffuse = diffuse * subsurface_ratio(distance_mm, model, subsurface_mm)
    eta = reflectance * (specular_fraction * mirror + (1.0 - specular_fraction) * diffuse)
    return model.output_voltage(eta)
