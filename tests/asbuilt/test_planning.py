"""Plans for identification: the D-optimal search, the pose count and their checks."""

import json
from dataclasses import replace

import numpy as np
import pytest

from reflector_opt.asbuilt.parameters import Layout
from reflector_opt.asbuilt.planning import (
    PoseInformation,
    candidate_poses,
    check_plans,
    d_optimal,
    exchange,
    greedy_selection,
    minimum_poses,
    pose_information,
    poses_needed,
    visiting_order,
)
from reflector_opt.calibration.plans import make_plan
from reflector_opt.cli import main
from reflector_opt.model.forward import voltages
from reflector_opt.tolerance.builtunit import REFERENCE_SIGMA_DEG


def _log_det(rows):
    flat = rows.reshape(-1, rows.shape[-1])
    return np.linalg.slogdet(np.eye(flat.shape[1]) + flat.T @ flat)[1]


@pytest.fixture(scope="module")
def random_rows():
    """40 candidate poses of 2 sensors and 6 parameters, of uneven strength."""
    rng = np.random.default_rng(3)
    return rng.normal(size=(40, 2, 6)) * np.array([3.0, 1.0, 0.5, 0.2, 0.1, 0.05])


def test_greedy_update_equals_the_direct_determinant(random_rows):
    order, gains, variances = greedy_selection(random_rows, 12)
    assert len(set(order.tolist())) == 12
    for k in range(1, 13):
        taken = random_rows[order[:k]]
        assert np.sum(gains[:k]) == pytest.approx(_log_det(taken), rel=1e-10, abs=1e-10)
        flat = taken.reshape(-1, 6)
        direct = np.diag(np.linalg.inv(np.eye(6) + flat.T @ flat))
        np.testing.assert_allclose(variances[k - 1], direct, rtol=1e-9)
    # each step took the candidate of largest direct determinant among those left
    for k in range(12):
        left = [i for i in range(40) if i not in order[:k]]
        direct = [_log_det(random_rows[[*order[:k], i]]) for i in left]
        assert _log_det(random_rows[order[: k + 1]]) == pytest.approx(max(direct), abs=1e-9)


def test_exchange_ends_where_no_single_swap_raises_the_determinant(random_rows):
    start = np.arange(10)  # a poor start: the first ten candidates
    plan = exchange(random_rows, start)
    best = _log_det(random_rows[plan])
    assert best > _log_det(random_rows[start]) + 1.0
    assert len(set(plan.tolist())) == 10
    for k in range(10):
        for j in set(range(40)) - set(plan.tolist()):
            swapped = plan.copy()
            swapped[k] = j
            assert _log_det(random_rows[swapped]) <= best + 1e-9


def test_pose_count_is_the_greedy_step_where_the_last_determinable_parameter_meets_it(
    random_rows,
):
    info = PoseInformation(np.zeros((40, 2)), random_rows, tuple("abcdef"), np.ones(6), settings={})
    count = poses_needed(info, 0.3)
    ratio_all = np.sqrt(np.diag(np.linalg.inv(info.information())))
    assert set(count.determinable) == {
        n for n, r in zip("abcdef", ratio_all, strict=True) if r <= 0.3
    }
    assert 0 < len(count.determinable) < 6
    order, _, _ = greedy_selection(random_rows, 40)
    for name, n in count.needed.items():
        if n is None:
            continue
        j = "abcdef".index(name)
        assert info.ratio(order[:n])[j] <= 0.3 < (info.ratio(order[: n - 1])[j] if n > 1 else 1)
    assert count.n_poses == max(max(v for v in count.needed.values() if v), minimum_poses(info))
    assert np.all(info.ratio(count.indices)[np.isin(info.names, count.determinable)] <= 0.3)
    assert info.log_det(count.indices) >= info.log_det(order[: count.n_poses]) - 1e-9


def _independent_log_det(design, poses):
    """log det(I + AᵀA) from the full model's voltages by this test's own differences.

    A = ∂V/∂x · σ_prior / σ_eff with σ_eff² = σ_V² + σ_ref² |∂V/∂(γ, α)|²; the parameter
    vector's meaning is the layout's (one unit), the derivatives are not.
    """
    layout = Layout(design, 1)
    working = design.replace(workspace=replace(design.workspace, step_deg=5.0))
    pitch, roll = poses[:, 0], poses[:, 1]

    def volts(x):
        built, mismatch = layout.unit_design(x, 0, working)
        return mismatch.apply(voltages(built, pitch, roll))

    h_deg = 1e-3
    slope_pitch = voltages(design, pitch + h_deg, roll) - voltages(design, pitch - h_deg, roll)
    slope_roll = voltages(design, pitch, roll + h_deg) - voltages(design, pitch, roll - h_deg)
    slope2 = (slope_pitch**2 + slope_roll**2) / (2 * h_deg) ** 2
    sigma = np.sqrt(design.noise.total_sigma_v**2 + REFERENCE_SIGMA_DEG**2 * slope2)
    prior = layout.prior_std()
    columns = []
    for j in range(layout.size):
        step = np.zeros(layout.size)
        step[j] = 1e-3 * prior[j]  # a thousandth of the prior std
        derivative = (volts(step) - volts(-step)) / (2 * step[j])
        columns.append((derivative / sigma).ravel() * prior[j])
    a = np.column_stack(columns)
    return np.linalg.slogdet(np.eye(layout.size) + a.T @ a)[1]


@pytest.mark.parametrize("n_poses", [25, 50])
def test_d_optimal_beats_sobol_and_grid_by_an_independent_jacobian(design, n_poses):
    info = pose_information(design, candidate_poses(design.workspace))
    plan = info.poses_deg[d_optimal(info, n_poses)]
    scores = {
        "d-optimal": _independent_log_det(design, plan),
        "sobol": _independent_log_det(design, make_plan(design.workspace, "sobol", n_poses)),
        "grid": _independent_log_det(design, make_plan(design.workspace, "grid", n_poses)),
    }
    # the module's information agrees with the independent one
    assert info.at(plan).log_det() == pytest.approx(scores["d-optimal"], rel=1e-4)
    assert scores["d-optimal"] > scores["sobol"] + 1.0
    assert scores["d-optimal"] > scores["grid"] + 1.0


def test_visiting_order_is_a_serpentine_over_pitch_rows():
    poses = np.array([[1.0, 5.0], [0.0, 2.0], [1.0, -3.0], [0.0, -1.0], [2.0, 0.0]])
    order = visiting_order(poses)
    np.testing.assert_array_equal(poses[order], [[0, -1], [0, 2], [1, 5], [1, -3], [2, 0]])


@pytest.fixture(scope="module")
def coarse_count(design):
    """The pose count on a 3° candidate grid (121 poses): small enough to check quickly."""
    info = pose_information(design, candidate_poses(design.workspace, 3.0))
    count = poses_needed(info, 0.5)
    poses = info.poses_deg[count.indices]
    return info, count, poses[visiting_order(poses)]


def test_pose_count_is_confirmed_by_identifying_units_of_the_model(design, coarse_count):
    """Units drawn from the prior and simulated by the identification's model: the RMS error
    of the identified determinable parameters over 10 units meets the target within 35 %
    (the RMS of 10 draws scatters by about 22 %), and the errors of every parameter match
    the predicted posterior std on average (mean of error²/variance within 0.6–1.5)."""
    info, count, poses = coarse_count
    assert 10 <= count.n_poses <= 60
    assert {"sensor_1_gain", "sensor_2_gain", "reflector_centre_x_mm"} <= set(count.determinable)
    (row,) = check_plans(design, [("chosen", poses)], n_units=10, truth="model", n_validation=50)
    predicted = info.ratio(count.indices)
    keep = np.isin(info.names, count.determinable)
    assert np.all(predicted[keep] <= 0.5)
    assert np.all(row.achieved[keep] <= 0.5 * 1.35), dict(
        zip(np.array(info.names)[keep], row.achieved[keep], strict=True)
    )
    assert 0.6 <= np.mean((row.achieved / predicted) ** 2) <= 1.5
    # the prior alone (no poses) would leave every parameter at its prior std
    assert np.all(row.achieved[keep] < 0.75)


def test_pose_count_holds_on_built_units_with_exact_optics(design, coarse_count):
    """Built units (exact optics the identification's model lacks): the geometry and
    read-out parameters the count calls determinable are within 1.5× the target over 6 units,
    and the identified model's angle error is within 20 % of the Cramér–Rao floor."""
    info, count, poses = coarse_count
    (row,) = check_plans(design, [("chosen", poses)], n_units=6, truth="built", n_validation=500)
    block = [n for n in count.determinable if n not in ("reflectance", "specular_fraction")]
    achieved = dict(zip(info.names, row.achieved, strict=True))
    assert all(achieved[name] <= 0.5 * 1.5 for name in block), achieved
    assert np.all(row.rms_deg <= 1.2 * row.floor_deg)


def test_cli_writes_the_d_optimal_plan_and_the_table(design, tmp_path, capsys):
    design.save(tmp_path / "design.json")
    out = tmp_path / "plan"
    argv = ["plan-calibration", str(tmp_path / "design.json"), "--for", "identification"]
    argv += ["--patterns", "d-optimal,grid", "--sizes", "25", "--units", "1"]
    argv += ["--candidate-step", "3", "--forms", "physical", "--out", str(out)]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "recommended:" in printed and "D-optimal poses" in printed
    assert "physical" in printed and "identification" in printed
    summary = json.loads((out / "plan.json").read_text())
    best = summary["recommended"]
    plan = np.genfromtxt(out / "plan.csv", delimiter=",", names=True)
    assert plan.dtype.names == ("pose", "pitch_deg", "roll_deg")
    poses = np.column_stack([plan["pitch_deg"], plan["roll_deg"]])
    assert len(np.unique(poses, axis=0)) == len(poses) == best["n_poses"]
    assert np.all(np.abs(poses) <= 15.0)
    assert [p["pattern"] for p in summary["patterns"]] == ["d-optimal", "grid"]
    assert summary["patterns"][0]["log_det"] > summary["patterns"][1]["log_det"]
    assert summary["calibration"]["predictions"][0]["form"] == "physical"


def test_cli_fisher_only_plan_without_a_check(design, tmp_path, capsys):
    out = tmp_path / "plan"
    argv = ["plan-calibration", "--for", "identification", "--no-check", "--sizes", "25,50"]
    argv += ["--patterns", "d-optimal,sobol", "--candidate-step", "2", "--target-std", "0.45"]
    assert main([*argv, "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "target: posterior std ≤ 0.45 × prior std" in printed
    summary = json.loads((out / "plan.json").read_text())
    assert summary["n_units"] == 0 and summary["calibration"] is None
    assert all(row["check"] is None for row in summary["patterns"])
    assert [(r["pattern"], r["n_poses"]) for r in summary["patterns"]] == [
        ("d-optimal", 25),
        ("d-optimal", 50),
        ("sobol", 25),
        ("sobol", 50),
    ]
    plan = np.genfromtxt(out / "plan.csv", delimiter=",", names=True)
    assert len(plan) == summary["recommended"]["n_poses"]
    assert set(summary["recommended"]["determinable"]) == {
        p["name"] for p in summary["parameters"] if p["ratio_all_candidates"] <= 0.45
    }


@pytest.mark.parametrize(
    ("extra", "fragment"),
    [
        (["--for", "identification", "--target-std", "1.5"], "--target-std"),
        (["--target-std", "0.5"], "--target-std applies to --for identification only"),
        (["--truth", "model"], "--truth applies to --for identification only"),
        (["--for", "identification", "--patterns", "raster"], "raster cannot be planned"),
        (["--for", "identification", "--sizes", "8"], "8 poses are too few"),
        (["--for", "identification", "--sizes", "2000"], "exceed the 961 candidates"),
        (["--for", "identification", "--truth", "model", "--forms", "auto"], "--forms"),
        (["--for", "testing"], "--for"),
        (["--for", "identification", "--candidate-step", "0.3"], "more than 4,000"),
    ],
)
def test_bad_input_is_one_line(design, tmp_path, capsys, extra, fragment):
    design.save(tmp_path / "design.json")
    out = tmp_path / "plan"
    argv = ["plan-calibration", str(tmp_path / "design.json"), *extra, "--out", str(out)]
    try:
        code = main(argv)
    except SystemExit as exit_info:
        code = exit_info.code
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and fragment in err[0]
    assert not out.exists()
