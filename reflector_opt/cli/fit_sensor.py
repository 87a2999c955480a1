"""``reflector-opt fit-sensor CURVE.csv``: a sensor model, or a material, from a measured curve.

Without ``--material`` the curve was measured against a reference target of known reflectance
and specular fraction, and the sensor's ω0, θ and gain are fitted and written into a design.
With ``--material`` the curve was measured against a flat sample of the reflector's material
with a sensor already known (a design's fitted model, or a preset), and the sample's
reflectance and specular fraction are fitted, printed and, with ``-o``, written into the
design's reflector.
"""

from __future__ import annotations

import contextlib
from dataclasses import replace

from reflector_opt.cli.arguments import (
    add_output_file,
    number,
    output_file,
    refuse_output_over_inputs,
)
from reflector_opt.cli.output import print_json, written_lines
from reflector_opt.util.errors import InputError

_DEFAULT_BASE = "NJL5901R-2"


def register(subparsers):
    """Add the ``fit-sensor`` subcommand."""
    p = subparsers.add_parser(
        "fit-sensor",
        help="fit a sensor model, or a material (--material), to a measured distance curve",
        description=(
            "Fit a sensor preset's optical parameters and gain to a curve measured against a "
            "flat reference target (CSV columns distance_mm, volts) and write a design that "
            "uses the fitted model; or, with --material, fit the reflectance and specular "
            "fraction of a flat sample of the reflector's material, the sensor known."
        ),
    )
    p.add_argument("curve", help="CSV with columns distance_mm, volts")
    add_output_file(
        p,
        "design.json (required without --material; with it, optional: the design with the "
        "fitted material)",
        required=False,
    )
    _add_fit_options(p)
    p.add_argument(
        "--part-file",
        type=output_file,
        metavar="PARTS",
        help="also write the fitted sensor as a sensor-catalogue part file (the base's package, "
        "the measured peak), for optimise --sensor PARTS.toml",
    )
    p.add_argument("--json", action="store_true", help="print machine-readable JSON")
    p.set_defaults(handler=run)


def _add_fit_options(p):
    """The options of what is fitted: the design, the sensor, the target and the material."""
    p.add_argument(
        "--design",
        metavar="DESIGN.json",
        help="design to update (default: the built-in design); with --material also the "
        "source of the sensor model",
    )
    p.add_argument(
        "--base",
        metavar="PRESET",
        help=f"sensor preset, or part of the sensor catalogue, to fit (default {_DEFAULT_BASE}; "
        "an unknown name lists the presets); with --material, the sensor to use instead of "
        "the design's",
    )
    p.add_argument(
        "--method",
        choices=("fit", "interpolate"),
        help="fit (default): parametric model; interpolate: also reproduce the points exactly",
    )
    p.add_argument(
        "--reflectance",
        type=number(0.0, 1.0, low_open=True),
        help="reflectance of the reference target (default 0.9)",
    )
    p.add_argument(
        "--specular-fraction",
        type=number(0.0, 1.0),
        help="mirror-like share of the reference target's reflectance (default 1, a mirror; "
        "0 for a white diffuse standard)",
    )
    p.add_argument(
        "--material",
        action="store_true",
        help="fit the sample's reflectance and specular fraction instead of the sensor",
    )
    p.add_argument(
        "--max-sigma-f",
        type=number(0.0, 1.0, low_open=True),
        help="with --material: largest accepted standard error of the specular fraction "
        "(default 0.1)",
    )


def run(args):
    """Fit the sensor or the material, write the design if asked; returns the exit code."""
    from reflector_opt.design import default_design, load_design
    from reflector_opt.model.measured import fit_sensor_model, read_curve_csv

    if args.output is not None:  # the design given may be updated in place, not the curve
        refuse_output_over_inputs(args.output, {"curve": args.curve})
    if args.material and args.part_file is not None:
        raise InputError("--part-file: not with --material (it writes a fitted sensor)")
    if args.material:
        return _run_material(args)
    _check_sensor_options(args)
    distance, volts = read_curve_csv(args.curve)
    design = default_design() if args.design is None else load_design(args.design)
    base = _base_model(_DEFAULT_BASE if args.base is None else args.base)
    target = (
        0.9 if args.reflectance is None else args.reflectance,
        1.0 if args.specular_fraction is None else args.specular_fraction,
    )
    with _naming(args.curve):
        fit = fit_sensor_model(
            distance,
            volts,
            base,
            method=args.method or "fit",
            reflectance=target[0],
            specular_fraction=target[1],
        )
    part = None if args.part_file is None else _part(args, fit, distance, volts, target)
    design.with_sensor_model(fit.model).save(args.output)
    if part is not None:
        from reflector_opt.model.catalogue import part_to_toml
        from reflector_opt.util.fileio import write_text

        write_text(args.part_file, part_to_toml(part))
    _print_sensor_fit(args, fit, distance, part)
    return 0


def _check_sensor_options(args):
    """Refuse the options a sensor fit (no --material) cannot take."""
    if args.output is None:
        raise InputError("-o/--out is required (unless --material)")
    if args.max_sigma_f is not None:
        raise InputError("--max-sigma-f applies to --material only")
    if args.part_file is not None:
        refuse_output_over_inputs(
            args.part_file, {"curve": args.curve, "-o": args.output}, option="--part-file"
        )


def _print_sensor_fit(args, fit, distance, part):
    """Print the fitted sensor model (as JSON with --json) and the files written."""
    m = fit.model
    if args.json:
        summary = {
            "sensor_model": m.to_dict(),
            "rms_residual_v": fit.rms_residual_v,
            "max_residual_v": fit.max_residual_v,
            "points": int(distance.size),
            "output": args.output,
        }
        print_json(summary)
        return
    print(
        f"{m.name}: emitter–detector {m.emitter_detector_mm:.3f} mm, source radius "
        f"{m.source_radius_mm:.3f} mm, divergence {m.divergence_deg:.1f}°, gain "
        f"{m.current_gain:.3g}; residual RMS {1e3 * fit.rms_residual_v:.2f} mV, "
        f"max {1e3 * fit.max_residual_v:.2f} mV over {distance.size} points"
    )
    print(written_lines([args.output, *([args.part_file] if part else [])], args.started))


def _base_model(name):
    """The preset of that name, else the sensor catalogue's part (its model)."""
    from reflector_opt.model.catalogue import get_part
    from reflector_opt.model.sensors import PRESETS, get_preset

    if name in PRESETS:
        return get_preset(name)
    try:
        return get_part(name).model
    except InputError:
        get_preset(name)  # the presets' message, which lists them
        raise


def _part(args, fit, distance, volts, target):
    """The catalogue part of ``--part-file``: the fitted model with the base part's figures."""
    from reflector_opt.model.catalogue import get_part, measured_part
    from reflector_opt.model.catalogue_fit import TARGETS

    names = [k for k, v in TARGETS.items() if v == target]
    if not names:
        raise InputError(
            "--part-file: the target must be one of the catalogue's test targets "
            + ", ".join(
                f"{k} (reflectance {r:g}, specular fraction {f:g})" for k, (r, f) in TARGETS.items()
            )
        )
    base = get_part(_DEFAULT_BASE if args.base is None else args.base)
    rms = fit.rms_residual_v
    return measured_part(fit.model, base, args.curve, distance, volts, names[0], rms)


@contextlib.contextmanager
def _naming(curve):
    """Name the curve file in a refusal of its readings (e.g. a curve without signal)."""
    try:
        yield
    except InputError as exc:
        raise InputError(f"{curve}: {exc}") from None


def _run_material(args):
    """``--material``: fit ρ and f of the sample with the sensor known."""
    from reflector_opt.design import default_design, load_design
    from reflector_opt.model.material_fit import fit_material
    from reflector_opt.model.measured import read_curve_csv
    from reflector_opt.model.sensors import get_preset

    for option, value in (
        ("--method", args.method),
        ("--reflectance", args.reflectance),
        ("--specular-fraction", args.specular_fraction),
    ):
        if value is not None:
            raise InputError(
                f"{option} describes the reference target of a sensor fit; with --material "
                "the sample's reflectance and specular fraction are fitted"
            )
    distance, volts = read_curve_csv(args.curve)
    design = default_design() if args.design is None else load_design(args.design)
    if args.base is not None:
        model = get_preset(args.base)
    else:
        models = {m.name: m for m in design.models}
        if len(models) != 1:
            raise InputError(
                f"the design's sensors use different models ({', '.join(sorted(models))}); "
                "fit the material with one of them (--base)"
            )
        (model,) = models.values()
    with _naming(args.curve):
        fit = fit_material(
            distance,
            volts,
            model,
            max_sigma_f=0.1 if args.max_sigma_f is None else args.max_sigma_f,
        )
    if args.output is not None:
        reflector = replace(
            design.reflector,
            reflectance=fit.reflectance,
            specular_fraction=fit.specular_fraction,
        )
        design.replace(reflector=reflector).save(args.output)
    if args.json:
        print_json({**fit.to_dict(), "sensor": model.name, "output": args.output})
        return 0
    print(
        f"material against {model.name}: reflectance ρ = {fit.reflectance:.3f} ± "
        f"{fit.reflectance_sigma:.3f}, specular fraction f = {fit.specular_fraction:.3f} ± "
        f"{fit.specular_fraction_sigma:.3f} (1σ; correlation {fit.correlation:+.2f})"
    )
    print(
        f"residual RMS {1e3 * fit.rms_residual_v:.2f} mV, max {1e3 * fit.max_residual_v:.2f} mV "
        f"over {fit.points} points ({fit.clamped} clamped, left out)"
    )
    print(written_lines([] if args.output is None else [args.output], args.started))
    return 0
