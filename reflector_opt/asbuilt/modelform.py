"""The part of the as-built uncertainty that comes from physics the model lacks.

The fast model the identification fits has a Gaussian emitter, a perfect mirror and an
opaque Lambertian surface. A printed unit's LED has its own pattern, white resin spreads the
light it scatters under its surface, and the specular skin is rough
(:class:`reflector_opt.tolerance.formerror.FormError`, docs/model.md §9). The fit takes up
what it can of them in its effective parameters (gains, emitter), but part of them lands in
the geometry: on the default design, a cosine-power emitter or 0.1 mm of sub-surface spread
each move the identified reflector centre by about 17 µm in z. Residuals at the noise level
do not show it, so the statistical covariance cannot.

This module estimates that part as a systematic (type B, in the sense of the GUM) term. The
nominal unit (no tolerances, the design's surface) is built with the exact reference's
physics and then with each optical effect at its documented default; the noise-free
calibration data of each on the batch's plan (and its curves, if the batch has curves) are
identified. The first estimate's departure from the design, **b_0**, is the fast model's
own approximation; each effect's shift **b_k** is its estimate's departure from the first.
The terms are taken as independent, each of unknown sign, so they add ``Σ_k b_k b_kᵀ`` to
the covariance — the same for every unit of the batch, and fully correlated between them: a
systematic error of the model does not average out over the units of a batch.
"""

from __future__ import annotations

import numpy as np

from reflector_opt.asbuilt.problem import Curve, UnitData
from reflector_opt.tolerance.formerror import FormError
from reflector_opt.tolerance.model import Tolerances
from reflector_opt.tolerance.truth import build_unit

__all__ = ["EXACT", "OPTICAL_EFFECTS", "reference_units", "shifts", "systematic_covariance"]

#: The name of the reference unit with the exact reference's physics and no effect.
EXACT = "exact_reference"

#: The effects whose shifts enter the covariance. Crosstalk and ambient light are constant
#: couplings, taken up exactly by the offsets.
OPTICAL_EFFECTS = ("specular_roughness_deg", "subsurface_mm", "emitter_pattern")


def reference_units(design, template, form_error=None):
    """Noise-free data of the nominal unit with each optical effect of ``form_error``.

    Parameters
    ----------
    design : reflector_opt.design.design.Design
    template : reflector_opt.asbuilt.problem.UnitData
        A unit of the batch: its poses and its curves' sensors and distances are used.
    form_error : reflector_opt.tolerance.formerror.FormError, optional
        The effects and their sizes (default ``FormError()``, the documented defaults).

    Returns
    -------
    list of (str, reflector_opt.asbuilt.problem.UnitData)
        The nominal unit's data: first with the exact reference's physics (:data:`EXACT`),
        then with each effect that is switched on, by its name.
    """
    form_error = FormError() if form_error is None else form_error
    reflector = design.reflector
    surface = (reflector.reflectance, reflector.specular_fraction)
    pitch, roll = template.angles_deg[:, 0], template.angles_deg[:, 1]
    effects = [(EXACT, FormError.none())]
    effects += [(name, form_error.only(name)) for name in OPTICAL_EFFECTS]
    out = []
    for effect, only in effects:
        if effect != EXACT and not only.has_optics:
            continue
        unit = build_unit(design, 0, tolerances=Tolerances.zero(), form_error=only, surface=surface)
        curves = tuple(
            Curve(c.sensor, c.distance_mm, unit.flat_curve(c.sensor, c.distance_mm, None))
            for c in template.curves
        )
        out.append((effect, UnitData(effect, unit.volts(pitch, roll), template.angles_deg, curves)))
    return out


def shifts(estimates):
    """The systematic shifts from the reference units' estimates (in :func:`reference_units`
    order): ``b_0`` the exact reference's, then each effect's less ``b_0``.

    Parameters
    ----------
    estimates : sequence of numpy.ndarray

    Returns
    -------
    list of numpy.ndarray
    """
    base = estimates[0]
    return [base, *(estimate - base for estimate in estimates[1:])]


def systematic_covariance(shifts, layout):
    """``Σ_k B_k B_kᵀ``: each effect's shift of the shared and one unit's parameters, the
    same in every unit's block.

    Parameters
    ----------
    shifts : sequence of numpy.ndarray
        Per effect, the estimate of a one-unit layout (shared, then one block).
    layout : reflector_opt.asbuilt.parameters.Layout
        The batch's layout.

    Returns
    -------
    numpy.ndarray
        Shape (layout.size, layout.size).
    """
    n_shared = len(layout.shared_names)
    cov = np.zeros((layout.size, layout.size))
    for shift in shifts:
        full = np.r_[shift[:n_shared], np.tile(shift[n_shared:], layout.n_units)]
        cov += np.outer(full, full)
    return cov
