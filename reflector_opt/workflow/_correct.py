"""The print loop's correction, as ``reflector-opt correct`` makes it: one library call.

:func:`correct_run` reads the ``AS_BUILT.json`` files of one print batch, checks them, pools
them (the scatter under its prior, the identification's model-form bias and angle reference
weighed), shrinks the batch mean into a correction, chooses its step by the next batch's
expected loss and cuts it back until the part the process is predicted to print passes
every check of ``export``, predicts the next batch, and writes ``design.json`` and the
corrected parts into a folder built beside the old one and swapped in whole
(docs/print-loop.md).
"""

from __future__ import annotations

from pathlib import Path

from reflector_opt.workflow._correctrun import CorrectRun
from reflector_opt.workflow._runs import cad_files

#: The command recorded in an output folder's manifest when the library wrote it.
LIBRARY_COMMAND = ("reflector_opt", "correct")


def _batch(as_built, design, assume_systematic):
    """The batch and the design to correct, checked against each other."""
    from reflector_opt.asbuilt._batch import check_design, load_batch
    from reflector_opt.asbuilt._correction import check_not_applied
    from reflector_opt.asbuilt._pooling import MIN_UNITS
    from reflector_opt.design import Design, load_design
    from reflector_opt.util._errors import InputError

    paths = [as_built] if isinstance(as_built, str | Path) else list(as_built)
    batch = load_batch(paths)
    name = "the as-built files' design" if design is None else str(design)
    if design is None:
        design = batch.design
    elif not isinstance(design, Design):
        design = load_design(design)
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

    batch, model_form = weigh_model_form(batch, options["model_form"], options["seed"])
    mean = pool(batch, options["assume_systematic"], model_form, options["scatter_prior"])
    correction = plan_correction(mean, level=options["level"], max_std=options["max_std"])
    printable = _Printable(mean, printable_options)
    correction, losses = choose_step(design, correction, feasible=printable)
    return mean, correction, losses, printable


def correct_run(
    as_built,
    *,
    out,
    design=None,
    assume_systematic=False,
    level=2.0,
    max_std=1.0,
    model_form="auto",
    scatter_prior=1.0,
    predict=True,
    seed=0,
    export_options=None,
    progress=None,
    command=LIBRARY_COMMAND,
):
    """Correct the next print of a batch and write the corrected design and parts.

    Parameters
    ----------
    as_built : str, pathlib.Path or sequence of them
        The ``AS_BUILT.json`` files of one print batch (written by ``identify``).
    out : str or pathlib.Path
        The output folder (written whole or not at all).
    design : reflector_opt.design._design.Design, str or pathlib.Path, optional
        The design to correct: the one the units were printed from (default: the one the
        files record).
    assume_systematic : bool
        With fewer than 3 units, take their deviation as systematic.
    level : float
        The shrinkage's level (:func:`reflector_opt.asbuilt._correction.shrinkage_factors`).
    max_std : float
        Largest std of a correctable direction, tolerance-spread units.
    model_form : {"auto", "simulate", "none"}
        How the identification's model-form bias is weighed
        (:func:`reflector_opt.asbuilt._model_form_bias.weigh_model_form`).
    scatter_prior : float
        The scale of the scatter's prior, a multiple of the tolerance model's scatter.
    predict : bool
        Predict the next batch with and without the correction (resolution, calibration).
    seed : int
        Seed of the simulated model form and the predicted calibration.
    export_options : dict, optional
        Keywords of :func:`reflector_opt.cad._export.export_parts` (``tolerance_mm``,
        ``params``, ``preview``); ``params`` may be the CAD parameters' TOML file
        (docs/cad.md), read before any work.
    progress : callable, optional
        ``progress(fraction, message)``.
    command : sequence of str, optional
        The command line recorded in the folder's manifest.

    Returns
    -------
    CorrectRun

    Raises
    ------
    InputError
        Files that do not belong together or to the design, too few units, a design already
        corrected from these files, a correction no step of which gives a printable part, or
        corrected parts that fail ``export``'s checks; nothing is written.
    """
    from reflector_opt.asbuilt._batchforecast import predict_next_batch
    from reflector_opt.asbuilt._correction import corrected_design, correction_block
    from reflector_opt.cad._export import export_parts
    from reflector_opt.util._atomic import atomic_folder
    from reflector_opt.util._errors import InputError
    from reflector_opt.util._progress import no_progress

    progress = progress or no_progress
    export_options = _export_options(export_options)
    preview = export_options.pop("preview", True)
    options = {"assume_systematic": assume_systematic, "level": level, "max_std": max_std}
    options |= {"model_form": model_form, "scatter_prior": scatter_prior, "seed": seed}
    batch, design = _batch(as_built, design, assume_systematic)
    progress(0.05, "pooling the batch and choosing the correction's step")
    mean, correction, losses, printable = _plan(batch, design, options, export_options)
    drawing = corrected_design(design, correction)
    prediction = predict_next_batch(mean.batch, drawing, seed=seed) if predict else None
    if prediction is not None:
        drawing = drawing.replace(correction=correction_block(correction, design, prediction))
    progress(0.5, "writing the corrected design and parts")
    with atomic_folder(out, command) as work:
        drawing.save(work / "design.json")
        try:
            parts = printable.parts(drawing)
            if parts is None:
                report = export_parts(
                    drawing, work, preview=preview, progress=progress, **export_options
                )
            else:
                report = parts.write(work, preview=preview, progress=progress)
        except InputError as exc:
            raise InputError(f"the corrected design cannot be exported: {exc}") from None
    out = Path(out)
    figures = _figures(mean, design, drawing)
    files = [out / "design.json", *cad_files(report, out)]
    return CorrectRun(mean, correction, drawing, prediction, losses, figures, report, out, files)


def _export_options(options):
    """``export_options`` with ``params`` read from its TOML file when given as a path."""
    from reflector_opt.design._parts import load_cad_parameters

    options = dict(options or {})
    if isinstance(options.get("params"), str | Path):
        options["params"] = load_cad_parameters(options["params"])
    return options


def _figures(mean, design, drawing):
    """The predicted next batch's figures without and with the correction (fast model)."""
    from reflector_opt.asbuilt._batchforecast import predicted_units
    from reflector_opt.asbuilt._userloss import batch_figures

    pairs = (("without", design), ("with", drawing))
    return {key: batch_figures(predicted_units(mean.batch, d)) for key, d in pairs}
