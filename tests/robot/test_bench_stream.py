"""benchmarks/bench_stream.py runs through the real stream path on a few frames (its figures are
not checked here: tests are never timed)."""

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_the_stream_benchmark_writes_every_frame_to_the_csv_and_says_what_limits_it():
    spec = importlib.util.spec_from_file_location(
        "bench_stream", ROOT / "benchmarks" / "bench_stream.py"
    )
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    result = bench.measure(ROOT, "thermal", rate=400.0, seconds=0.05, profiled=True)
    for run in ("unpaced", "paced"):
        assert result[run]["frames"] == result[run]["rows"] == 20
        assert 0 < result[run]["p50_ms"] <= result[run]["p99_ms"] <= result[run]["max_ms"]
    assert len(result["profile"]) == 12 and result["reference_us"] > 0
