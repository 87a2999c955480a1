"""``reflector-opt smallest --target-deg X [--sensor PARTS] [--conditions COND.toml]
[--config FILE.toml] [--workspace-deg W] [--seed N] [--workers N] [--scheduler ADDRESS]
[-o DIR] [--json] [-q] [-v]``.

Parses the options and calls :func:`reflector_opt.workflow.smallest.smallest_run`, which
traces the size–accuracy frontier and writes the smallest unit meeting the target; prints the
frontier and the choice.
"""

from __future__ import annotations

from reflector_opt.cli.arguments import DEFAULT_OUT, add_output_folder, count, number, seed
from reflector_opt.cli.output import folder_lines, print_json, progress_for
from reflector_opt.util.limits import MAX_WORKERS


def register(subparsers):
    """Add the ``smallest`` subcommand."""
    p = subparsers.add_parser(
        "smallest",
        help="the smallest unit for an accuracy target: the size-accuracy frontier",
        description=(
            "Optimise the unit at diameters from 22 mm down, for each sensor part and on the "
            "catalogue's bearings, to the smallest that fits (to 0.5 mm); write the frontier "
            "(frontier.csv, frontier.png) and design.json of the smallest unit whose "
            "objective meets --target-deg."
        ),
    )
    p.add_argument(
        "--target-deg",
        type=number(0.0, 90.0, "degrees", low_open=True),
        metavar="X",
        help="the objective to meet, degrees (the quantity optimise reports; needed)",
    )
    p.add_argument(
        "--sensor",
        metavar="PARTS",
        default="auto",
        help="parts: auto (default), names or PARTS.toml files, by commas",
    )
    p.add_argument(
        "--conditions",
        metavar="COND.toml",
        help="operating conditions (docs/conditions.md): meet the target in them",
    )
    p.add_argument("--config", metavar="FILE.toml", help="settings (see docs/optimiser.md)")
    p.add_argument(
        "--workspace-deg",
        type=number(0.0, 90.0, "degrees", low_open=True),
        metavar="W",
        help="pitch and roll range ±W, degrees (default the config's)",
    )
    p.add_argument("--seed", type=seed, metavar="N", help="seed of the searches (config or 0)")
    p.add_argument(
        "--workers", type=count(1, MAX_WORKERS), metavar="N", help="worker processes (config or 2)"
    )
    p.add_argument(
        "--scheduler", metavar="ADDRESS", help="Dask scheduler address for the parts' frontiers"
    )
    add_output_folder(p, f"{DEFAULT_OUT}/smallest", "design.json, frontier.csv and frontier.png")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(handler=run)


def run(args):
    """Trace the frontier through :func:`~reflector_opt.workflow.smallest.smallest_run`, print
    it (or ``--json``); returns the exit code."""
    from reflector_opt.cli.arguments import output_folder
    from reflector_opt.workflow.smallest import SmallestOptions, smallest_run

    keys = ("target_deg", "sensor", "conditions", "config", "seed", "workers", "scheduler")
    options = SmallestOptions(
        **{k: getattr(args, k) for k in keys}, workspace_deg=args.workspace_deg
    )
    out = output_folder(args.out)
    with progress_for(args) as progress:
        result = smallest_run(options, out=out, progress=progress, command=args.argv)
    if args.json:
        print_json(result.to_dict())
        return 0
    print(f"size-accuracy frontier (target {options.target_deg:g}°):")
    print("  part          mm     objective  bearing  binding (margin)")
    print("\n".join(_row_line(row) for row in result.rows))
    print(f"smallest: {result!r}")
    print(folder_lines(result.out, result.files, args.started))
    return 0


def _row_line(row):
    """One frontier row as a line of the printed table."""
    head = f"  {row['part']:<12} {row['unit_diameter_mm']:>5g}  "
    if row["status"] != "feasible":
        return head + f"no design fits: {row['reason']}"
    margin = f"{row['binding_margin']:.3g} {row['binding_unit']}".strip()
    return head + f"{row['objective_deg']:.4f}°  {row['bearing']:<8} {row['binding']} ({margin})"
