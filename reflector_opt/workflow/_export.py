"""A design's printable parts written and checked, as ``reflector-opt export`` does it.

The parts are built, checked (printability, clearance over the workspace, the Eq 3 ray
check) and written with their pictures, the CAD report and, unless the pictures are skipped,
the interactive 3D view (``view.html``), all into a folder swapped in whole.
"""

from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

from reflector_opt.util._declared import Angle, Options, option, takes
from reflector_opt.util._display import Printed
from reflector_opt.util._limits import DEFAULT_TOLERANCE_MM, MAX_TOLERANCE_MM

_PARTS = ("reflector", "body", "assembly")
#: What ``part`` may name, and the parts each writes: one of them, or all.
PART_CHOICES = {**{p: (p,) for p in _PARTS}, "all": _PARTS}


@dataclass(frozen=True, repr=False)
class ExportRun(Printed):
    """A design's parts built and checked in memory (:func:`export`); :meth:`write` writes
    them.

    Attributes
    ----------
    design : reflector_opt.design._design.Design
    parts : reflector_opt.cad._export.CheckedParts
        The parts, checked.
    params : reflector_opt.design._parts.CadParameters or None
        The CAD parameters (None: the design's layout's), for the 3D view.
    preview : bool
        :meth:`write` writes the pictures and the 3D view.
    out : pathlib.Path or None
        The output folder, once written.
    report : dict
        The export's report (:func:`reflector_opt.cad.export_parts`): before :meth:`write`
        without its files; after, with them and with ``view``, the 3D view's file name, when
        it was written.
    files : tuple of pathlib.Path
        Every file written: parts, pictures, the CAD report, the 3D view (empty before
        :meth:`write`).
    progress : callable or None
        The run's ``progress(fraction, message)``, which :meth:`write` goes on with.
    """

    design: object
    parts: object
    params: object = None
    preview: bool = True
    out: Path | None = None
    report: dict | None = None
    files: tuple = ()
    progress: object = field(default=None, compare=False)

    def __post_init__(self):
        if self.report is None:
            object.__setattr__(self, "report", self.parts.summary())

    def write(self, folder, *, command=("reflector_opt", "export"), progress=None):
        """Write the parts, their pictures, the CAD report and the 3D view into ``folder``,
        built beside the old one and swapped in whole.

        Parameters
        ----------
        folder : str or pathlib.Path
        command : sequence of str, optional
            The command line recorded in the folder's manifest.
        progress : callable, optional
            ``progress(fraction, message)`` as the files are written (default the run's).

        Returns
        -------
        ExportRun
            This run, written: ``out``, ``report`` and ``files`` filled in.
        """
        from reflector_opt.workflow._runs import written

        def write_into(work):
            progressing = progress or self.progress
            report = write_checked_parts(self.parts, work, self.params, self.preview, progressing)
            return export_names(report), {"report": report}

        return written(self, folder, command, write_into)

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


#: How far the parts' meshes may depart from their surfaces, mm (export's and correct's).
ChordTolerance = option(
    float,
    "chord tolerance between mesh and surface, mm",
    flag="--chord-tolerance",
    metavar="MM",
    gt=0,
    le=MAX_TOLERANCE_MM,
)
#: The CAD parameters (export's and correct's).
CadConfig = option(
    object,
    "CAD parameters (a TOML file, docs/cad.md); the defaults if left out",
    metavar="FILE.toml",
)


class ExportOptions(Options):
    """The options of ``reflector-opt export``, declared once."""

    part: option(
        Literal[tuple(PART_CHOICES)],
        "what to write: reflector, body, assembly (every solid at --pose) or all",
    ) = "all"
    chord_tolerance_mm: ChordTolerance = DEFAULT_TOLERANCE_MM
    pose_deg: option(
        tuple[Angle, Angle],
        "pitch and roll of the assembly view, degrees",
        flag="--pose",
        metavar=("PITCH", "ROLL"),
    ) = (0.0, 0.0)
    config: CadConfig = None
    format: option(
        Literal["mesh", "step"],
        "mesh: STL and 3MF; step: also STEP files of the printed parts, exact solids for CAD "
        "(needs: pip install 'reflector-opt[step]')",
    ) = "mesh"
    preview: option(bool, "write the PNG pictures and the interactive 3D view (view.html)") = True


@takes(ExportOptions)
def export(design, options, progress=None):
    """Build and check a design's printable parts in memory: ``reflector-opt export``;
    :meth:`ExportRun.write` writes them.

    Parameters
    ----------
    design : reflector_opt.design._design.Design, str or pathlib.Path
        The design or its ``design.json``.
    options : ExportOptions
        As keyword arguments (below).
    progress : callable, optional
        ``progress(fraction, message)`` as the work advances.

    Returns
    -------
    ExportRun

    Raises
    ------
    InputError
        A design or CAD parameter file that cannot be read, parts that fail a check or an
        unknown ``part``.
    """
    from reflector_opt.cad._export import check_parts
    from reflector_opt.design import as_design
    from reflector_opt.design._parts import load_cad_parameters

    design = as_design(design)
    params = None if options.config is None else load_cad_parameters(options.config)
    parts = check_parts(
        design,
        PART_CHOICES[options.part],
        options.chord_tolerance_mm,
        params,
        tuple(options.pose_deg),
        options.format == "step",
        progress,
        preview=options.preview,
    )
    return ExportRun(design, parts, params, options.preview, progress=progress)


def write_checked_parts(parts, work, params, preview, progress):
    """Write checked parts (:func:`~reflector_opt.cad._export.check_parts`) and, with their
    pictures, the 3D view into ``work``, a folder being written; the export's report.

    Parameters
    ----------
    parts : reflector_opt.cad._export.CheckedParts
    work : pathlib.Path
    params : reflector_opt.design._parts.CadParameters or None
        The CAD parameters of the 3D view (None: the design's layout's).
    preview : bool
        Write the pictures and the 3D view.
    progress : callable or None

    Returns
    -------
    dict
    """
    from reflector_opt.report._view3d import write_view

    report = parts.write(work, preview, progress)
    if preview:  # the interactive 3D view beside the pictures
        view = write_view(parts.design, work, params=params, tolerance_mm=parts.tolerance_mm)
        report["view"] = view.name
    return report


def export_names(report):
    """The file names of a :func:`write_checked_parts` report: parts, pictures, the CAD report
    and the 3D view.

    Parameters
    ----------
    report : dict

    Returns
    -------
    list of str
    """
    from reflector_opt.workflow._runs import cad_names

    return [*cad_names(report), *([report["view"]] if "view" in report else [])]
