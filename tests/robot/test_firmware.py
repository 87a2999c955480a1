"""The calibration as C99 (reflector_opt.robot._firmware): compiled with the system's C compiler,
its angles on the sample log against the Python calibration's ``predict``."""

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from reflector_opt.calibration._files import read_voltage_log
from reflector_opt.calibration._temperature import TemperatureCompensated
from reflector_opt.calibration._unit_calibration import UnitCalibration, calibrate_csv
from reflector_opt.robot import _firmware
from reflector_opt.robot._firmware import firmware_header, fixed_point_bound
from reflector_opt.util._errors import InputError

DATA = Path(__file__).resolve().parents[2] / "examples" / "data"
CC = shutil.which("cc")
needs_cc = pytest.mark.skipif(CC is None, reason="no system C compiler (cc)")

#: Reads ``unit v1 v2 t_c`` lines; prints the float angles and the fixed-point ones (degrees).
DRIVER = r"""
#include <stdio.h>
#include <math.h>
#include "calibration.h"
int main(void)
{
    int unit; double v1, v2, t;
    while (scanf("%d %lf %lf %lf", &unit, &v1, &v2, &t) == 4) {
        RO_REAL f[2]; int32_t q[2];
        if (ro_angles_f(unit, (RO_REAL)v1, (RO_REAL)v2, (RO_REAL)t, f)) return 1;
        if (ro_angles_q(unit, (int32_t)lround(v1 * 1e6), (int32_t)lround(v2 * 1e6),
                        (int32_t)lround(t * 1e3), q)) return 1;
        printf("%.17g %.17g %.17g %.17g\n", (double)f[0], (double)f[1],
               q[0] / 1048576.0, q[1] / 1048576.0);
    }
    return 0;
}
"""


def _compiled_angles(tmp_path, header, rows, real="float"):
    """(float angles, fixed-point angles), each (n, 2), of ``rows`` (unit, v1, v2, t_c)."""
    (tmp_path / "calibration.h").write_text(header, encoding="utf-8")
    (tmp_path / "driver.c").write_text(DRIVER, encoding="utf-8")
    exe = tmp_path / "driver"
    flags = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-O2", f"-DRO_REAL={real}"]
    subprocess.run([CC, *flags, tmp_path / "driver.c", "-o", exe, "-lm"], check=True)
    lines = "".join(f"{int(u)} {v1:.6f} {v2:.6f} {t:.3f}\n" for u, v1, v2, t in rows)
    out = subprocess.run([exe], input=lines, capture_output=True, text=True, check=True).stdout
    values = np.loadtxt(out.splitlines(), ndmin=2)
    return values[:, :2], values[:, 2:]


@pytest.fixture(scope="module")
def sample():
    """The sample segment's Eq 6 and poly3 calibrations (data.csv) and its log's rows."""
    log = read_voltage_log(DATA / "log.csv")
    calibrations = calibrate_csv(DATA / "data.csv", "eq6", folds=2)
    calibrations[1] = UnitCalibration(
        "2", calibrate_csv(DATA / "data.csv", "poly3", folds=2)[1].model
    )
    rows = np.array(
        [
            (j, *log.volts[i, j], 25.0)
            for i in range(len(log.instants))
            for j in range(len(log.units))
        ]
    )
    return calibrations, rows


def _predicted(calibrations, rows):
    out = []
    for unit, v1, v2, t in rows:
        model = calibrations[int(unit)].model
        args = (np.array([v1, v2]), t) if isinstance(model, TemperatureCompensated) else ([v1, v2],)
        out.append(model.predict(*args))
    return np.array(out)


def _bound(calibrations, rows):
    """The fixed-point bound of each row's unit, at the log's largest |u|."""
    bounds = []
    for unit, *volts, t in rows:
        model = calibrations[int(unit)].model
        thermal = model if isinstance(model, TemperatureCompensated) else None
        form = model.form_ if thermal else model
        v = thermal.compensated(np.array(volts), t) if thermal else np.array(volts)
        u = np.abs((v - form.centre_v_) / form.scale_v_).max()
        bounds.append(fixed_point_bound(form, thermal, max(1.0, u)))
    return np.array(bounds)[:, None]


@needs_cc
def test_the_header_gives_predict_s_angles_in_float_double_and_fixed_point(tmp_path, sample):
    """On the sample log (50 instants × 4 units): float (float32) within 1e-4° of ``predict``
    (float32's 6e-8 relative on the voltages and sums), double within 1e-9°, and the fixed-point
    angles within :func:`fixed_point_bound` of each row's unit (about 1e-5°)."""
    calibrations, rows = sample
    header = firmware_header(calibrations)
    expected = _predicted(calibrations, rows)
    as_float, fixed = _compiled_angles(tmp_path, header, rows)
    np.testing.assert_allclose(as_float, expected, rtol=0, atol=1e-4)
    assert (np.abs(fixed - expected) <= _bound(calibrations, rows)).all()
    as_double, _ = _compiled_angles(tmp_path, header, rows, "double")
    np.testing.assert_allclose(as_double, expected, rtol=0, atol=1e-9)


@needs_cc
def test_a_compensated_calibration_compiles_to_the_same_angles(tmp_path, sample):
    """Unit 1's data made warm and cold by Eq (1) of the compensation (gain −0.4 %/K, offset
    +1 mV/K, curvature 1e-5 /K²), fitted compensated with Eq 6, then read at 10 … 45 °C: the
    header's angles equal ``predict``'s (double 1e-9°, fixed point within its bound)."""
    rng = np.random.default_rng(1)
    data = np.genfromtxt(DATA / "data.csv", delimiter=",", names=True, dtype=None, encoding=None)
    one = data[data["unit"] == 1]
    volts = np.column_stack([one["v1"], one["v2"]])
    angles = np.column_stack([one["pitch_deg"], one["roll_deg"]])
    temps = rng.choice([15.0, 25.0, 35.0], len(volts))
    dt = temps[:, None] - 25.0
    warm = 3.3 - (3.3 - volts) * (1 - 0.004 * dt + 1e-5 * dt**2) - 1e-3 * dt
    model = TemperatureCompensated("eq6", degree=2).fit(warm, angles, temps)
    calibrations = [UnitCalibration("1", model)]
    t = np.round(rng.uniform(10, 45, 40), 3)
    dt = t[:, None] - 25.0
    v = 3.3 - (3.3 - volts[:40]) * (1 - 0.004 * dt + 1e-5 * dt**2) - 1e-3 * dt
    rows = np.column_stack([np.zeros(40), np.round(v, 6), t])
    header = firmware_header(calibrations)
    expected = _predicted(calibrations, rows)
    as_double, fixed = _compiled_angles(tmp_path, header, rows, "double")
    np.testing.assert_allclose(as_double, expected, rtol=0, atol=1e-9)
    assert (np.abs(fixed - expected) <= _bound(calibrations, rows)).all()


@needs_cc
def test_a_coefficient_emitted_wrong_fails_the_comparison(tmp_path, sample, monkeypatch):
    """The guard: one coefficient of the header off by 0.1 % (the scaled form's v1 term of
    pitch), and the compiled angles leave ``predict``'s tolerance."""
    calibrations, rows = sample
    scaled = _firmware._scaled

    def wrong(form):
        coef = scaled(form).copy()
        coef[0, 0] *= 1.001
        return coef

    monkeypatch.setattr(_firmware, "_scaled", wrong)
    as_float, fixed = _compiled_angles(tmp_path, firmware_header(calibrations), rows)
    expected = _predicted(calibrations, rows)
    assert np.abs(as_float - expected).max() > 1e-4
    assert (np.abs(fixed - expected) > _bound(calibrations, rows)).any()


def test_the_physical_model_and_a_bad_name_are_refused_in_one_line(sample):
    class Physical:
        pass

    with pytest.raises(InputError, match=r"^unit 7: a Physical calibration cannot be compiled"):
        firmware_header([UnitCalibration("7", Physical())])
    with pytest.raises(InputError, match="not a C identifier"):
        firmware_header(sample[0], name="2bad")


def test_the_command_writes_the_header_and_refuses_bad_input_in_one_line(tmp_path, capsys):
    """``reflector-opt firmware``: exit 0 and a header that the C compiler takes with ``-Wall
    -Werror``; a file that is not a calibration: exit 2, one line, nothing written."""
    from reflector_opt.calibration._unit_calibration import save_calibrations
    from reflector_opt.cli import main

    coefficients = tmp_path / "coef.json"
    save_calibrations(coefficients, calibrate_csv(DATA / "data.csv", "eq5", folds=2))
    assert main(["firmware", str(coefficients), "-o", str(tmp_path / "c.h"), "-q"]) == 0
    assert "per frame (float)" in capsys.readouterr().out
    if CC is not None:
        (tmp_path / "main.c").write_text('#include "c.h"\nint main(void) { return 0; }\n')
        flags = ["-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror", "-c"]
        subprocess.run([CC, *flags, tmp_path / "main.c", "-o", tmp_path / "main.o"], check=True)
    out = tmp_path / "bad.h"
    assert main(["firmware", str(DATA / "log.csv"), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "log.csv" in err and not out.exists()
