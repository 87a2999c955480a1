"""The report's print-correction section: what ``correct`` changed and what it predicts.

A design written by ``reflector-opt correct`` carries a ``correction`` block
(docs/print-loop.md): the batch and files it came from, each drawing change with its
uncertainty, the combinations left as drawn, and the next batch predicted without and with
the correction. :func:`correction_blocks` turns it into report blocks; a design without the
block gets none.
"""


def _number(value, digits=4):
    return "n/a" if value is None else f"{value:.{digits}g}"


def _source_text(correction):
    sources = correction.get("sources") or []
    files = ", ".join(str(s.get("file")) for s in sources) or "n/a"
    units = sum(len(s.get("units") or []) for s in sources)
    batch = correction.get("batch") or "unnamed"
    return (
        f"Corrected from {units or correction.get('n_units', 'n/a')} identified unit(s) of "
        f"print batch {batch} ({files}). Only combinations the calibration data determine "
        "and show to be systematic were changed (docs/print-loop.md)."
    )


def _prediction_rows(prediction):
    rows = []
    for key, label in (("without", "as drawn before"), ("with", "corrected")):
        figures = prediction.get(key) or {}
        worst = figures.get("worst_resolution_deg") or {}
        calibration = figures.get("calibration_rms_deg") or {}
        rows.append(
            (
                label,
                _number(worst.get("mean")),
                _number(worst.get("max")),
                _number(calibration.get("pitch")),
                _number(calibration.get("roll")),
            )
        )
    return rows


def correction_blocks(design):
    """Report blocks of a design's print correction (none if it carries none).

    Parameters
    ----------
    design : reflector_opt.design._design.Design

    Returns
    -------
    list of tuple
        Blocks as :func:`reflector_opt.report._report.report_blocks` returns them.
    """
    correction = design.correction
    if not correction:
        return []
    blocks = [("h2", "Print correction"), ("p", _source_text(correction))]
    changed = correction.get("changed") or {}
    if changed:
        rows = [
            (name, _number(row.get("change")), _number(row.get("std")))
            for name, row in changed.items()
        ]
        blocks.append(("table", ("drawing parameter", "change", "std"), rows))
    else:
        blocks.append(("p", "Nothing was changed: no determined deviation was significant."))
    left = correction.get("not_determined") or []
    if left:
        blocks.append(("p", "Left as drawn (not determined by the data): " + "; ".join(left)))
    prediction = correction.get("prediction")
    if prediction:
        blocks.append(
            (
                "table",
                (
                    "next batch",
                    "worst-case resolution, mean (°)",
                    "worst (°)",
                    "calibration RMS pitch (°)",
                    "roll (°)",
                ),
                _prediction_rows(prediction),
            )
        )
        blocks.append(
            (
                "p",
                f"Predicted gain in worst-case resolution: {_number(prediction.get('gain'))}× "
                "(the batch's own deviations printed again on each drawing).",
            )
        )
    return blocks
