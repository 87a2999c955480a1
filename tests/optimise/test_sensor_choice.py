"""The optimiser picks the part: each part's problem, the ranking, the CLI's ``--sensor``."""

import json
import re

import pytest

from reflector_opt.cli import main
from reflector_opt.design import Workspace, load_design
from reflector_opt.design._conditions import Conditions
from reflector_opt.model._catalogue import get_part
from reflector_opt.optimiser import Problem, SearchBudget, optimise
from reflector_opt.optimiser._sensor_choice import (
    _ranked,
    choose_sensor,
    part_problem,
    rank_key,
    record_part,
)
from reflector_opt.report._ranking import ranking_rows
from reflector_opt.util._dask_pool import dask_cluster
from reflector_opt.util._errors import InputError
from reflector_opt.workflow._optimise_text import ranking_lines
from tests.optimise.rankings import ranked_row
from tests.searchsettings import small_search, write_settings

#: The small search, the parts' searches on two workers.
SMALL = small_search(workers=2)
BUDGET = SearchBudget(popsize=5, maxiter=8, workers=2)
PROBLEM = Problem(workspace=Workspace(step_deg=0.5))


def test_each_part_gets_its_model_package_and_backing():
    njl = part_problem(Problem(), get_part("NJL5901R-2"))
    assert njl.cad == Problem().cad and njl.sensor_backing_mm == Problem().sensor_backing_mm
    assert njl.bounds == Problem().bounds and njl.sensor == get_part("NJL5901R-2").model
    vcnt = part_problem(Problem(bounds={"centre_z_mm": (-1.0, 1.0)}), get_part("VCNT2020"))
    assert vcnt.sensor_backing_mm == pytest.approx(1.2)  # 0.2 mm deeper than the NJL5901R-2
    assert vcnt.cad.sensor_length_mm == 2.5 and vcnt.cad.sensor_depth_mm == 0.8
    assert vcnt.bounds["centre_z_mm"] == (-1.0, 1.0)  # a stated bound is kept
    assert vcnt.bounds["gap_mm"] == get_part("VCNT2020").model.range_mm  # the part's range
    with pytest.raises(InputError, match=r"^CNY70 \(7 × 7 × 6 mm\): wall: "):
        part_problem(Problem(), get_part("CNY70"))


def test_the_njl5901r_2_part_gives_the_default_design():
    """The catalogue's NJL5901R-2 moves nothing: the same design as without --sensor."""
    plain = optimise(PROBLEM, seed=0, budget=BUDGET)
    problem = part_problem(PROBLEM, get_part("NJL5901R-2"))
    part = optimise(problem, seed=0, budget=BUDGET)
    assert part.evaluation.values == plain.evaluation.values
    assert part.objective == plain.objective
    # one given part: a one-row ranking, no calibration simulated for it
    recorded = record_part(part, get_part("NJL5901R-2"), problem, seed=0)
    choice = recorded.design.predicted.sensor_choice
    assert choice["chosen"] == "NJL5901R-2" and len(choice["ranking"]) == 1
    assert choice["ranking"][0]["calibration_rms_deg"] is None
    assert ranking_rows(choice)[0][6] == "n/a"


def test_sensor_list_ranks_the_parts_and_returns_the_best(tmp_path, capsys):
    out = tmp_path / "out"
    parts = "NJL5901R-2,VCNT2020,QRE1113"
    args = [
        "optimise",
        "--sensor",
        parts,
        "--config",
        write_settings(tmp_path, SMALL),
        "-o",
        str(out),
    ]
    assert main([*args, "--no-report", "--quiet"]) == 0
    doc = json.loads((out / "design.json").read_text())
    choice = doc["predicted"]["sensor_choice"]
    ranked = [r for r in choice["ranking"] if r["status"] == "ranked"]
    skipped = [r for r in choice["ranking"] if r["status"] == "skipped"]
    assert {r["part"] for r in ranked} == {"NJL5901R-2", "VCNT2020"}
    assert [r["rank"] for r in ranked] == [1, 2]
    assert rank_key(ranked[0]) <= rank_key(ranked[1])  # in use: the worst case first
    for row in ranked:  # the predicted calibration error: above the resolution's noise floor
        error = row["calibration_rms_deg"]
        assert 0 < error["pitch"] < 1 and 0 < error["roll"] < 1
    assert [r["part"] for r in skipped] == ["QRE1113"] and "wall" in skipped[0]["reason"]
    best = ranked[0]["part"]
    assert choice["chosen"] == best and choice["part"]["name"] == best
    assert choice["part"]["datasheet"] and choice["part"]["figures"]["package_mm"]["source"]
    design = load_design(out / "design.json")
    assert {s.model for s in design.sensors} == {best}
    assert design.models[0] == get_part(best).model  # its package included
    # the parts are ranked in the stated read-out; the design is judged in the one chosen for it
    block = doc["predicted"]["conditions"]
    read_out = block["read_out"]
    if read_out["chosen"]["drive"] == read_out["searched_in"]["drive"]:
        assert doc["predicted"]["objective_deg"] == ranked[0]["objective_deg"]
    assert block["worst_case_deg"] == pytest.approx(read_out["chosen"]["worst_case_deg"])
    text = capsys.readouterr().out
    assert "sensor parts ranked" in text and f"chosen: {best}" in text
    assert re.search(r"-  QRE1113 .* skipped: wall", text)


def test_a_part_that_does_not_fit_is_refused_alone(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["optimise", "--sensor", "CNY70", "-o", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("reflector-opt optimise: error: CNY70 (7 × 7 × 6 mm): wall:")
    assert "\n" not in err and not out.exists()


@pytest.mark.parametrize(
    ("extra", "fragment"),
    [
        (["--sensor", "XYZ"], "unknown sensor part 'XYZ'"),
        (["--sensor", "auto", "--pareto"], "not with --pareto"),
        (["--sensor", "NJL5901R-2,VCNT2020", "--starts", "2"], "not with --starts"),
        (["--sensor", "missing.toml"], "cannot read missing.toml"),
        (["--sensor", "CNY70,TCRT1000"], "no sensor part fits the unit: CNY70: wall"),
    ],
)
def test_bad_sensor_options_exit_2_and_write_nothing(tmp_path, capsys, extra, fragment):
    out = tmp_path / "out"
    assert (
        main(
            ["optimise", *extra, "--config", write_settings(tmp_path, SMALL), "-o", str(out), "-q"]
        )
        == 2
    )
    err = capsys.readouterr().err.strip()
    assert fragment in err and "\n" not in err
    assert not out.exists()


@pytest.mark.slow
def test_parts_on_a_dask_cluster_rank_alike():
    """The same ranking from local processes and from a Dask LocalCluster."""
    distributed = pytest.importorskip("distributed")
    parts = [get_part("VCNT2020"), get_part("QRE1113"), get_part("NJL5901R-2")]
    local = choose_sensor(PROBLEM, parts, seed=0, budget=BUDGET)
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None, host="127.0.0.1"
    ) as cluster:
        remote = choose_sensor(
            PROBLEM, parts, seed=0, budget=BUDGET, executor=dask_cluster(cluster.scheduler_address)
        )
    strip = [{k: v for k, v in r.items() if k != "seconds"} for r in local.record["ranking"]]
    assert strip == [
        {k: v for k, v in r.items() if k != "seconds"} for r in remote.record["ranking"]
    ]
    assert remote.result.evaluation.values == local.result.evaluation.values
    assert any("skipped" in line for line in ranking_lines(local.record))


def test_the_predicted_calibration_error_breaks_a_tie_of_the_resolution():
    parts = [get_part("NJL5901R-2"), get_part("VCNT2020"), get_part("CNY70")]
    rows = [
        ranked_row("NJL5901R-2", 0.08851, {"pitch": 0.30, "roll": 0.2}, margin=0.2),
        ranked_row("VCNT2020", 0.08849, {"pitch": 0.10, "roll": 0.12}),
        {
            "part": "CNY70",
            "maker": "m",
            "package_mm": [7, 7, 6],
            "status": "skipped",
            "reason": "wall: too thin",
        },
    ]
    best, record = _ranked(parts, rows, seed=0)
    # equal to 3 significant figures: the smaller calibration error wins over the larger margin
    assert best.name == "VCNT2020" and record["chosen"] == "VCNT2020"
    assert [r["part"] for r in record["ranking"]] == ["VCNT2020", "NJL5901R-2", "CNY70"]
    rows[0]["objective_deg"] = 0.0870  # a better resolution outranks any calibration error
    best, _ = _ranked(parts, rows, seed=0)
    assert best.name == "NJL5901R-2"


def test_in_conditions_the_parts_rank_by_their_in_use_worst_case_not_the_white_noise():
    """The NJL5901R-2 has the better white-noise objective (0.07° against 0.09°), the VCNT2020
    the smaller in-use worst case (1.10° against 1.25°): in conditions the VCNT2020 ranks
    first, and the table shows each part's in-use figure beside its white-noise floor."""
    parts = [get_part("NJL5901R-2"), get_part("VCNT2020")]
    rows = [
        ranked_row("NJL5901R-2", 0.07, {"pitch": 0.1, "roll": 0.1}) | {"worst_case_deg": 1.25},
        ranked_row("VCNT2020", 0.09, {"pitch": 0.1, "roll": 0.1}) | {"worst_case_deg": 1.10},
    ]
    best, record = _ranked(parts, rows, seed=0, conditions=Conditions())
    assert best.name == "VCNT2020"
    assert [r["part"] for r in record["ranking"]] == ["VCNT2020", "NJL5901R-2"]
    assert record["criteria"].startswith("the in-use worst-case total error")
    table = ranking_rows(record)
    assert [row[3:6] for row in table] == [
        ("1.1000", "0.0900", "0.0900"),
        ("1.2500", "0.0700", "0.0700"),
    ]
    # the same rows judged by the white-noise objective alone (no in-use figure) rank the
    # other way: the order above is the in-use figure's
    plain = [{k: v for k, v in r.items() if k not in ("worst_case_deg", "rank")} for r in rows]
    assert _ranked(parts, plain, seed=0)[0].name == "NJL5901R-2"
