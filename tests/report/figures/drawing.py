"""Helpers of the figure tests: render a figure failing on any warning, read its axis labels."""

import warnings

from matplotlib.figure import Figure

PITCH, ROLL = "pitch γ (°)", "roll α (°)"


def axis_labels(fig):
    """(xlabel, ylabel) of every axes that is not a colour bar, and the colour bar labels."""
    main = [(ax.get_xlabel(), ax.get_ylabel()) for ax in fig.axes if ax.get_label() != "<colorbar>"]
    bars = [ax.get_ylabel() for ax in fig.axes if ax.get_label() == "<colorbar>"]
    return main, bars


def render(make):
    """Build and draw a figure, failing on any warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fig = make()
        fig.canvas.draw()
    assert isinstance(fig, Figure)
    return fig
