"""PNG pictures of the parts: a shaded 3-D view and a cross-section, drawn with matplotlib.

Figures are made with :class:`matplotlib.figure.Figure` on an Agg canvas, so no pyplot
state or interactive backend is involved, and saved atomically.
"""

import numpy as np
import trimesh
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import to_rgb
from matplotlib.figure import Figure
from matplotlib.patches import Circle, PathPatch
from matplotlib.path import Path
from matplotlib.ticker import MaxNLocator
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

from reflector_opt.cad._drawing import simplified
from reflector_opt.model._geometry import rotate_centre
from reflector_opt.util._fileio import write_file

#: Colour of each solid in the pictures.
COLOURS = {
    "reflector": "#d8dde3",
    "body": "#7f95ad",
    "outer_ring": "#555555",
    "inner_ring": "#8a8a8a",
    "sensors": "#c0392b",
}
#: What each solid is, in the legend of the sections.
LABELS = {
    "reflector": "reflector (rotates with the upper part)",
    "body": "lower body",
    "outer_ring": "bearing, outer ring",
    "inner_ring": "bearing, inner ring",
    "sensors": "sensor packages on their PCB strip",
}
_LIGHT = np.array([0.6, 0.2, 0.78]) / np.linalg.norm([0.6, 0.2, 0.78])
#: Longest triangle edge drawn in a 3-D preview, mm.
PREVIEW_EDGE_MM = 1.5
#: Most tick intervals on each axis of a 3-D preview, and the tick labels' size, points.
PREVIEW_TICKS, PREVIEW_TICK_SIZE = 5, 8


def _save(fig, path):
    FigureCanvasAgg(fig)
    write_file(path, lambda tmp: fig.savefig(tmp, format="png", dpi=fig.dpi), ".png")


def space_ticks(ax):
    """Few, round ticks on each axis of a 3-D view, so their labels do not overlap.

    matplotlib's default puts a tick every 2.5 mm on a part of 20 mm, and the foreshortened
    axes of the oblique view then print their labels over each other. At most
    :data:`PREVIEW_TICKS` intervals, at steps of 1, 2 or 5 times a power of ten, labelled in
    a smaller font.

    Parameters
    ----------
    ax : mpl_toolkits.mplot3d.axes3d.Axes3D
    """
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_major_locator(MaxNLocator(nbins=PREVIEW_TICKS, steps=[1, 2, 5, 10]))
    ax.tick_params(labelsize=PREVIEW_TICK_SIZE, pad=1)


def render_meshes(path, meshes, title="", simplify=True):
    """Shaded 3-D view of one or more meshes, saved as PNG.

    Parameters
    ----------
    path : str or pathlib.Path
    meshes : dict of str to trimesh.Trimesh
        Name (a key of :data:`COLOURS`) → mesh, mm.
    title : str
    simplify : bool
        Draw each mesh simplified for the picture
        (:func:`~reflector_opt.cad._drawing.simplified`); False if it already is.
    """
    fig = Figure(figsize=(6.0, 5.0), dpi=110)
    ax = fig.add_subplot(projection="3d")
    lo = np.min([m.bounds[0] for m in meshes.values()], axis=0)
    hi = np.max([m.bounds[1] for m in meshes.values()], axis=0)
    for name, mesh in meshes.items():
        # matplotlib paints faces back to front by their centres; long thin triangles (the
        # fans on flat faces) would be misordered, so split them for the picture.
        drawn = simplified(mesh) if simplify else mesh
        vertices, faces = trimesh.remesh.subdivide_to_size(
            drawn.vertices, drawn.faces, max_edge=PREVIEW_EDGE_MM
        )
        triangles = vertices[faces]
        normals = trimesh.triangles.normals(triangles)[0]
        base = np.array(to_rgb(COLOURS.get(name, "#999999")))
        shade = 0.35 + 0.65 * np.clip(normals @ _LIGHT, 0.0, 1.0)
        colours = np.clip(base[None, :] * shade[:, None], 0.0, 1.0)
        ax.add_collection3d(
            Poly3DCollection(triangles, facecolors=colours, edgecolors="none", linewidths=0)
        )
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(hi - lo)
    ax.view_init(elev=18.0, azim=40.0)
    space_ticks(ax)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_zlabel("z (mm)")
    ax.set_title(title, fontsize=10)
    _save(fig, path)


def _outline(polygons):
    """Closed polygons as one matplotlib Path (None if there are none)."""
    vertices, codes = [], []
    for poly in polygons:
        vertices.extend([*poly, poly[0]])
        codes.extend([Path.MOVETO] + [Path.LINETO] * (len(poly) - 1) + [Path.CLOSEPOLY])
    return Path(np.asarray(vertices), codes) if vertices else None


def render_section(path, sections, layout, azimuths_deg, pose_deg=(0.0, 0.0), title=""):
    """Cross-sections through the unit's axis at given azimuths, saved as PNG.

    Parameters
    ----------
    path : str or pathlib.Path
    sections : list of dict of str to list of numpy.ndarray
        For each azimuth, name (a key of :data:`COLOURS`) → the solid's outline in that
        half-plane (:func:`~reflector_opt.cad._drawing.section_polygons` of the solid, posed
        as wanted), mm.
    layout : reflector_opt.design._layout.Layout
        For the reference circles (reflecting sphere, inner surface).
    azimuths_deg : sequence of float
        One panel per azimuth: the half-plane through z at that azimuth and its opposite.
    pose_deg : (float, float)
        Pitch and roll the rotating solids were posed at (for the sphere's drawn centre).
    title : str
    """
    centre = rotate_centre(layout.sphere_centre_mm, *pose_deg)
    fig = Figure(figsize=(5.2 * len(azimuths_deg), 5.4), dpi=110)
    for k, azimuth in enumerate(azimuths_deg):
        ax = fig.add_subplot(1, len(azimuths_deg), k + 1)
        for name, polygons in sections[k].items():
            outline = _outline(polygons)
            if outline is not None:
                ax.add_patch(
                    PathPatch(
                        outline, facecolor=COLOURS.get(name, "#999999"), edgecolor="k", lw=0.4
                    )
                )
        a = np.deg2rad(azimuth)
        along = centre[0] * np.cos(a) + centre[1] * np.sin(a)
        ax.add_patch(
            Circle((along, centre[2]), layout.sphere_radius_mm, fill=False, ls="--", lw=0.6)
        )
        ax.add_patch(Circle((0, 0), layout.inner_radius_mm, fill=False, ls=":", lw=0.6))
        ax.plot([0], [0], "k+", ms=8)
        ax.annotate("O", (0.3, 0.3), fontsize=8)
        ax.plot([along], [centre[2]], "kx", ms=6)
        r = layout.envelope_radius_mm + 1.0
        ax.set_xlim(-r, r)
        ax.set_ylim(layout.body_bottom_z_mm - 1.0, layout.flange_top_z_mm + 1.0)
        ax.set_aspect("equal")
        ax.set_xlabel(f"distance along azimuth {azimuth:.1f}° (mm)")
        ax.set_ylabel("z (mm)")
        ax.grid(True, lw=0.3)
    fig.suptitle(title, fontsize=10)
    _section_legend(fig, [name for section in sections for name in section if section[name]])
    _save(fig, path)


def _section_legend(fig, names):
    """The legend of :func:`render_section`, below the panels: each solid drawn, the
    reflecting sphere, the inner surface and the two centres."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    handles = [
        Patch(facecolor=COLOURS.get(n, "#999999"), edgecolor="k", lw=0.4, label=LABELS.get(n, n))
        for n in dict.fromkeys(names)
    ]
    handles += [
        Line2D([], [], color="k", ls="--", lw=0.6, label="reflecting sphere"),
        Line2D([], [], color="k", ls=":", lw=0.6, label="reflector's inner surface"),
        Line2D([], [], color="k", marker="+", ls="", label="O, rotation centre"),
        Line2D([], [], color="k", marker="x", ls="", label="sphere centre C"),
    ]
    fig.legend(handles=handles, loc="lower center", ncol=3, fontsize=7, frameon=False)
    fig.subplots_adjust(bottom=0.24)
