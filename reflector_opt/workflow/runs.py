"""What a workflow call returns: the run's results, the files it wrote, a ``repr`` and a
notebook display (the text the command prints, :class:`~reflector_opt.util.display.Printed`, or
a summary of its key figures, :class:`~reflector_opt.util.display.Summarised`) and a JSON-ready
summary (the commands' ``--json``)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from reflector_opt.util.display import Printed, Summarised
from reflector_opt.workflow import evaluate_text, optimise_text

__all__ = ["EvaluateRun", "OptimiseRun", "ReportRun", "cad_files"]

#: The file entries of a CAD export report, in the order they are listed.
_CAD_KEYS = ("stl", "3mf", "step", "png", "section_png")


def cad_files(report, folder):
    """The files of a :func:`~reflector_opt.cad.export_parts` report: parts, pictures, report.

    Parameters
    ----------
    report : dict or None
        The export's report (None when nothing was exported); it names its files within the
        output folder.
    folder : str or pathlib.Path
        The folder the export wrote into.

    Returns
    -------
    list of pathlib.Path
    """
    if report is None:
        return []
    folder = Path(folder)
    names = [entry[key] for entry in report["files"].values() for key in _CAD_KEYS if key in entry]
    return [folder / name for name in [*names, report["report"]]]


def _cad_summary(cad, folder):
    """JSON-ready CAD outcome: were the parts written, why not, where their report is."""
    if cad is None:
        return {"written": False, "error": None, "report": None}
    if cad.error is not None:
        return {"written": False, "error": cad.error, "report": None}
    return {"written": True, "error": None, "report": str(Path(folder) / cad.report["report"])}


@dataclass(frozen=True, repr=False)
class OptimiseRun(Printed):
    """An optimisation run (:func:`reflector_opt.workflow.optimise_run`).

    Its ``repr`` and notebook display are the text ``optimise`` prints (:meth:`text`).

    Attributes
    ----------
    result : reflector_opt.optimise.OptimisationResult
        The optimised design (``result.design``, its ``predicted`` filled in) and the search.
    robust : reflector_opt.optimise.robust.RobustResult or None
        The robust rounds, when run against tolerances.
    front : reflector_opt.optimise.pareto.ParetoFront or None
        The Pareto front, when traced.
    predicted : dict or None
        :func:`~reflector_opt.tolerance.prediction.predicted_performance` of the design, with
        the report.
    cad : reflector_opt.report.outputs.CadOutcome or None
        The printable parts' outcome, with the report.
    out : pathlib.Path
        The output folder.
    files : list of pathlib.Path
        Every file written, ``design.json`` first (the folder's ``manifest.json`` besides).
    tolerances : str or pathlib.Path or None
        Where the tolerances of the robust rounds and the yields came from, named in their
        labels: the tolerance file as given, ``"given as an object"``, or None (the built-in
        ones, or none used).
    """

    result: object
    robust: object
    front: object
    predicted: dict | None
    cad: object
    out: Path
    files: list
    tolerances: object = None

    @property
    def design(self):
        """The optimised :class:`~reflector_opt.design.design.Design`."""
        return self.result.design

    def ranking_lines(self):
        """The sensor parts' ranking as printed lines (none when one part was optimised).

        Returns
        -------
        list of str
        """
        choice = self.design.predicted.get("sensor_choice")
        if choice is None:
            return []
        from reflector_opt.workflow.optimise_text import ranking_lines

        return ranking_lines(choice)

    def to_dict(self):
        """JSON-ready summary (``optimise --json``): the design as ``design.json`` holds it,
        the predicted performance, the robust rounds, the Pareto front, the parts, the files."""
        return {
            "out": str(self.out),
            "seed": self.result.seed,
            "evaluations": sum(self.result.evaluations.values()),
            "design": self.design.to_dict(),
            "predicted": self.predicted,
            "robust": None if self.robust is None else self.robust.to_dict(),
            "pareto": None if self.front is None else self.front.to_dict(),
            "cad": _cad_summary(self.cad, self.out),
            "files": [str(path) for path in self.files],
        }

    def text(self):
        """The text ``optimise`` prints before the files it wrote
        (:func:`~reflector_opt.workflow.optimise_text.format_run`)."""
        return optimise_text.format_run(self)


@dataclass(frozen=True, repr=False)
class ReportRun(Summarised):
    """A report written (:func:`reflector_opt.workflow.report_run`).

    Attributes
    ----------
    design : reflector_opt.design.design.Design
    out : pathlib.Path
        The output folder.
    seed : int
        Seed of the simulations.
    as_built : bool
        The report has an as-built section.
    cad : reflector_opt.report.outputs.CadOutcome or None
        The printable parts' outcome (None when not exported).
    files : list of pathlib.Path
        Every file written, ``report.md`` and ``report.html`` first (the folder's
        ``manifest.json`` besides).
    """

    design: object
    out: Path
    seed: int
    as_built: bool
    cad: object
    files: list

    def to_dict(self):
        """JSON-ready summary (``report --json``): the pages, the parts, every file."""
        return {
            "out": str(self.out),
            "seed": self.seed,
            "as_built": self.as_built,
            "markdown": str(self.files[0]),
            "html": str(self.files[1]),
            "cad": _cad_summary(self.cad, self.out),
            "files": [str(path) for path in self.files],
        }

    def _summary(self):
        cad = _cad_summary(self.cad, self.out)
        return "design report", [
            ("Markdown", str(self.files[0])),
            ("HTML", str(self.files[1])),
            ("as-built section", "yes" if self.as_built else "no"),
            ("printable parts", "written" if cad["written"] else cad["error"] or "not exported"),
            ("files written", f"{len(self.files)} in {self.out}"),
        ]


@dataclass(frozen=True, repr=False)
class EvaluateRun(Printed):
    """A design evaluated over its workspace (:func:`reflector_opt.workflow.evaluate_run`).

    Its ``repr`` and notebook display are the text ``evaluate`` prints (:meth:`text`).

    Attributes
    ----------
    design : reflector_opt.design.design.Design
    summary : dict
        :func:`~reflector_opt.tolerance.prediction.evaluation_summary`'s summary (``evaluate
        --json``).
    """

    design: object
    summary: dict

    def to_dict(self):
        """The summary, JSON-ready (``evaluate --json``)."""
        return self.summary

    def text(self):
        """The text ``evaluate`` prints: ranges, surface, drift, budget, predicted errors."""
        return evaluate_text.format_summary(self.summary)
