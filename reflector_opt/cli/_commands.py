"""The subcommands of ``reflector-opt``: each one's parser (``add_<name>``) and handler
(``run_<name>``).

An ``add_<name>(subparsers)`` adds the command's parser: its inputs, its output (``-o/--out``,
a folder or a file, :mod:`reflector_opt.cli._arguments`), its options as the run declares
them (:func:`~reflector_opt.util._declared.add_options`) and ``--json``. A ``run_<name>(args)``
reads the options back, checked once (:func:`~reflector_opt.util._declared.options_of`),
refuses an output that cannot be written before any work, makes the run through the
workflow, writes it and prints it (:func:`~reflector_opt.cli._command.print_run`); it
returns the exit code. The workflow is imported in the handler, so that ``--help`` loads only
the declarations' light modules (tests/test_startup.py). The commands' pages in the docs:
docs/cli.md (generated from these parsers) and the page each handler names.
"""

import sys

from reflector_opt.cli._arguments import (
    DEFAULT_OUT,
    add_output_file,
    add_output_folder,
    deprecated_alias,
    output_file,
    refuse_output_over_inputs,
)
from reflector_opt.cli._command import call_into_folder, print_run
from reflector_opt.cli._output import folder_lines, print_json, progress_for
from reflector_opt.util._declared import add_options, options_of
from reflector_opt.workflow._calibrate import CalibrateOptions
from reflector_opt.workflow._correct import CorrectOptions
from reflector_opt.workflow._estimate import EstimateOptions
from reflector_opt.workflow._evaluate import CompareOptions, EvaluateOptions
from reflector_opt.workflow._export import ExportOptions
from reflector_opt.workflow._firmware import FirmwareOptions
from reflector_opt.workflow._fit_sensor import FitSensorOptions
from reflector_opt.workflow._identify import IdentifyOptions
from reflector_opt.workflow._options import OptimiseOptions
from reflector_opt.workflow._plan_calibration import PlanCalibrationOptions
from reflector_opt.workflow._record import RecordOptions
from reflector_opt.workflow._report import ReportOptions
from reflector_opt.workflow._smallest import SmallestOptions
from reflector_opt.workflow._stream import StreamOptions
from reflector_opt.workflow._sweep import SweepOptions
from reflector_opt.workflow._tolerance import ToleranceOptions


def _parser(subparsers, name, run, help, description):
    """A subcommand's parser, with ``run`` as its handler."""
    parser = subparsers.add_parser(name, help=help, description=description)
    parser.set_defaults(handler=run)
    return parser


def _json(parser, help="print the summary as JSON"):
    parser.add_argument("--json", action="store_true", help=help)


def add_evaluate(subparsers):
    """Add the ``evaluate`` subcommand."""
    p = _parser(
        subparsers,
        "evaluate",
        run_evaluate,
        "distance and voltage ranges of a design over its workspace",
        "Evaluate a design over its workspace; with no file, the built-in default.",
    )
    p.add_argument("design", metavar="DESIGN.json", nargs="?", help="default: the built-in design")
    add_options(p, EvaluateOptions)
    _json(p, "print machine-readable JSON")


def run_evaluate(args):
    """``reflector-opt evaluate [DESIGN.json]``: distance and voltage ranges of a design and
    its predicted calibration and segment errors (:func:`reflector_opt.workflow.evaluate`).
    A design whose printable parts cannot be laid out is refused with the message ``export``
    gives."""
    from reflector_opt.workflow import evaluate

    with progress_for(args) as progress:
        run = evaluate(args.design, options_of(args, EvaluateOptions), progress=progress)
    if args.json:
        print_json(run.to_dict())
    else:
        print(run.text())
    return 0


def add_optimise(subparsers):
    """Add the ``optimise`` subcommand."""
    p = _parser(
        subparsers,
        "optimise",
        run_optimise,
        "optimise the reflector and sensor placement; writes design.json",
        "Find the reflector radius, centre offset and sensor placement, with the drive "
        "and calibration they are read with, of least worst-case error in use (the default "
        "conditions, or --conditions; --objective resolution: the white-noise resolution) "
        "that keeps every sensor inside its usable range and meets the envelope, wall and "
        "no-fold constraints. With no options it runs on the built-in defaults and writes "
        "cad_out/design.json.",
    )
    add_output_folder(p, DEFAULT_OUT, "design.json, the report and the parts")
    add_options(p, OptimiseOptions)
    _json(p)


def run_optimise(args):
    """``reflector-opt optimise``: the design of least worst-case error in use
    (:func:`reflector_opt.workflow.optimise`; its options
    :class:`~reflector_opt.workflow._options.OptimiseOptions`), written with its report and
    parts; a robust margin that did not converge is a warning."""
    from reflector_opt.workflow import optimise

    run = call_into_folder(args, optimise, options_of(args, OptimiseOptions))
    if run.robust is not None and not run.robust.converged:
        print(
            "reflector-opt optimise: warning: the robust margin did not converge in "
            f"{len(run.robust.rounds)} rounds; design.json keeps the last round "
            "(raise [robust] max_rounds)",
            file=sys.stderr,
        )
    return print_run(args, run, folder=run.out)


def add_fit_sensor(subparsers):
    """Add the ``fit-sensor`` subcommand."""
    p = _parser(
        subparsers,
        "fit-sensor",
        run_fit_sensor,
        "fit a sensor model, or a material (--material), to a measured distance curve",
        "Fit a sensor preset's optical parameters and gain to a curve measured against a "
        "flat reference target (CSV columns distance_mm, volts) and write a design that "
        "uses the fitted model; or, with --material, fit the reflectance and specular "
        "fraction of a flat sample of the reflector's material, the sensor known.",
    )
    p.add_argument("curve", help="CSV with columns distance_mm, volts")
    add_output_file(
        p,
        "design.json (required without --material; with it, optional: the design with the "
        "fitted material)",
        required=False,
    )
    add_options(p, FitSensorOptions)
    p.add_argument(
        "--part-file",
        type=output_file,
        metavar="PARTS",
        help="also write the fitted sensor as a sensor-catalogue part file (the base's package, "
        "the measured peak), for optimise --sensor PARTS.toml",
    )
    _json(p, "print machine-readable JSON")


def run_fit_sensor(args):
    """``reflector-opt fit-sensor CURVE.csv``: a sensor model fitted to a curve measured
    against a reference target, or with ``--material`` the sample's reflectance, specular
    fraction and sub-surface spread (:func:`~reflector_opt.workflow._fit_sensor.fit_sensor`),
    written into the design (``-o``) and the part (``--part-file``)."""
    from reflector_opt.workflow._fit_sensor import check_outputs, fit_sensor

    options = options_of(args, FitSensorOptions)
    check_outputs(options.material, args.output, args.part_file)
    if args.output is not None:  # the design given may be updated in place, not the curve
        inputs = {"curve": args.curve, "--reference": options.reference}
        refuse_output_over_inputs(args.output, inputs)
    if args.part_file is not None:
        inputs = {"curve": args.curve, "-o": args.output}
        refuse_output_over_inputs(args.part_file, inputs, option="--part-file")
    run = fit_sensor(args.curve, options).write(args.output, args.part_file)
    return print_run(args, run)


def add_calibrate(subparsers):
    """Add the ``calibrate`` subcommand."""
    p = _parser(
        subparsers,
        "calibrate",
        run_calibrate,
        "fit per-unit calibrations to measured data (CSV)",
        "Fit one calibration model per unit to a CSV with columns unit, v1, v2, "
        "pitch_deg, roll_deg (one row per sample) and write the coefficients as JSON. With "
        "a temperature_c column (°C) spanning at least 1 K, each unit's form is "
        "temperature-compensated (its sensors' gain and offset change per kelvin fitted "
        "with it); the logs to estimate then need that column too.",
    )
    p.add_argument("data", help="calibration CSV")
    add_options(p, CalibrateOptions)
    add_output_file(p, "the coefficients (JSON)")
    _json(p)


def run_calibrate(args):
    """``reflector-opt calibrate DATA.csv -o coefficients.json``: one calibration model per
    unit, its k-fold cross-validated error printed (nothing written if any unit fails)."""
    from reflector_opt.workflow._calibrate import calibrate

    options = options_of(args, CalibrateOptions)
    refuse_output_over_inputs(args.output, {"data": args.data, "--design": options.design})
    with progress_for(args) as progress:
        run = calibrate(args.data, options, progress=progress).write(args.output)
    return print_run(args, run, [args.output])


def add_estimate(subparsers):
    """Add the ``estimate`` subcommand."""
    p = _parser(
        subparsers,
        "estimate",
        run_estimate,
        "unit and tip angles from a voltage log",
        "Estimate every unit's pitch and roll from a voltage log (columns unit, v1, v2 and "
        "optionally sample or time, and temperature_c, which a temperature-compensated "
        "calibration needs) with the coefficients written by calibrate, and the tip's "
        "angles and position; units are chained base first in the coefficients' order. "
        "Each angle's 1σ (the calibration's cross-validated error, --noise-v through "
        "its gradient and, with --conditions, the in-use error budget's bias) is in the "
        "last columns.",
    )
    p.add_argument(
        "coefficients", help="coefficients JSON written by calibrate, or AS_BUILT.json by identify"
    )
    p.add_argument("log", help="voltage log CSV")
    add_options(p, EstimateOptions)
    add_output_file(p, "the angles (CSV)")
    _json(p)


def run_estimate(args):
    """``reflector-opt estimate coefficients.json LOG.csv -o angles.csv``: per-unit pitch and
    roll and, when the log holds every calibrated unit, the tip's orientation and position."""
    from reflector_opt.workflow._estimate import estimate

    refuse_output_over_inputs(args.output, {"coefficients": args.coefficients, "log": args.log})
    options = options_of(args, EstimateOptions)
    run = estimate(args.coefficients, args.log, options).write(args.output)
    return print_run(args, run, [args.output])


def add_firmware(subparsers):
    """Add the ``firmware`` subcommand."""
    p = _parser(
        subparsers,
        "firmware",
        run_firmware,
        "the calibration as a C99 header for the microcontroller",
        "Write the coefficients of calibrate as a C99 header: per unit, pitch and roll from "
        "its voltages (and temperature, where compensated), in float and in fixed point; "
        "prints the operations per frame, the fixed-point error and the code size.",
    )
    p.add_argument("coefficients", help="coefficients JSON written by calibrate")
    add_options(p, FirmwareOptions)
    add_output_file(p, "the C header")
    _json(p)


def run_firmware(args):
    """``reflector-opt firmware coefficients.json -o calibration.h``: the calibration as a C99
    header (docs/robot.md), float and fixed point."""
    from reflector_opt.workflow._firmware import firmware

    refuse_output_over_inputs(args.output, {"coefficients": args.coefficients})
    options = options_of(args, FirmwareOptions)
    run = firmware(args.coefficients, options).write(args.output)
    return print_run(args, run, [args.output])


def add_stream(subparsers):
    """Add the ``stream`` subcommand."""
    p = _parser(
        subparsers,
        "stream",
        run_stream,
        "live angles from a device's frames",
        "Read a device's frames (docs/robot.md) from a link and write each frame's per-unit "
        "pitch and roll with their 1σ and the tip's pose to a CSV, flushed block by block, "
        "and with --mcap to an MCAP log with ROS 2 schemas (JointState, TFMessage); "
        "prints the frames, the link's faults and whether the estimator kept up.",
    )
    p.add_argument("link", help="serial:PORT, udp:HOST:PORT, - (standard input) or a file")
    p.add_argument("coefficients", help="coefficients JSON written by calibrate")
    add_options(p, StreamOptions)
    add_output_file(p, "the angles (CSV)")
    _json(p)


def run_stream(args):
    """``reflector-opt stream LINK coefficients.json -o angles.csv [--mcap FILE]``: each
    frame's angles with their 1σ, block by block, until the link ends, a bound is reached or
    Ctrl-C (which prints the summary and exits 130, every file closed whole)."""
    from reflector_opt.workflow._stream import stream

    options = options_of(args, StreamOptions)
    inputs = {"coefficients": args.coefficients, "link": args.link}
    refuse_output_over_inputs(args.output, inputs)
    if options.mcap:
        refuse_output_over_inputs(options.mcap, {**inputs, "--out": args.output}, "--mcap")
    run = stream(args.link, args.coefficients, options).write(args.output)
    code = print_run(args, run)
    return 130 if run.interrupted else code


def add_identify(subparsers):
    """Add the ``identify`` subcommand."""
    p = _parser(
        subparsers,
        "identify",
        run_identify,
        "identify how printed units were built from their calibration data",
        "Estimate each unit's as-built geometry and read-out (and the batch's surface) "
        "from a calibration CSV (columns unit, v1, v2, pitch_deg, roll_deg), with the "
        "tolerance model as the prior, and write AS_BUILT.json.",
    )
    p.add_argument("data", help="calibration CSV (one or more units)")
    add_options(p, IdentifyOptions)
    _json(p)
    add_output_file(p, "AS_BUILT.json")


def run_identify(args):
    """``reflector-opt identify CAL.csv -o AS_BUILT.json``: how each unit was built, each
    parameter's uncertainty and whether the data determine it, and the angle reference's
    offsets (nothing written if any unit fails)."""
    from reflector_opt.workflow._identify import identify

    options = options_of(args, IdentifyOptions)
    inputs = {"data": args.data, "--design": options.design, "--tolerances": options.tolerances}
    inputs["--conditions"] = options.conditions
    inputs.update({f"--curve {c}": c.partition("=")[2] or None for c in options.curves})
    refuse_output_over_inputs(args.output, inputs)
    with progress_for(args) as progress:
        run = identify(args.data, options, progress=progress).write(args.output)
    return print_run(args, run, [args.output])


def add_correct(subparsers):
    """Add the ``correct`` subcommand."""
    p = _parser(
        subparsers,
        "correct",
        run_correct,
        "pre-compensate the next print by the systematic deviation of a printed batch",
        "Pool the AS_BUILT.json files of one print batch (written by identify), estimate "
        "the deviation that repeats from print to print and the unit-to-unit scatter, "
        "correct the drawing by every systematic deviation the data determine and show "
        "to be significant, predict the next batch with and without the correction, and "
        "write DIR/design.json and the corrected parts (the checks of export).",
    )
    p.add_argument("as_built", nargs="+", metavar="AS_BUILT.json", help="identified units")
    add_output_folder(p, f"{DEFAULT_OUT}/corrected", "design.json and the corrected parts")
    add_options(p, CorrectOptions)
    _json(p, "print the full summary as JSON")


def run_correct(args):
    """``reflector-opt correct AS_BUILT.json [more …] -o DIR``: the next print corrected
    (:func:`reflector_opt.workflow.correct`); nothing is written if any step fails
    (docs/print-loop.md)."""
    from reflector_opt.workflow import correct

    options = options_of(args, CorrectOptions)
    run = call_into_folder(args, correct, args.as_built, options)
    return print_run(args, run, folder=args.out)


def add_plan_calibration(subparsers):
    """Add the ``plan-calibration`` subcommand."""
    p = _parser(
        subparsers,
        "plan-calibration",
        run_plan_calibration,
        "predicted calibration error against the number and pattern of poses",
        "Predict the RMS and maximum calibration error of each form (eq6, auto, physical) "
        "on plans of each pattern (the paper's raster, coarse grids, Sobol points, a "
        "spiral) and size, against built units of the design; recommend the smallest plan "
        "within a fraction of the Cramér–Rao floor and write it as a CSV of poses. With "
        "--for identification, choose the D-optimal poses for identifying a unit's "
        "as-built parameters and the number that brings each determinable one to "
        "--target-std of its prior std, beside Sobol points and grids.",
    )
    p.add_argument("design", metavar="DESIGN.json", nargs="?", help="default: the built-in design")
    add_options(p, PlanCalibrationOptions)
    _json(p, "print the summary (the table, the recommendation and the files) as JSON")
    add_output_folder(p, f"{DEFAULT_OUT}/calibration_plan", "the plan, its table and curves")


def run_plan_calibration(args):
    """``reflector-opt plan-calibration [DESIGN.json]``: each calibration form's predicted
    error against the number and pattern of poses, the recommended plan written as a CSV of
    poses (``--for identification``: the D-optimal poses)."""
    from reflector_opt.workflow._plan_calibration import plan_calibration

    options = options_of(args, PlanCalibrationOptions)
    run = call_into_folder(args, plan_calibration, args.design, options)
    return print_run(args, run, folder=args.out)


def add_record(subparsers):
    """Add the ``record`` subcommand."""
    p = _parser(
        subparsers,
        "record",
        run_record,
        "record a calibration live from the device and an angle reference",
        "Step through a plan of plan-calibration with the device's frames and an angle "
        "reference (lines time_s,unit,pitch_deg,roll_deg: an IMU or the robot's encoders), "
        "keep each pose once the readings settle with the reference at it, and write the "
        "calibration CSV calibrate reads; links are serial:PORT, udp:HOST:PORT, - or a path.",
    )
    p.add_argument("plan", help="plan.csv written by plan-calibration")
    p.add_argument("device", help="the device's link")
    p.add_argument("reference", help="the angle reference's link")
    add_options(p, RecordOptions)
    add_output_file(p, "the calibration samples (CSV)")
    _json(p)


def run_record(args):
    """``reflector-opt record plan.csv DEVICE REFERENCE -o data.csv``: a calibration recorded
    live (docs/robot.md), written atomically at the end."""
    from reflector_opt.workflow._record import record

    refuse_output_over_inputs(args.output, {"plan": args.plan})
    options = options_of(args, RecordOptions)
    with progress_for(args) as progress:
        run = record(args.plan, args.device, args.reference, options, progress=progress)
    return print_run(args, run.write(args.output), [args.output])


def add_export(subparsers):
    """Add the ``export`` subcommand."""
    p = _parser(
        subparsers,
        "export",
        run_export,
        "write the reflector part and the unit body as checked STL and 3MF files",
        "Build the reflector part and the body of a design, check that they are "
        "printable and clear of each other over the workspace, verify the reflecting "
        "surface against the model (Eq 3), and write binary STL, 3MF and PNG previews, "
        "an interactive 3D view (view.html, one file that needs no network) and, with "
        "--format step, STEP files of exact solids.",
    )
    p.add_argument("design", metavar="DESIGN.json", help="the design to build")
    add_output_folder(p, DEFAULT_OUT, "the parts, their pictures and the CAD report")
    add_options(p, ExportOptions)
    _json(p, "print the full report as JSON")
    for old, new in (
        ("--output", "--out"),
        ("--tolerance", "--chord-tolerance"),
        ("--params", "--config"),
    ):
        deprecated_alias(p, old, new)


def run_export(args):
    """``reflector-opt export DESIGN.json [-o DIR]``: the printable reflector part and body,
    checked."""
    from reflector_opt.workflow._export import export

    run = call_into_folder(args, export, args.design, options_of(args, ExportOptions))
    return print_run(args, run, folder=args.out)


def add_report(subparsers):
    """Add the ``report`` subcommand."""
    p = _parser(
        subparsers,
        "report",
        run_report,
        "write a design report (Markdown with PNG figures, self-contained HTML) and the parts",
        "Write report.md with its PNG figures and report.html, one file with its images "
        "inside: the design, its constraints and their slack (zero slack flagged), sensor "
        "windows with a section through each sensor's plane, resolution maps, the predicted "
        "calibration and segment errors beside the paper's, the printability of the parts "
        "with links to their files, and print and material notes; with --as-built, how "
        "each printed unit was built and which of its deviations cost resolution. The "
        "parts (STL, 3MF) are written too when the design passes the printability checks.",
    )
    p.add_argument("design", metavar="DESIGN.json", help="the design to report")
    add_output_folder(p, f"{DEFAULT_OUT}/report", "the report, its figures and the parts")
    add_options(p, ReportOptions)
    _json(p)


def run_report(args):
    """``reflector-opt report DESIGN.json [-o DIR]``: the report written
    (:func:`reflector_opt.workflow.report`), and where it went."""
    from reflector_opt.workflow import report

    run = call_into_folder(args, report, args.design, options_of(args, ReportOptions))
    if args.json:
        print_json(run.to_dict())
        return 0
    if run.cad is not None and run.cad.error is not None:
        print(run.cad.summary())
    print(folder_lines(run.out, run.files, args.started))
    return 0


def add_tolerance(subparsers):
    """Add the ``tolerance`` subcommand."""
    p = _parser(
        subparsers,
        "tolerance",
        run_tolerance,
        "Monte Carlo tolerance analysis of a design: yield and sensitivity",
        "Simulate building, calibrating and validating many units of a design with random "
        "manufacturing and read-out errors; report the distance window, resolution and "
        "calibrated error distributions, the yield against targets and which tolerance "
        "drives the error. Runs on local processes or a Dask cluster (--scheduler).",
    )
    p.add_argument("design", metavar="DESIGN.json")
    add_output_folder(p, f"{DEFAULT_OUT}/tolerance", "the study's tables and figures")
    add_options(p, ToleranceOptions)
    deprecated_alias(p, "--config", "--tolerances")
    _json(p, "print the summary (study.json's content and the files written) as JSON")


def run_tolerance(args):
    """``reflector-opt tolerance DESIGN.json [-o DIR]``: the Monte Carlo study written, and a
    summary."""
    from reflector_opt.workflow._tolerance import tolerance

    run = call_into_folder(args, tolerance, args.design, options_of(args, ToleranceOptions))
    return print_run(args, run, folder=args.out)


def add_sweep(subparsers):
    """Add the ``sweep`` subcommand."""
    p = _parser(
        subparsers,
        "sweep",
        run_sweep,
        "nominal performance and tolerance yield over a grid of design variables",
        "Change numbers of the design over a grid (--vary PATH=START:STOP:N or "
        "PATH=V1,V2,…; PATH like reflector.radius_mm or sensors[0].position_mm[0]) and "
        "report each point's in-use worst-case error (in --conditions, the default "
        "conditions without them), nominal calibrated error, window and white-noise "
        "resolution and, with "
        "--samples N, its yield over N simulated units. Writes sweep.csv (and sweep.png "
        "for one variable).",
    )
    p.add_argument("design", metavar="DESIGN.json")
    p.add_argument(
        "--vary", action="append", required=True, metavar="PATH=SPEC", help="a design variable"
    )
    add_output_folder(p, f"{DEFAULT_OUT}/sweep", "sweep.csv and sweep.png")
    add_options(p, SweepOptions)
    deprecated_alias(p, "--config", "--tolerances")
    _json(p, "print the points as JSON")


def run_sweep(args):
    """``reflector-opt sweep DESIGN.json --vary PATH=START:STOP:N [--vary …]``: sweep.csv (and
    sweep.png) written, and a table."""
    from reflector_opt.workflow._sweep import sweep

    options = options_of(args, SweepOptions)
    run = call_into_folder(args, sweep, args.design, args.vary, options)
    return print_run(args, run, folder=args.out)


def add_smallest(subparsers):
    """Add the ``smallest`` subcommand."""
    p = _parser(
        subparsers,
        "smallest",
        run_smallest,
        "the smallest unit for an accuracy target: the size-accuracy frontier",
        "Optimise the unit at diameters from 22 mm down, for each sensor part and on the "
        "catalogue's bearings, to the smallest that fits (to 0.5 mm); write the frontier "
        "(frontier.csv, frontier.png) and design.json of the smallest unit whose in-use "
        "worst-case error (in --conditions, the default conditions without it) meets "
        "--target-deg, with its printable parts as export writes them.",
    )
    add_options(p, SmallestOptions)
    add_output_folder(
        p, f"{DEFAULT_OUT}/smallest", "design.json, its parts, frontier.csv and frontier.png"
    )
    _json(p)


def run_smallest(args):
    """``reflector-opt smallest --target-deg X``: the size-accuracy frontier traced
    (:func:`~reflector_opt.workflow._smallest.smallest`) and printed."""
    from reflector_opt.workflow._smallest import smallest

    options = options_of(args, SmallestOptions)
    result = call_into_folder(args, smallest, options)
    if args.json:
        print_json(result.to_dict())
        return 0
    judged = "in-use worst case" if options.objective == "in-use" else "objective"
    print(f"size-accuracy frontier (target {options.target_deg:g}°, the {judged}):")
    print(f"  part          mm  {judged:>17}  white noise  bearing  binding (margin)")
    print("\n".join(_row_line(row) for row in result.rows))
    print(_limit_lines(result.limits))
    if result.segment is not None:
        print(_segment_lines(result.segment, judged))
    print(f"smallest: {result!r}")
    print(result.parts.text())
    print(folder_lines(result.out, result.files, args.started))
    return 0


def _row_line(row):
    """One frontier row as a line of the printed table."""
    head = f"  {row['part']:<12} {row['unit_diameter_mm']:>5g}  "
    if row["status"] != "feasible":
        return head + f"no design fits: {row['reason']}"
    from reflector_opt.optimiser._size import judged_deg

    margin = f"{row['binding_margin']:.3g} {row['binding_unit']}".strip()
    figures = f"{judged_deg(row):>16.4f}°  {row['white_noise_deg']:>10.4f}°"
    return head + f"{figures}  {row['bearing']:<8} {row['binding']} ({margin})"


def _limit_lines(limits):
    """The smallest size each part fits and what fails below it, as lines."""
    lines = ["smallest size a design fits, and what fails below it:"]
    for limit in limits:
        head = f"  {limit['part']:<12} "
        if limit["smallest_mm"] is None:
            lines.append(head + f"none down from {limit['fails_at_mm']:g} mm: {limit['reason']}")
        elif limit["fails_at_mm"] is None:
            lines.append(head + f"{limit['smallest_mm']:g} mm (no smaller size tried)")
        else:
            lines.append(
                head + f"{limit['smallest_mm']:g} mm; at {limit['fails_at_mm']:g} mm "
                f"{limit['binding']}: {limit['reason']}"
            )
    return "\n".join(lines)


def _segment_lines(segment, judged):
    """The segment's choices (``judged``: the name of the unit's figure) and the chosen one's
    Table I beside the paper's, as lines."""
    from reflector_opt.optimiser._size import judged_deg

    lines = [
        f"segment of ±{segment['range_deg']:g}° on {segment['link_mm']:g} mm links "
        "(tip errors of built units, recommended calibration):",
        f"  units  each     length  {judged}  orientation rms/max   position rms/max",
    ]
    for c in segment["choices"]:
        head = f"  {c['n_units']:>5}  ±{c['unit_workspace_deg']:<6.4g} "
        if c["status"] != "feasible":
            lines.append(head + f"no design fits: {c['reason']}")
            continue
        lines.append(
            head + f"{c['segment_length_mm']:>5g} mm  {judged_deg(c):>{len(judged)}.4f}°  "
            f"{c['orientation_rms_deg']:.3f}° / {c['orientation_max_deg']:.3f}°    "
            f"{c['position_rms_mm']:.3f} / {c['position_max_mm']:.3f} mm"
        )
    lines.append(f"chosen: {segment['chosen']['n_units']} units; the paper's motion (Table I):")
    for axis, entry in segment["errors"]["paper_motion"].items():
        p, paper = entry["predicted"], entry["paper"]
        lines.append(
            f"  {axis:<5} ±{entry['amplitude_deg']:g}°: predicted rms {p['rms_deg']:.3f}°, "
            f"max {p['max_deg']:.3f}°; "
            f"the paper measured rms {paper['rms_deg']:g}°, max {paper['max_deg']:g}° "
            "(4 units, ±60°)"
        )
    return "\n".join(lines)


def add_compare(subparsers):
    """Add the ``compare`` subcommand."""
    p = _parser(
        subparsers,
        "compare",
        run_compare,
        "two designs side by side, with the differences and figures",
        "Evaluate two designs (B defaults to the built-in design) and show each figure "
        "of both with B − A: worst-case resolution, distance and voltage windows, drift "
        "sensitivity, the error budget in --conditions, the predicted calibration. "
        "Writes resolution_maps_a.png, resolution_maps_b.png and, where the workspaces "
        "share their grid, resolution_difference.png.",
    )
    p.add_argument("a", metavar="A.json")
    p.add_argument("b", metavar="B.json", nargs="?", help="default: the built-in design")
    add_options(p, CompareOptions)
    add_output_folder(p, f"{DEFAULT_OUT}/compare", "the resolution maps and their difference")
    _json(p, "print the rows as JSON")


def run_compare(args):
    """``reflector-opt compare A.json [B.json]``: two designs side by side
    (:func:`~reflector_opt.workflow._compare.compare`), the resolution maps written."""
    from reflector_opt.workflow._compare import compare

    run = call_into_folder(args, compare, args.a, args.b, options_of(args, CompareOptions))
    return print_run(args, run, folder=args.out)


#: Every subcommand's ``add_<name>``, in the order ``--help`` lists them.
SUBCOMMANDS = (
    add_evaluate,
    add_optimise,
    add_fit_sensor,
    add_calibrate,
    add_estimate,
    add_firmware,
    add_stream,
    add_identify,
    add_correct,
    add_plan_calibration,
    add_record,
    add_export,
    add_report,
    add_tolerance,
    add_sweep,
    add_smallest,
    add_compare,
)
