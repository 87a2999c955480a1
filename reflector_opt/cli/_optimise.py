"""``reflector-opt optimise [--config FILE.toml] [-o DIR] [--seed N] [--surface PRESET]
[--sensor PARTS] [--conditions COND.toml] [--objective {in-use,resolution}]
[--read-out {chosen,stated}] [--starts N] [--workers N] [--pareto]
[--drift-front] [--tolerances FILE.toml] [--scheduler ADDRESS] [--no-report] [--json] [-q]
[-v]``.

Parses the options and calls :func:`reflector_opt.workflow.optimise`, which makes the
run; prints its summary.
"""

from __future__ import annotations

import sys

from reflector_opt.cli._arguments import DEFAULT_OUT, add_objective, add_output_folder, count, seed
from reflector_opt.cli._command import call_into_folder, print_run
from reflector_opt.model._surface import DEFAULT_MATERIAL, MATERIALS
from reflector_opt.util._limits import MAX_STARTS, MAX_WORKERS
from reflector_opt.workflow._options import READ_OUTS


def register(subparsers):
    """Add the ``optimise`` subcommand."""
    p = subparsers.add_parser(
        "optimise",
        help="optimise the reflector and sensor placement; writes design.json",
        description=(
            "Find the reflector radius, centre offset and sensor placement, with the drive "
            "and calibration they are read with, of least worst-case error in use (the default "
            "conditions, or --conditions; --objective resolution: the white-noise resolution) "
            "that keeps every sensor inside its usable range and meets the envelope, wall and "
            "no-fold constraints. With no options it runs on the built-in defaults and writes "
            "cad_out/design.json."
        ),
    )
    p.add_argument("--config", metavar="FILE.toml", help="settings (see docs/optimiser.md)")
    add_output_folder(p, DEFAULT_OUT, "design.json, the report and the parts")
    p.add_argument("--seed", type=seed, metavar="N", help="seed of the search (config or 0)")
    _add_design_arguments(p)
    _add_search_arguments(p)
    p.add_argument(
        "--no-report",
        action="store_true",
        help="skip the report, the predicted calibration errors and the printable parts",
    )
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(handler=run)


def _add_design_arguments(p):
    """``--surface``, ``--sensor`` and ``--conditions``: what the design is made of and the
    conditions it is used in."""
    p.add_argument(
        "--surface",
        metavar="PRESET",
        choices=sorted(MATERIALS),
        help=(
            "the reflector's surface to design for: "
            + ", ".join(
                f"{m.name} (ρ {m.reflectance}, f {m.specular_fraction})" for m in MATERIALS.values()
            )
            + f"; default the config's or {DEFAULT_MATERIAL}"
        ),
    )
    p.add_argument(
        "--sensor",
        metavar="PARTS",
        help=(
            "choose the sensor part: auto (every part of the sensor catalogue), part names or "
            "PARTS.toml catalogue files, separated by commas; each part that fits the unit is "
            "optimised (in parallel on --workers processes, or on --scheduler) and the best "
            "kept; replaces the config's [sensor]"
        ),
    )
    p.add_argument(
        "--conditions",
        metavar="COND.toml",
        help=(
            "operating conditions ([conditions] TOML, docs/conditions.md) the design is judged "
            "in; replaces the config's [conditions]; default the config's, or the default "
            "conditions"
        ),
    )
    add_objective(p)
    p.add_argument(
        "--read-out",
        choices=READ_OUTS,
        default=READ_OUTS[0],
        help="chosen (default): the optimiser chooses the drive, sample rate and temperature "
        "compensation with the geometry, the conditions' being the default design's; stated: "
        "keep the conditions' own",
    )


def _add_search_arguments(p):
    """How the search runs: starts, workers, Pareto and drift fronts, tolerances, scheduler."""
    p.add_argument(
        "--starts",
        type=count(1, MAX_STARTS),
        default=1,
        metavar="N",
        help="independent searches from seeds derived from --seed, the best one kept (1)",
    )
    p.add_argument(
        "--workers",
        type=count(1, MAX_WORKERS),
        metavar="N",
        help="worker processes of the search (config or 2)",
    )
    p.add_argument(
        "--pareto",
        action="store_true",
        help="also trace resolution against distance margin (pareto.json, pareto.png; slow)",
    )
    p.add_argument(
        "--drift-front",
        action="store_true",
        help=(
            "also trace white-noise resolution against drift sensitivity (drift_front.json; "
            "slow), with each design's total error in --conditions"
        ),
    )
    p.add_argument(
        "--tolerances",
        metavar="FILE.toml",
        help=(
            "optimise robustly against these tolerances (the file of `tolerance --tolerances`): "
            "the distance margin is raised until it covers [robust] coverage of built units; "
            "with --pareto, each point gets its yield"
        ),
    )
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help=(
            "run the searches of --starts and the tolerance studies on a Dask scheduler, "
            "e.g. tcp://host:8786"
        ),
    )


def run(args):
    """Optimise through :func:`~reflector_opt.workflow.optimise`, print a summary (or
    ``--json``); returns the exit code."""
    from reflector_opt.workflow import OptimiseOptions, optimise

    options = OptimiseOptions(
        config=args.config,
        seed=args.seed,
        surface=args.surface,
        sensor=args.sensor,
        starts=args.starts,
        workers=args.workers,
        pareto=args.pareto,
        tolerances=args.tolerances,
        scheduler=args.scheduler,
        report=not args.no_report,
        conditions=args.conditions,
        drift_front=args.drift_front,
        objective=args.objective,
        read_out=args.read_out,
    )
    result = call_into_folder(args, optimise, options)
    if result.robust is not None and not result.robust.converged:
        print(
            "reflector-opt optimise: warning: the robust margin did not converge in "
            f"{len(result.robust.rounds)} rounds; design.json keeps the last round "
            "(raise [robust] max_rounds)",
            file=sys.stderr,
        )
    return print_run(args, result, folder=result.out)
