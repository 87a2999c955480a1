"""reflector_opt.report._ranking: the report's sensor-choice section."""

from reflector_opt.design import default_design
from reflector_opt.model._catalogue import get_part
from reflector_opt.optimiser._sensor_choice import _ranked
from reflector_opt.report._ranking import RANKING_HEADER, ranking_blocks
from tests.optimise.rankings import ranked_row


def test_the_report_shows_the_ranking_of_a_chosen_part():
    parts = [get_part("NJL5901R-2"), get_part("CNY70")]
    rows = [
        ranked_row("NJL5901R-2", 0.08851, {"pitch": 0.0984, "roll": 0.0820}),
        {
            "part": "CNY70",
            "maker": "m",
            "package_mm": [7, 7, 6],
            "status": "skipped",
            "reason": "wall: too thin",
        },
    ]
    _, record = _ranked(parts, rows, seed=3)
    design = default_design()
    assert ranking_blocks(design) == []  # a design without a sensor choice
    chosen = design.replace(predicted={"sensor_choice": record})
    blocks = ranking_blocks(chosen)
    assert blocks[0] == ("h2", "Sensor choice")
    assert "NJL5901R-2" in blocks[1][1] and "seed 3" in blocks[1][1]
    kind, header, table = blocks[2]
    assert kind == "table" and header == RANKING_HEADER
    assert table[0][:3] == ("1", "NJL5901R-2", "1 × 1.4 × 0.6")
    assert table[0][3] == "n/a"  # ranked without conditions: no in-use worst case
    assert table[0][6] == "0.098 / 0.082"
    assert table[1][:3] == ("-", "CNY70", "skipped: wall: too thin")
    assert all(len(row) == len(header) for row in table)
