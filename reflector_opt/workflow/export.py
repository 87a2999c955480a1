"""A design's printable parts written and checked, as ``reflector-opt export`` does it.

The parts are built, checked (printability, clearance over the workspace, the Eq 3 ray
check) and written with their pictures, the CAD report and, unless the pictures are skipped,
the interactive 3D view (``view.html``), all into a folder swapped in whole.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from reflector_opt.design.parts import DEFAULT_TOLERANCE_MM
from reflector_opt.util.display import Printed

__all__ = ["PART_CHOICES", "ExportRun", "export_files", "export_run", "write_parts"]

#: What ``part`` may name, and the parts each writes.
PART_CHOICES = {
    "reflector": ("reflector",),
    "body": ("body",),
    "assembly": ("assembly",),
    "all": ("reflector", "body", "assembly"),
}


@dataclass(frozen=True, repr=False)
class ExportRun(Printed):
    """The parts written by :func:`export_run`.

    Attributes
    ----------
    design : reflector_opt.design.design.Design
    out : pathlib.Path
        The output folder.
    report : dict
        The export's report (:func:`reflector_opt.cad.export_parts`) with ``view``, the 3D
        view's file name, when it was written.
    files : tuple of pathlib.Path
        Every file written: parts, pictures, the CAD report, the 3D view.
    """

    design: object
    out: Path
    report: dict
    files: tuple

    def to_dict(self):
        """JSON-ready: the export's report (``--json``)."""
        return self.report

    def text(self):
        """One line per part, its printability, the clearance proof and the ray check."""
        report = self.report
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
                f"{name}: printable; thinnest wall {p['thinnest_wall']} "
                f"{p['thinnest_wall_mm']:.3f} mm (minimum {p['min_wall_required_mm']:g} mm), "
                f"volume {p['volume_mm3']:.1f} mm³"
            )
        return "\n".join([*lines, *_check_lines(report)])


def _check_lines(report):
    """The clearance proof and the Eq 3 ray check, a line each."""
    c, r = report["collision"], report["ray_check"]
    g, a = c["worst_pose_deg"]
    where = f"smallest gap {c['min_clearance_mm']:.3f} mm at pitch {g:g}°, roll {a:g}°"
    if c["collision_free"]:
        clearance = f"collision-free over the workspace ({c['cells']} cells proved; {where})"
    else:
        clearance = (
            f"no contact found, but {c['unproved_cells']} cells of the workspace are not "
            f"proved clear ({where})"
        )
    rays = (
        f"Eq 3 ray check: {r['rays']} rays, largest deviation {r['max_error_mm']:.4f} mm "
        f"(tolerance {r['tolerance_mm']:g} mm)"
    )
    return [clearance, rays]


def export_run(
    design,
    out,
    *,
    part="all",
    chord_tolerance_mm=DEFAULT_TOLERANCE_MM,
    config=None,
    pose_deg=(0.0, 0.0),
    preview=True,
    step=False,
    progress=None,
    command=None,
):
    """Build, check and write a design's printable parts: ``reflector-opt export``.

    Parameters
    ----------
    design : reflector_opt.design.design.Design, str or pathlib.Path
        The design or its ``design.json``.
    out : str or pathlib.Path
        The output folder (built beside the old one and swapped in whole).
    part : {"all", "reflector", "body", "assembly"}, optional
        What to write (``assembly``: every solid at ``pose_deg``).
    chord_tolerance_mm : float, optional
        How far the meshes may depart from their surfaces, mm.
    config : str or pathlib.Path, optional
        CAD parameters (TOML, docs/cad.md); the defaults if None.
    pose_deg : (float, float), optional
        Pitch and roll of the assembly view, degrees.
    preview : bool, optional
        Write the PNG pictures and the interactive 3D view.
    step : bool, optional
        Also write STEP files of exact solids (needs the ``step`` extra).
    progress : callable, optional
        ``progress(fraction, message)`` as the work advances.
    command : sequence of str, optional
        The command line recorded in the folder's manifest (default the library's).

    Returns
    -------
    ExportRun

    Raises
    ------
    InputError
        A design or CAD parameter file that cannot be read, parts that fail a check, an
        unknown ``part`` or an output folder that cannot be written; nothing is written.
    """
    from reflector_opt.design import as_design
    from reflector_opt.design.parts import load_cad_parameters
    from reflector_opt.util.atomic import atomic_folder, check_output_folder
    from reflector_opt.util.errors import InputError

    if part not in PART_CHOICES:
        raise InputError(f"part: expected one of {', '.join(PART_CHOICES)}, got {part!r}")
    check_output_folder(out)  # refused before any work
    design = as_design(design)
    params = None if config is None else load_cad_parameters(config)
    options = {
        "part": part,
        "chord_tolerance_mm": chord_tolerance_mm,
        "params": params,
        "pose_deg": tuple(pose_deg),
        "preview": preview,
        "step": step,
    }
    with atomic_folder(out, command or ("reflector_opt", "export")) as work:
        report = write_parts(design, work, progress=progress, **options)
    out = Path(out)
    return ExportRun(design, out, report, tuple(export_files(report, out)))


def export_files(report, folder):
    """The files of a :func:`write_parts` report in ``folder``: parts, pictures, the CAD
    report and the 3D view.

    Parameters
    ----------
    report : dict
    folder : pathlib.Path

    Returns
    -------
    list of pathlib.Path
    """
    from reflector_opt.workflow.runs import cad_files

    return [*cad_files(report, folder), *([folder / report["view"]] if "view" in report else [])]


def write_parts(
    design,
    work,
    *,
    part="all",
    chord_tolerance_mm=DEFAULT_TOLERANCE_MM,
    params=None,
    pose_deg=(0.0, 0.0),
    preview=True,
    step=False,
    progress=None,
):
    """Build, check and write a design's parts into a folder being written: the work of
    :func:`export_run` inside its atomic folder, for a workflow that writes them beside its
    own files.

    Parameters
    ----------
    design : reflector_opt.design.design.Design
    work : pathlib.Path
        The folder being written (e.g. an :func:`~reflector_opt.util.atomic.atomic_folder`).
    part, chord_tolerance_mm, pose_deg, preview, step, progress
        As for :func:`export_run`; the chord tolerance in mm, the pose in degrees.
    params : reflector_opt.design.parts.CadParameters, optional
        CAD parameters (None: the design's layout's).

    Returns
    -------
    dict
        The export's report (:func:`reflector_opt.cad.export_parts`), with ``view`` when the
        3D view was written. Raises InputError when a part fails a check (printability,
        clearance over the workspace, the Eq 3 ray check).
    """
    from reflector_opt.cad.export import export_parts
    from reflector_opt.report.view3d import write_view

    report = export_parts(
        design,
        work,
        parts=PART_CHOICES[part],
        tolerance_mm=chord_tolerance_mm,
        params=params,
        pose_deg=tuple(pose_deg),
        preview=preview,
        step=step,
        progress=progress,
    )
    if preview:  # the interactive 3D view beside the pictures
        view = write_view(design, work, params=params, tolerance_mm=chord_tolerance_mm)
        report["view"] = view.name
    return report
