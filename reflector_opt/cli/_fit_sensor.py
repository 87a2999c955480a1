"""``reflector-opt fit-sensor CURVE.csv``: a sensor model, or a material, from a measured curve.

Without ``--material`` the curve was measured against a reference target of known reflectance
and specular fraction (``--target`` by name, or ``--reflectance`` and
``--specular-fraction``), and the sensor's ω0, θ and gain, with the read-out's offset, are
fitted and written into a design. With ``--material`` the curve was measured against a flat
sample of the reflector's material, and the sample's reflectance, specular fraction and
sub-surface spread are fitted (:func:`reflector_opt.model._material_fit.fit_material`): with
the sensor held (a design's fitted model, or a preset), or, with ``--reference``, fitted
jointly from the same sensor's curve against a reference target. A material curve the model
does not describe (RMS residual above 3× the design's noise) is refused unless
``--accept-misfit``. The result is printed and, with ``-o``, written into the design's
reflector (and, with ``--reference``, its sensor model).
"""

from __future__ import annotations

from reflector_opt.cli._arguments import (
    add_accept_units,
    add_output_file,
    number,
    output_file,
    refuse_output_over_inputs,
)
from reflector_opt.cli._command import print_run
from reflector_opt.workflow._fit_sensor import (
    DEFAULT_BASE,
    DEFAULT_MAX_SIGMA_F,
    DEFAULT_REFLECTANCE,
    DEFAULT_SPECULAR_FRACTION,
)


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
        help=f"sensor preset, or part of the sensor catalogue, to fit (default {DEFAULT_BASE}; "
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
        f"(default {DEFAULT_MAX_SIGMA_F:g})",
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
        help=f"reflectance of the reference target (default {DEFAULT_REFLECTANCE:g})",
    )
    p.add_argument(
        "--specular-fraction",
        type=number(0.0, 1.0),
        help="mirror-like share of the reference target's reflectance (default "
        f"{DEFAULT_SPECULAR_FRACTION:g}, a mirror; 0 for a white diffuse standard)",
    )


def run(args):
    """Fit the sensor or the material, write the design if asked; returns the exit code."""
    from reflector_opt.workflow._fit_sensor import fit_sensor_run

    if args.output is not None:  # the design given may be updated in place, not the curve
        inputs = {"curve": args.curve, "--reference": args.reference}
        refuse_output_over_inputs(args.output, inputs)
    if args.part_file is not None and args.output is not None and not args.material:
        inputs = {"curve": args.curve, "-o": args.output}
        refuse_output_over_inputs(args.part_file, inputs, option="--part-file")
    run = fit_sensor_run(
        args.curve,
        args.output,
        design=args.design,
        base=args.base,
        method=args.method,
        target=args.target,
        reflectance=args.reflectance,
        specular_fraction=args.specular_fraction,
        material=args.material,
        reference=args.reference,
        max_sigma_f=args.max_sigma_f,
        accept_misfit=args.accept_misfit,
        part_file=args.part_file,
        accept_units=args.accept_units,
    )
    return print_run(args, run)
