"""What a workflow call returns: the run's results, the files it wrote, a short ``repr``, a
table for a notebook (``_repr_html_``) and a JSON-ready summary (the commands' ``--json``)."""

from __future__ import annotations

import html
from dataclasses import dataclass
from pathlib import Path

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


def _html_table(caption, rows):
    """A two-column HTML table (quantity, value) under a caption, its text escaped."""
    cells = "".join(
        f"<tr><th>{html.escape(str(k))}</th><td>{html.escape(_text(v))}</td></tr>" for k, v in rows
    )
    return f"<table><caption>{html.escape(caption)}</caption>{cells}</table>"


def _text(value):
    return "–" if value is None else str(value)


def _deg(value):
    return "inf" if value is None else f"{value:.4f}°"


@dataclass(frozen=True)
class OptimiseRun:
    """An optimisation run (:func:`reflector_opt.workflow.optimise_run`).

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
    """

    result: object
    robust: object
    front: object
    predicted: dict | None
    cad: object
    out: Path
    files: list

    @property
    def design(self):
        """The optimised :class:`~reflector_opt.design.design.Design`."""
        return self.result.design

    def _resolution(self):
        return self.design.predicted["metrics"]["resolution_deg"]

    def ranking_lines(self):
        """The sensor parts' ranking as printed lines (none when one part was optimised).

        Returns
        -------
        list of str
        """
        choice = self.design.predicted.get("sensor_choice")
        if choice is None:
            return []
        from reflector_opt.optimise.sensor_choice import ranking_lines

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

    def __repr__(self):
        r = self._resolution()
        return (
            f"OptimiseRun(seed {self.result.seed}: worst pitch {_deg(r['pitch_worst'])}, "
            f"roll {_deg(r['roll_worst'])}; {len(self.files)} files in {self.out})"
        )

    def _repr_html_(self):
        r, refl = self._resolution(), self.design.reflector
        improvement = self.design.predicted.get("improvement", {}).get("worst")
        robust = self.robust and (
            f"{len(self.robust.rounds)} round(s), "
            + ("covered" if self.robust.converged else "not covered")
        )
        rows = [
            ("seed", self.result.seed),
            ("reflector radius (mm)", f"{refl.radius_mm:.3f}"),
            ("worst 1σ pitch resolution", _deg(r["pitch_worst"])),
            ("worst 1σ roll resolution", _deg(r["roll_worst"])),
            ("improvement on the default design", improvement and f"{improvement:.2f}×"),
            ("robust margin", robust),
            ("Pareto points", self.front and len(self.front.points)),
            ("files written", f"{len(self.files)} in {self.out}"),
        ]
        return _html_table("optimisation run", rows)


@dataclass(frozen=True)
class ReportRun:
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

    def __repr__(self):
        parts = "no parts" if self.cad is None or self.cad.error else "with the parts"
        return f"ReportRun({self.out / 'report.html'}, {parts}, {len(self.files)} files)"

    def _repr_html_(self):
        cad = _cad_summary(self.cad, self.out)
        rows = [
            ("Markdown", self.files[0]),
            ("HTML", self.files[1]),
            ("as-built section", "yes" if self.as_built else "no"),
            ("printable parts", "written" if cad["written"] else cad["error"] or "not exported"),
            ("files written", f"{len(self.files)} in {self.out}"),
        ]
        return _html_table("design report", rows)


@dataclass(frozen=True)
class EvaluateRun:
    """A design evaluated over its workspace (:func:`reflector_opt.workflow.evaluate_run`).

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

    def __repr__(self):
        verdict = "inside" if self.summary["in_range"] else "OUTSIDE"
        return (
            f"EvaluateRun({len(self.summary['sensors'])} sensors, {verdict} their range over "
            f"{self.summary['workspace']['poses']} poses)"
        )

    def _repr_html_(self):
        rows = [
            (
                f"{s['name']} ({s['model']})",
                f"d {s['distance_mm']['min']:.3f}–{s['distance_mm']['max']:.3f} mm, "
                f"V {s['volts']['min']:.3f}–{s['volts']['max']:.3f} V, "
                + ("inside" if s["in_range"] else "OUTSIDE")
                + f" {s['range_mm'][0]}–{s['range_mm'][1]} mm",
            )
            for s in self.summary["sensors"]
        ]
        return _html_table("design evaluated over its workspace", rows)
