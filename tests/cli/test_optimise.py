"""``reflector-opt optimise``: outputs, summary, and bad input (exit 2, nothing written)."""

import json
import re
from pathlib import Path

import pytest

from reflector_opt.cli import main
from reflector_opt.design import load_design
from tests.searchsettings import SMALL_SEARCH, write_settings

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.slow
def test_default_run_writes_design_json(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["optimise", "--out", str(out), "--quiet"]) == 0
    design = load_design(out / "design.json")  # the format evaluate/export read
    predicted = design.predicted
    assert predicted.metrics["grid_step_deg"] == pytest.approx(0.1)
    assert all(c["met"] for c in predicted.constraints.values())
    assert predicted.improvement["worst"] > 1.0
    text = capsys.readouterr().out
    assert "worst-case 1σ resolution" in text and "improvement" in text
    # the closing lines list every file written: the design, the report, the parts
    files = sorted(out.iterdir())
    assert text.splitlines()[-len(files) - 1].startswith(f"wrote {len(files)} files in ")
    assert sorted(text.splitlines()[-len(files) :]) == sorted(f"  {p}" for p in files)
    assert (out / "report.md").is_file() and (out / "report.html").is_file()
    if (out / "reflector.stl").is_file():
        assert (out / "reflector.3mf").is_file() and (out / "body.stl").is_file()
    else:
        assert "no printable parts: " in text


@pytest.mark.slow
def test_config_seed_and_pareto(tmp_path, capsys):
    out = tmp_path / "out"
    # 1.3 mm cannot fit in the 0.5–3 mm range twice: recorded as infeasible, not searched
    config = write_settings(tmp_path, SMALL_SEARCH + "[pareto]\nmargins_mm = [0.0, 1.3]\n")
    code = main(
        [
            "optimise",
            "--config",
            config,
            "--out",
            str(out),
            "--seed",
            "5",
            "--pareto",
            "--no-report",
        ]
    )
    assert code == 0
    doc = json.loads((out / "design.json").read_text())
    assert doc["predicted"]["optimiser"]["seed"] == 5
    assert doc["workspace"]["step_deg"] == 0.5
    front = json.loads((out / "pareto.json").read_text())
    assert [p["required_margin_mm"] for p in front["points"]] == [0.0, 1.3]
    assert [p["feasible"] for p in front["points"]] == [True, False]
    assert (out / "pareto.png").read_bytes()[:4] == b"\x89PNG"
    assert "pareto.png" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        ("[search]\nspeed = 3\n", "[search]: unknown key(s) speed"),
        ("[bounds]\ncentre_z_mm = [2, -2]\n", "centre_z_mm: min 2.0 is greater than max -2.0"),
        ("[sensor]\nrange_mm = [0.5, 0.6]\n", "distance window"),
        ("[bounds\n", "not valid TOML"),
        # every candidate has the sphere centred on the rotation centre: no sensitivity
        (
            SMALL_SEARCH
            + "[bounds]\ncentre_along_mm = [0, 0]\ncentre_z_mm = [0, 0]\n"
            + "sensor_height_mm = [0, 0]\n",
            "fold_fraction",
        ),
    ],
)
def test_bad_input_exits_2_and_writes_nothing(tmp_path, capsys, text, fragment):
    out = tmp_path / "out"
    assert main(["optimise", "--config", write_settings(tmp_path, text), "--out", str(out)]) == 2
    *progress, err = capsys.readouterr().err.splitlines()
    assert err.startswith("reflector-opt optimise: error:")
    assert fragment in err
    # one line, no traceback: before it only the progress lines of the work done so far
    assert all(re.fullmatch(r"\d\d:\d\d:\d\d +\d+% .* \(\d+ s\)", line) for line in progress)
    assert not out.exists() or not any(out.iterdir())


def test_missing_config_and_bad_out(tmp_path, capsys):
    assert main(["optimise", "--config", str(tmp_path / "nope.toml")]) == 2
    assert "cannot read" in capsys.readouterr().err
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert main(["optimise", "--out", str(blocker), "--quiet"]) == 2
    assert "is not a folder" in capsys.readouterr().err


def test_usage_errors_exit_2(capsys):
    for bad in (["--seed", "many"], ["--starts", "0"], ["--workers", "-1"]):
        assert main(["optimise", *bad]) == 2
        err = capsys.readouterr().err
        assert err.startswith(f"reflector-opt optimise: error: {bad[0]}: expected a whole number")
        assert err.count("\n") == 1 and f"got '{bad[1]}'" in err


def test_multi_start_options_that_cannot_work_are_refused(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["optimise", "--scheduler", "tcp://127.0.0.1:1", "--out", str(out)]) == 2
    assert "give --starts N or --tolerances" in capsys.readouterr().err
    tolerances = ROOT / "examples" / "tolerance.toml"
    assert main(["optimise", "--starts", "2", "--tolerances", str(tolerances)]) == 2
    assert "--starts: not with --tolerances" in capsys.readouterr().err
    args = ["optimise", "--starts", "2", "--scheduler", "tcp://127.0.0.1:1", "--out", str(out)]
    assert main(args) == 2
    assert "cannot reach the Dask scheduler" in capsys.readouterr().err
    assert not out.exists()


def test_surface_option_designs_for_that_material(tmp_path):
    out = tmp_path / "out"
    args = ["optimise", "--config", write_settings(tmp_path, SMALL_SEARCH), "--out", str(out)]
    assert main([*args, "--surface", "polished", "--quiet", "--no-report"]) == 0
    assert load_design(out / "design.json").reflector.specular_fraction == 1.0


def test_unknown_surface_is_a_usage_error(tmp_path, capsys):
    assert main(["optimise", "--surface", "chrome", "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "--surface: expected one of 'matte', 'polished', 'white-sla-resin', got 'chrome'" in err
    assert not (tmp_path / "out").exists()
