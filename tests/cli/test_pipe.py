"""A reader that closes stdout early (``reflector-opt … --json | head``): a quiet end."""

import signal
import subprocess
import sys
from pathlib import Path

SAMPLE = Path(__file__).parents[2] / "examples" / "data"


def test_a_closed_stdout_is_no_internal_error_and_the_file_is_written(tmp_path):
    out = tmp_path / "design.json"
    argv = [
        "fit-sensor",
        str(SAMPLE / "mirror.csv"),
        "--reflectance",
        "0.87",
        "--specular-fraction",
        "1",
    ]
    argv += ["-o", str(out)]
    process = subprocess.Popen(
        [sys.executable, "-m", "reflector_opt", *argv, "--json"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    process.stdout.close()  # the reader is gone before anything is printed
    err = process.stderr.read()
    process.wait(timeout=120)
    assert err == "" and process.returncode == 128 + signal.SIGPIPE
    assert out.stat().st_size > 0
