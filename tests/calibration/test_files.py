"""The lab's CSV readers: a row that does not fit its header, and values out of range, are
refused with the file, the line and the column named."""

import numpy as np
import pytest

from reflector_opt.calibration._files import read_calibration_csv, read_voltage_log
from reflector_opt.calibration._logstream import Unordered, log_blocks
from reflector_opt.util._errors import InputError

HEADER = "unit,v1,v2,pitch_deg,roll_deg\n"
ROWS = [f"1,{1 + 0.01 * i},{2 - 0.01 * i},{i - 10.0},{5.0 - i}\n" for i in range(20)]


def _write(tmp_path, text, name="data.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    ("cells", "message"),
    [
        # an angle of 1e308° once went on to an infinite cross-validation error: exit 1
        ("1,2.0,2.5,-15.0,1e308", "column roll_deg: expected a number > -90 and < 90°, got 1e308"),
        ("1,2.0,2.5,90,0", "column pitch_deg: expected a number > -90 and < 90°, got 90"),
        ("1,2.0,-1e300,0,0", "column v2: expected a number from -1000 to 1000 V, got -1e300"),
    ],
)
def test_calibration_values_out_of_range_are_refused(tmp_path, cells, message):
    path = _write(tmp_path, HEADER + cells + "\n" + "".join(ROWS))
    with pytest.raises(InputError, match=f"^{path}, line 2: {message}$"):
        read_calibration_csv(path)


def test_the_range_limits_themselves(tmp_path):
    path = _write(tmp_path, HEADER + "1,1000,-1000,89.999,-89.999\n" + "".join(ROWS))
    samples = read_calibration_csv(path, accept_units=True)["1"]  # far beyond the supply
    assert samples.volts[0].tolist() == [1000.0, -1000.0]
    assert samples.angles_deg[0].tolist() == [89.999, -89.999]


def test_a_row_longer_than_the_header_is_refused(tmp_path):
    """A stray comma (a decimal comma) shifted the cells after it: 1,2,015,2.7,-15,-15 was
    read as v1 2, v2 15, pitch 2.7, roll -15, the last cell dropped."""
    text = HEADER + "".join(ROWS[:3]) + "1,2,015,2.7,-15,-15\n" + "".join(ROWS[3:])
    path = _write(tmp_path, text)
    with pytest.raises(InputError, match=f"^{path}, line 5: 6 cells, the header has 5 columns$"):
        read_calibration_csv(path)


def test_empty_cells_after_the_last_column_are_allowed(tmp_path):
    """A spreadsheet's trailing separators."""
    path = _write(tmp_path, HEADER + "".join(r.replace("\n", ",,\n") for r in ROWS))
    assert len(read_calibration_csv(path)["1"].volts) == len(ROWS)


def test_a_log_voltage_out_of_range_is_refused_by_both_readers(tmp_path):
    rows = "".join(f"{i},1,2.0,2.5\n{i},2,2.1,2.4\n" for i in range(4))
    path = _write(tmp_path, "sample,unit,v1,v2\n" + rows + "4,1,2.0,1e120\n4,2,2.1,2.4\n")
    with pytest.raises(InputError, match=f"^{path}, line 10: column v2: expected a number from"):
        read_voltage_log(path)
    with pytest.raises(Unordered):  # the stream leaves it to the whole read, which names it
        list(log_blocks(path))


def test_angles_in_radians_are_refused_naming_the_columns(tmp_path):
    """The ±15° workspace in radians (±0.26) is named as radians; degrees of the same rows are
    read."""
    import numpy as np

    angles = np.deg2rad([[-15.0, 15.0], [0.0, 5.0], [15.0, -15.0]])
    rows = "".join(f"1,1.0,2.0,{p},{r}\n" for p, r in angles)
    path = tmp_path / "rad.csv"
    path.write_text("unit,v1,v2,pitch_deg,roll_deg\n" + rows)
    with pytest.raises(InputError, match=r"pitch_deg and roll_deg .* look like radians"):
        read_calibration_csv(path)
    rows = "".join(f"1,1.0,2.0,{p},{r}\n" for p, r in np.rad2deg(angles))
    path.write_text("unit,v1,v2,pitch_deg,roll_deg\n" + rows)
    assert read_calibration_csv(path)["1"].angles_deg.max() == pytest.approx(15.0)


def test_a_plan_reads_back_as_written(tmp_path):
    """write_plan_csv then read_plan_csv: the same poses, bit for bit, numbered from 1."""
    from reflector_opt.calibration._files import read_plan_csv, write_plan_csv

    poses = np.array([[-15.0, 0.1], [1 / 3, 14.999999999999998], [2.5e-7, -7.25]])
    write_plan_csv(tmp_path / "plan.csv", poses)
    lines = (tmp_path / "plan.csv").read_text().splitlines()
    assert (
        lines[0] == "pose,pitch_deg,roll_deg"
        and lines[2] == "2,0.3333333333333333,14.999999999999998"
    )
    read, changes = read_plan_csv(tmp_path / "plan.csv")
    assert changes is None and np.array_equal(read, poses)
    write_plan_csv(tmp_path / "t.csv", poses, [0.0, -10.0, 10.0])
    read, changes = read_plan_csv(tmp_path / "t.csv")
    assert np.array_equal(read, poses) and changes.tolist() == [0.0, -10.0, 10.0]


@pytest.mark.parametrize(
    ("cells", "message"),
    [
        ("1,95,0", "line 2: column pitch_deg"),
        ("1,0,nan", r"line 2: column roll_deg is nan \(not finite\)"),
        ("1,0,0,150", "line 2: column temperature_change_k"),
    ],
)
def test_a_plan_out_of_range_is_refused(tmp_path, cells, message):
    from reflector_opt.calibration._files import read_plan_csv

    path = tmp_path / "plan.csv"
    header = "pose,pitch_deg,roll_deg" + (",temperature_change_k" if cells.count(",") == 3 else "")
    path.write_text(f"{header}\n{cells}\n1,0,0{',0' if 'temperature' in header else ''}\n")
    with pytest.raises(InputError, match=message):
        read_plan_csv(path)
