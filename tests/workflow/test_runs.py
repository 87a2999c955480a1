"""The runs of evaluate, optimise and report (reflector_opt/workflow/_runs.py), built from
hand-made values: frozen, a JSON summary that holds what the fields hold, the display each
run defines, and the CAD files and outcome they list."""

import dataclasses
import json
from pathlib import Path
from types import SimpleNamespace

import pytest

from reflector_opt.design import load_design
from reflector_opt.report._outputs import CadOutcome
from reflector_opt.tolerance._prediction import Evaluation, Prediction
from reflector_opt.workflow import OptimiseRun
from reflector_opt.workflow._runs import EvaluateRun, ReportRun, cad_files

SAMPLE = Path(__file__).resolve().parents[2] / "examples" / "data" / "design.json"

#: An export report as :func:`reflector_opt.cad.export_parts` names its files: per part,
#: the file kinds in any order (an entry it does not list, ``mass_g``, is not a file).
EXPORT = {
    "files": {
        "reflector": {
            "png": "r.png",
            "step": "r.step",
            "stl": "r.stl",
            "mass_g": 1.5,
            "3mf": "r.3mf",
        },
        "body": {"section_png": "b_section.png", "step": "b.step"},
    },
    "report": "cad_report.json",
}


def _json(summary):
    """The summary through strict JSON and back (no NaN, no infinity, no objects)."""
    return json.loads(json.dumps(summary, allow_nan=False))


def test_cad_files_lists_each_parts_files_in_kind_order_then_the_report():
    assert cad_files(EXPORT, "out") == [
        Path("out/r.stl"),
        Path("out/r.3mf"),
        Path("out/r.step"),
        Path("out/r.png"),
        Path("out/b.step"),
        Path("out/b_section.png"),
        Path("out/cad_report.json"),
    ]
    assert cad_files(None, "out") == []


# --- report ---------------------------------------------------------------------------------

FILES = [Path("o/report.md"), Path("o/report.html"), Path("o/fig.png")]


def _report_run(cad):
    return ReportRun(design=None, out=Path("o"), seed=7, as_built=True, cad=cad, files=FILES)


@pytest.mark.parametrize(
    ("cad", "summary", "row"),
    [
        (None, {"written": False, "error": None, "report": None}, "not exported"),
        (
            CadOutcome(error="reflector: wall 0.4 mm < 0.8 mm"),
            {"written": False, "error": "reflector: wall 0.4 mm < 0.8 mm", "report": None},
            "reflector: wall 0.4 mm < 0.8 mm",
        ),
        (
            CadOutcome(report=EXPORT),
            {"written": True, "error": None, "report": str(Path("o/cad_report.json"))},
            "written",
        ),
    ],
    ids=["not exported", "refused", "written"],
)
def test_a_report_run_summarises_its_pages_and_its_parts(cad, summary, row):
    run = _report_run(cad)
    assert _json(run.to_dict()) == {
        "out": "o",
        "seed": 7,
        "as_built": True,
        "markdown": str(FILES[0]),
        "html": str(FILES[1]),
        "cad": summary,
        "files": [str(p) for p in FILES],
    }
    cells = [
        ("Markdown", str(FILES[0])),
        ("HTML", str(FILES[1])),
        ("as-built section", "yes"),
        ("printable parts", row),
        ("files written", "3 in o"),
    ]
    assert repr(run) == "design report\n" + "\n".join(f"  {k}: {v}" for k, v in cells)
    left = 'style="text-align:left"'
    body = "".join(
        f"<tr><th {left}>{k}</th><td {left}>{v.replace('<', '&lt;')}</td></tr>" for k, v in cells
    )
    assert run._repr_html_() == f"<table><caption><b>design report</b></caption>{body}</table>"


def test_a_runs_fields_cannot_be_reassigned():
    runs = [_report_run(None), EvaluateRun(None, {}), OptimiseRun(*[None] * 7)]
    for run in runs:
        for field in dataclasses.fields(run):
            with pytest.raises(dataclasses.FrozenInstanceError):
                setattr(run, field.name, None)


# --- evaluate -------------------------------------------------------------------------------

#: An evaluation summary of two sensors, one leaving its range (the keys evaluate prints).
SUMMARY = {
    "in_use": {
        "conditions": {
            "temperature_range_k": 2.0,
            "drive": "dc",
            "sample_rate_hz": 10000.0,
            "temperature_compensated": False,
        },
        "conditions_source": "the default conditions (docs/conditions.md)",
        "worst_case_deg": 0.5,
        "worst_pitch_deg": 0.5,
        "worst_roll_deg": 0.25,
        "rms_deg": 0.3,
        "median_deg": 0.2,
        "white_noise_floor_deg": 0.1,
        "binding": {
            "pose_deg": [15.0, -15.0],
            "angle": "pitch",
            "sources_deg": {"reference": 0.4, "noise": 0.3},
            "shares": {"reference": 0.64, "noise": 0.36},
        },
        "baseline": {"worst_case_deg": 1.0, "rms_deg": 0.6, "median_deg": 0.3},
        "improvement": 2.0,
        "improvement_median": 1.5,
    },
    "workspace": {"poses": 3721},
    "sensors": [
        {
            "name": "s1",
            "model": "NJL5901R-2",
            "distance_mm": {"min": 1.2345, "max": 3.5},
            "volts": {"min": 0.1, "max": 2.25},
            "range_mm": [1.0, 4.0],
            "margin_mm": 0.2345,
            "in_range": True,
        },
        {
            "name": "s<2>",
            "model": "NJL5901R-2",
            "distance_mm": {"min": 0.5, "max": 3.0},
            "volts": {"min": 0.0, "max": 1.0},
            "range_mm": [1.0, 4.0],
            "margin_mm": -0.5,
            "in_range": False,
        },
    ],
    "in_range": False,
    "surface": {
        "reflectance": 0.9,
        "specular_fraction": 0.8,
        "resolution_against_specular_fraction": {"design": [], "default_design": []},
    },
    "drift_sensitivity": {
        "s1": {"pitch_rms_deg": 0.1, "roll_rms_deg": 0.2, "pitch_max_deg": 0.3, "roll_max_deg": 1}
    },
}


def test_an_evaluate_run_is_its_summary_and_shows_what_evaluate_prints():
    run = EvaluateRun(design=None, summary=Evaluation.from_dict(SUMMARY))
    assert _json(run.to_dict()) == SUMMARY
    assert run.summary.sensors[1].margin_mm == -0.5 and run.summary.sensors[0].volts.max == 2.25
    lines = run.text().splitlines()
    assert lines[:4] == [
        "in use in the default conditions (docs/conditions.md) (±2 K, dc drive at 10000 Sa/s; form "
        "misfit left out): worst case 0.5000° (pitch 0.5000°, roll 0.2500°), RMS 0.3000°, "
        "median 0.2000°; white-noise floor 0.1000° (worst-case 1σ resolution)",
        "  default design in the same conditions: worst case 1.0000°, RMS 0.6000°, median "
        "0.3000°; improvement in use 2.00× (worst), 1.50× (median)",
        "  quote the worst case in use: what a calibrated unit can read in these conditions; the "
        "white-noise floor is its limit where nothing drifts",
        "  at its worst (pitch at 15°, -15°): reference 0.400° (64 %), noise 0.300° (36 %)",
    ]
    assert lines[4:8] == [
        "workspace: 3721 poses",
        "s1 (NJL5901R-2): d 1.234–3.500 mm (usable 1.0–4.0 mm: inside), V 0.100–2.250 V",
        "s<2> (NJL5901R-2): d 0.500–3.000 mm (usable 1.0–4.0 mm: OUTSIDE), V 0.000–1.000 V",
        "design leaves the sensor range",
    ]
    assert lines[-1] == "        s1: RMS 0.100° / 0.200°, max 0.300° / 1.000°"
    assert repr(run) == run.text()
    assert "s&lt;2&gt; (NJL5901R-2): d 0.500–3.000 mm" in run._repr_html_()


# --- optimise -------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def sample():
    """The optimised sample design (its ``predicted`` block filled in)."""
    return load_design(SAMPLE)


def _optimise_run(design, **fields):
    result = SimpleNamespace(design=design, seed=3, evaluations={"search": 100, "polish": 20})
    values = {"robust": None, "front": None, "predicted": None, "cad": None}
    values |= {"out": Path("out"), "files": [Path("out/design.json")]}
    return OptimiseRun(result=result, **(values | fields))


def test_an_optimise_run_summarises_the_design_search_rounds_and_front(sample):
    rounds = SimpleNamespace(to_dict=lambda: {"rounds": [{"round": 1, "margin_mm": 0.1}]})
    front = SimpleNamespace(to_dict=lambda: {"points": [], "seed": 0})
    predicted = Prediction(calibration=None, segment={"a": 1.5}, segment_recommended=None)
    run = _optimise_run(sample, robust=rounds, front=front, predicted=predicted)
    assert run.design is sample
    assert _json(run.to_dict()) == {
        "out": "out",
        "seed": 3,
        "evaluations": 120,
        "design": _json(sample.to_dict()),
        "predicted": {"calibration": None, "segment": {"a": 1.5}, "segment_recommended": None},
        "robust": {"rounds": [{"round": 1, "margin_mm": 0.1}]},
        "pareto": {"points": [], "seed": 0},
        "cad": {"written": False, "error": None, "report": None},
        "files": [str(Path("out/design.json"))],
    }
    bare = _optimise_run(sample, cad=CadOutcome(report=EXPORT)).to_dict()
    assert bare["robust"] is None and bare["pareto"] is None
    assert bare["cad"] == {
        "written": True,
        "error": None,
        "report": str(Path("out/cad_report.json")),
    }


def test_an_optimise_runs_text_is_the_command_text_with_why_no_parts_were_written(sample):
    run = _optimise_run(sample, cad=CadOutcome(error="body: collides with the reflector"))
    lines = run.text().splitlines()
    assert lines[0] == "optimised design (seed 3, 120 model evaluations)"
    assert lines[-1] == "no printable parts: body: collides with the reflector"
    assert repr(run) == run.text()
    assert run._repr_html_().startswith("<pre>optimised design (seed 3, 120 model evaluations)\n")


def test_an_optimise_run_ranks_the_sensor_parts_only_when_several_were_tried(sample):
    assert _optimise_run(sample).ranking_lines() == []
    choice = {
        "seed": 4,
        "criteria": "worst 1σ resolution",
        "ranking": [{"part": "XY-1", "package_mm": [3, 2], "status": "skipped", "reason": "big"}],
        "chosen": "NJL5901R-2",
        "part": {"datasheet": "NJR 2019"},
    }
    ranked = sample.replace(predicted=sample.predicted.replace(sensor_choice=choice))
    lines = _optimise_run(ranked).ranking_lines()
    assert lines[0] == "sensor parts ranked (seed 4; worst 1σ resolution):"
    assert lines[-2].split() == ["-", "XY-1", "skipped:", "big"]
    assert lines[-1] == "  chosen: NJL5901R-2 (NJR 2019)"
