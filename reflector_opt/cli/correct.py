"""``reflector-opt correct AS_BUILT.json [more …] [--design D] -o DIR``: correct the next print.

Pools the identified units of one print batch, separates the deviation that repeats (the
batch mean) from the unit-to-unit scatter, pre-compensates the drawing by every determined
and significant systematic deviation, predicts the next batch with and without the
correction, and writes DIR/design.json (with its ``correction`` block) and the corrected
parts with the checks of ``export``. Nothing is written if any step fails
(docs/print-loop.md).
"""

from __future__ import annotations

from reflector_opt.cli.arguments import (
    DEFAULT_OUT,
    add_output_folder,
    number,
    output_folder,
    seed,
)
from reflector_opt.cli.export import add_chord_tolerance
from reflector_opt.cli.output import cad_files, folder_lines, print_json, progress_for


def register(subparsers):
    """Add the ``correct`` subcommand."""
    p = subparsers.add_parser(
        "correct",
        help="pre-compensate the next print by the systematic deviation of a printed batch",
        description=(
            "Pool the AS_BUILT.json files of one print batch (written by identify), estimate "
            "the deviation that repeats from print to print and the unit-to-unit scatter, "
            "correct the drawing by every systematic deviation the data determine and show "
            "to be significant, predict the next batch with and without the correction, and "
            "write DIR/design.json and the corrected parts (the checks of export)."
        ),
    )
    p.add_argument("as_built", nargs="+", metavar="AS_BUILT.json", help="identified units")
    p.add_argument(
        "--design",
        metavar="DESIGN.json",
        help="the design to correct: the one the units were printed from (default: the one "
        "the as-built files record)",
    )
    add_output_folder(p, f"{DEFAULT_OUT}/corrected", "design.json and the corrected parts")
    _add_correction_options(p)
    p.add_argument(
        "--no-prediction", action="store_true", help="skip the prediction of the next batch"
    )
    p.add_argument(
        "--seed", type=seed, default=0, metavar="N", help="seed of the predicted calibration"
    )
    p.add_argument("--config", metavar="FILE.toml", help="CAD parameters (see docs/cad.md)")
    add_chord_tolerance(p)
    p.add_argument("--no-preview", action="store_true", help="skip the PNG pictures")
    p.add_argument("--json", action="store_true", help="print the full summary as JSON")
    p.set_defaults(handler=run)


def _add_correction_options(p):
    """The options that decide which deviations are corrected."""
    p.add_argument(
        "--assume-systematic",
        action="store_true",
        help="with fewer than 3 units, take their deviation as systematic (it cannot be told "
        "from the scatter)",
    )
    p.add_argument(
        "--level",
        type=number(0, 10),
        default=2.0,
        metavar="T",
        help="correct a determined combination when |estimate| > T × its std (default 2)",
    )
    p.add_argument(
        "--max-std",
        type=number(0, 10, low_open=True),
        default=1.0,
        metavar="S",
        help="correct a combination only where the batch mean is known to within S × the "
        "tolerance spread (default 1)",
    )
    p.add_argument(
        "--model-form",
        choices=("auto", "simulate", "none"),
        default="auto",
        help="weigh the identification's model-form bias as an uncertainty common to the "
        "batch: the term the as-built files record, or if they record none, simulated on "
        "units with physics the fast model lacks (auto, the default; about 10 s); simulate: "
        "always simulated; none: trust the identification's model",
    )


def _plan(args):
    """Read, check, pool and correct: (batch mean, correction, corrected design, prediction)."""
    from reflector_opt.asbuilt.batch import check_design, load_batch
    from reflector_opt.asbuilt.correction import (
        check_not_applied,
        corrected_design,
        plan_correction,
    )
    from reflector_opt.asbuilt.formbias import weigh_model_form
    from reflector_opt.asbuilt.nextbatch import predict_next_batch
    from reflector_opt.asbuilt.pooling import MIN_UNITS, pool
    from reflector_opt.design import load_design
    from reflector_opt.util.errors import InputError

    batch = load_batch(args.as_built)
    design = batch.design if args.design is None else load_design(args.design)
    name = args.design or "the as-built files' design"
    check_not_applied(design, batch, name)
    check_design(batch, design, name)
    if batch.n_units < MIN_UNITS and not args.assume_systematic:
        raise InputError(
            f"{batch.n_units} unit(s) cannot tell a systematic deviation from the unit-to-unit "
            f"scatter ({MIN_UNITS} needed); identify more units of the batch, or pass "
            "--assume-systematic to take their deviation as systematic"
        )
    batch, model_form = weigh_model_form(batch, args.model_form, args.seed)
    mean = pool(batch, args.assume_systematic, model_form)
    correction = plan_correction(mean, level=args.level, max_std=args.max_std)
    drawing = corrected_design(design, correction)
    prediction = None
    if not args.no_prediction:
        prediction = predict_next_batch(batch, drawing, seed=args.seed)
        drawing = corrected_design(design, correction, prediction)
    return mean, correction, drawing, prediction


def run(args):
    """Correct, export, report; returns the exit code."""
    from reflector_opt.cad.export import export_parts
    from reflector_opt.design.parts import load_cad_parameters
    from reflector_opt.util.atomic import atomic_folder
    from reflector_opt.util.errors import InputError

    output_folder(args.out)  # refused before any work, named by its option
    params = None if args.config is None else load_cad_parameters(args.config)
    mean, correction, drawing, prediction = _plan(args)
    with progress_for(args) as progress, atomic_folder(args.out, args.argv) as work:
        drawing.save(work / "design.json")
        try:
            report = export_parts(
                drawing,
                work,
                parts=("reflector", "body"),
                tolerance_mm=args.chord_tolerance,
                params=params,
                preview=not args.no_preview,
                progress=progress,
            )
        except InputError as exc:
            raise InputError(f"the corrected design cannot be exported: {exc}") from None
    if args.json:
        summary = {
            "batch": mean.to_dict(),
            "correction": correction.to_dict(),
            "prediction": prediction,
            "cad": report,
        }
        print_json(summary)
    else:
        print(format_report(mean, correction, prediction))
        files = [args.out + "/design.json", *cad_files(report, args.out)]
        print(folder_lines(args.out, files, args.started))
    return 0


#: Undetermined combinations listed in the text output.
_LISTED = 5

#: Smallest change listed in the text output, per unit (--json lists every one).
_SHOWN = {" mm": 0.0005, "°": 0.005}


def _unit(name):
    return "°" if name.endswith("_deg") else " mm"


def _batch_lines(mean):
    batch = mean.batch
    where = f"batch {batch.batch!r}" if batch.batch else "batch (no name recorded)"
    scatter = (
        "estimated"
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


def format_report(mean, correction, prediction):
    """Human-readable lines: the batch, the determined combinations, the changes, the gain."""
    lines = _batch_lines(mean)
    lines.append("determined combinations: batch mean ± std, in tolerance-spread units")
    for direction, applied, resolved in zip(
        mean.directions, correction.applied, correction.resolved, strict=True
    ):
        state = "corrected" if applied else ("left" if resolved else "left, std > tolerance")
        form = f", model form ± {direction.model_form:.2f}" if mean.model_form else ""
        if direction.reference > 0.005:
            form += f", angle reference ± {direction.reference:.2f}"
        lines.append(
            f"  {direction.name}: {direction.estimate:+.2f} ± {direction.std:.2f} "
            f"(t {direction.t:+.1f}{form}, {state})"
        )
    test = "significant" if correction.significant else "not significant"
    lines.append(
        f"systematic deviation: χ² {correction.chi2:.1f} on {correction.dof} resolved "
        f"combination(s), {correction.confidence:.0%} threshold {correction.threshold:.1f}: "
        f"{test}"
    )
    rows = {k: r for k, r in correction.rows().items() if abs(r["change"]) >= _SHOWN[_unit(k)]}
    if not correction.changes_anything:
        lines.append("changes to the drawing: none (the design is unchanged)")
    else:
        lines.append("changes to the drawing (± std; below 0.5 µm and 0.005° not listed):")
    for name, row in rows.items():
        unit = _unit(name)
        lines.append(f"  {name:<32}{row['change']:+.4f}{unit} ± {row['std']:.4f}{unit}")
    if mean.undetermined:
        lines.append("left as drawn, not determined by the data:")
        lines += [f"  {d.name}" for d in mean.undetermined[:_LISTED]]
        if len(mean.undetermined) > _LISTED:
            lines.append(f"  and {len(mean.undetermined) - _LISTED} more (--json lists them)")
    if prediction is not None:
        lines += _prediction_lines(prediction)
    return "\n".join(lines)


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
