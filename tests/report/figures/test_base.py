"""The shared figure helpers: the pose map, the worst pose's cross and its room, saving."""

import numpy as np
import pytest
from matplotlib.figure import Figure

from reflector_opt.report.figures._base import (
    WORST_MARKER_PAD,
    mark_worst,
    new_figure,
    pose_map,
    save_figure,
    side_view,
    single_axes,
)
from tests.report.figures.drawing import PITCH, ROLL, axis_labels


def _grid():
    """A 3 × 4 map on pitch −10…10° (10° cells) and roll 0…6° (2° cells), largest at (10, 2)."""
    pitch, roll = np.array([-10.0, 0.0, 10.0]), np.array([0.0, 2.0, 4.0, 6.0])
    values = np.arange(12.0).reshape(3, 4)
    values[2, 1] = 99.0
    return pitch, roll, values


def test_the_pose_map_puts_pitch_across_and_roll_up():
    pitch, roll, values = _grid()
    fig = new_figure()
    ax = fig.add_subplot()
    mesh = pose_map(fig, ax, pitch, roll, values, "thing (mm)")
    assert axis_labels(fig) == ([(PITCH, ROLL)], ["thing (mm)"])
    # the mesh holds values transposed: one row per roll, one column per pitch
    assert np.array_equal(np.asarray(mesh.get_array()).reshape(4, 3), values.T)


def test_the_worst_cross_sits_on_the_largest_value_with_room_around_the_grid():
    pitch, roll, values = _grid()
    _, ax = single_axes(None)
    mark_worst(ax, pitch, roll, values)
    (cross,) = ax.lines
    assert (cross.get_xdata()[0], cross.get_ydata()[0]) == (10.0, 2.0)
    # pad = 5 % of the span + half a cell: 0.05·20 + 5 = 6° in pitch, 0.05·6 + 1 = 1.3° in roll
    assert WORST_MARKER_PAD == 0.05
    assert ax.get_xlim() == pytest.approx((-16.0, 16.0))
    assert ax.get_ylim() == pytest.approx((-1.3, 7.3))


def test_single_axes_draws_into_the_given_axes():
    fig = Figure()
    ax = fig.add_subplot()
    assert single_axes(ax) == (fig, ax)


def test_side_view_puts_the_named_length_across_z_up_on_one_scale():
    _, ax = single_axes(None)
    side_view(ax, "along azimuth 45°", "S1: section", fontsize=10)
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("along azimuth 45° (mm)", "z (mm)")
    assert (ax.get_title(), ax.title.get_fontsize()) == ("S1: section", 10)
    assert ax.get_aspect() == 1.0
    assert all(line.get_visible() for line in ax.xaxis.get_gridlines())


@pytest.mark.parametrize("suffix, magic", [(".png", b"\x89PNG"), (".svg", b"<?xml")])
def test_save_figure_writes_the_format_of_the_suffix(tmp_path, suffix, magic):
    path = tmp_path / f"f{suffix}"
    save_figure(new_figure(), path)
    assert path.read_bytes().startswith(magic)
    assert [p.name for p in tmp_path.iterdir()] == [path.name]  # no temporary left
