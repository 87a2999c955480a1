"""The calibration form's own error: what a form cannot represent of a unit's response.

A calibration form (:mod:`.models`) fitted to a unit's noise-free voltages still errs where
the form cannot follow the response: its *misfit*, the ``form`` source of a design's error
budget (:mod:`reflector_opt.analysis._budget`). It is measured here on the fast model's
noise-free voltages at the given poses, the form fitted on the same poses (with hundreds of
poses and at most tens of terms, the fitting error is within a few percent of the error at
new poses).
"""

import numpy as np

from reflector_opt.calibration._estimators import make_estimator
from reflector_opt.model._forward import voltages


def form_misfit_deg(design, pitch_deg, roll_deg, form="auto"):
    """Error of a calibration form fitted to a design's noise-free voltages, degrees.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    pitch_deg, roll_deg : array_like
        Poses, degrees, shape (n,).
    form : str, optional
        ``"auto"`` (chosen by cross-validation, :class:`~.selection.AutoModel`), ``"eq5"``,
        ``"eq6"`` or ``"polyN"``.

    Returns
    -------
    numpy.ndarray
        Shape (n, 2): estimated minus true (pitch, roll), degrees.
    """
    pitch = np.asarray(pitch_deg, dtype=float).ravel()
    roll = np.asarray(roll_deg, dtype=float).ravel()
    volts = voltages(design, pitch, roll)
    angles = np.column_stack([pitch, roll])
    return make_estimator(form).fit(volts, angles).predict(volts) - angles
