"""Plane geometry of the section drawings: a sensor's vertical plane, points in its coordinates,
and the circle a sphere cuts from it."""

import numpy as np


def sensor_plane(design, sensor):
    """The vertical plane that holds a sensor's optical axis, as an origin and two directions.

    The plane contains the sensor position f, the vertical z and the horizontal part of the
    optical axis a (the radial direction of f if a is vertical, +x if f is on the axis too).
    Its in-plane coordinates are (along, z): ``along`` measured from the point of the plane
    nearest the unit's axis, positive towards the sensor's side, so the sensor sits on the
    right looking left.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    sensor : int
        Index of the sensor.

    Returns
    -------
    normal : numpy.ndarray, shape (3,)
        Unit normal n of the plane (horizontal).
    offset : float
        ``n · f``: signed distance of the plane from the unit's axis, mm.
    along : numpy.ndarray, shape (3,)
        Unit horizontal direction in the plane, pointing from the axis towards the sensor.
    """
    f, a = design.positions_mm[sensor], design.axes[sensor]
    horizontal = np.array([a[0], a[1], 0.0])
    for fallback in ([f[0], f[1], 0.0], [1.0, 0.0, 0.0]):
        if np.linalg.norm(horizontal) < 1e-9:
            horizontal = np.array(fallback)
    along = horizontal / np.linalg.norm(horizontal)
    if along @ f < 0:
        along = -along
    normal = np.cross(along, [0.0, 0.0, 1.0])
    return normal, float(normal @ f), along


def in_plane(points, along):
    """In-plane coordinates (along, z) of points in a sensor's plane.

    Parameters
    ----------
    points : array_like
        Shape (..., 3): points of the plane, mm.
    along : numpy.ndarray, shape (3,)
        The plane's horizontal direction (:func:`sensor_plane`).

    Returns
    -------
    along_mm, z_mm : numpy.ndarray
        Shape (...): the coordinates, mm.
    """
    points = np.asarray(points, dtype=float)
    return points @ along, points[..., 2]


def section_circle(ax, centre, radius, normal, offset, along, **style):
    """Draw the circle a sphere cuts from a sensor's plane, in its (along, z) coordinates.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    centre : numpy.ndarray, shape (3,)
        The sphere's centre, mm.
    radius : float
        The sphere's radius, mm.
    normal, offset, along
        The plane, as :func:`sensor_plane` gives it.
    **style
        Keywords of :meth:`matplotlib.axes.Axes.plot`.

    Returns
    -------
    bool
        False if the sphere misses the plane (nothing drawn).
    """
    depth = float(normal @ centre) - offset
    if radius**2 <= depth**2:
        return False
    rho = np.sqrt(radius**2 - depth**2)
    t = np.linspace(0.0, 2.0 * np.pi, 361)
    ax.plot(float(along @ centre) + rho * np.cos(t), centre[2] + rho * np.sin(t), **style)
    return True
