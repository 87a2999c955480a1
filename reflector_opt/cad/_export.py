"""Export the printable parts of a design: build, check, verify, then write.

:func:`export_parts` is what ``reflector-opt export`` and the optimiser call. Nothing is
written unless every requested part passes its printability report and the reflector's
surface passes the Eq 3 ray check; a failure raises
:class:`~reflector_opt.util._errors.InputError` with one line naming the first problem.
"""

import math
import tempfile
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from reflector_opt.cad._background import BackgroundCall, BackgroundFiles
from reflector_opt.cad._clearance import (
    collision_report,
    gap_at_pose,
    overlap_mm3,
    prove_clearance,
)
from reflector_opt.cad._drawing import section_polygons, simplified
from reflector_opt.cad._meshfiles import write_3mf, write_stl
from reflector_opt.cad._printability import check_printability
from reflector_opt.cad._solids import SOLIDS, build_parts, pose_matrix
from reflector_opt.cad._step import build_step_parts, step_available, write_step
from reflector_opt.cad._tessellation import circle_segments, sphere_segments, to_trimesh
from reflector_opt.cad._verification import verify_distances
from reflector_opt.design._layout import plan_layout
from reflector_opt.util._errors import InputError
from reflector_opt.util._fileio import write_json
from reflector_opt.util._limits import DEFAULT_TOLERANCE_MM, MAX_TOLERANCE_MM
from reflector_opt.util._progress import no_progress

#: Printed parts and the assembly view that :func:`export_parts` can write.
PARTS = ("reflector", "body", "assembly")


def _check_request(parts, tolerance_mm, pose_deg, step):
    unknown = sorted(set(parts) - set(PARTS))
    if unknown or not parts:
        raise InputError(f"part: expected some of {', '.join(PARTS)}, got {list(parts)}")
    if not (isinstance(tolerance_mm, int | float) and math.isfinite(tolerance_mm)):
        raise InputError(f"tolerance: expected a length in mm, got {tolerance_mm!r}")
    if not 0.0 < tolerance_mm <= MAX_TOLERANCE_MM:
        raise InputError(
            f"tolerance: must lie in (0, {MAX_TOLERANCE_MM:g}] mm, got {tolerance_mm:g}"
        )
    if not all(math.isfinite(a) and abs(a) < 90.0 for a in pose_deg):
        raise InputError(f"pose: pitch and roll must lie within (-90, 90) degrees, got {pose_deg}")
    if step and not step_available():
        raise InputError("step: STEP export needs build123d: pip install 'reflector-opt[step]'")


def _layout_summary(layout, design, tolerance_mm):
    refl = design.reflector
    return {
        "band_top_deg": layout.band_top_deg,
        "patches": [
            {
                "sensor": p.sensor,
                "elevation_deg": list(p.elevation_deg),
                "azimuth_deg": list(p.azimuth_deg),
                "margin_mm": p.margin_mm,
                "outer_radius_mm": p.outer_radius_mm,
            }
            for p in layout.patches
        ],
        "tilt_max_deg": layout.tilt_max_deg,
        "tendon_azimuths_deg": list(layout.tendon_azimuths_deg),
        "heights_mm": {
            "body_bottom": layout.body_bottom_z_mm,
            "bearing_seat": layout.seat_z_mm,
            "body_top": layout.body_top_z_mm,
            "flange": layout.flange_z_mm,
            "flange_top": layout.flange_top_z_mm,
        },
        "walls_mm": {"reflector": layout.reflector_walls_mm, "body": layout.body_walls_mm},
        "segments": {
            "reflecting_sphere": sphere_segments(refl.radius_mm, tolerance_mm),
            "circle_of_the_sphere": circle_segments(refl.radius_mm, tolerance_mm),
        },
        "cad_parameters": layout.params.to_dict(),
    }


def _file_entry(paths, triangles):
    """File names (within the output folder), their sizes in bytes, and the triangle count."""
    entry = {k: v.name for k, v in paths.items()}
    entry.update({f"{k}_bytes": v.stat().st_size for k, v in paths.items()})
    entry["triangles"] = triangles
    return entry


def _write_part(out, name, mesh):
    paths = {"stl": out / f"{name}.stl", "3mf": out / f"{name}.3mf"}
    write_stl(paths["stl"], mesh)
    write_3mf(paths["3mf"], {name: mesh})
    return paths


def _turned(solids, meshes, pose_deg):
    """Every solid's mesh at the pose: the turning meshes are the zero-pose meshes turned."""
    turn = np.vstack([pose_matrix(*pose_deg), [0.0, 0.0, 0.0, 1.0]])
    return {
        name: meshes[name].copy().apply_transform(turn) if name in solids.rotating else meshes[name]
        for name in SOLIDS
    }


def _assembly_clearance(solids, pose_deg, gap):
    """Clearance of the reflector part at the assembly's pose (``gap`` from
    :func:`gap_at_pose`); the overlap volume is measured only if the gap there is zero."""
    return {
        "pose_deg": list(pose_deg),
        "intersection_mm3": 0.0 if gap > 0.0 else overlap_mm3(solids, pose_deg, ("reflector",)),
        "clearance_mm": gap,
    }


def _check(design, solids, meshes, layout, parts, tolerance_mm, pose_deg, progress):
    """Clearance (over the workspace and, for the assembly, at its pose), printability and
    the Eq 3 ray check; one line for the first problem.

    The clearance is proved in a forked process (coal on the meshes) while the parts are
    checked here; the assembly's gap at its pose and the overlap volumes (manifold3d) are
    measured here.
    """
    with BackgroundCall(lambda: prove_clearance(meshes, design.workspace)) as measuring:
        progress(0.2, "checking printability and proving clearance over the workspace")
        printed = [p for p in ("reflector", "body") if p in parts or "assembly" in parts]
        reports = {
            name: check_printability(
                name, getattr(solids, name), meshes[name], layout, tolerance_mm
            )
            for name in printed
        }
        progress(0.4, "checking the reflector against Eq 3")
        ray = verify_distances(meshes["reflector"], design, tolerance_mm)
        gap = gap_at_pose(meshes, pose_deg) if "assembly" in parts else None
        progress(0.5, "proving clearance over the workspace")
        proof = measuring.result()
    collision = collision_report(solids, design.workspace, proof)
    assembly = None if gap is None else _assembly_clearance(solids, pose_deg, gap)
    problems = [] if collision.problem is None else [collision.problem]
    problems += [line for r in reports.values() for line in r.problems]
    if not ray.passed:
        problems.append(
            f"reflector: the mesh departs from the Eq 3 sphere by {ray.max_error_mm:.4f} mm "
            f"({ray.missed} of {ray.rays} rays missed), more than the tolerance {tolerance_mm:g} mm"
        )
    if problems:
        more = f" (and {len(problems) - 1} more)" if len(problems) > 1 else ""
        raise InputError(problems[0] + more)
    return collision, reports, ray, assembly


def _pictures(parts, solids, meshes, layout, pose_deg):
    """The PNG pictures of the parts: each file's part and key, and a call drawing them all.

    What the pictures show (meshes simplified, sections cut) is made here with manifold3d;
    ``draw(folder)`` only draws, importing matplotlib itself, so that an export without
    pictures never imports it and a forked process can draw.
    """
    printed = [name for name in ("reflector", "body") if name in parts]
    names = {f"{name}.png": (name, "png") for name in printed}
    shown = SOLIDS if "assembly" in parts else printed
    drawn = {name: simplified(meshes[name]) for name in shown}  # each solid simplified once
    if "assembly" in parts:
        names["assembly.png"] = ("assembly", "png")
        names["assembly_section.png"] = ("assembly", "section_png")
        posed_drawn = _turned(solids, drawn, pose_deg)
        azimuths = [math.degrees(math.atan2(m.front_mm[1], m.front_mm[0])) for m in layout.sensors]
        posed = solids.posed(*pose_deg)
        sections = [
            {name: section_polygons(solid, azimuth) for name, solid in posed.items()}
            for azimuth in azimuths
        ]

    def draw(folder):
        from reflector_opt.cad._preview import render_meshes, render_section

        for name in printed:
            title = f"{name}: {len(meshes[name].faces)} triangles"
            render_meshes(folder / f"{name}.png", {name: drawn[name]}, title, simplify=False)
        if "assembly" in parts:
            label = f"pitch {pose_deg[0]:g}°, roll {pose_deg[1]:g}°"
            title = f"assembly at {label}"
            render_meshes(folder / "assembly.png", posed_drawn, title, simplify=False)
            render_section(
                folder / "assembly_section.png",
                sections,
                layout,
                azimuths,
                pose_deg,
                title=f"sections through the sensors at {label}",
            )

    return names, draw


def _report(design, layout, meshes, paths, checks, tolerance_mm):
    """The JSON-ready report of :func:`export_parts` from the written files (None: not
    written yet, no files) and the checks."""
    collision, reports, ray, assembly = checks
    triangles = {name: len(mesh.faces) for name, mesh in meshes.items()}
    triangles["assembly"] = sum(triangles[name] for name in SOLIDS)
    files = {name: _file_entry(p, triangles[name]) for name, p in (paths or {}).items()}
    return {
        "tolerance_mm": tolerance_mm,
        "files": files,
        "printability": {name: r.to_dict() for name, r in reports.items()},
        "collision": collision.to_dict(),
        "ray_check": ray.to_dict(),
        "assembly": assembly,
        "layout": _layout_summary(layout, design, tolerance_mm),
        "report": "cad_report.json",
    }


def _built(design, params, tolerance_mm):
    """The design's layout, solids and meshes: each solid is meshed once, and the checks, the
    files and the pictures share the meshes."""
    layout = plan_layout(design, params)
    solids = build_parts(design, layout, tolerance_mm)
    return layout, solids, {name: to_trimesh(getattr(solids, name)) for name in SOLIDS}


@contextmanager
def _drawn(parts, built, pose_deg, preview):
    """The pictures drawn in another process while the caller goes on: (their file names,
    the :class:`BackgroundFiles`), or None without ``preview``; nothing is kept unless they
    are collected."""
    if not preview:
        yield None
        return
    layout, solids, meshes = built
    names, draw = _pictures(parts, solids, meshes, layout, pose_deg)
    with BackgroundFiles(draw) as files:
        yield names, files


@dataclass(frozen=True)
class CheckedParts:
    """A design's parts built and passed by every check of :func:`export_parts`, held in
    memory (:func:`check_parts`); :meth:`write` writes them as :func:`export_parts` does.

    Attributes
    ----------
    design : reflector_opt.design.Design
    built : tuple
        The layout, the solids and their meshes.
    checks : tuple
        The collision report, the printability reports, the ray check and the assembly's
        clearance at its pose.
    parts : tuple of str
    tolerance_mm : float
    pose_deg : (float, float)
    exact : dict
        The printed parts' exact STEP solids, checked against their meshes (empty unless
        asked for).
    pictures : dict
        The PNG pictures drawn while the parts were checked (:func:`check_parts` with
        ``preview``): each file's name to its part, its key and its bytes; empty if none.
    """

    design: object
    built: tuple
    checks: tuple
    parts: tuple
    tolerance_mm: float
    pose_deg: tuple
    exact: dict = field(default_factory=dict)
    pictures: dict = field(default_factory=dict, repr=False)

    def summary(self):
        """The export's report without its files (:func:`export_parts`), before writing."""
        layout, _, meshes = self.built
        return _report(self.design, layout, meshes, None, self.checks, self.tolerance_mm)

    def write(self, out_dir, preview=True, progress=None):
        """Write the parts' files into ``out_dir`` (parameters as :func:`export_parts`'s)
        and return the export's report; the checks are not run again, and pictures drawn
        with them are written as drawn."""
        with _drawn(
            self.parts, self.built, self.pose_deg, preview and not self.pictures
        ) as pictures:
            return self._write(Path(out_dir), pictures, progress or no_progress, preview)

    def _write(self, out, pictures, progress, preview=True):
        layout, solids, meshes = self.built
        printed = tuple(name for name in ("reflector", "body") if name in self.parts)
        progress(0.7, "writing the parts and their pictures")
        paths = {name: _write_part(out, name, meshes[name]) for name in printed}
        if "assembly" in self.parts:
            paths["assembly"] = {"3mf": out / "assembly.3mf"}
            write_3mf(paths["assembly"]["3mf"], _turned(solids, meshes, self.pose_deg))
        for name, solid in self.exact.items():
            paths[name]["step"] = write_step(out / f"{name}.step", solid)
        drawn = {} if pictures is None else _collected(pictures, out)
        for file, (name, key, data) in (self.pictures if preview else {}).items():
            (out / file).write_bytes(data)
            drawn[file] = (name, key, out / file)
        for name, key, path in drawn.values():
            paths[name][key] = path
        report = _report(self.design, layout, meshes, paths, self.checks, self.tolerance_mm)
        write_json(out / "cad_report.json", report)
        progress(1.0, "parts written")
        return report


def _collected(pictures, folder):
    """The pictures of :func:`_drawn` moved into ``folder``: each file's part, key, path."""
    names, files = pictures
    return {file: (*names[file], path) for file, path in files.collect(folder, list(names)).items()}


def _checked(design, built, parts, tolerance_mm, pose_deg, step, progress):
    layout, solids, meshes = built
    checks = _check(design, solids, meshes, layout, parts, tolerance_mm, pose_deg, progress)
    exact = {}
    if step:
        progress(0.6, "building the STEP solids and checking them against the meshes")
        printed = tuple(name for name in ("reflector", "body") if name in parts)
        exact = build_step_parts(design, layout, printed, reference=solids)
    return CheckedParts(design, built, checks, parts, tolerance_mm, pose_deg, exact)


def check_parts(
    design,
    parts=("reflector", "body"),
    tolerance_mm=DEFAULT_TOLERANCE_MM,
    params=None,
    pose_deg=(0.0, 0.0),
    step=False,
    progress=None,
    preview=False,
):
    """Build and check the parts of a design as :func:`export_parts` does, writing nothing.

    Parameters are :func:`export_parts`'s; with ``preview`` the pictures are drawn in another
    process while the parts are checked, and kept in memory.

    Returns
    -------
    CheckedParts
        The parts with their checks, to be written by :meth:`CheckedParts.write`.

    Raises
    ------
    reflector_opt.util._errors.InputError
        The first problem :func:`export_parts` would refuse the parts for (one line).
    """
    parts, pose_deg = tuple(parts), tuple(float(a) for a in pose_deg)
    _check_request(parts, tolerance_mm, pose_deg, step)
    progress = progress or no_progress
    built = _built(design, params, tolerance_mm)
    with _drawn(parts, built, pose_deg, preview) as pictures:
        checked = _checked(design, built, parts, tolerance_mm, pose_deg, step, progress)
        if pictures is None:
            return checked
        with tempfile.TemporaryDirectory() as folder:
            drawn = _collected(pictures, Path(folder))
            kept = {
                file: (name, key, path.read_bytes()) for file, (name, key, path) in drawn.items()
            }
    return replace(checked, pictures=kept)


def export_parts(
    design,
    out_dir="cad_out",
    parts=("reflector", "body"),
    tolerance_mm=DEFAULT_TOLERANCE_MM,
    params=None,
    pose_deg=(0.0, 0.0),
    preview=True,
    step=False,
    progress=None,
):
    """Build, check and write the printable parts of a design.

    Writes, for each printed part, ``<part>.stl`` (binary), ``<part>.3mf`` and (with
    ``preview``) ``<part>.png``; for ``"assembly"``, ``assembly.3mf`` and ``assembly.png``
    with every solid (bearing and sensors too) at ``pose_deg``, plus a cross-section
    ``assembly_section.png``; with ``step``, ``<part>.step`` for each printed part (exact
    solids, :mod:`reflector_opt.cad._step`, each checked against its mesh before anything is
    written); and always ``cad_report.json``, the returned report. The same design and
    arguments give byte-identical STL and 3MF files.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    out_dir : str or pathlib.Path
        Output folder (created if missing).
    parts : sequence of {"reflector", "body", "assembly"}
        What to write.
    tolerance_mm : float
        Chord tolerance between the meshes and the true surfaces, mm (0 < δ ≤ 0.05).
    params : reflector_opt.cad.CadParameters, optional
        Printable-part dimensions; the paper's prototype by default.
    pose_deg : (float, float)
        Pitch and roll of the assembly view, degrees.
    preview : bool
        Also render the PNG pictures.
    step : bool
        Also write the printed parts as STEP files (needs the optional build123d:
        ``pip install 'reflector-opt[step]'``).
    progress : callable, optional
        ``progress(fraction, message)`` before each step
        (:class:`~reflector_opt.util._progress.Progress`).

    Returns
    -------
    dict
        JSON-ready: ``files`` (per part: file names within ``out_dir``, triangle count, byte
        sizes; a part's STEP file is its ``step`` entry), ``printability`` (per printed part),
        ``collision``, ``ray_check``, ``assembly`` (clearance at the pose), ``layout``,
        ``tolerance_mm`` and ``report`` (``"cad_report.json"``).

    Raises
    ------
    reflector_opt.util._errors.InputError
        The design cannot be made into parts, a part fails its printability report, the
        parts collide, the Eq 3 ray check fails, STEP is asked for without build123d, a STEP
        solid disagrees with its mesh (:func:`~reflector_opt.cad._step.mesh_disagreement`), or
        the output cannot be written. Nothing is written in the first six cases.
    """
    parts, pose_deg = tuple(parts), tuple(float(a) for a in pose_deg)
    _check_request(parts, tolerance_mm, pose_deg, step)
    progress = progress or no_progress
    progress(0.0, "building the solids")
    built = _built(design, params, tolerance_mm)
    # The pictures are drawn while the parts are checked, and written only if they pass.
    with _drawn(parts, built, pose_deg, preview) as pictures:
        checked = _checked(design, built, parts, tolerance_mm, pose_deg, step, progress)
        return checked._write(Path(out_dir), pictures, progress)
