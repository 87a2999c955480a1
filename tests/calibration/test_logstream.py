"""Voltage logs streamed in blocks: the same instants as the whole reading, in bounded memory."""

import csv
import json
import subprocess
import sys

import numpy as np
import pyarrow as pa
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import reflector_opt as ro
from reflector_opt.calibration._files import read_voltage_log, write_calibration_csv
from reflector_opt.calibration._logstream import Unordered, log_blocks
from reflector_opt.calibration._synthetic import built_units, calibration_data
from reflector_opt.calibration._unit_calibration import (
    calibrate_csv,
    estimate_log,
    estimate_to_csv,
    load_calibrations,
    save_calibrations,
)
from reflector_opt.util._errors import InputError


@pytest.fixture(scope="module")
def coefficients(tmp_path_factory):
    """Coefficients (Eq 6) of three simulated units, and the voltages they were fitted on."""
    folder = tmp_path_factory.mktemp("coef")
    design = ro.default_design()
    units = built_units(design, seed=3)[:3]
    data = calibration_data(design, units, step_deg=3.0, seed=1)
    write_calibration_csv(folder / "data.csv", data["unit"], data["volts"], data["angles_deg"])
    save_calibrations(folder / "coef.json", calibrate_csv(folder / "data.csv", folds=0))
    return folder / "coef.json", np.asarray(data["volts"])


def _log_text(instants, units, volts, key="sample", order=None):
    """CSV text of a log: one row per instant and unit, the units of an instant in ``order``."""
    header = f"{key},unit,v1,v2\n" if key else "unit,v1,v2\n"
    rows = []
    for i, instant in enumerate(instants):
        for j in order[i] if order is not None else range(len(units)):
            cells = [instant] if key else []
            cells += [units[j], repr(float(volts[i, j, 0])), repr(float(volts[i, j, 1]))]
            rows.append(",".join(cells) + "\n")
    return header + "".join(rows)


def _joined(blocks):
    blocks = list(blocks)
    instants = [str(x) for b in blocks for x in b.instants]
    return blocks[0].key, instants, blocks[0].units, np.concatenate([b.volts for b in blocks])


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    n_units=st.integers(1, 3),
    n_instants=st.integers(2, 40),
    key=st.sampled_from(["sample", "time", None]),
    block=st.integers(128, 1024),
    seed=st.integers(0, 2**16),
)
def test_blocks_of_an_ordered_log_are_the_whole_reading(
    tmp_path, n_units, n_instants, key, block, seed
):
    rng = np.random.default_rng(seed)
    volts = rng.uniform(0.1, 3.3, (n_instants, n_units, 2))  # within the supply
    units = [f"u{j}" for j in rng.permutation(n_units)]
    order = [rng.permutation(n_units) for _ in range(n_instants)]
    instants = [f"{t:.3f}" for t in np.cumsum(rng.uniform(0.001, 1, n_instants))]
    if key is None:  # without a key the k-th row of each unit is instant k, in turn
        order = [range(n_units)] * n_instants
    path = tmp_path / f"log-{seed}.csv"
    path.write_text(_log_text(instants, units, volts, key, order))
    whole = read_voltage_log(path)
    key_read, read_instants, read_units, read_volts = _joined(log_blocks(path, block))
    assert key_read == whole.key and read_instants == whole.instants
    assert read_units == whole.units
    np.testing.assert_array_equal(read_volts, whole.volts)


@pytest.mark.parametrize(
    "text",
    [
        "sample,unit,v1,v2\n0,1,2,3\n1,1,2,3\n0,2,2,3\n1,2,2,3\n",  # rows of an instant apart
        "unit,v1,v2\n1,2,3\n1,2,3\n2,2,3\n2,2,3\n",  # unit by unit, without a key
        "sample,unit,v1,v2\n0,1,2,3\n0,2,2,3\n1,1,2,3\n",  # a unit missing
        "sample,unit,v1,v2\n0,1,2,3\n0,1,2,3\n",  # a unit twice
        "sample,unit,v1,v2\n0,1,2,x\n1,1,2,3\n",  # not a number
        "sample,unit,v1,v2\n0,1,2,inf\n1,1,2,3\n",  # not finite
        "sample,unit,v1,v2\n0,1,2\n1,1,2,3\n",  # a short row
        "sample,unit,v1\n0,1,2\n1,1,2\n",  # a missing column
    ],
)
def test_what_cannot_be_streamed_is_left_to_the_whole_reading(tmp_path, text):
    path = tmp_path / "log.csv"
    path.write_text(text)
    with pytest.raises(Unordered):
        list(log_blocks(path, 128))


def _angles(path):
    with open(path, newline="", encoding="utf-8") as handle:
        rows = list(csv.reader(handle))
    return (
        rows[0],
        [r[0] for r in rows[1:]],
        np.array([[float(x) for x in r[1:]] for r in rows[1:]]),
    )


@pytest.mark.parametrize("ordered", [True, False])
def test_estimate_to_csv_writes_what_estimate_log_computes(coefficients, tmp_path, ordered):
    coef, fitted = coefficients
    calibrations = load_calibrations(coef)
    n = 100
    volts = fitted[: n * 3].reshape(n, 3, 2)
    instants = [str(i) for i in range(n)]
    if ordered:
        text = _log_text(instants, ["1", "2", "3"], volts)
    else:  # unit by unit: read whole
        text = "sample,unit,v1,v2\n" + "".join(
            f"{i},{u},{float(volts[i, j, 0])!r},{float(volts[i, j, 1])!r}\n"
            for j, u in enumerate(["1", "2", "3"])
            for i in range(n)
        )
    log = tmp_path / "log.csv"
    log.write_text(text)
    done = estimate_to_csv(calibrations, log, tmp_path / "angles.csv", 18.0)
    assert done == {"instants": n, "units": ["1", "2", "3"], "tip": True}
    shape = estimate_log(calibrations, log, 18.0)
    header, rows, numbers = _angles(tmp_path / "angles.csv")
    assert header == shape.header() and rows == instants
    np.testing.assert_array_equal(numbers, shape.table())  # the shortest round-trip digits
    # and by an independent path: each unit's model on its voltages
    for j, c in enumerate(calibrations):
        np.testing.assert_array_equal(numbers[:, 2 * j : 2 * j + 2], c.model.predict(volts[:, j]))


def test_memory_of_a_stream_is_bounded_by_the_block(coefficients, tmp_path):
    rng = np.random.default_rng(0)
    n = 40_000
    volts = rng.uniform(1.0, 4.0, (n, 1, 2))
    path = tmp_path / "log.csv"
    path.write_text(_log_text([str(i) for i in range(n)], ["1"], volts))
    size = path.stat().st_size
    peak, blocks = 0, 0
    for block in log_blocks(path, 16_384):
        blocks += 1
        assert block.volts.nbytes < 16_384
        peak = max(peak, pa.total_allocated_bytes())
    assert blocks > 50 and peak < size / 2, (blocks, peak, size)


@pytest.mark.parametrize(
    "volts",
    [
        (900.0, 900.0),  # far outside what the calibration covers: beyond ±90°
        (50.0, -30.0),  # a finite angle of tens of thousands of degrees was once written
    ],
)
def test_voltages_whose_angles_are_not_poses_are_refused(coefficients, tmp_path, volts):
    coef, fitted = coefficients
    log_volts = fitted[:6].reshape(2, 3, 2).copy()
    log_volts[1, 2] = volts
    log = tmp_path / "log.csv"
    log.write_text(_log_text(["0", "1"], ["1", "2", "3"], log_volts))
    output = tmp_path / "angles.csv"
    with pytest.raises(
        InputError,
        match=r"sample 1: the calibration of unit 3 gives a (pitch|roll)_deg of .* outside what "
        r"it covers \(a pose lies within ±90°\)",
    ):
        estimate_to_csv(load_calibrations(coef), log, output, accept_units=True)
    assert not output.exists() and [p.name for p in tmp_path.iterdir()] == ["log.csv"]


#: The command run in a fresh interpreter: its exit code, its peak resident memory and
#: whether the forward model (numba) or SciPy's optimisers were imported. The peak is the
#: process's VmHWM: ru_maxrss of a process started from a large one (this test run) reports
#: the larger one's resident memory when it was forked.
MEASURED = """
import json, sys
from pathlib import Path
from reflector_opt.cli import main
code = main(["estimate", *sys.argv[1:]])
status = Path("/proc/self/status").read_text().splitlines()
peak_mb = next(int(line.split()[1]) for line in status if line.startswith("VmHWM:")) / 1024
heavy = sorted(m for m in ("numba", "scipy.optimize") if m in sys.modules)
print(json.dumps({"code": code, "peak_mb": peak_mb, "heavy": heavy}))
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc/self/status")
def test_the_estimate_command_imports_no_forward_model_and_peaks_below_200_mb(
    coefficients, tmp_path
):
    """``estimate`` with coefficients once imported numba and SciPy's optimisers through the
    physical model's module: 237-243 MB on a 1,000,000-row log. The peak does not grow with
    the log (the test above), so 300,000 rows show it."""
    coef, fitted = coefficients
    n = 100_000
    volts = np.resize(fitted, (n * 3, 2)).reshape(n, 3, 2)
    log = tmp_path / "log.csv"
    log.write_text(_log_text([str(i) for i in range(n)], ["1", "2", "3"], volts))
    out = tmp_path / "angles.csv"
    done = subprocess.run(
        [sys.executable, "-c", MEASURED, str(coef), str(log), "-o", str(out)],
        capture_output=True,
        text=True,
        check=False,
        cwd=tmp_path,
    )
    assert done.returncode == 0, done.stderr
    measured = json.loads(done.stdout.splitlines()[-1])
    assert measured["code"] == 0 and measured["heavy"] == []
    assert measured["peak_mb"] < 200, measured
    assert sum(1 for _ in open(out, encoding="utf-8")) == n + 1
