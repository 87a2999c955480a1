"""The report's files: the printable parts (the CAD export, its failure turned into an outcome
the report states) and the pages with their figures, in one folder.

:func:`write_design_outputs` runs the CAD export, the predicted performance and
:func:`write_report`, which writes ``report.md`` with its figures as PNG files and the
self-contained ``report.html`` from the blocks of
:func:`reflector_opt.report._report.report_blocks`.
"""

from dataclasses import dataclass
from pathlib import Path

from reflector_opt.cad import export_parts
from reflector_opt.report._asbuilt import read_as_built
from reflector_opt.report._render import render_html, render_markdown
from reflector_opt.report._report import report_blocks
from reflector_opt.report.figures._base import save_figure
from reflector_opt.tolerance._prediction import predicted_performance
from reflector_opt.util._errors import InputError
from reflector_opt.util._fileio import write_text
from reflector_opt.util._progress import Phases, monotone


@dataclass(frozen=True)
class CadOutcome:
    """What the CAD export produced for the report.

    Attributes
    ----------
    report : dict or None
        The :func:`~reflector_opt.cad.export_parts` report when the parts were written.
    error : str or None
        Why no parts were written (a failed printability or collision check).
    """

    report: dict | None = None
    error: str | None = None

    def summary(self, folder=""):
        """One line: where the CAD report went (in ``folder``), or why no parts were written."""
        if self.error is not None:
            return f"no printable parts: {self.error}"
        return f"wrote the printable parts; CAD report {Path(folder) / self.report['report']}"


def export_cad(design, out_dir, progress=None):
    """Export the printable parts, turning a failed check into a reported outcome.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    out_dir : str or pathlib.Path
    progress : callable, optional
        ``progress(fraction, message)`` as the export advances.

    Returns
    -------
    CadOutcome
        With the export report, or the one-line reason nothing was written.
    """
    try:
        return CadOutcome(report=export_parts(design, out_dir, progress=progress))
    except InputError as exc:
        return CadOutcome(error=str(exc))


def write_report(
    design,
    out_dir,
    *,
    cad=None,
    seed=0,
    step_deg=None,
    predicted=None,
    as_built=None,
    conditions=None,
    progress=None,
):
    """Write ``report.md`` with its figures (PNG) and the self-contained ``report.html``
    (which embeds every image, the figures and the part previews, as a data URI).

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    out_dir : str or pathlib.Path
        Output folder (created if missing).
    cad : CadOutcome, optional
        Outcome of :func:`export_cad` into the same folder (its previews are linked).
    seed : int, optional
        Seed of the simulated calibration and segment motions.
    step_deg : float, optional
        Pose grid of the metrics, degrees (the workspace's step by default).
    predicted : reflector_opt.tolerance._prediction.Prediction, optional
        :func:`~reflector_opt.tolerance._prediction.predicted_performance` of the design, if
        already computed (with the same seed); computed here otherwise.
    as_built : str, pathlib.Path or reflector_opt.asbuilt._asbuiltfile.AsBuiltFile, optional
        ``AS_BUILT.json`` of units printed from this design: adds the as-built section.
    conditions : reflector_opt.design._conditions.Conditions, str or pathlib.Path, optional
        Operating conditions or their file, the default ones where None: the figures in use
        head the report and the error budget in them is given.
    progress : callable, optional
        ``progress(fraction, message)`` before the sections and each figure.

    Returns
    -------
    list of pathlib.Path
        The files written, the two report pages first.
    """
    out = _output_folder(out_dir)
    progress = monotone(progress)
    progress(0.0, "writing the report: metrics, segment motions")
    options = {"seed": seed, "step_deg": step_deg, "predicted": predicted}
    options |= {"as_built": as_built, "conditions": conditions}
    blocks, figures = report_blocks(design, cad=cad, **options)
    written = [out / "report.md", out / "report.html"]
    for i, (name, fig) in enumerate(figures.items()):  # the figures: 3/4 of the time
        progress(0.25 + 0.75 * i / len(figures), f"writing the report: {name}")
        save_figure(fig, out / name, dpi=110)
        written.append(out / name)
    write_text(out / "report.md", render_markdown(blocks))
    images = {b[1]: (out / b[1]).read_bytes() for b in blocks if b[0] == "img"}
    write_text(out / "report.html", render_html(blocks, images=images))
    return written


def write_design_outputs(
    design,
    out_dir,
    *,
    seed=0,
    step_deg=None,
    cad=True,
    progress=None,
    predicted=None,
    as_built=None,
    conditions=None,
):
    """The printable parts (when the design passes the checks) and the report, in one folder.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    out_dir : str or pathlib.Path
    seed : int, optional
        Seed of the simulated calibration and segment motions.
    step_deg : float, optional
        Pose grid of the metrics, degrees (the workspace's step by default).
    cad : bool, optional
        Run the CAD export (the slowest step); the report's printability section says if not.
    progress : callable, optional
        ``progress(fraction, message)`` as the work advances (see
        :class:`~reflector_opt.util._progress.Progress`).
    predicted : reflector_opt.tolerance._prediction.Prediction, optional
        :func:`~reflector_opt.tolerance._prediction.predicted_performance` of the design, if
        already computed (with the same seed); computed here otherwise.
    as_built : str, pathlib.Path or reflector_opt.asbuilt._asbuiltfile.AsBuiltFile, optional
        ``AS_BUILT.json`` of units printed from this design: adds the as-built section
        (read and checked before any part is written).
    conditions : reflector_opt.design._conditions.Conditions, str or pathlib.Path, optional
        Operating conditions or their file, the default ones where None: the figures in use
        head the report and the error budget in them is given.

    Returns
    -------
    written : list of pathlib.Path
        The report files and figures.
    outcome : CadOutcome or None
        The CAD export's outcome (its report lists the part files).
    """
    _output_folder(out_dir)
    if as_built is not None:
        as_built = read_as_built(as_built, design)
    phases = Phases(progress, _phase_work(cad, predicted is None, design.mechanics.n_units))
    parts = phases("parts")
    outcome = None
    if cad:
        outcome = export_cad(design, out_dir, progress=lambda f, m: parts(f, f"parts: {m}"))
    if predicted is None:
        predicted = predicted_performance(design, seed=seed, progress=phases("prediction"))
    options = {"seed": seed, "step_deg": step_deg, "predicted": predicted}
    options |= {"as_built": as_built, "conditions": conditions}
    written = write_report(design, out_dir, cad=outcome, progress=phases("report"), **options)
    phases.finish("report written")
    return written, outcome


def _output_folder(out_dir):
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise InputError(f"{out}: exists and is not a folder")
    return out


def _phase_work(cad, predict, n_units):
    """The work of :func:`write_design_outputs`'s phases, s (measured on the defaults): the
    parts, the prediction (3 s a built unit) and the report itself."""
    return {"parts": 4.0 if cad else 0.0, "prediction": 3.0 * n_units * predict, "report": 16.0}
