"""What a workflow call returns: the run's results, the files it wrote, a ``repr`` and a
notebook display (the text the command prints, :class:`~reflector_opt.util._display.Printed`, or
a summary of its key figures, :class:`~reflector_opt.util._display.Summarised`) and a JSON-ready
summary (the commands' ``--json``)."""

from dataclasses import dataclass, field, replace
from pathlib import Path

from reflector_opt.util._display import Printed, Summarised
from reflector_opt.workflow._evaluate_text import format_summary

#: The file entries of a CAD export report, in the order they are listed.
_CAD_KEYS = ("stl", "3mf", "step", "png", "section_png")


def cad_names(report):
    """The file names of a :func:`~reflector_opt.cad.export_parts` report: parts, pictures,
    report.

    Parameters
    ----------
    report : dict or None
        The export's report (None when nothing was exported); it names its files within the
        output folder.

    Returns
    -------
    list of str
    """
    if report is None:
        return []
    names = [entry[key] for entry in report["files"].values() for key in _CAD_KEYS if key in entry]
    return [*names, report["report"]]


def cad_files(report, folder):
    """The files of a :func:`~reflector_opt.cad.export_parts` report in ``folder``
    (:func:`cad_names`).

    Parameters
    ----------
    report : dict or None
    folder : str or pathlib.Path
        The folder the export wrote into.

    Returns
    -------
    list of pathlib.Path
    """
    return [Path(folder) / name for name in cad_names(report)]


def written(run, folder, command, write_into):
    """A run written into ``folder``, whole or not at all
    (:func:`~reflector_opt.util._atomic.atomic_folder`).

    Parameters
    ----------
    run : dataclass
        A frozen run with ``out`` and ``files`` fields.
    folder : str or pathlib.Path
    command : sequence of str
        The command line recorded in the folder's manifest.
    write_into : callable
        ``write_into(work)`` writes the run's files into ``work``, the folder being built, and
        returns their names in it and a dict of the run's further fields it fills in.

    Returns
    -------
    dataclass
        ``run`` with ``out``, ``files`` (the folder's files, in the order named) and those
        fields set.
    """
    from reflector_opt.util._atomic import atomic_folder

    with atomic_folder(folder, command) as work:
        names, fields = write_into(work)
    out = Path(folder)
    return replace(run, out=out, files=tuple(out / name for name in names), **fields)


def cad_summary(cad, folder):
    """JSON-ready CAD outcome: were the parts written, why not, where their report is.

    Parameters
    ----------
    cad : reflector_opt.report._outputs.CadOutcome or None
    folder : pathlib.Path or None
        The folder the parts were written into.

    Returns
    -------
    dict
    """
    if cad is None or cad.error is not None:
        return {"written": False, "error": cad and cad.error, "report": None}
    return {"written": True, "error": None, "report": str(Path(folder) / cad.report["report"])}


@dataclass(frozen=True, repr=False)
class ReportRun(Summarised):
    """A design's report (:func:`reflector_opt.workflow._report.report`), its inputs read and
    checked; :meth:`write` renders and writes it.

    Attributes
    ----------
    design : reflector_opt.design._design.Design
    seed : int
        Seed of the simulations.
    as_built : reflector_opt.asbuilt._asbuiltfile.AsBuiltFile or None
        The units printed from the design, for the as-built section.
    conditions : reflector_opt.design._conditions.Conditions, str, pathlib.Path or None
        Operating conditions (None: the default ones).
    parts : bool
        Write the printable parts too.
    progress : callable or None
        ``progress(fraction, message)`` as the report is written.
    out : pathlib.Path or None
        The output folder, once written.
    cad : reflector_opt.report._outputs.CadOutcome or None
        The printable parts' outcome (None when not exported or not written yet).
    files : tuple of pathlib.Path
        Every file written, ``report.md`` and ``report.html`` first (the folder's
        ``manifest.json`` besides); empty before :meth:`write`.
    """

    design: object
    seed: int = 0
    as_built: object = None
    conditions: object = None
    parts: bool = True
    progress: object = field(default=None, compare=False)
    out: Path | None = None
    cad: object = None
    files: tuple = ()

    def write(self, folder, *, command=("reflector_opt", "report")):
        """Render the report (Markdown, HTML, figures) and, with ``parts``, the printable
        parts into ``folder``, whole or not at all.

        Returns
        -------
        ReportRun
            This run, written: ``out``, ``cad`` and ``files`` filled in.
        """
        from reflector_opt.report._outputs import write_design_outputs

        def write_into(work):
            paths, outcome = write_design_outputs(
                self.design,
                work,
                seed=self.seed,
                cad=self.parts,
                progress=self.progress,
                as_built=self.as_built,
                conditions=self.conditions,
            )
            names = [*(p.name for p in paths), *cad_names(outcome and outcome.report)]
            return names, {"cad": outcome}

        return written(self, folder, command, write_into)

    def to_dict(self):
        """JSON-ready summary (``report --json``): the pages, the parts, every file."""
        return {
            "out": None if self.out is None else str(self.out),
            "seed": self.seed,
            "as_built": self.as_built is not None,
            "markdown": str(self.files[0]) if self.files else None,
            "html": str(self.files[1]) if self.files else None,
            "cad": cad_summary(self.cad, self.out),
            "files": [str(path) for path in self.files],
        }

    def _summary(self):
        if not self.files:
            return "design report (not written yet)", [("seed", self.seed)]
        cad = cad_summary(self.cad, self.out)
        return "design report", [
            ("Markdown", str(self.files[0])),
            ("HTML", str(self.files[1])),
            ("as-built section", "yes" if self.as_built is not None else "no"),
            ("printable parts", "written" if cad["written"] else cad["error"] or "not exported"),
            ("files written", f"{len(self.files)} in {self.out}"),
        ]


@dataclass(frozen=True, repr=False)
class EvaluateRun(Printed):
    """A design evaluated over its workspace (:func:`reflector_opt.workflow.evaluate_run`).

    Its ``repr`` and notebook display are the text ``evaluate`` prints (:meth:`text`).

    Attributes
    ----------
    design : reflector_opt.design._design.Design
    summary : reflector_opt.tolerance._prediction.Evaluation
        The figures in use, the sensors' windows, the surface, the drift, the budget and the
        predicted calibration, read by attribute (``summary.in_use.worst_case_deg``,
        ``summary.sensors[0].margin_mm``, ``summary.calibration.recommended.rms_deg.pitch``).
    """

    design: object
    summary: object

    def to_dict(self):
        """The summary, JSON-ready (``evaluate --json``)."""
        return self.summary.to_dict()

    def text(self):
        """The text ``evaluate`` prints: ranges, surface, drift, budget, predicted errors."""
        return format_summary(self.summary)
