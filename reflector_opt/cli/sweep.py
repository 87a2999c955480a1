"""``reflector-opt sweep DESIGN.json --vary PATH=START:STOP:N [--vary …] [--samples N]
[--seed N] [--scheduler ADDRESS] [-o DIR] [--tolerances FILE.toml] [--quiet]``."""

from __future__ import annotations

from reflector_opt.cli.arguments import DEFAULT_OUT, add_output_folder, count, output_folder
from reflector_opt.cli.output import folder_lines, print_json, progress_for
from reflector_opt.cli.tolerance import add_execution_arguments, execution, yield_basis
from reflector_opt.util.limits import MAX_SIMULATED_UNITS


def register(subparsers):
    """Add the ``sweep`` subcommand."""
    p = subparsers.add_parser(
        "sweep",
        help="nominal performance and tolerance yield over a grid of design variables",
        description=(
            "Change numbers of the design over a grid (--vary PATH=START:STOP:N or "
            "PATH=V1,V2,…; PATH like reflector.radius_mm or sensors[0].position_mm[0]) and "
            "report each point's nominal calibrated error, window and resolution and, with "
            "--samples N, its yield over N simulated units. Writes sweep.csv (and sweep.png "
            "for one variable)."
        ),
    )
    p.add_argument("design", metavar="DESIGN.json")
    p.add_argument(
        "--vary", action="append", required=True, metavar="PATH=SPEC", help="a design variable"
    )
    p.add_argument(
        "--samples",
        dest="units_per_point",
        type=count(0, MAX_SIMULATED_UNITS),
        default=0,
        metavar="N",
        help="units per point for the yield (0)",
    )
    add_output_folder(p, f"{DEFAULT_OUT}/sweep", "sweep.csv and sweep.png")
    add_execution_arguments(p)
    p.add_argument("--json", action="store_true", help="print the points as JSON")
    p.set_defaults(handler=run)


def run(args):
    """Run the sweep, write sweep.csv (and sweep.png) and print a table; returns the exit code."""
    from reflector_opt.design import load_design
    from reflector_opt.report.plots import save_figure, sweep_figure
    from reflector_opt.tolerance.output import write_csv
    from reflector_opt.tolerance.sweep import parse_variable, sweep
    from reflector_opt.util.atomic import atomic_folder

    design = load_design(args.design)
    variables = [parse_variable(spec) for spec in args.vary]
    config, factory = execution(args)
    out = output_folder(args.out)
    with progress_for(args) as progress:
        rows = sweep(
            design,
            variables,
            config.tolerances,
            samples=args.units_per_point,
            seed=config.run.seed,
            settings=config.settings,
            targets=config.targets,
            factory=factory,
            batch_size=config.run.batch_size,
            progress=progress,
        )
    written = ["sweep.csv"]
    with atomic_folder(out, args.argv) as work:
        write_csv(work / "sweep.csv", rows)
        if len(variables) == 1:
            save_figure(sweep_figure(rows, variables[0][0]), work / "sweep.png")
            written.append("sweep.png")
    if args.json:
        print_json({"points": rows, "folder": str(out), "files": written})
        return 0
    basis = yield_basis(args.units_per_point, config.run.seed, args.tolerances)
    print(format_table(rows, [path for path, _ in variables], basis))
    print(folder_lines(out, written, args.started))
    return 0


def _num(value, digits=3):
    return "n/a" if value != value else f"{value:.{digits}f}"


def format_table(rows, paths, basis=None):
    """One line per sweep point: the worst-case resolution the optimiser minimises first,
    then the distance window, the nominal calibrated RMS error and the yield (``basis``: what
    it counts, :func:`~reflector_opt.cli.tolerance.yield_basis`)."""
    lines = []
    for row in rows:
        point = ", ".join(f"{p}={row[p]:g}" for p in paths)
        if row["status"] != "ok":
            lines.append(f"{point}: {row['status']}")
            continue
        text = (
            f"{point}: worst 1σ resolution pitch/roll {_num(row['nominal_resolution_pitch_deg'])}"
            f"/{_num(row['nominal_resolution_roll_deg'])}° (what the optimiser minimises), window "
            f"{'kept' if row['nominal_window_kept'] else 'LOST'} "
            f"(margin {_num(row['nominal_distance_margin_mm'])} mm), RMS pitch/roll "
            f"{_num(row['nominal_rms_pitch_deg'])}/{_num(row['nominal_rms_roll_deg'])}°"
        )
        if "yield" in row:
            text += f", yield {100 * row['yield']:.1f} %"
            text += "" if basis is None else f" ({basis})"
        lines.append(text)
    return "\n".join(lines)
