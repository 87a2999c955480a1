"""The run_study snippet of docs/tolerance.md works however Python runs it, and leaves no
process behind: as a plain script without a ``__main__`` guard, piped to ``python -``, as
``python -c``, under the guard, and in a notebook; interrupted and killed too."""

import os
import re
import signal
import subprocess
import sys
import uuid
from pathlib import Path

import pytest

from tests.processes import HAS_PROC, ROOT, descendants, wait_until

pytestmark = pytest.mark.skipif(not HAS_PROC, reason="reads processes from Linux's /proc")

#: Draws of the snippet's study in these runs (the docs' 1000 take minutes on two cores):
#: two batches of 32, so that both workers have work.
SAMPLES = 64

#: The snippet's line, and what each run prints besides it: the summary in full precision.
PRINTED = re.compile(r"^yield \d+\.\d%, required margin \d+\.\d{4} mm$", re.M)
FULL = 'print("summary", repr(study.summary["yield"]), repr(study.summary["required_margin_mm"]))\n'


def _snippet():
    """The Python block of docs/tolerance.md that calls run_study, with SAMPLES draws."""
    text = (ROOT / "docs" / "tolerance.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    (block,) = [b for b in blocks if "run_study(" in b]
    assert "samples=1000" in block
    return block.replace("samples=1000", f"samples={SAMPLES}") + FULL


def _guarded(code):
    body = "".join(f"    {line}\n" for line in code.splitlines())
    return f'if __name__ == "__main__":\n{body}'


def _marked(mark):
    """Running processes whose environment carries ``mark`` (the run's and its workers')."""
    found = []
    for entry in Path("/proc").iterdir():
        try:
            if entry.name.isdigit() and mark.encode() in (entry / "environ").read_bytes():
                found.append(int(entry.name))
        except OSError:
            continue
    return found


def _env(mark):
    return dict(
        os.environ, PYTHONPATH=str(ROOT), SNIPPET_RUN=mark, PYTHONWARNINGS="error::RuntimeWarning"
    )


def _run(args, tmp_path, stdin=None):
    """Run ``python args`` to its end; its output, after checking that nothing is left."""
    mark = uuid.uuid4().hex
    done = subprocess.run(
        [sys.executable, *args],
        input=stdin,
        cwd=tmp_path,
        env=_env(mark),
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr and "Warning" not in done.stderr, done.stderr
    assert PRINTED.search(done.stdout), done.stdout
    assert wait_until(lambda: _marked(mark) == [], 10), "a worker outlived the run"
    return done.stdout


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """The snippet's output run each way (one module-wide set: each run takes seconds)."""
    tmp_path = tmp_path_factory.mktemp("snippet")
    code = _snippet()
    (tmp_path / "plain.py").write_text(code, encoding="utf-8")
    (tmp_path / "guarded.py").write_text(_guarded(code), encoding="utf-8")
    return {
        "plain script": _run(["plain.py"], tmp_path),
        "pipe": _run(["-"], tmp_path, stdin=code),
        "-c": _run(["-c", code], tmp_path),
        "guarded script": _run(["guarded.py"], tmp_path),
    }


@pytest.mark.slow
def test_the_snippet_runs_as_a_plain_script_a_pipe_and_python_c(runs):
    """Before, the plain script and the pipe died: spawned workers re-ran the script (or
    could not read stdin) and the pool broke (``BrokenProcessPool``)."""
    assert set(runs.values()) == {runs["guarded script"]}  # the same study every way


@pytest.mark.parametrize("stop", [signal.SIGINT, signal.SIGKILL], ids=["ctrl-c", "killed"])
def test_an_interrupted_or_killed_plain_script_leaves_no_worker(tmp_path, stop):
    """Ctrl-C (SIGINT to the process group, as a terminal sends it) or SIGKILL of an
    unguarded script while its forked workers compute: nothing is left running."""
    (tmp_path / "plain.py").write_text(_snippet().replace(f"samples={SAMPLES}", "samples=5000"))
    mark = uuid.uuid4().hex
    run = subprocess.Popen(
        [sys.executable, "plain.py"],
        cwd=tmp_path,
        env=_env(mark),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    try:
        assert wait_until(lambda: len(descendants(run.pid)) >= 2, 120), "no workers started"
        if stop == signal.SIGINT:
            os.killpg(run.pid, stop)
        else:
            os.kill(run.pid, stop)
        _, err = run.communicate(timeout=60)
    finally:
        if run.poll() is None:
            run.kill()
    assert run.returncode != 0
    if stop == signal.SIGINT:
        assert err.rstrip().endswith("KeyboardInterrupt"), err
        assert "Exception ignored" not in err and "BrokenProcessPool" not in err, err
    assert wait_until(lambda: _marked(mark) == [], 30), "a worker outlived the run"


@pytest.mark.slow
def test_the_snippet_runs_in_a_notebook(runs, tmp_path, monkeypatch):
    """A notebook kernel's ``__main__`` has no file: the workers are spawned as usual."""
    nbformat = pytest.importorskip("nbformat", reason="the [test] extra runs notebooks")
    nbclient = pytest.importorskip("nbclient", reason="the [test] extra runs notebooks")
    mark = uuid.uuid4().hex
    monkeypatch.setenv("PYTHONPATH", str(ROOT))
    monkeypatch.setenv("SNIPPET_RUN", mark)
    book = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(_snippet())])
    client = nbclient.NotebookClient(
        book, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}
    )
    client.execute()
    (cell,) = book.cells
    printed = "".join(o.get("text", "") for o in cell.outputs if o.get("name") == "stdout")
    assert printed == runs["guarded script"]
    errors = [o for o in cell.outputs if o.output_type == "error" or o.get("name") == "stderr"]
    assert errors == []
    assert wait_until(lambda: _marked(mark) == [], 30), "a worker or the kernel outlived it"
