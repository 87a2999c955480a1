"""``reflector-opt fit-sensor CURVE.csv``: a sensor model from a measured flat-target curve."""

from __future__ import annotations

from reflector_opt.design import default_design, load_design
from reflector_opt.model.measured import fit_sensor_model, read_curve_csv
from reflector_opt.model.sensors import PRESETS, get_preset


def register(subparsers):
    """Add the ``fit-sensor`` subcommand."""
    p = subparsers.add_parser(
        "fit-sensor",
        help="fit a sensor model to a measured voltage-versus-distance curve",
        description=(
            "Fit a sensor preset's optical parameters and gain to a measured flat-target curve "
            "(CSV columns distance_mm, volts) and write a design that uses the fitted model."
        ),
    )
    p.add_argument("curve", help="CSV with columns distance_mm, volts")
    p.add_argument("-o", "--output", required=True, help="design.json to write")
    p.add_argument("--design", help="design to update (default: the built-in design)")
    p.add_argument("--base", default="NJL5901R-2", choices=sorted(PRESETS), help="preset to fit")
    p.add_argument(
        "--method",
        default="fit",
        choices=("fit", "interpolate"),
        help="fit: parametric model; interpolate: also reproduce the points exactly",
    )
    p.add_argument(
        "--reflectance", type=float, default=0.9, help="reflectance of the measurement target"
    )
    p.set_defaults(handler=run)


def run(args):
    """Fit, write the design and print the fitted parameters; returns the exit code."""
    distance, volts = read_curve_csv(args.curve)
    design = load_design(args.design) if args.design else default_design()
    fit = fit_sensor_model(
        distance, volts, get_preset(args.base), method=args.method, reflectance=args.reflectance
    )
    design.with_sensor_model(fit.model).save(args.output)
    m = fit.model
    print(
        f"{m.name}: emitter–detector {m.emitter_detector_mm:.3f} mm, source radius "
        f"{m.source_radius_mm:.3f} mm, divergence {m.divergence_deg:.1f}°, gain "
        f"{m.current_gain:.3g}; residual RMS {1e3 * fit.rms_residual_v:.2f} mV, "
        f"max {1e3 * fit.max_residual_v:.2f} mV over {distance.size} points"
    )
    print(f"wrote {args.output}")
    return 0
