"""Fixtures the figure tests share: the default design's metrics on a 1° grid, and the
default design with its sensors turned off the x and y axes."""

from dataclasses import replace

import numpy as np
import pytest

from reflector_opt.analysis._metrics import evaluate_metrics


@pytest.fixture(scope="package")
def metrics(design):
    return evaluate_metrics(design, step_deg=1.0)


@pytest.fixture(scope="package")
def turned(design):
    """The default design with its sensors moved to ±40° azimuth, looking at the unit's axis."""
    sensors = []
    for s, azimuth in zip(design.sensors, (40.0, -40.0), strict=True):
        c, s_ = np.cos(np.radians(azimuth)), np.sin(np.radians(azimuth))
        sensors.append(replace(s, position_mm=(10.0 * c, 10.0 * s_, 0.0), axis=(-c, -s_, 0.0)))
    return design.replace(sensors=tuple(sensors))
