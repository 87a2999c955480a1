"""The parts of a design: reflector, sensors, workspace, mechanics, noise."""

import math


def test_workspace_grid_is_the_paper_protocol(design):
    pitch, roll = design.workspace.grid()
    assert pitch.shape == (301, 1) and roll.shape == (1, 301)  # 90,601 poses
    assert pitch[0, 0] == -15 and roll[0, -1] == 15
    assert math.isclose(pitch[1, 0] - pitch[0, 0], 0.1)
