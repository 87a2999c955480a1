"""An interactive 3D view of a design, in one HTML file that needs no network.

The view shows the printed parts (the reflector part and the unit body, the body cut away on
the sensors' side), the bearing's rings, the sensor packages, each sensor's optical axis up
to where it meets the reflector, and the shortest sensor-to-reflector distance of paper Eq 3
(d = ‖f − s1‖ − r_s) with its value, at a pose chosen with two sliders, pitch and roll, over
the design's workspace. A drag turns the camera, the wheel zooms. The same page and script
draw the live view of ``stream --view`` (:func:`live_page`): a chain of the units, posed by a
WebSocket's messages.

Everything drawn is computed here, by the package: the meshes are the CAD solids
(:func:`reflector_opt.cad._solids.build_parts` on the layout of
:func:`reflector_opt.design._layout.plan_layout`), simplified to within
:data:`VIEW_SIMPLIFY_MM`; the slider values form a grid over the workspace
(:func:`slider_values`), and at every pose of it the forward model
(:func:`reflector_opt.model._forward.respond`) gives the Eq 3 and axial distances. The page
turns the reflector part and the inner ring about the joint centre O by R = Rx(α)·Ry(γ)
(paper Eq 1) from the model's own Rx and Ry (:mod:`reflector_opt.model._geometry`) at the
slider values, and draws the meshes on a 2D canvas (no WebGL) with a small script shipped
with the package (``report/templates/view3d.js``); the data sit in the page as base64
arrays. It loads nothing from anywhere.

:func:`design_view` gives the page, :func:`write_view` writes it (``reflector-opt export``
writes ``view.html``) and :func:`view_blocks` is the report's section, which carries the
same view inside ``report.html``.
"""

import base64
import json
import math
from pathlib import Path

import numpy as np
from markupsafe import Markup

from reflector_opt.cad._drawing import simplified
from reflector_opt.cad._solids import SOLIDS, build_parts
from reflector_opt.cad._tessellation import to_trimesh
from reflector_opt.design._layout import plan_layout
from reflector_opt.model._forward import respond
from reflector_opt.model._geometry import rotation_x, rotation_y, surface_normal, unit
from reflector_opt.report._render import render_template
from reflector_opt.util._errors import InputError
from reflector_opt.util._fileio import write_text
from reflector_opt.util._limits import DEFAULT_TOLERANCE_MM

#: The file :func:`write_view` writes.
VIEW_FILE = "view.html"

#: The view draws each mesh simplified to within this distance of the CAD mesh, mm.
VIEW_SIMPLIFY_MM = 0.05

#: A slider's step, degrees: the first of these that takes at most :data:`SLIDER_STEPS`
#: steps over the workspace range.
SLIDER_STEPS_DEG = (1.0, 2.0, 5.0, 10.0, 20.0)

#: Steps a slider takes at most over its range (1° steps up to a 30° range).
SLIDER_STEPS = 30

#: Each solid's colour and label in the view.
_SOLID_STYLE = {
    "reflector": ("#e6e1d3", "reflector part (turns with the pose)"),
    "inner_ring": ("#8d949e", "bearing inner ring (turns)"),
    "body": ("#9dbad9", "unit body, cut away on the sensors' side"),
    "outer_ring": ("#6f7680", "bearing outer ring"),
    "sensors": ("#2b2b2b", "sensor packages"),
}
#: Colours of the sensors' beams, in turn.
_BEAM_COLOURS = ("#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b")


def slider_values(span_deg):
    """The values a pose slider takes over one workspace range.

    Both ends of the range and the whole multiples of a step between them (so zero, where
    the range holds it): 1°, or the first step of :data:`SLIDER_STEPS_DEG` that takes at most
    :data:`SLIDER_STEPS` steps over the range.

    Parameters
    ----------
    span_deg : (float, float)
        The range's ends, degrees (low, high).

    Returns
    -------
    numpy.ndarray
        The slider's values, degrees, ascending.
    """
    low, high = (float(a) for a in span_deg)
    step = next(
        (s for s in SLIDER_STEPS_DEG if high - low <= s * SLIDER_STEPS), SLIDER_STEPS_DEG[-1]
    )
    inner = step * np.arange(math.floor(low / step), math.ceil(high / step) + 1)
    inner = inner[(inner > low + 1e-9) & (inner < high - 1e-9)]
    return np.unique(np.concatenate([[low], inner, [high]]))


def _b64(array, dtype):
    """An array as base64 of its little-endian bytes (``<f4`` or ``<u4``)."""
    return base64.b64encode(np.ascontiguousarray(array, dtype=dtype).tobytes()).decode("ascii")


def _cut_normal(design):
    """The horizontal direction away from the sensors: the body's half on it is kept."""
    xy = design.positions_mm[:, :2].mean(axis=0)
    if np.hypot(*xy) < 1e-6:  # sensors facing each other: cut on the first one's side
        xy = design.positions_mm[0, :2]
    if np.hypot(*xy) < 1e-6:
        xy = np.array([1.0, 0.0])
    return -xy / np.hypot(*xy)


def _mesh_entries(design, params, tolerance_mm):
    """Every solid of the joint as a simplified mesh (vertices ``<f4``, faces ``<u4``, base64)."""
    layout = plan_layout(design, params)
    solids = build_parts(design, layout, tolerance_mm)
    normal = (*_cut_normal(design), 0.0)
    entries = []
    for name in SOLIDS:
        solid = getattr(solids, name)
        if name in ("body", "outer_ring"):
            solid = solid.trim_by_plane(normal, 0.0)
        if solid.is_empty():
            continue
        mesh = simplified(to_trimesh(solid), VIEW_SIMPLIFY_MM)
        colour, label = _SOLID_STYLE[name]
        entries.append(
            {
                "name": name,
                "label": label,
                "colour": colour,
                "rotating": name in solids.rotating,
                "vertices": _b64(mesh.vertices, "<f4"),
                "faces": _b64(mesh.faces, "<u4"),
                "triangles": len(mesh.faces),
            }
        )
    return entries


def _pose_entries(design, pitch_deg, roll_deg):
    """The model at every slider pose: Eq 3 and axial distances, and the beams' end points.

    Arrays are laid out (pitch, roll, sensor[, xyz]) and flattened, as base64 ``<f4``.
    """
    pitch, roll = np.meshgrid(pitch_deg, roll_deg, indexing="ij")
    response = respond(design, pitch, roll)
    sensors = design.positions_mm
    hit = sensors + response.axial_distance_mm[..., None] * unit(design.axes)
    towards = surface_normal(sensors, design.reflector.centre_mm, pitch, roll)
    nearest = sensors - response.distance_mm[..., None] * towards
    return {
        "distance_mm": _b64(response.distance_mm, "<f4"),
        "axial_mm": _b64(response.axial_distance_mm, "<f4"),
        "hit_mm": _b64(hit, "<f4"),
        "nearest_mm": _b64(nearest, "<f4"),
        "rx": [rotation_x(a).tolist() for a in roll_deg],
        "ry": [rotation_y(a).tolist() for a in pitch_deg],
    }


def view_scene(design, *, params=None, tolerance_mm=DEFAULT_TOLERANCE_MM):
    """Everything the 3D view draws, JSON-ready.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    params : reflector_opt.design._parts.CadParameters, optional
        Printable-part dimensions; the paper's prototype by default.
    tolerance_mm : float, optional
        Chord tolerance the solids are built with, mm, before they are simplified to within
        :data:`VIEW_SIMPLIFY_MM`.

    Returns
    -------
    dict
        ``meshes`` (name, label, colour, ``rotating``, base64 ``vertices`` in mm and
        ``faces``, triangle count), ``sensors`` (name, ``position_mm``, colour),
        ``pitch_deg`` and ``roll_deg`` (the slider values, degrees), ``start`` (their
        indices nearest zero), ``rx`` and ``ry`` (the model's Rx(α) and Ry(γ) at them), the
        per-pose arrays ``distance_mm`` (Eq 3), ``axial_mm``, ``hit_mm`` (where each axis
        meets the sphere) and ``nearest_mm`` (the sphere's point nearest each sensor),
        ``centre_mm`` (O), ``extent_mm`` and ``azimuth_deg`` for the camera, and ``live``
        (None: the live view's, :func:`live_page`).

    Raises
    ------
    reflector_opt.util._errors.InputError
        The parts cannot be laid out, or a sensor meets the reflector at a slider pose.
    """
    pitch_deg = slider_values(design.workspace.pitch_deg)
    roll_deg = slider_values(design.workspace.roll_deg)
    meshes = _mesh_entries(design, params, tolerance_mm)
    sensors = [
        {
            "name": s.name,
            "position_mm": [float(x) for x in s.position_mm],
            "colour": _BEAM_COLOURS[i % len(_BEAM_COLOURS)],
        }
        for i, s in enumerate(design.sensors)
    ]
    towards_sensors = -_cut_normal(design)
    return {
        "meshes": meshes,
        "sensors": sensors,
        "pitch_deg": pitch_deg.tolist(),
        "roll_deg": roll_deg.tolist(),
        "start": [int(np.abs(pitch_deg).argmin()), int(np.abs(roll_deg).argmin())],
        **_pose_entries(design, pitch_deg, roll_deg),
        "centre_mm": [0.0, 0.0, 0.0],
        "extent_mm": 0.5
        * math.hypot(design.mechanics.unit_diameter_mm, design.mechanics.unit_height_mm),
        "azimuth_deg": math.degrees(math.atan2(towards_sensors[1], towards_sensors[0])),
        "live": None,
    }


def _script_json(data):
    """JSON for a ``<script type="application/json">`` element: ``<``, ``>``, ``&`` escaped."""
    text = json.dumps(data, separators=(",", ":"), allow_nan=False)
    text = text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")
    return Markup(text)


def view_fragment(design, **options):
    """The 3D view as an HTML fragment to put in a page (its style and script inside).

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    **options
        ``params`` and ``tolerance_mm`` of :func:`view_scene`.

    Returns
    -------
    markupsafe.Markup
        One ``<div class="view3d">`` element; several can share a page.
    """
    return _fragment(view_scene(design, **options))


def _fragment(scene):
    legend = [(m["colour"], m["label"]) for m in scene["meshes"]]
    fragment = render_template(
        "view3d.html.j2", scene=scene, data=_script_json(scene), legend=legend
    )
    return Markup(fragment)


def design_view(design, *, title="Reflector design: 3D view", **options):
    """The 3D view of a design as a whole HTML page that needs no network.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    title : str, optional
    **options
        ``params`` and ``tolerance_mm`` of :func:`view_scene`.

    Returns
    -------
    str
        The page (a few hundred kB: the meshes and the per-pose data are inside it).
    """
    return render_template(
        "view3d_page.html.j2", title=title, view=view_fragment(design, **options)
    )


def live_page(design, n_units, link_length_mm):
    """The live view of ``stream --view``: the design's units stacked one link length apart,
    each posed by the newest shape the page's WebSocket pushes
    (:class:`reflector_opt.robot._live.LiveView`, at :data:`~reflector_opt.robot._live.PATH`).

    Unit i's body stands in the frame F_i = R_1 ⋯ R_{i-1} at c_i = L Σ_{k<i} (R_1 ⋯ R_k) ẑ, its
    reflector part and inner ring in F_i R_i, with R_k = Rx(roll)·Ry(pitch) of unit k (paper
    Eq 1) as the message carries it: the chain of
    :func:`reflector_opt.calibration._segment.tip_pose`, composed by the page, whose tip is
    c_{n+1}. No sliders and no beams: the poses are the stream's, not a grid's.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    n_units : int
        Units in the chain, base first.
    link_length_mm : float
        L, the distance between consecutive rotation centres, mm.

    Returns
    -------
    str
        The page; it loads nothing but the WebSocket.
    """
    from reflector_opt.robot._live import PATH, UPDATES_PER_S

    scene = view_scene(design)
    height = n_units * link_length_mm + design.mechanics.unit_height_mm
    scene.update(
        live={"link_mm": link_length_mm, "units": n_units, "path": PATH, "per_s": UPDATES_PER_S},
        centre_mm=[0.0, 0.0, 0.5 * n_units * link_length_mm],
        extent_mm=0.5 * math.hypot(design.mechanics.unit_diameter_mm, height),
    )
    title = f"Live shape: {n_units} unit(s), {link_length_mm:g} mm apart"
    return render_template("view3d_page.html.j2", title=title, view=_fragment(scene))


def write_view(design, out_dir, **options):
    """Write :func:`design_view` to ``out_dir/view.html`` (atomically).

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    out_dir : str or pathlib.Path
        An existing folder.
    **options
        ``params`` and ``tolerance_mm`` of :func:`view_scene`.

    Returns
    -------
    pathlib.Path
        The page written.
    """
    path = Path(out_dir) / VIEW_FILE
    write_text(path, design_view(design, **options))
    return path


def view_blocks(design):
    """The report's "3D view" section: the view inside ``report.html``, a pointer in Markdown.

    Parameters
    ----------
    design : reflector_opt.design._design.Design

    Returns
    -------
    list of tuple
        A heading, a paragraph and an ``("html", fragment, markdown text)`` block; or, for a
        design whose parts cannot be made, the heading and the reason.
    """
    blocks = [("h2", "3D view")]
    try:
        fragment = view_fragment(design)
    except InputError as exc:
        return [*blocks, ("p", f"No 3D view: {exc}")]
    blocks.append(
        (
            "p",
            "The parts at a pose chosen with the sliders: each sensor's optical axis (solid "
            "line) up to where it meets the reflector, and the Eq 3 distance d it measures "
            "(dashed, the shortest way to the sphere). Drag to turn the view, scroll to zoom. "
            f"`reflector-opt export` writes the same view alone as `{VIEW_FILE}`.",
        )
    )
    markdown = "The interactive 3D view is in `report.html`: open that page in a browser."
    return [*blocks, ("html", fragment, markdown)]
