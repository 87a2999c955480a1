"""reflector_opt.workflow._plan_text: the text of a calibration plan and of a plan for
identification, from hand-made summaries."""

from reflector_opt.workflow._plan_text import (
    format_identification,
    format_summary,
    temperature_lines,
)


def _prediction():
    return {
        "pattern": "grid",
        "n_poses": 25,
        "form": "eq6",
        "rms_deg": {"pitch": 0.01234, "roll": 0.02},
        "floor_ratio": {"pitch": 1.5, "roll": 1.25},
        "max_deg": {"pitch": 0.05, "roll": 0.0625},
    }


def _summary(**more):
    best = {**_prediction(), "motion_time_s": 90.0, "speed_deg_s": 10.0, "dwell_s": 0.5}
    return {
        "floor_rms_deg": {"pitch": 0.008, "roll": 0.016},
        "n_units": 4,
        "seed": 7,
        "predictions": [_prediction()],
        "recommended": best,
        **more,
    }


def test_the_plan_table_and_its_recommendation():
    lines = format_summary(_summary()).splitlines()
    assert lines[0] == (
        "predicted calibration error over 4 built units (seed 7); Cramér–Rao floor RMS pitch "
        "0.0080°, roll 0.0160°"
    )
    assert (
        lines[2] == "  grid         25  eq6         0.0123°   0.0200°   1.50/1.25    0.050°/0.062°"
    )
    assert lines[3] == (
        "recommended: eq6 on a 25-pose grid (1.50× / 1.25× the floor); motion 1.5 min at "
        "10°/s with 0.5 s per pose"
    )
    assert len(lines) == 4  # no temperature study asked
    none = format_summary(_summary(recommended=None)).splitlines()[-1]
    assert none == "no plan comes within the requested fraction of the floor"


def test_the_temperature_lines():
    assert temperature_lines(_summary()) == []
    assert temperature_lines(_summary(temperature=None)) == [
        "temperature: no recommended plan to extend (try a larger --within)"
    ]
    thermal = {
        "validation_k": [-5.0, 5.0],
        "change_k": 5.0,
        "form": "eq6",
        "base_poses": 25,
        "pattern": "grid",
        "n_units": 4,
        "uncompensated_ratio": [[3.0, 2.0], [4.0, 1.0]],
        "predictions": [
            {"n_poses": 6, "changes_k": [-5.0, 5.0], "ratio": [[1.1, 1.2], [1.3, 1.0]]}
        ],
        "recommended": {
            "n_poses": 6,
            "changes_k": [-5.0, 5.0],
            "ratio": [[1.1, 1.2], [1.3, 1.0]],
            "motion_time_s": 30.0,
        },
    }
    lines = temperature_lines(_summary(temperature=thermal))
    assert "within ±5 K" in lines[0] and "ΔT = -5, +5 K" in lines[0]
    assert lines[1] == "  the plan alone, uncompensated     3.00   4.00"  # worse of each row
    assert lines[2] == "  6 poses at T0 -5, +5 K            1.20   1.30"
    assert lines[3] == (
        "temperature: the plan at T0, then 6 Sobol poses at T0 -5 K and T0 +5 K "
        "(plan_temperature.csv; 1.30× their T0 error at worst, uncompensated 4.00×; "
        "motion 0.5 min)"
    )
    thermal["recommended"] = None
    assert temperature_lines(_summary(temperature=thermal))[-1].startswith(
        "temperature: no layout tried"
    )


def test_the_identification_tables_give_each_parameter_in_its_unit():
    summary = {
        "target_std_ratio": 0.5,
        "candidates": {"n_poses": 100, "step_deg": 2.0},
        "parameters": [
            {"name": "gap_mm", "prior_std": 0.02, "ratio_all_candidates": 0.25, "poses_needed": 8},
            {
                "name": "tilt_deg",
                "prior_std": 0.5,
                "ratio_all_candidates": 0.9,
                "poses_needed": None,
            },
        ],
        "recommended": None,
        "patterns": [
            {
                "pattern": "grid",
                "n_poses": 25,
                "log_det": 3.456,
                "determined": ["gap_mm"],
                "check": None,
            }
        ],
        "smallest_within_floor": {"identification": {}},
    }
    lines = format_identification(summary).splitlines()
    assert lines[0].startswith("plan for identification: 2 as-built parameters")
    assert "100 candidate poses on a 2° grid; target: posterior std ≤ 0.5 × prior std" in lines[0]
    assert lines[2].split() == ["gap_mm", "20", "µm", "0.25", "8", "—", "—"]  # 0.02 mm = 20 µm
    assert lines[3].split() == ["tilt_deg", "0.5°", "0.90", "—", "—", "—"]
    assert "no parameter reaches the target even with every candidate pose" in lines
    assert lines[-2].split() == ["grid", "25", "3.46", "1", "—"]
