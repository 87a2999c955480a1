"""One factory for every calibration model, from the name a user gives it.

The command line, the calibration of measured units
(:mod:`reflector_opt.calibration._unit_calibration`) and the predictions
(:mod:`reflector_opt.tolerance._planning`, :mod:`reflector_opt.tolerance._thermalplan`,
:mod:`reflector_opt.calibration._misfit`) all turn a form's name into an unfitted estimator
here: ``eq5``, ``eq6`` and ``polyN``
(:func:`~reflector_opt.calibration._models.make_model`), ``auto`` (the form chosen by
cross-validation, :class:`~reflector_opt.calibration._selection.AutoModel`) and ``physical``
(the fitted forward model, :class:`~reflector_opt.calibration._physical.PhysicalModel`).
"""

from reflector_opt.calibration._models import make_model
from reflector_opt.calibration._physical import PhysicalModel
from reflector_opt.calibration._selection import AutoModel
from reflector_opt.util._errors import InputError


def make_estimator(form, *, fit="lsq", design=None, folds=5, seed=0):
    """An unfitted calibration model from its name.

    Parameters
    ----------
    form : str
        ``"eq5"``, ``"eq6"``, ``"polyN"`` (N = 1 … 10), ``"auto"`` or ``"physical"``.
    fit : {"lsq", "huber", "minimax"}
        How the coefficients are fitted (``physical``: least squares only).
    design : reflector_opt.design._design.Design, optional
        The units' design; ``physical`` needs it.
    folds : int
        Cross-validation folds of ``auto``'s choice.
    seed : int
        Seed of ``auto``'s folds.

    Returns
    -------
    Eq5, Eq6, Polynomial, AutoModel or PhysicalModel

    Raises
    ------
    InputError
        An unknown form, ``physical`` without a design or with another fit.
    """
    name = str(form).strip().lower()
    if name == PhysicalModel.name:
        if design is None:
            raise InputError("physical calibration needs the units' design (--design design.json)")
        if fit != "lsq":
            raise InputError(f"physical calibration fits by least squares only, not {fit!r}")
        return PhysicalModel(design)
    if name == "auto":
        return AutoModel(loss=fit, folds=folds, seed=seed)
    return make_model(name, fit)


def selected(model):
    """The fitted form itself: the one ``auto`` chose, else the model."""
    return model.selected_ if isinstance(model, AutoModel) else model
