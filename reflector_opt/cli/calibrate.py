"""``reflector-opt calibrate DATA.csv [--model M] [--design D] [--fit F] -o coefficients.json``.

Fits one calibration model per unit of a measured calibration CSV, prints the k-fold
cross-validated error and writes the coefficients (nothing is written if any unit fails). A
``temperature_c`` column that spans at least 1 K makes every unit's form
temperature-compensated; its thermal parameters are printed with their standard deviations.
"""

from __future__ import annotations

from pathlib import Path

from reflector_opt.calibration.choices import FITS
from reflector_opt.cli.arguments import (
    add_accept_units,
    add_output_file,
    count,
    refuse_output_over_inputs,
    seed,
)
from reflector_opt.cli.output import print_json, progress_for, written_lines


def register(subparsers):
    """Add the ``calibrate`` subcommand."""
    p = subparsers.add_parser(
        "calibrate",
        help="fit per-unit calibrations to measured data (CSV)",
        description=(
            "Fit one calibration model per unit to a CSV with columns unit, v1, v2, "
            "pitch_deg, roll_deg (one row per sample) and write the coefficients as JSON. With "
            "a temperature_c column (°C) spanning at least 1 K, each unit's form is "
            "temperature-compensated (its sensors' gain and offset change per kelvin fitted "
            "with it); the logs to estimate then need that column too."
        ),
    )
    p.add_argument("data", help="calibration CSV")
    p.add_argument(
        "--model",
        default="eq6",
        help="eq5, eq6 (the paper's, default), polyN (e.g. poly4), auto (chosen per unit by "
        "cross-validation) or physical (the design's model fitted per unit; needs --design)",
    )
    p.add_argument(
        "--design",
        metavar="DESIGN.json",
        help="the units' design (needed by --model physical; its sensors' supply is the "
        "temperature compensation's pivot, default 3.3 V)",
    )
    p.add_argument("--fit", default="lsq", help=f"{', '.join(FITS)} (default lsq)")
    p.add_argument(
        "--folds",
        type=count(0, 1000),
        default=5,
        help="cross-validation folds; 0 skips (default 5)",
    )
    p.add_argument(
        "--seed", type=seed, default=0, metavar="N", help="seed of the fold shuffle (default 0)"
    )
    add_output_file(p, "the coefficients (JSON)")
    add_accept_units(p, "the calibration CSV")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(handler=run)


def run(args):
    """Calibrate, report, write; returns the exit code."""
    from reflector_opt.calibration.lab import calibrate_csv, save_calibrations
    from reflector_opt.design import load_design

    refuse_output_over_inputs(args.output, {"data": args.data, "--design": args.design})
    design = None if args.design is None else load_design(args.design)
    with progress_for(args) as progress:
        calibrations = calibrate_csv(
            args.data,
            args.model,
            args.fit,
            args.folds,
            args.seed,
            design,
            progress,
            accept_units=args.accept_units,
        )
    save_calibrations(args.output, calibrations, source=Path(args.data).name)
    if args.json:
        print_json(summary(calibrations, args))
    else:
        print(format_report(calibrations, args))
        print(written_lines([args.output], args.started))
    return 0


def summary(calibrations, args):
    """Per unit, the model, the samples, the cross-validated errors (degrees) and, when
    compensated, the ``temperature`` block of its coefficients (thermal parameters and std)."""
    units = {}
    for c in calibrations:
        entry = c.to_dict()
        units[c.unit] = {
            "model": c.model.name,
            "samples": c.model.n_samples_,
            "cross_validation": entry["cross_validation"],
        }
        if "temperature" in entry["model"]:
            units[c.unit]["temperature"] = entry["model"]["temperature"]
    return {"fit": args.fit, "folds": args.folds, "units": units, "output": args.output}


def format_report(calibrations, args):
    """Table of the per-unit cross-validated errors."""
    names = "/".join(sorted({c.model.name for c in calibrations}))
    thermal = [c for c in calibrations if hasattr(c.model, "gain_per_k_")]
    compensated = ", temperature-compensated" if thermal else ""
    lines = [f"{len(calibrations)} unit(s) calibrated with {names} ({args.fit}{compensated})"]
    if args.folds:
        lines.append(f"{args.folds}-fold cross-validated error (estimate − reference):")
        lines.append(
            f"  {'unit':<8}{'samples':>8}{'RMS pitch':>12}{'RMS roll':>11}"
            f"{'max pitch':>12}{'max roll':>11}"
        )
        for c in calibrations:
            rms, peak = c.cross_validation["rms_deg"], c.cross_validation["max_deg"]
            lines.append(
                f"  {c.unit:<8}{c.model.n_samples_:>8}{rms[0]:>11.3f}°{rms[1]:>10.3f}°"
                f"{peak[0]:>11.3f}°{peak[1]:>10.3f}°"
            )
    return "\n".join(lines + _thermal_lines(thermal))


def _thermal_lines(calibrations):
    """The thermal parameters of compensated units, ± one standard deviation."""
    if not calibrations:
        return []
    lines = [
        "temperature compensation (change per kelvin ± 1 std; T0 the mean calibration "
        "temperature):",
        f"  {'unit':<8}{'T0 °C':>7}{'range °C':>14}{'gain 1 %/K':>19}{'gain 2 %/K':>19}"
        f"{'offset 1 mV/K':>19}{'offset 2 mV/K':>19}",
    ]
    for c in calibrations:
        m = c.model
        low, high = m.temperature_range_c_
        cells = [
            f"{scale * v:+.4f} ± {scale * s:.4f}"
            for scale, values, stds in (
                (100, m.gain_per_k_, m.gain_per_k_std_),
                (1e3, m.offset_v_per_k_, m.offset_v_per_k_std_),
            )
            for v, s in zip(values, stds, strict=True)
        ]
        lines.append(
            f"  {c.unit:<8}{m.reference_temperature_c_:>7.2f}{f'{low:.1f}–{high:.1f}':>14}"
            + "".join(f"{cell:>19}" for cell in cells)
        )
    return lines
