"""``reflector-opt export DESIGN.json [-o DIR]``: write the printable reflector part and body."""

from __future__ import annotations

from reflector_opt.cli.arguments import (
    DEFAULT_OUT,
    add_output_folder,
    deprecated_alias,
    output_folder,
)
from reflector_opt.cli.output import cad_files, folder_lines, print_json, progress_for
from reflector_opt.design.parts import DEFAULT_TOLERANCE_MM

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
            "surface against the model (Eq 3), and write binary STL, 3MF and PNG previews, "
            "an interactive 3D view (view.html, one file that needs no network) and, with "
            "--format step, STEP files of exact solids."
        ),
    )
    p.add_argument("design", metavar="DESIGN.json", help="the design to build")
    add_output_folder(p, DEFAULT_OUT, "the parts, their pictures and the CAD report")
    p.add_argument(
        "--part",
        choices=sorted(_CHOICES),
        default="all",
        help="what to write: reflector, body, assembly (all solids at --pose) or all",
    )
    add_chord_tolerance(p)
    p.add_argument(
        "--pose",
        type=float,
        nargs=2,
        default=(0.0, 0.0),
        metavar=("PITCH", "ROLL"),
        help="pose of the assembly view, degrees (default 0 0)",
    )
    p.add_argument("--config", metavar="FILE.toml", help="CAD parameters (see docs/cad.md)")
    p.add_argument(
        "--format",
        choices=("mesh", "step"),
        default="mesh",
        help="mesh: STL and 3MF (default); step: also STEP files of the printed parts, exact "
        "solids for CAD (needs: pip install 'reflector-opt[step]')",
    )
    p.add_argument(
        "--no-preview",
        action="store_true",
        help="skip the PNG pictures and the interactive 3D view (view.html)",
    )
    p.add_argument("--json", action="store_true", help="print the full report as JSON")
    for old, new in (
        ("--output", "--out"),
        ("--tolerance", "--chord-tolerance"),
        ("--params", "--config"),
    ):
        deprecated_alias(p, old, new)
    p.set_defaults(handler=run)


def add_chord_tolerance(parser):
    """``--chord-tolerance MM``: how far the parts' meshes may depart from their surfaces."""
    parser.add_argument(
        "--chord-tolerance",
        type=float,
        default=DEFAULT_TOLERANCE_MM,
        metavar="MM",
        help=f"chord tolerance between mesh and surface, mm (default {DEFAULT_TOLERANCE_MM})",
    )


def run(args):
    """Export and print a summary; returns the exit code."""
    from reflector_opt.cad.export import export_parts
    from reflector_opt.design import load_design
    from reflector_opt.design.parts import load_cad_parameters
    from reflector_opt.report.view3d import write_view
    from reflector_opt.util.atomic import atomic_folder

    output_folder(args.out)  # refused before any work, named by its option
    design = load_design(args.design)
    params = None if args.config is None else load_cad_parameters(args.config)
    with progress_for(args) as progress, atomic_folder(args.out, args.argv) as work:
        report = export_parts(
            design,
            work,
            parts=_CHOICES[args.part],
            tolerance_mm=args.chord_tolerance,
            params=params,
            pose_deg=tuple(args.pose),
            preview=not args.no_preview,
            step=args.format == "step",
            progress=progress,
        )
        if not args.no_preview:  # the interactive 3D view beside the pictures
            report["view"] = write_view(
                design, work, params=params, tolerance_mm=args.chord_tolerance
            ).name
    if args.json:
        print_json(report)
    else:
        print(format_report(report))
        view = [report["view"]] if "view" in report else []
        print(folder_lines(args.out, [*cad_files(report, args.out), *view], args.started))
    return 0


def format_report(report):
    """Human-readable lines for an :func:`~reflector_opt.cad.export_parts` report."""
    lines = []
    for name, entry in report["files"].items():
        sizes = ", ".join(
            f"{k.upper()} {entry[k + '_bytes'] / 1024:.0f} kB"
            for k in ("stl", "3mf", "step")
            if k in entry
        )
        lines.append(f"{name}: {entry['triangles']} triangles ({sizes})")
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
    return "\n".join(lines)
