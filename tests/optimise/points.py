"""Points of the default optimisation problem shared by the optimiser's tests."""

import numpy as np

from reflector_opt.design._layout import plan_layout

POINT = {
    "gap_mm": 0.8,
    "centre_along_mm": 0.9,
    "centre_across_mm": 0.0,
    "centre_z_mm": -0.6,
    "sensor_radius_mm": 10.0,
    "sensor_height_mm": -0.3,
    "sensor_tilt_deg": 15.0,
    "sensor_azimuth_deg": 0.0,
    "sensor_separation_deg": 80.0,
}


#: An optimum of an earlier version, which judged walls by the light spots alone: every
#: constraint is met on the workspace grid, but the body's wall behind each sensor channel
#: is 0.770 mm by the CAD's rules, below the 0.8 mm minimum.
THIN_CHANNEL_WALL = {
    "gap_mm": 0.8293438919775658,
    "centre_along_mm": 1.2659238714284986,
    "centre_across_mm": 0.0,
    "centre_z_mm": 0.8521007724534853,
    "sensor_radius_mm": 10.0,
    "sensor_height_mm": 0.3369284523696221,
    "sensor_tilt_deg": 1.4314471660410284,
    "sensor_azimuth_deg": 0.0,
    "sensor_separation_deg": 80.27402329304914,
}


def bounds_of(problem):
    """The problem's free variable names and their search bounds as arrays."""
    names = problem.free_names
    lower = np.array([problem.search_bounds[n][0] for n in names])
    upper = np.array([problem.search_bounds[n][1] for n in names])
    return names, lower, upper


def cad_walls(design, params=None):
    """Every wall of the printed parts by the CAD's layout, mm."""
    layout = plan_layout(design, params)
    return {**layout.reflector_walls_mm, **layout.body_walls_mm}
