"""``reflector-opt export DESIGN.json``: write the printable reflector part and body."""

from __future__ import annotations

import json

from reflector_opt.cad import DEFAULT_TOLERANCE_MM, export_parts, load_cad_parameters
from reflector_opt.design import load_design

_CHOICES = {
    "reflector": ("reflector",),
    "body": ("body",),
    "assembly": ("assembly",),
    "all": ("reflector", "body", "assembly"),
}


def register(subparsers):
    """Add the ``export`` subcommand."""
    p = subparsers.add_parser(
        "export",
        help="write the reflector part and the unit body as checked STL and 3MF files",
        description=(
            "Build the reflector part and the body of a design, check that they are "
            "printable and clear of each other over the workspace, verify the reflecting "
            "surface against the model (Eq 3), and write binary STL, 3MF and PNG previews."
        ),
    )
    p.add_argument("design", help="design.json")
    p.add_argument("-o", "--output", default="cad_out", help="output folder (default: cad_out/)")
    p.add_argument(
        "--part",
        choices=sorted(_CHOICES),
        default="all",
        help="what to write: reflector, body, assembly (all solids at --pose) or all",
    )
    p.add_argument(
        "--tolerance",
        type=float,
        default=DEFAULT_TOLERANCE_MM,
        metavar="MM",
        help=f"chord tolerance between mesh and surface, mm (default {DEFAULT_TOLERANCE_MM})",
    )
    p.add_argument(
        "--pose",
        type=float,
        nargs=2,
        default=(0.0, 0.0),
        metavar=("PITCH", "ROLL"),
        help="pose of the assembly view, degrees (default 0 0)",
    )
    p.add_argument("--params", metavar="CAD.toml", help="CAD parameters (TOML)")
    p.add_argument("--no-preview", action="store_true", help="skip the PNG pictures")
    p.add_argument("--json", action="store_true", help="print the full report as JSON")
    p.set_defaults(handler=run)


def run(args):
    """Export and print a summary; returns the exit code."""
    design = load_design(args.design)
    params = load_cad_parameters(args.params) if args.params else None
    report = export_parts(
        design,
        args.output,
        parts=_CHOICES[args.part],
        tolerance_mm=args.tolerance,
        params=params,
        pose_deg=tuple(args.pose),
        preview=not args.no_preview,
    )
    print(json.dumps(report, indent=2) if args.json else format_report(report))
    return 0


def format_report(report):
    """Human-readable lines for an :func:`~reflector_opt.cad.export_parts` report."""
    lines = []
    for name, entry in report["files"].items():
        sizes = ", ".join(
            f"{entry[k]} ({entry[k + '_bytes'] / 1024:.0f} kB)"
            for k in ("stl", "3mf", "png", "section_png")
            if k in entry
        )
        lines.append(f"{name}: {entry['triangles']} triangles -> {sizes}")
    for name, p in report["printability"].items():
        lines.append(
            f"{name}: printable; thinnest wall {p['thinnest_wall']} {p['thinnest_wall_mm']:.3f} mm "
            f"(minimum {p['min_wall_required_mm']:g} mm), volume {p['volume_mm3']:.1f} mm³"
        )
    c, r = report["collision"], report["ray_check"]
    g, a = c["worst_pose_deg"]
    where = f"smallest gap {c['min_clearance_mm']:.3f} mm at pitch {g:g}°, roll {a:g}°"
    if c["collision_free"]:
        lines.append(f"collision-free over the workspace ({c['cells']} cells proved; {where})")
    else:
        lines.append(
            f"no contact found, but {c['unproved_cells']} cells of the workspace are not "
            f"proved clear ({where})"
        )
    lines.append(
        f"Eq 3 ray check: {r['rays']} rays, largest deviation {r['max_error_mm']:.4f} mm "
        f"(tolerance {r['tolerance_mm']:g} mm)"
    )
    lines.append(f"report: {report['report']}")
    return "\n".join(lines)
