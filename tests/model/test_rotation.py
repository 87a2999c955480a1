"""The Eq 1 rotation formula against hand-computed turns and the rotation matrices."""

import numpy as np
import pytest

from reflector_opt.model._geometry import rotation_x, rotation_y
from reflector_opt.model._rotation import rotated_centre


def _turned(centre, pitch_deg, roll_deg):
    g, a = np.radians(pitch_deg), np.radians(roll_deg)
    return rotated_centre(*centre, np.cos(g), np.sin(g), np.cos(a), np.sin(a))


@pytest.mark.parametrize(
    ("pitch", "roll", "expected"),
    [
        (0.0, 0.0, (1.0, 2.0, 3.0)),
        (90.0, 0.0, (3.0, 2.0, -1.0)),  # Ry(90°): (x, y, z) → (z, y, −x)
        (90.0, 90.0, (3.0, 1.0, 2.0)),  # then Rx(90°): (x, y, z) → (x, −z, y)
        (0.0, -90.0, (1.0, 3.0, -2.0)),  # Rx(−90°): (x, y, z) → (x, z, −y)
    ],
)
def test_quarter_turns_by_hand(pitch, roll, expected):
    np.testing.assert_allclose(_turned((1.0, 2.0, 3.0), pitch, roll), expected, atol=1e-12)


def test_arrays_of_poses_match_the_rotation_matrices():
    centre = np.array([0.4, -1.3, 2.2])
    pitch, roll = np.meshgrid(np.linspace(-30, 30, 7), np.linspace(-25, 25, 5))
    x, y, z = _turned(centre, pitch, roll)
    expected = rotation_x(roll) @ rotation_y(pitch) @ centre
    np.testing.assert_allclose(np.stack([x, y, z], axis=-1), expected, atol=1e-12)
