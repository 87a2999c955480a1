"""``reflector-opt identify CAL.csv [--design D] [--curve U:S=FILE …] [--batch B] -o OUT.json``.

Identifies how each unit of a calibration CSV was built (reflector radius and centre, each
sensor's seat, gain and offset; the batch's surface), with each parameter's uncertainty and
whether the data determine it, and the angle reference's zero offsets and twist in each
unit's calibration (prior: the stated defaults, ``--conditions`` or none with
``--reference-zero fixed``); prints the determined deviations and the reference's parameters
and writes ``AS_BUILT.json`` (nothing is written if any unit fails).
"""

from __future__ import annotations

from reflector_opt.cli.arguments import add_output_file, number, refuse_output_over_inputs
from reflector_opt.cli.output import print_json, progress_for, written_lines


def register(subparsers):
    """Add the ``identify`` subcommand."""
    p = subparsers.add_parser(
        "identify",
        help="identify how printed units were built from their calibration data",
        description=(
            "Estimate each unit's as-built geometry and read-out (and the batch's surface) "
            "from a calibration CSV (columns unit, v1, v2, pitch_deg, roll_deg), with the "
            "tolerance model as the prior, and write AS_BUILT.json."
        ),
    )
    p.add_argument("data", help="calibration CSV (one or more units)")
    p.add_argument(
        "--design", metavar="DESIGN.json", help="the units' design (default: the built-in design)"
    )
    p.add_argument(
        "--curve",
        action="append",
        default=[],
        metavar="[UNIT:]SENSOR=FILE",
        help="a sensor's flat-target curve measured before assembly (the fit-sensor CSV); "
        "repeat for each sensor and unit, e.g. --curve 1:S1=s1.csv",
    )
    p.add_argument(
        "--tolerances",
        metavar="FILE.toml",
        help="tolerance config whose [tolerances] are the prior (default: the built-in ones)",
    )
    p.add_argument(
        "--reference-sigma",
        type=number(0, 5, "degrees"),
        default=None,
        metavar="DEG",
        help="RMS noise of the angle reference at each pose (default 0.05°)",
    )
    _add_reference_options(p)
    p.add_argument(
        "--no-profiles", action="store_true", help="skip the profile-likelihood intervals"
    )
    p.add_argument(
        "--batch",
        metavar="NAME",
        help="the print batch the units came from, recorded in AS_BUILT.json (correct pools "
        "only files of one batch)",
    )
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    add_output_file(p, "AS_BUILT.json")
    p.set_defaults(handler=run)


def _add_reference_options(p):
    """The options of the angle reference's prior."""
    p.add_argument(
        "--conditions",
        metavar="COND.toml",
        help="operating conditions ([conditions] TOML) whose reference_zero_deg and "
        "reference_twist_deg are the prior std of the reference's zero offsets and twist "
        "(default 1.5°, 1.5°, 0.5°)",
    )
    p.add_argument(
        "--reference-zero",
        choices=("free", "fixed"),
        default="free",
        help="free (default): fit each unit's reference zero offsets and twist; fixed: take "
        "the reference as exact (a known mechanical zero)",
    )


def run(args):
    """Identify, report, write; returns the exit code."""
    from reflector_opt.asbuilt.asbuiltfile import check_batch_name, save_as_built
    from reflector_opt.asbuilt.lab import identify_files
    from reflector_opt.design import default_design, load_design
    from reflector_opt.tolerance.config import load_tolerance_config
    from reflector_opt.tolerance.truth import REFERENCE_SIGMA_DEG

    inputs = {"data": args.data, "--design": args.design, "--tolerances": args.tolerances}
    inputs["--conditions"] = args.conditions
    inputs.update({f"--curve {c}": c.partition("=")[2] or None for c in args.curve})
    refuse_output_over_inputs(args.output, inputs)
    check_batch_name(args.batch)
    reference_std = _reference_prior(args)
    design = default_design() if args.design is None else load_design(args.design)
    tolerances = None if args.tolerances is None else load_tolerance_config(args.tolerances)
    with progress_for(args) as progress:
        result = identify_files(
            design,
            args.data,
            args.curve,
            tolerances=None if tolerances is None else tolerances.tolerances,
            reference_sigma_deg=(
                REFERENCE_SIGMA_DEG if args.reference_sigma is None else args.reference_sigma
            ),
            reference_std=reference_std,
            profiles=not args.no_profiles,
            progress=progress,
        )
    save_as_built(result, args.output, source=args.data, batch=args.batch)
    if args.json:
        print_json(summary(result))
    else:
        print(format_report(result))
        print(written_lines([args.output], args.started))
    return 0


def _reference_prior(args):
    """The reference's prior std from --reference-zero and --conditions (None: fixed)."""
    from reflector_opt.asbuilt.parameters import REFERENCE_PRIOR_STD, reference_std_of
    from reflector_opt.design.conditions import load_conditions
    from reflector_opt.util.errors import InputError

    if args.reference_zero == "fixed":
        if args.conditions is not None:
            raise InputError(
                "--reference-zero fixed takes the reference as exact, --conditions gives its "
                "errors; give one of them"
            )
        return None
    if args.conditions is None:
        return dict(REFERENCE_PRIOR_STD)
    return reference_std_of(load_conditions(args.conditions))


def summary(result):
    """Per unit, the determined parameters' deviations and the determined combinations."""
    units = {}
    for u, label in enumerate(result.labels):
        rows = result.unit_parameters(u)
        units[label] = {
            "determined": {
                name: {"deviation": r["estimate"] - r["design"], "std": r["std"]}
                for name, r in rows.items()
                if r["identifiable"]
            },
            "combinations": [c.name for c in result.combinations[u]],
            "reference": result.reference_parameters(u),
        }
    return {"shared": result.shared_parameters(), "units": units, "seconds": result.seconds}


def format_report(result):
    """Human-readable lines: the surface, then each unit's determined deviations, its
    model-form amplitudes the data move and its reference."""
    lines = [f"{len(result.labels)} unit(s) identified in {result.seconds:.1f} s"]
    for name, row in result.shared_parameters().items():
        state = "determined" if row["identifiable"] else "not determined by the data"
        lines.append(
            f"  {name}: {row['estimate']:.4g} ± {row['std']:.2g} (prior ± {row['prior_std']:.2g}, "
            f"{state})"
        )
    for u, label in enumerate(result.labels):
        rows = result.unit_parameters(u)
        lines.append(f"unit {label}: deviation from the design (± std), determined ones")
        for name, row in rows.items():
            if row["identifiable"]:
                deviation = row["estimate"] - row["design"]
                lines.append(f"    {name:<34}{deviation:+10.4f} ± {row['std']:.4f}")
        for combination in result.combinations[u][:6]:
            lines.append(f"    determined: {combination.name} (std {combination.ratio:.2f}× prior)")
        lines += _form_lines(result.form_parameters(u))
        lines += _reference_lines(result.reference_parameters(u))
    if not result.layout.reference_names:
        lines.append("the angle reference was taken as exact (--reference-zero fixed)")
    if result.inflation > 1.5:
        lines.append(
            f"note: each region of the workspace is predicted from the others "
            f"{result.inflation**0.5:.1f}× worse than the noise (block cross-validation); the "
            "model does not describe these units exactly, and the uncertainties are widened to "
            "match"
        )
    return "\n".join(lines)


def _form_lines(rows):
    """The model-form amplitudes the data move from their prior (1 = the effect at its
    documented size), or none."""
    moved = [
        f"{name.removeprefix('form_')} {row['estimate']:+.2f} ± {row['std']:.2f}"
        for name, row in rows.items()
        if abs(row["estimate"]) > row["std"]
    ]
    if not moved:
        return []
    return ["    model form (effect sizes, prior 0 ± 1): " + ", ".join(moved)]


def _reference_lines(rows):
    """The reference's parameters of one unit: estimate ± std, and what they trade with."""
    lines = []
    for name, row in rows.items():
        state = "determined" if row["identifiable"] else "not determined"
        lines.append(
            f"    {name:<34}{row['estimate']:+10.4f} ± {row['std']:.4f} ({state}; "
            f"correlation {row['correlation']:+.2f} with {row['correlated_with']})"
        )
        if row["combination"] is not None:
            lines.append(f"        determined together: {row['combination']}")
    return lines
