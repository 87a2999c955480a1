"""``reflector-opt tolerance DESIGN.json [--samples N] [--seed N] [--scheduler ADDRESS]
[-o DIR] [--tolerances FILE.toml] [--json] [--quiet]``."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

from reflector_opt.cli.arguments import (
    DEFAULT_OUT,
    add_output_folder,
    count,
    deprecated_alias,
    output_folder,
    seed,
)
from reflector_opt.cli.output import folder_lines, print_json, progress_for
from reflector_opt.util.limits import MAX_SIMULATED_UNITS


def add_execution_arguments(p):
    """Options shared by ``tolerance`` and ``sweep``.

    The tolerance file is ``--tolerances``, as in ``optimise`` and ``identify``; the former
    spelling ``--config`` stays accepted, hidden, with a warning.
    """
    p.add_argument(
        "--tolerances",
        metavar="FILE.toml",
        help="tolerances and study settings (see docs/tolerance.md)",
    )
    deprecated_alias(p, "--config", "--tolerances")
    p.add_argument("--seed", type=seed, metavar="N", help="seed of every draw (config or 0)")
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="run on a Dask distributed scheduler, e.g. tcp://host:8786 (default: local processes)",
    )


def execution(args):
    """The config with command-line overrides and the executor factory."""
    from reflector_opt.tolerance.config import ToleranceConfig, load_tolerance_config
    from reflector_opt.workflow.optimise import executor_factory

    path = args.tolerances
    config = ToleranceConfig() if path is None else load_tolerance_config(path)
    run = config.run
    overrides = {
        k: getattr(args, k) for k in ("samples", "seed") if getattr(args, k, None) is not None
    }
    if overrides:
        run = replace(run, **overrides)
        config = replace(config, run=run)
    return config, executor_factory(args.scheduler, run.workers)


def register(subparsers):
    """Add the ``tolerance`` subcommand."""
    p = subparsers.add_parser(
        "tolerance",
        help="Monte Carlo tolerance analysis of a design: yield and sensitivity",
        description=(
            "Simulate building, calibrating and validating many units of a design with random "
            "manufacturing and read-out errors; report the distance window, resolution and "
            "calibrated error distributions, the yield against targets and which tolerance "
            "drives the error. Runs on local processes or a Dask cluster (--scheduler)."
        ),
    )
    p.add_argument("design", metavar="DESIGN.json")
    p.add_argument(
        "--samples",
        type=count(1, MAX_SIMULATED_UNITS),
        metavar="N",
        help="Monte Carlo samples (config or 500)",
    )
    add_output_folder(p, f"{DEFAULT_OUT}/tolerance", "the study's tables and figures")
    add_execution_arguments(p)
    p.add_argument(
        "--json",
        action="store_true",
        help="print the summary (study.json's content and the files written) as JSON",
    )
    p.set_defaults(handler=run)


def run(args):
    """Run the study, write the outputs and print a summary; returns the exit code."""
    from reflector_opt.design import load_design
    from reflector_opt.report.plots import (
        error_histograms,
        save_figure,
        sensitivity_bars,
        yield_bars,
    )
    from reflector_opt.tolerance.output import write_study
    from reflector_opt.tolerance.study import run_study
    from reflector_opt.util.atomic import atomic_folder

    design = load_design(args.design)
    config, factory = execution(args)
    out = output_folder(args.out)
    r = config.run
    with progress_for(args) as progress:
        study = run_study(
            design,
            config.tolerances,
            samples=r.samples,
            seed=r.seed,
            settings=config.settings,
            targets=config.targets,
            oat_samples=r.oat_samples,
            sobol_samples=r.sobol_samples,
            factory=factory,
            batch_size=r.batch_size,
            progress=progress,
        )
    figures = {"yield.png": yield_bars(study)}
    if study.settings.calibrate:
        figures["errors.png"] = error_histograms(study)
    if study.one_at_a_time or study.sobol:
        figures["sensitivity.png"] = sensitivity_bars(study)
    with atomic_folder(out, args.argv) as work:
        written = write_study(work, study)
        for name, fig in figures.items():
            save_figure(fig, work / name)
            written.append(work / name)
    if args.json:
        files = [str(out / Path(path).name) for path in written]
        print_json({**study.to_dict(), "folder": str(out), "files": files})
    else:
        print(format_summary(study, args.tolerances))
        print(folder_lines(out, written, args.started))
    return 0


def _percent(fraction):
    return "not assessed" if fraction is None else f"{100 * fraction:.1f} %"


def _dist(d, key):
    v = d[key]
    return (
        "n/a" if v is None else f"median {v['median']:.3f}, p95 {v['p95']:.3f}, max {v['max']:.3f}"
    )


def _index(value, ci):
    if value is None:
        return "n/a"
    low, high = ("?" if v is None else f"{v:.2f}" for v in ci)
    return f"{value:.2f} ({low} to {high})"


def format_sobol(sobol):
    """Lines of a table of the Sobol indices (ranked by total index) with their intervals."""
    head = (
        f"  Sobol indices of the worse RMS error ({sobol['rows']} rows of "
        f"{sobol['rows_requested']}; {100 * sobol['confidence']:g} % bootstrap intervals)"
    )
    if sobol["dropped"] or sobol["unused"]:
        head += (
            f"; {sobol['dropped']} rows left out with a unit not built or calibrated, "
            f"{sobol['unused']} to keep a power of two"
        )
    if "error" in sobol:
        return [head, f"    not computed: {sobol['error']}"]
    ranked = sorted(
        sobol["groups"], key=lambda g: -(g["total"] if g["total"] is not None else -math.inf)
    )
    width = max(len(g["tolerance"]) for g in ranked)
    lines = [head, f"    {'tolerance':<{width}}  {'total index':<22}first-order index"]
    lines += [
        f"    {g['tolerance']:<{width}}  {_index(g['total'], g['total_ci']):<22}"
        f"{_index(g['first'], g['first_ci'])}"
        for g in ranked
    ]
    lines += [
        f"  WARNING: the {'first-order' if o['index'] == 'first' else 'total'} index of "
        f"{o['tolerance']}, {_index(o['value'], o['ci'])}, lies outside [0, 1] beyond its "
        "interval: sampling scatter does not explain it; check the model runs"
        for o in sobol["outside"]
    ]
    lines += [f"  note: bootstrap of the Sobol indices: {w}" for w in sobol["warnings"]]
    return lines


def yield_basis(samples, seed, tolerances, judged="all targets"):
    """What a yield is computed on, for its label: ``500 units, seed 0, tolerances FILE
    (built-in without one), all targets``.

    ``tolerance``, ``sweep`` and ``optimise --tolerances`` draw their units from the tolerance
    file they are given with their own sample counts and seeds, so one design's yield differs
    between them; each names its basis with this label.
    """
    source = "built-in" if tolerances is None else str(tolerances)
    return f"{samples} units, seed {seed}, tolerances {source}, {judged}"


def format_summary(study, tolerances=None):
    """Human-readable lines for a :class:`~reflector_opt.tolerance.ToleranceStudy`
    (``tolerances``: the file its tolerances came from, None for the built-in ones)."""
    s = study.summary
    y, t, d = s["yield"], s["targets"], s["distributions"]
    low, high = s["yield_interval"]["all"]
    lines = [
        f"{s['samples']} units (seed {study.seed}, tolerances "
        f"{'built-in' if tolerances is None else tolerances}; {s['invalid']} invalid, "
        f"{s['unfit']} not calibratable): yield "
        f"{100 * y['all']:.1f} % (95 % interval {100 * low:.1f}–{100 * high:.1f} %; "
        f"window kept {100 * y['window']:.1f} %, "
        f"RMS ≤ {t['rms_deg']:g}° {_percent(y['rms'])}, max ≤ {t['max_deg']:g}° "
        f"{_percent(y['max'])})",
    ]
    for key, label in (
        ("rms_pitch_deg", "RMS pitch error (°)"),
        ("rms_roll_deg", "RMS roll error (°)"),
        ("max_pitch_deg", "max pitch error (°)"),
        ("max_roll_deg", "max roll error (°)"),
        ("distance_margin_mm", "distance margin (mm)"),
    ):
        lines.append(f"  {label}: {_dist(d, key)}")
    if "required_margin_mm" in s:
        m = s["required_margin_mm"]
        bound = (
            f"{100 * m['confidence']:g} % upper bound; estimate {m['estimate']:.3f} mm"
            if m["confidence"] is not None
            else "estimate; too few samples for a confidence bound"
        )
        lines.append(
            f"  margin lost to the tolerances in {100 * m['coverage']:g} % of units: "
            f"{m['value']:.3f} mm ({bound}; optimise --tolerances sets it as the distance "
            "margin)"
        )
    if study.sobol:
        lines += format_sobol(study.sobol)
    return "\n".join(lines)
