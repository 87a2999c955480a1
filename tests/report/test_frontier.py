"""The report's size-and-segment section from a design's frontier and segment records."""

import matplotlib

from reflector_opt.design import default_design
from reflector_opt.report._frontier import SEGMENT_HEADER, frontier_blocks

matplotlib.use("Agg")

ROWS = [
    {
        "part": "VCNT2020",
        "unit_diameter_mm": 22.0,
        "status": "feasible",
        "objective_deg": 0.0588,
        "bearing": "GE4E",
        "binding": "sensor_envelope_mm",
        "binding_margin": 0.0,
        "binding_unit": "mm",
    },
    {
        "part": "VCNT2020",
        "unit_diameter_mm": 20.5,
        "status": "feasible",
        "objective_deg": 0.0740,
        "bearing": "GE4E",
        "binding": "sensor_envelope_mm",
        "binding_margin": 0.0,
        "binding_unit": "mm",
        "carried_from_mm": 20.0,
    },
    {
        "part": "VCNT2020",
        "unit_diameter_mm": 20.0,
        "status": "feasible",
        "objective_deg": 0.0740,
        "bearing": "GE4E",
        "binding": "sensor_envelope_mm",
        "binding_margin": 0.0,
        "binding_unit": "mm",
    },
    {
        "part": "VCNT2020",
        "unit_diameter_mm": 19.5,
        "status": "infeasible",
        "bearing": "GE4E",
        "binding": "wall_mm",
        "reason": "wall_mm is short",
    },
]


def _paper(axis, rms, mx):
    return {
        "amplitude_deg": 60.0,
        "predicted": {"rms_deg": 0.2, "max_deg": 0.6},
        "paper": {"rms_deg": rms, "max_deg": mx},
    }


def test_a_design_without_a_frontier_has_no_section():
    assert frontier_blocks(default_design(), {}) == []


def test_the_section_names_the_choice_and_each_row_and_the_segment_beside_table_one():
    choice = {
        "n_units": 8,
        "unit_workspace_deg": 11.25,
        "segment_length_mm": 144.0,
        "status": "feasible",
        "objective_deg": 0.07,
        "orientation_rms_deg": 0.41,
        "orientation_max_deg": 1.2,
        "position_rms_mm": 0.5,
        "position_max_mm": 1.5,
    }
    segment = {
        "range_deg": 90.0,
        "link_mm": 18.0,
        "chosen": choice,
        "errors": {
            "paper_motion": {
                "pitch": _paper("pitch", 2.45, 6.03),
                "roll": _paper("roll", 3.27, 6.86),
            }
        },
        "choices": [choice, {"n_units": 9, "unit_workspace_deg": 10.0, "status": "infeasible"}],
    }
    record = {"target_deg": 0.08, "chosen": ROWS[2], "frontier": ROWS}
    design = default_design().replace(
        predicted={"size_frontier": record, "segment_choice": segment}
    )
    figures = {}
    blocks = frontier_blocks(design, figures)
    assert blocks[0] == ("h2", "Size and segment")
    assert "VCNT2020 on the GE4E at 20 mm (0.0740°)" in blocks[1][1]
    table = next(b for b in blocks if b[0] == "table")
    assert [r[1] for r in table[2]] == ["22", "20.5", "20", "19.5"]
    assert table[2][1][2] == "0.0740 (the 20 mm design)"
    assert table[1][2] == "objective (°)" and table[2][0][3] == "–"  # no white-noise figure
    assert table[2][3][5] == "no design fits: wall_mm"
    assert list(figures) == ["frontier.png"]
    seg_table = [b for b in blocks if b[0] == "table"][1]
    assert seg_table[1] == SEGMENT_HEADER
    assert seg_table[2][0] == ("8", "11.25", "144", "0.0700", "0.410 / 1.200", "0.500 / 1.500")
    text = next(b[1] for b in blocks if b[0] == "p" and "Chosen: 8 units" in b[1])
    assert "the paper measured 2.45° and 6.03° with four units over ±60°" in text
    assert "the fewest that no other choice beats" in text


def test_in_conditions_the_section_judges_the_in_use_worst_case_beside_the_floor():
    rows = [r | {"worst_case_deg": 1.1, "white_noise_deg": 0.07} for r in ROWS[:3]] + ROWS[3:]
    record = {"target_deg": 1.2, "chosen": rows[2], "frontier": rows}
    blocks = frontier_blocks(default_design().replace(predicted={"size_frontier": record}), {})
    assert "whose in-use worst case meets 1.2°" in blocks[1][1] and "(1.1000°)" in blocks[1][1]
    _, header, table = next(b for b in blocks if b[0] == "table")
    assert header[2:4] == ("in-use worst case (°)", "white-noise floor (°)")
    assert table[0][2:4] == ("1.1000", "0.0700")
