"""``reflector-opt fit-sensor CURVE.csv``: a sensor model, or a material, from a measured curve.

Without ``--material`` the curve was measured against a reference target of known reflectance
and specular fraction (``--target`` by name, or ``--reflectance`` and
``--specular-fraction``), and the sensor's ω0, θ and gain, with the read-out's offset, are
fitted and written into a design. With ``--material`` the curve was measured against a flat
sample of the reflector's material, and the sample's reflectance, specular fraction and
sub-surface spread are fitted (:func:`reflector_opt.model.material_fit.fit_material`): with
the sensor held (a design's fitted model, or a preset), or, with ``--reference``, fitted
jointly from the same sensor's curve against a reference target. A material curve the model
does not describe (RMS residual above 3× the design's noise) is refused unless
``--accept-misfit``. The result is printed and, with ``-o``, written into the design's
reflector (and, with ``--reference``, its sensor model).
"""

from __future__ import annotations

import contextlib
from dataclasses import replace

from reflector_opt.cli.arguments import (
    add_accept_units,
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
    _add_target_options(p)
    p.add_argument(
        "--material",
        action="store_true",
        help="fit the sample's reflectance, specular fraction and sub-surface spread instead "
        "of the sensor",
    )
    p.add_argument(
        "--reference",
        metavar="REFERENCE.csv",
        help="with --material: the same sensor's curve against a reference target (named by "
        "--target, or --reflectance and --specular-fraction); the sensor is then fitted "
        "jointly with the material instead of taken from the design",
    )
    p.add_argument(
        "--max-sigma-f",
        type=number(0.0, 1.0, low_open=True),
        help="with --material: largest accepted standard error of the specular fraction "
        "(default 0.1)",
    )
    p.add_argument(
        "--accept-misfit",
        action="store_true",
        help="with --material: fit even when a curve's RMS residual exceeds 3x the design's "
        "noise (the model does not describe it; the values are then effective ones)",
    )
    add_accept_units(p, "the curves")


def _add_target_options(p):
    """The reference target: by name, or by its reflectance and specular fraction."""
    p.add_argument(
        "--target",
        metavar="NAME",
        help="the reference target by name: white-card (Kodak grey card's white side, "
        "reflectance 0.9, diffuse), aluminium (evaporated mirror, 0.9) or mirror (ideal, 1)",
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


def run(args):
    """Fit the sensor or the material, write the design if asked; returns the exit code."""
    from reflector_opt.design import default_design, load_design
    from reflector_opt.model.measured import fit_sensor_model

    if args.output is not None:  # the design given may be updated in place, not the curve
        inputs = {"curve": args.curve, "--reference": args.reference}
        refuse_output_over_inputs(args.output, inputs)
    if args.material and args.part_file is not None:
        raise InputError("--part-file: not with --material (it writes a fitted sensor)")
    if args.material:
        return _run_material(args)
    _check_sensor_options(args)
    design = default_design() if args.design is None else load_design(args.design)
    base = _base_model(_DEFAULT_BASE if args.base is None else args.base)
    distance, volts = _read_curve(args, args.curve, base)
    target = _target(args)
    with _naming(args.curve):
        fit = fit_sensor_model(
            distance,
            volts,
            base,
            method=args.method or "fit",
            reflectance=target[0],
            specular_fraction=target[1],
            fit_offset=True,
        )
    part = None if args.part_file is None else _part(args, fit, distance, volts, target)
    _warn_misfit(fit.rms_residual_v, design.noise.total_sigma_v)
    design.with_sensor_model(fit.model).save(args.output)
    if part is not None:
        from reflector_opt.model.catalogue import part_to_toml
        from reflector_opt.util.fileio import write_text

        write_text(args.part_file, part_to_toml(part))
    _print_sensor_fit(args, fit, distance, part)
    return 0


def _read_curve(args, path, model):
    """A curve's distances and voltages, its units checked against ``model``'s supply."""
    from reflector_opt.model.measured import read_curve_csv

    return read_curve_csv(path, supply_v=model.supply_v, accept_units=args.accept_units)


def _target(args, required=False):
    """(ρ, f) of the reference target: --target, else --reflectance and --specular-fraction
    (defaults 0.9 and 1, a mirror, unless ``required``)."""
    from reflector_opt.model.catalogue_fit import TARGETS

    if args.target is not None:
        if args.reflectance is not None or args.specular_fraction is not None:
            raise InputError(
                "--target names the reference's reflectance and specular fraction; give it "
                "or --reflectance and --specular-fraction, not both"
            )
        if args.target not in TARGETS:
            raise InputError(f"--target {args.target!r}: unknown; known: {', '.join(TARGETS)}")
        return TARGETS[args.target]
    if required and (args.reflectance is None or args.specular_fraction is None):
        raise InputError(
            "--reference: name its target, --target (e.g. white-card) or --reflectance and "
            "--specular-fraction"
        )
    return (
        0.9 if args.reflectance is None else args.reflectance,
        1.0 if args.specular_fraction is None else args.specular_fraction,
    )


def _warn_misfit(rms_v, sigma_v):
    """One line on stderr when a sensor fit leaves residuals above 3× the noise."""
    import sys

    from reflector_opt.model.material_fit import MAX_MISFIT

    if rms_v > MAX_MISFIT * sigma_v:
        print(
            f"reflector-opt fit-sensor: warning: residual RMS {1e3 * rms_v:.2f} mV is "
            f"{rms_v / sigma_v:.1f}x the design's noise ({1e3 * sigma_v:.2f} mV): the model does "
            "not describe this curve (the target, its distance zero, the LED's pattern)",
            file=sys.stderr,
        )


def _check_sensor_options(args):
    """Refuse the options a sensor fit (no --material) cannot take."""
    if args.output is None:
        raise InputError("-o/--out is required (unless --material)")
    for option, value in (
        ("--max-sigma-f", args.max_sigma_f),
        ("--reference", args.reference),
        ("--accept-misfit", args.accept_misfit or None),
    ):
        if value is not None:
            raise InputError(f"{option} applies to --material only")
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
            "offset_v": fit.offset_v,
            "points": int(distance.size),
            "output": args.output,
        }
        print_json(summary)
        return
    print(
        f"{m.name}: emitter–detector {m.emitter_detector_mm:.3f} mm, source radius "
        f"{m.source_radius_mm:.3f} mm, divergence {m.divergence_deg:.1f}°, gain "
        f"{m.current_gain:.3g}, output offset {1e3 * fit.offset_v:+.1f} mV; residual RMS "
        f"{1e3 * fit.rms_residual_v:.2f} mV, max {1e3 * fit.max_residual_v:.2f} mV over "
        f"{distance.size} points"
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
    """``--material``: fit ρ, f and ℓ of the sample, the sensor held or fitted jointly."""
    from reflector_opt.design import default_design, load_design
    from reflector_opt.model.material_fit import fit_material

    _check_material_options(args)
    design = default_design() if args.design is None else load_design(args.design)
    model, reference = _material_sensor(args, design), None
    distance, volts = _read_curve(args, args.curve, model)
    if args.reference is not None:
        from reflector_opt.model.flat_target import MeasuredCurve

        target = _target(args, required=True)
        curve = _read_curve(args, args.reference, model)
        with _naming(args.reference):
            reference = MeasuredCurve(*map(tuple, curve), *target)
    with _naming(args.curve):
        fit = fit_material(
            distance,
            volts,
            model,
            reference=reference,
            sigma_v=design.noise.total_sigma_v,
            max_sigma_f=0.1 if args.max_sigma_f is None else args.max_sigma_f,
            accept_misfit=args.accept_misfit,
        )
    if args.output is not None:
        reflector = replace(
            design.reflector,
            reflectance=fit.reflectance,
            specular_fraction=fit.specular_fraction,
        )
        if reference is not None:
            design = design.with_sensor_model(fit.sensor.with_(name=f"{model.name}-measured"))
        design.replace(reflector=reflector).save(args.output)
    if args.json:
        print_json({**fit.to_dict(), "sensor": fit.sensor.name, "output": args.output})
        return 0
    _print_material(args, fit, model, reference)
    return 0


def _check_material_options(args):
    """Refuse what a material fit cannot take: the sensor fit's method, and a reference
    target without a reference curve."""
    if args.method is not None:
        raise InputError("--method describes a sensor fit; with --material it does not apply")
    if args.reference is None:
        for option, value in (
            ("--reflectance", args.reflectance),
            ("--specular-fraction", args.specular_fraction),
            ("--target", args.target),
        ):
            if value is not None:
                raise InputError(
                    f"{option} describes the reference target of a sensor fit; with --material "
                    "it needs the reference's curve (--reference), else the sample's "
                    "reflectance and specular fraction are fitted with the sensor held"
                )


def _material_sensor(args, design):
    """The sensor of a material fit: --base, else the design's one sensor model."""
    from reflector_opt.model.sensors import get_preset

    if args.base is not None:
        return get_preset(args.base)
    models = {m.name: m for m in design.models}
    if len(models) != 1:
        raise InputError(
            f"the design's sensors use different models ({', '.join(sorted(models))}); "
            "fit the material with one of them (--base)"
        )
    (model,) = models.values()
    return model


def _print_material(args, fit, model, reference):
    """The fitted material in three lines, a misfit warning, and the file written."""
    against = f"material against {model.name}"
    if reference is not None:
        against += (
            f" (fitted with it on {args.reference}: reflectance {reference.reflectance:g}, "
            f"specular fraction {reference.specular_fraction:g})"
        )
    spread = (
        "sub-surface spread not resolved"
        if fit.subsurface_mm is None
        else f"sub-surface spread ℓ = {fit.subsurface_mm:.3f} mm"
    )
    print(
        f"{against}: reflectance ρ = {fit.reflectance:.3f} ± {fit.reflectance_sigma:.3f}, "
        f"specular fraction f = {fit.specular_fraction:.3f} ± {fit.specular_fraction_sigma:.3f} "
        f"(1σ statistical; correlation {fit.correlation:+.2f}); {spread}"
    )
    print(_interval_line(fit))
    reference_rms = (
        "" if fit.reference_rms_v is None else f"; reference RMS {1e3 * fit.reference_rms_v:.2f} mV"
    )
    print(
        f"residual RMS {1e3 * fit.rms_residual_v:.2f} mV, max {1e3 * fit.max_residual_v:.2f} mV "
        f"over {fit.points} points ({fit.clamped} clamped, left out){reference_rms}; noise "
        f"σ_V {1e3 * fit.sigma_v:.2f} mV; output offset {1e3 * fit.offset_v:+.1f} mV"
    )
    if fit.misfit:
        print(
            "warning: a curve's residual exceeds 3x the noise (--accept-misfit): the model does "
            "not describe it and these are effective values"
        )
    print(written_lines([] if args.output is None else [args.output], args.started))


def _interval_line(fit):
    """The 90 % intervals, with the LED-pattern model-form std they include."""
    rho, f = fit.reflectance_interval, fit.specular_fraction_interval
    line = (
        f"90 % intervals (statistical and LED-pattern model form, ± "
        f"{fit.reflectance_model_form_sigma:.3f} in ρ, ± "
        f"{fit.specular_fraction_model_form_sigma:.3f} in f): ρ {rho[0]:.3f}–{rho[1]:.3f}, "
        f"f {f[0]:.3f}–{f[1]:.3f}"
    )
    if fit.subsurface_interval_mm is not None:
        low, high = fit.subsurface_interval_mm
        line += f", ℓ {low:.3f}–{high:.3f} mm"
    return line
