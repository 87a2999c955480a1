"""A sensor's vertical plane."""

import numpy as np
import pytest

from reflector_opt.report.figures._planes import sensor_plane


@pytest.mark.parametrize("sensor, azimuth", [(0, 40.0), (1, -40.0)])
def test_sensor_plane_holds_the_sensor_and_its_axis(turned, sensor, azimuth):
    normal, offset, along = sensor_plane(turned, sensor)
    f, a = turned.positions_mm[sensor], turned.axes[sensor]
    assert offset == pytest.approx(0.0, abs=1e-12)  # a radial sensor: the plane holds O
    assert normal @ a == pytest.approx(0.0, abs=1e-12) and normal @ f == pytest.approx(0.0)
    assert np.degrees(np.arctan2(along[1], along[0])) == pytest.approx(azimuth)
    assert along @ f == pytest.approx(10.0)
