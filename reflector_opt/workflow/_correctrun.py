"""What :func:`reflector_opt.workflow.correct` returns: the correction, the predicted next
batch before and after, the parts checked and, once written, the files; its text
(``correct``'s output, also its ``repr`` and notebook display) and the JSON summary of
``--json``."""

from dataclasses import dataclass

from reflector_opt.util._display import Printed
from reflector_opt.workflow._runs import cad_names, written

#: The command recorded in an output folder's manifest when the library wrote it.
LIBRARY_COMMAND = ("reflector_opt", "correct")

#: Undetermined combinations listed in the text.
_LISTED = 5

#: Smallest change listed in the text, per unit (``to_dict`` lists every one).
_SHOWN = {" mm": 0.0005, "°": 0.005}


def _unit(name):
    return "°" if name.endswith("_deg") else " mm"


@dataclass(frozen=True, repr=False)
class CorrectRun(Printed):
    """A print correction made (:func:`reflector_opt.workflow.correct`), in memory;
    :meth:`write` writes it.

    Attributes
    ----------
    mean : reflector_opt.asbuilt._pooling.BatchMean
        The batch mean, its uncertainty and the scatter.
    correction : reflector_opt.asbuilt._correction.Correction
        The shrunk correction with its step and what it gave up.
    design : reflector_opt.design._design.Design
        The corrected design written (its ``correction`` block records it all).
    prediction : dict or None
        :func:`~reflector_opt.asbuilt._batchforecast.predict_next_batch` (None: not asked for).
    losses : dict
        The next batch's expected loss per step, degrees (empty: nothing to choose).
    figures : dict
        ``without`` and ``with``: :func:`~reflector_opt.asbuilt._userloss.batch_figures` of the
        predicted next batch (angle error, drift sensitivity, margins).
    parts : reflector_opt.cad._export.CheckedParts
        The corrected parts, built and checked as export checks them.
    preview : bool
        Their pictures are written too.
    cad : dict or None
        The export's report of the corrected parts, once written.
    out : pathlib.Path or None
        The output folder, once written.
    files : tuple of pathlib.Path
        Every file written, ``design.json`` first (the folder's ``manifest.json`` besides).
    """

    mean: object
    correction: object
    design: object
    prediction: dict | None
    losses: dict
    figures: dict
    parts: object
    preview: bool = True
    cad: dict | None = None
    out: object = None
    files: tuple = ()

    def write(self, folder, *, command=LIBRARY_COMMAND, progress=None):
        """Write ``design.json`` and the corrected parts into ``folder``, whole or not at all.

        Parameters
        ----------
        folder : str or pathlib.Path
        command : sequence of str, optional
            The command line recorded in the folder's manifest.
        progress : callable, optional
            ``progress(fraction, message)`` as the pictures are drawn.

        Returns
        -------
        CorrectRun
            This run with ``cad``, ``out`` and ``files`` filled in.
        """

        def write_into(work):
            self.design.save(work / "design.json")
            report = self.parts.write(work, preview=self.preview, progress=progress)
            return ["design.json", *cad_names(report)], {"cad": report}

        return written(self, folder, command, write_into)

    def to_dict(self):
        """JSON-ready summary (``correct --json``)."""
        return {
            "batch": self.mean.to_dict(),
            "correction": self.correction.to_dict(),
            "expected_loss_deg": {f"{k:g}": v for k, v in self.losses.items()},
            "figures": self.figures,
            "prediction": self.prediction,
            "cad": self.cad,
            "files": [str(path) for path in self.files],
        }

    def text(self):
        """Human-readable lines: the batch, the directions, the step, the changes, the gain."""
        lines = _batch_lines(self.mean) + _direction_lines(self.mean, self.correction)
        lines += _change_lines(self.correction) + _left_lines(self.mean)
        lines += _figure_lines(self.figures)
        if self.prediction is not None:
            lines += _prediction_lines(self.prediction)
        return "\n".join(lines)


def _batch_lines(mean):
    batch = mean.batch
    where = f"batch {batch.batch!r}" if batch.batch else "batch (no name recorded)"
    scatter = (
        f"estimated, prior scale {mean.scatter_prior:g}"
        if mean.scatter_estimated
        else ("assumed: none, --assume-systematic" if mean.assume_systematic else "assumed")
    )
    lines = [
        f"{where}: {batch.n_units} unit(s) from {len(batch.sources)} file(s); unit-to-unit "
        f"scatter {mean.scatter_factor:.2f}× the tolerance model's ({scatter})"
    ]
    if mean.model_form:
        where = ", ".join(mean.model_form)
        lines.append(
            f"  the identification's model-form bias is weighed as an uncertainty ({where})"
        )
    if not mean.separable:
        lines.append(
            "  note: fewer than 3 units cannot tell systematic from random; their deviation "
            "is taken as systematic"
        )
    return lines


def _direction_lines(mean, correction):
    lines = ["determined combinations: batch mean ± std, in tolerance-spread units"]
    for direction, a, resolved in zip(
        mean.directions, correction.factors, correction.resolved, strict=True
    ):
        share = a * correction.step
        state = (
            f"corrected by {share:.2f}"
            if share > 0
            else ("left" if resolved else "left, std > tolerance")
        )
        form = f", model form ± {direction.model_form:.2f}" if mean.model_form else ""
        if direction.reference > 0.005:
            form += f", angle reference ± {direction.reference:.2f}"
        lines.append(
            f"  {direction.name}: {direction.estimate:+.2f} ± {direction.std:.2f} "
            f"(t {direction.t:+.1f}{form}, {state})"
        )
    lines.append(
        f"rule: each resolved combination by max(0, 1 − ({correction.level:g}/t)²), times the "
        f"step {correction.step:.3g} (least expected loss, predicted print printable)"
    )
    lines += [f"  given up: {text}" for text in correction.given_up]
    return lines


def _change_lines(correction):
    rows = {k: r for k, r in correction.rows().items() if abs(r["change"]) >= _SHOWN[_unit(k)]}
    if not correction.changes_anything:
        return ["changes to the drawing: none (the design is unchanged)"]
    lines = ["changes to the drawing (± std; below 0.5 µm and 0.005° not listed):"]
    for name, row in rows.items():
        unit = _unit(name)
        lines.append(f"  {name:<32}{row['change']:+.4f}{unit} ± {row['std']:.4f}{unit}")
    return lines


def _left_lines(mean):
    if not mean.undetermined:
        return []
    lines = ["left as drawn, not determined by the data:"]
    lines += [f"  {d.name}" for d in mean.undetermined[:_LISTED]]
    if len(mean.undetermined) > _LISTED:
        lines.append(f"  and {len(mean.undetermined) - _LISTED} more (--json lists them)")
    return lines


def _mm(values):
    return "/".join(f"{1e3 * v:.0f}" for v in values)


def _figure_lines(figures):
    lines = ["next batch, predicted (fast model): without → with the correction"]
    a, b = figures["without"], figures["with"]
    lines.append(
        f"  worst-case resolution, mean over units: {a['angle_deg']['mean']:.4f}° → "
        f"{b['angle_deg']['mean']:.4f}°; drift per 1 % light: {a['drift_deg']['mean']:.4f}° → "
        f"{b['drift_deg']['mean']:.4f}°"
    )
    lines.append(
        f"  smallest margins, µm: window {_mm(a['window_mm'])} → {_mm(b['window_mm'])}; peak "
        f"{_mm(a['peak_mm'])} → {_mm(b['peak_mm'])}; clearance "
        f"{_mm([a['clearance_mm']])} → {_mm([b['clearance_mm']])}"
    )
    return lines


def _deg(value):
    """Degrees with 4 decimals, or "no sensitivity" for a figure that is not finite."""
    return "no sensitivity" if value is None else f"{value:.4f}°"


def _prediction_lines(prediction):
    without, corrected = prediction["without"], prediction["with"]
    gain = "n/a" if prediction["gain"] is None else f"{prediction['gain']:.3f}×"
    lines = [
        "next batch, predicted (fast model, this batch's deviations printed again):",
        f"  worst-case resolution, mean over units: "
        f"{_deg(without['worst_resolution_deg']['mean'])} without, "
        f"{_deg(corrected['worst_resolution_deg']['mean'])} with the correction (gain {gain})",
    ]
    if "calibration_rms_deg" in without:
        a, b = without["calibration_rms_deg"], corrected["calibration_rms_deg"]
        lines.append(
            f"  calibration RMS (pitch, roll): {a['pitch']:.4f}°, {a['roll']:.4f}° without; "
            f"{b['pitch']:.4f}°, {b['roll']:.4f}° with"
        )
    return lines
