"""``evaluate --conditions``: the budget and drift sensitivity it prints, and bad conditions."""

import json
from pathlib import Path

import pytest

from reflector_opt.analysis._budget import SOURCES
from reflector_opt.cli import main
from reflector_opt.design._conditions import Conditions

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
KEYS = {"pitch_rms_deg", "roll_rms_deg", "pitch_max_deg", "roll_max_deg"}


def run(argv):
    try:
        return main([str(a) for a in argv])
    except SystemExit as exc:
        return exc.code


def test_evaluate_json_prints_the_budget_and_the_conditions(capsys):
    design = EXAMPLES / "data" / "design.json"
    argv = ["evaluate", design, "--no-predict", "--conditions", EXAMPLES / "conditions.toml"]
    assert run([*argv, "--json", "-q"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert set(summary["budget"]) == {*SOURCES, "total"}
    assert all(set(row) == KEYS for row in summary["budget"].values())
    assert set(summary["drift_sensitivity"]) == {"common", "S1", "S2"}
    assert summary["conditions"]["temperature_range_k"] == 5.0
    assert summary["drive"]["scheme"] == "dc"
    assert set(summary["drive_comparison"]) == {"dc", "multiplexed", "modulated"}
    comparison = summary["drive_comparison"]
    assert comparison["modulated"]["frame_rate_hz"] == comparison["dc"]["frame_rate_hz"] / 2
    assert summary["worst_case_deg"] >= summary["budget"]["temperature"]["pitch_max_deg"]
    # the sample design's common 1 % drift, 0.303° RMS pitch: half the white-noise sample
    # design's 0.61° (docs/conditions.md), as the in-use objective trades resolution for drift
    assert summary["drift_sensitivity"]["common"]["pitch_rms_deg"] == pytest.approx(0.303, abs=0.01)
    total = summary["budget"]["total"]["pitch_rms_deg"]
    parts = sum(row["pitch_rms_deg"] ** 2 for k, row in summary["budget"].items() if k != "total")
    assert total == pytest.approx(parts**0.5)
    assert run([*argv, "-q"]) == 0
    text = capsys.readouterr().out
    assert "error budget in use (±5 K" in text and "temperature" in text


def test_evaluate_json_has_drift_sensitivity_and_the_default_conditions_without_any(capsys):
    assert run(["evaluate", "--no-predict", "--json", "-q"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert set(summary["drift_sensitivity"]["common"]) == KEYS
    # no conditions given: judged in the default ones, and said so
    assert summary["in_use"]["conditions"] == Conditions().to_dict()
    assert "default conditions" in summary["in_use"]["conditions_source"]


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        ("[conditions]\ntemperature_range_k = -5\n", "conditions.temperature_range_k"),
        ('[conditions]\ndrive = "pwm"\n', "conditions.drive"),
        ("[conditions]\nambient_mv = nan\n", "nan"),
        ("[conditions]\nreference_zero_deg = [0.0017, 0.0017]\n", "radians"),
        ("[condition]\n", "condition"),
        ("[conditions]\nresin_cte_ppm_per_k = -30\n", "conditions.resin_cte_ppm_per_k"),
        ("[conditions]\nstrip_cte_ppm_per_k = nan\n", "conditions.strip_cte_ppm_per_k"),
        ("[conditions]\nresin_cte_ppm_per_k = 1.45e-4\n", "per kelvin"),
        ('[conditions]\nangle_reference = "gps"\n', "conditions.angle_reference"),
        ('[conditions]\nangle_reference = "stated"\n', "conditions.reference_zero_deg"),
    ],
)
@pytest.mark.parametrize("design", [[], [EXAMPLES / "data" / "design.json"]], ids=["", "DESIGN"])
def test_bad_conditions_exit_2_with_one_line(tmp_path, capsys, text, fragment, design):
    path = tmp_path / "cond.toml"
    path.write_text(text)
    assert run(["evaluate", *design, "--no-predict", "--conditions", path]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and fragment in err, err


def test_a_missing_conditions_file_exits_2(tmp_path, capsys):
    assert run(["evaluate", "--no-predict", "--conditions", tmp_path / "none.toml"]) == 2
    assert "none.toml" in capsys.readouterr().err
