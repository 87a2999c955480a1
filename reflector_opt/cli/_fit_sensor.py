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

from reflector_opt.cli._arguments import add_output_file, output_file, refuse_output_over_inputs
from reflector_opt.cli._command import print_run
from reflector_opt.util._declared import add_options, options_of
from reflector_opt.workflow._fit_sensor import FitSensorOptions


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
    add_options(p, FitSensorOptions)
    p.add_argument(
        "--part-file",
        type=output_file,
        metavar="PARTS",
        help="also write the fitted sensor as a sensor-catalogue part file (the base's package, "
        "the measured peak), for optimise --sensor PARTS.toml",
    )
    p.add_argument("--json", action="store_true", help="print machine-readable JSON")
    p.set_defaults(handler=run)


def run(args):
    """Fit the sensor or the material, write the design if asked; returns the exit code."""
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
