"""reflector-opt smallest: options refused before any work, in one line, nothing written."""

import pytest

from reflector_opt.cli import main
from reflector_opt.util.errors import InputError
from reflector_opt.workflow import SmallestOptions, smallest_run


@pytest.mark.parametrize(
    ("options", "fragment"),
    [
        (SmallestOptions(target_deg=float("nan")), "--target-deg: expected a finite number"),
        (SmallestOptions(target_deg=-0.1), "--target-deg: must lie in (0, 90)"),
        (SmallestOptions(target_deg=0.1), "tilts the unit by up to 21.1°"),
        (SmallestOptions(target_deg=0.1, workspace_deg=11, sensor="NOPE"), "unknown sensor part"),
        (SmallestOptions(target_deg=0.1, workspace_deg=11, largest_mm=12), "not inside a 12 mm"),
    ],
)
def test_bad_options_are_refused_before_any_work(tmp_path, options, fragment):
    with pytest.raises(InputError, match=fragment.replace("(", r"\(").replace(")", r"\)")):
        smallest_run(options, out=tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_the_command_refuses_a_workspace_no_bearing_permits_with_exit_2(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["smallest", "--target-deg", "0.1", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "the most any bearing permits is 16° (GE4E)" in err and len(err.splitlines()) == 1
    assert not out.exists()
