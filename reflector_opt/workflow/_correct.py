"""The print loop's correction, as ``reflector-opt correct`` makes it, in memory.

:func:`correct` reads the ``AS_BUILT.json`` files of one print batch, checks them, pools
them (the scatter under its prior, the identification's model-form bias and angle reference
weighed), shrinks the batch mean into a correction, chooses its step by the next batch's
expected loss and cuts it back until the part the process is predicted to print passes
every check of ``export`` and predicts the next batch; its run's
:meth:`~reflector_opt.workflow._correctrun.CorrectRun.write` writes ``design.json`` and the
corrected parts into a folder built beside the old one and swapped in whole
(docs/print-loop.md).
"""

from pathlib import Path
from typing import Literal

from reflector_opt.util._declared import Options, Seed, option, takes
from reflector_opt.util._limits import DEFAULT_TOLERANCE_MM
from reflector_opt.workflow._correctrun import CorrectRun
from reflector_opt.workflow._export import CadConfig, ChordTolerance


def _batch(as_built, design, assume_systematic):
    """The batch and the design to correct, checked against each other."""
    from reflector_opt.asbuilt._batch import check_design, load_batch
    from reflector_opt.asbuilt._correction import check_not_applied
    from reflector_opt.asbuilt._pooling import MIN_UNITS
    from reflector_opt.design import as_design
    from reflector_opt.util._errors import InputError

    paths = [as_built] if isinstance(as_built, str | Path) else list(as_built)
    batch = load_batch(paths)
    name = "the as-built files' design" if design is None else str(design)
    design = batch.design if design is None else as_design(design)
    check_not_applied(design, batch, name)
    check_design(batch, design, name)
    if batch.n_units < MIN_UNITS and not assume_systematic:
        raise InputError(
            f"{batch.n_units} unit(s) cannot tell a systematic deviation from the unit-to-unit "
            f"scatter ({MIN_UNITS} needed); identify more units of the batch, or pass "
            "--assume-systematic to take their deviation as systematic"
        )
    return batch, design


class _Printable:
    """``correct``'s printability judgement, handed to the step search as ``feasible``: the
    cheap checks and export's on the print the process is predicted to make of a drawing,
    then export's on the drawing's own parts — export judges the parts it writes, and the
    drawing is what it writes (a shell the process thickens is refused there too). Export's
    checks are made in memory (:func:`reflector_opt.cad._export.check_parts`), nothing
    written; the parts of the last drawing that passed are kept for :meth:`parts`."""

    def __init__(self, mean, options):
        self.mean, self.options, self.kept = mean, options, None

    def _checked(self, design, what=""):
        from reflector_opt.cad._export import check_parts
        from reflector_opt.util._errors import InputError

        try:
            return check_parts(design, **self.options), None
        except InputError as exc:
            return None, f"{what}{exc}"

    def __call__(self, drawing):
        from reflector_opt.asbuilt._stepsearch import predicted_print, print_problem

        problem = print_problem(drawing, self.mean)
        if problem is None:
            problem = self._checked(predicted_print(drawing, self.mean))[1]
        if problem is None:
            parts, problem = self._checked(
                drawing, "the drawing's own parts, as export writes them: "
            )
            self.kept = parts or self.kept
        return problem

    def parts(self, drawing):
        """The kept parts if they are ``drawing``'s (its correction block aside), else None."""
        kept = self.kept
        same = kept and kept.design == drawing.replace(correction=kept.design.correction)
        return kept if same else None


def _plan(batch, design, options, printable_options):
    """Pool, shrink, step: (batch mean, correction with its step, expected losses, the
    printability judgement that chose the step)."""
    from reflector_opt.asbuilt._correction import plan_correction
    from reflector_opt.asbuilt._model_form_bias import weigh_model_form
    from reflector_opt.asbuilt._pooling import pool
    from reflector_opt.asbuilt._stepsearch import choose_step

    batch, model_form = weigh_model_form(batch, options.model_form, options.seed)
    mean = pool(batch, options.assume_systematic, model_form, options.scatter_prior)
    correction = plan_correction(mean, level=options.level, max_std=options.max_std)
    printable = _Printable(mean, printable_options)
    correction, losses = choose_step(design, correction, feasible=printable)
    return mean, correction, losses, printable


class CorrectOptions(Options):
    """The options of ``reflector-opt correct``, declared once."""

    design: option(
        object,
        "the design to correct (a Design or its design.json): the one the units were printed "
        "from; the one the as-built files record if left out",
        metavar="DESIGN.json",
    ) = None
    assume_systematic: option(
        bool,
        "with fewer than 3 units, take their deviation as systematic (it cannot be told from "
        "the scatter)",
    ) = False
    level: option(
        float,
        "shrink each resolved combination's correction by max(0, 1 − (T/t)²): nothing below "
        "|t| = T (reflector_opt.asbuilt.shrinkage_factors)",
        metavar="T",
        gt=0,
        le=10,
    ) = 2.0
    scatter_prior: option(
        float,
        "centre of the unit-to-unit scatter's prior, × the tolerance model's",
        metavar="S",
        gt=0,
        le=100,
    ) = 1.0
    max_std: option(
        float,
        "correct a combination only where the batch mean is known to within S × the "
        "tolerance spread",
        metavar="S",
        gt=0,
        le=10,
    ) = 1.0
    model_form: option(
        Literal["auto", "simulate", "none"],
        "weigh the identification's model-form bias as an uncertainty common to the batch: "
        "auto, the term the as-built files record, or if they record none, simulated on units "
        "with physics the fast model lacks (about 10 s); simulate: always simulated; none: "
        "trust the identification's model",
    ) = "auto"
    predict: option(
        bool,
        "predict the next batch with and without the correction (resolution, calibration)",
        flag="--no-prediction",
    ) = True
    seed: option(Seed, "seed of the simulated model form and the predicted calibration") = 0
    config: CadConfig = None
    chord_tolerance_mm: ChordTolerance = DEFAULT_TOLERANCE_MM
    preview: option(bool, "write the PNG pictures") = True


@takes(CorrectOptions)
def correct(as_built, options, progress=None):
    """Correct the next print of a batch, in memory: ``reflector-opt correct``;
    :meth:`~reflector_opt.workflow._correctrun.CorrectRun.write` writes the corrected design
    and parts.

    Parameters
    ----------
    as_built : str, pathlib.Path or sequence of them
        The ``AS_BUILT.json`` files of one print batch (written by ``identify``).
    options : CorrectOptions
        As keyword arguments (below); the CAD parameters' file is read before any work.
    progress : callable, optional
        ``progress(fraction, message)``.

    Returns
    -------
    CorrectRun

    Raises
    ------
    InputError
        Files that do not belong together or to the design, too few units, a design already
        corrected from these files, a correction no step of which gives a printable part, or
        corrected parts that fail ``export``'s checks.
    """
    from reflector_opt.asbuilt._batchforecast import predict_next_batch
    from reflector_opt.asbuilt._correction import corrected_design, correction_block
    from reflector_opt.cad._export import check_parts
    from reflector_opt.design._parts import load_cad_parameters
    from reflector_opt.util._errors import InputError
    from reflector_opt.util._progress import no_progress

    progress = progress or no_progress
    params = options.config
    params = load_cad_parameters(params) if isinstance(params, str | Path) else params
    export_options = {"tolerance_mm": options.chord_tolerance_mm, "params": params}
    batch, design = _batch(as_built, options.design, options.assume_systematic)
    progress(0.05, "pooling the batch and choosing the correction's step")
    mean, correction, losses, printable = _plan(batch, design, options, export_options)
    drawing = corrected_design(design, correction)
    seed = options.seed
    prediction = predict_next_batch(mean.batch, drawing, seed=seed) if options.predict else None
    if prediction is not None:
        drawing = drawing.replace(correction=correction_block(correction, design, prediction))
    progress(0.5, "checking the corrected parts")
    try:
        parts = printable.parts(drawing) or check_parts(
            drawing, preview=options.preview, **export_options
        )
    except InputError as exc:
        raise InputError(f"the corrected design cannot be exported: {exc}") from None
    figures = _figures(mean, design, drawing)
    return CorrectRun(
        mean, correction, drawing, prediction, losses, figures, parts, options.preview
    )


def _figures(mean, design, drawing):
    """The predicted next batch's figures without and with the correction (fast model)."""
    from reflector_opt.asbuilt._batchforecast import predicted_units
    from reflector_opt.asbuilt._userloss import batch_figures

    pairs = (("without", design), ("with", drawing))
    return {key: batch_figures(predicted_units(mean.batch, d)) for key, d in pairs}
