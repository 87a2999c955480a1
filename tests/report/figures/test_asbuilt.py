"""The as-built deviations figure."""

from reflector_opt.report.figures._asbuilt import as_built_deviation_figure


def test_deviation_figure_marks_the_determined():
    records = [
        {"name": "a_mm", "z": 0.5, "z_std": 0.2, "determined": True},
        {"name": "b_deg", "z": -1.2, "z_std": 0.9, "determined": False},
    ]
    fig = as_built_deviation_figure([("unit 1", records)], {"a_mm": "a", "b_deg": "b"})
    (ax,) = fig.axes
    assert [t.get_text() for t in ax.get_yticklabels()] == ["a", "b"]
    lines = [line for line in ax.lines if len(line.get_xdata()) == 1]
    faces = {float(line.get_xdata()[0]): line.get_markerfacecolor() for line in lines}
    assert faces[-1.2] == "white" and faces[0.5] != "white"
