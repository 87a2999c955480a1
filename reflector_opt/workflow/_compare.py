"""Two designs side by side, as ``reflector-opt compare A.json B.json`` shows them.

Each design is evaluated as ``evaluate`` does (the figures in use, windows, drift sensitivity,
the error budget in the operating conditions given or the default ones, the predicted
calibration of built units), its resolution mapped on one grid, and every figure both have is
set beside the other's with the difference B − A, the figures in use first, and the two ranked
by their worst case in use. With an output folder, the two resolution maps and, where the two
workspaces share their grid, the map of the difference are written there (swapped in whole).
"""

import math
from dataclasses import dataclass, field
from pathlib import Path

from reflector_opt.design._conditions import as_conditions
from reflector_opt.report._in_use import QUOTE, in_use_figures, in_use_where
from reflector_opt.util._declared import takes
from reflector_opt.util._display import Printed
from reflector_opt.util._fileio import Record
from reflector_opt.util._progress import Phases
from reflector_opt.workflow._evaluate import CompareOptions

#: Pose grid of the resolution maps and their worst cases, degrees.
COMPARE_STEP_DEG = 0.5
#: The figures compared, as paths into the ``evaluate`` summary (a ``*`` stands for each
#: sensor by name, then each key below).
_COMPARED = (
    "in_use.worst_case_deg",
    "in_use.rms_deg",
    "in_use.median_deg",
    "in_use.white_noise_floor_deg",
    "metrics",
    "sensors",
    "drift_sensitivity.common",
    "budget",
    "calibration.eq5.rms_deg",
    "calibration.eq6.rms_deg",
    "calibration.recommended.rms_deg",
    "calibration.floor_rms_deg",
)


def _leaves(value, prefix=""):
    """Dotted path → number of every finite number in ``value`` (sensors keyed by name)."""
    if isinstance(value, dict):
        out = {}
        for key, item in value.items():
            out |= _leaves(item, f"{prefix}.{key}" if prefix else str(key))
        return out
    if (
        isinstance(value, list)
        and value
        and all(isinstance(v, dict) and "name" in v for v in value)
    ):
        return _leaves({v["name"]: v for v in value}, prefix)
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        return {}
    return {prefix: float(value)}


def compared_rows(summary_a, summary_b):
    """The figures of two ``evaluate`` summaries side by side.

    Parameters
    ----------
    summary_a, summary_b : dict
        :func:`~reflector_opt.tolerance._prediction.evaluation_summary` summaries, with a
        ``metrics`` block (worst-case 1σ resolution, degrees).

    Returns
    -------
    list of dict
        ``quantity`` (dotted path, its unit in its name), ``a``, ``b`` (None where that
        design has no such figure) and ``difference`` (B − A, None unless both have it), in
        the order of :data:`_COMPARED`.
    """
    rows = []
    for section in _COMPARED:
        a, b = (_leaves(_at(s, section), section) for s in (summary_a, summary_b))
        for key in [*a, *(k for k in b if k not in a)]:
            va, vb = a.get(key), b.get(key)
            difference = None if va is None or vb is None else vb - va
            rows.append({"quantity": key, "a": va, "b": vb, "difference": difference})
    return rows


def _at(summary, path):
    for key in path.split("."):
        summary = summary.to_dict() if isinstance(summary, Record) else summary
        summary = summary.get(key) if isinstance(summary, dict) else None
    return summary


@dataclass(frozen=True, repr=False)
class CompareRun(Printed):
    """Two designs compared (:func:`compare`), in memory; :meth:`write` writes the resolution
    maps and their difference.

    Attributes
    ----------
    designs : tuple of reflector_opt.design._design.Design
        A and B.
    sources : tuple of str
        Where each came from (a file, or ``built-in default``).
    summaries : tuple of dict
        Their ``evaluate`` summaries, each with a ``metrics`` block and its ``in_use``
        (:class:`~reflector_opt.design._in_use.InUse`).
    rows : tuple of dict
        :func:`compared_rows`.
    metrics : tuple
        Each design's :class:`~reflector_opt.analysis._metrics.Metrics` on the comparison's
        grid, for the figures.
    out : pathlib.Path or None
        The output folder, once written.
    files : tuple of pathlib.Path
        The figures written (empty before :meth:`write`).
    """

    designs: tuple
    sources: tuple
    summaries: tuple
    rows: tuple
    metrics: tuple = field(default=(), compare=False)
    out: Path | None = None
    files: tuple = ()

    def write(self, folder, *, command=("reflector_opt", "compare")):
        """Write the two designs' resolution maps and their difference into ``folder``,
        whole or not at all.

        Returns
        -------
        CompareRun
            This run, written: ``out`` and ``files`` filled in.
        """
        from reflector_opt.workflow._runs import written

        return written(
            self, folder, command, lambda work: (_figures(work, self.designs, self.metrics), {})
        )

    @property
    def better_in_use(self):
        """``"a"`` or ``"b"``, the design with the smaller worst case in use (None if equal)."""
        a, b = (s["in_use"].worst_case_deg for s in self.summaries)
        return None if a == b else "ab"[int(b < a)]

    def to_dict(self):
        """JSON-ready: the sources, the figures in use of each (``in_use``: the keys of
        ``evaluate``'s) and which is the better, the rows, the folder and its files
        (``--json``)."""
        return {
            "a": self.sources[0],
            "b": self.sources[1],
            "in_use": {
                "a": self.summaries[0]["in_use"].to_dict(),
                "b": self.summaries[1]["in_use"].to_dict(),
                "better": self.better_in_use,
            },
            "rows": list(self.rows),
            "folder": None if self.out is None else str(self.out),
            "files": [str(f) for f in self.files],
        }

    def text(self):
        """The two designs in use, ranked, then one line per figure: A, B and B − A."""
        lines = [f"A: {self.sources[0]}", f"B: {self.sources[1]}", *self._in_use_lines()]
        width = max(len(r["quantity"]) for r in self.rows)
        lines.append(f"{'quantity':<{width}}  {'A':>10}  {'B':>10}  {'B − A':>10}")
        for r in self.rows:
            cells = ("–" if r[k] is None else f"{r[k]:.4g}" for k in ("a", "b", "difference"))
            lines.append(f"{r['quantity']:<{width}}  " + "  ".join(f"{c:>10}" for c in cells))
        return "\n".join(lines)

    def _in_use_lines(self):
        a, b = (s["in_use"] for s in self.summaries)
        better = self.better_in_use
        verdict = "equal" if better is None else f"{better.upper()} is the better"

        def ratio(key):
            return f"{getattr(b, key) / getattr(a, key):.2f}×"

        return [
            f"{in_use_where(a)}:",
            f"  A: {in_use_figures(a)}",
            f"  B: {in_use_figures(b)}",
            f"  in use {verdict}: B's worst case is {ratio('worst_case_deg')} A's, its median "
            f"{ratio('median_deg')}",
            f"  {QUOTE}",
        ]


def _evaluated(design, step, progress, conditions, options):
    """The ``evaluate`` summary of ``design`` (in ``conditions``, the defaults where None) with
    its ``metrics`` block, and the metrics."""
    from reflector_opt.analysis._metrics import evaluate_metrics
    from reflector_opt.optimiser._conditions import search_conditions
    from reflector_opt.report._conditions import in_use_block
    from reflector_opt.tolerance._prediction import evaluation_summary

    judged = search_conditions("in-use", as_conditions(conditions))
    summary = {"in_use": in_use_block(design, conditions)}
    summary |= evaluation_summary(design, progress=progress, conditions=judged, **options).to_dict()
    metrics = evaluate_metrics(design, step)
    summary["metrics"] = {
        "worst_pitch_resolution_deg": metrics.worst_pitch_deg,
        "worst_roll_resolution_deg": metrics.worst_roll_deg,
    }
    return summary, metrics


def _figures(work, designs, metrics):
    """The two resolution maps and, on a shared grid, their difference; the names written."""
    from reflector_opt.report.figures._base import save_figure
    from reflector_opt.report.figures._resolution import (
        resolution_difference_figure,
        resolution_maps_figure,
    )

    names = []
    for label, design, found in zip("ab", designs, metrics, strict=True):
        save_figure(resolution_maps_figure(found, design), work / f"resolution_maps_{label}.png")
        names.append(f"resolution_maps_{label}.png")
    grids = [d.workspace.axes(COMPARE_STEP_DEG) for d in designs]
    if all(len(x) == len(y) and (x == y).all() for x, y in zip(*grids, strict=True)):
        figure = resolution_difference_figure(*metrics, designs[0])
        save_figure(figure, work / "resolution_difference.png")
        names.append("resolution_difference.png")
    return names


@takes(CompareOptions)
def compare(a, b=None, options=None, progress=None):
    """Compare two designs in memory: ``reflector-opt compare``; :meth:`CompareRun.write`
    writes the resolution maps.

    Parameters
    ----------
    a, b : reflector_opt.design._design.Design, str, pathlib.Path or None
        The designs or their ``design.json``; None for the built-in default design (for
        ``b`` with ``a`` given: the built-in geometry in A's unit,
        :func:`~reflector_opt.design._defaults.default_design` ``(like=A)``, the design
        ``evaluate`` and ``optimise`` compare A with).
    options : CompareOptions
        As keyword arguments (below), as ``evaluate`` takes them: both designs are judged in
        the conditions, and the same seed simulates both designs' calibrations.
    progress : callable, optional
        ``progress(fraction, message)`` of the whole comparison.

    Returns
    -------
    CompareRun

    Raises
    ------
    InputError
        A design or conditions file that cannot be read.
    """
    from reflector_opt.design import Design, as_design
    from reflector_opt.design._defaults import default_design

    first = as_design(a)
    designs = (first, as_design(b) if b is not None or a is None else default_design(like=first))
    sources = tuple(
        "built-in default"
        if given is None
        else ("given" if isinstance(given, Design) else str(given))
        for given in (a, b)
    )
    if b is None and a is not None:
        sources = (sources[0], "built-in default, in A's unit")
    conditions = options.conditions
    options = {"predict": options.predict, "seed": options.seed}
    as_conditions(conditions)  # read before any work: a file that cannot be read is refused
    phases = Phases(progress, {"a": 1.0, "b": 1.0})
    evaluated = [
        _evaluated(d, COMPARE_STEP_DEG, phases(label), conditions, options)
        for d, label in zip(designs, "ab", strict=True)
    ]
    phases.finish("compared")
    summaries, metrics = zip(*evaluated, strict=True)
    return CompareRun(designs, sources, summaries, tuple(compared_rows(*summaries)), metrics)
