"""Execution: the same seed gives the same results on local processes and on a real Dask
LocalCluster (loopback), whatever the batch size; a worker that dies mid-run costs a retry,
not a result."""

import os
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from reflector_opt.tolerance import (
    Job,
    Settings,
    Tolerances,
    dask_cluster,
    draw_sample,
    run_study,
)
from reflector_opt.tolerance._analysis import evaluate_draws
from reflector_opt.tolerance._study import batched
from reflector_opt.util._errors import InputError
from reflector_opt.util._pools import local_processes, reused, run_batches, supplied

distributed = pytest.importorskip("distributed")

FAST = Settings(calibration_step_deg=2.0, n_validation=300, metrics_step_deg=2.0)
SAMPLES = 12


@pytest.fixture(scope="module")
def cluster():
    with distributed.LocalCluster(
        n_workers=2,
        threads_per_worker=1,
        processes=True,
        dashboard_address=None,
        host="127.0.0.1",
    ) as c:
        yield c


@pytest.fixture(scope="module")
def reference(design):
    """The study on the caller's own thread pool, batch size 5."""
    with ThreadPoolExecutor(2) as pool:
        return run_study(
            design,
            samples=SAMPLES,
            seed=5,
            settings=FAST,
            factory=supplied(pool),
            batch_size=5,
            oat_samples=2,
            sobol_samples=2,
        )


def _study(design, factory, batch_size):
    return run_study(
        design,
        samples=SAMPLES,
        seed=5,
        settings=FAST,
        factory=factory,
        batch_size=batch_size,
        oat_samples=2,
        sobol_samples=2,
    )


def _same(a, b):
    """Records equal field by field (NaN equal to NaN)."""
    assert len(a) == len(b)
    for x, y in zip(a, b, strict=True):
        assert x.keys() == y.keys()
        for key in x:
            assert x[key] == y[key] or (x[key] != x[key] and y[key] != y[key]), key


def test_local_processes_match_the_reference(design, reference):
    study = _study(design, local_processes(2), batch_size=3)
    _same(study.records, reference.records)
    assert study.to_dict() == reference.to_dict()


def test_dask_cluster_matches_the_reference(design, reference, cluster):
    for batch_size in (4, 32):
        study = _study(design, dask_cluster(cluster.scheduler_address), batch_size)
        _same(study.records, reference.records)
        assert study.to_dict() == reference.to_dict()
    assert reference.records[0]["index"] == 0 and len(reference.records) == SAMPLES


def _die_once(args, batch):
    """Evaluate a batch; the first worker to see sample 7 dies instead (marker file)."""
    marker, job = args
    if any(d.index == 7 for d in batch) and not Path(marker).exists():
        Path(marker).write_text("died", encoding="utf-8")
        os._exit(1)
    return evaluate_draws(job, batch)


def _killed_worker_run(tmp_path, design, factory):
    job = Job(design, Tolerances(), FAST)
    draws = [draw_sample(job.tolerances, 2, 5, i) for i in range(SAMPLES)]
    marker = tmp_path / f"marker-{id(factory)}"
    results = run_batches(_die_once, (str(marker), job), batched(draws, 4), factory)
    assert marker.exists(), "the worker did die"
    return [r for batch in results for r in batch]


def test_a_killed_local_worker_is_retried(tmp_path, design, reference):
    records = _killed_worker_run(tmp_path, design, local_processes(2))
    assert [r["index"] for r in records] == list(range(SAMPLES))
    _same(records, reference.records)


def test_a_killed_dask_worker_is_retried(tmp_path, design, reference, cluster):
    records = _killed_worker_run(tmp_path, design, dask_cluster(cluster.scheduler_address))
    assert [r["index"] for r in records] == list(range(SAMPLES))
    _same(records, reference.records)


def _fails(args, batch):
    raise InputError("a genuine error in the work")


def test_an_error_in_the_work_is_not_retried():
    with ThreadPoolExecutor(1) as pool, pytest.raises(InputError, match="genuine"):
        run_batches(_fails, None, [[1], [2]], supplied(pool))


def _pid_or_die(marker, batch):
    """The worker's process id; with a marker path, the first worker to see it dies."""
    if marker is not None and not Path(marker).exists():
        Path(marker).write_text("died", encoding="utf-8")
        os._exit(1)
    return os.getpid()


def test_a_reused_pool_is_kept_and_replaced_once_broken(tmp_path):
    marker = tmp_path / "marker"
    with reused(local_processes(1)) as shared:
        first = run_batches(_pid_or_die, None, range(6), shared)
        again = run_batches(_pid_or_die, None, range(6), shared)
        assert set(again) <= set(first)  # the same worker processes
        retried = run_batches(_pid_or_die, str(marker), range(6), shared)
        after = run_batches(_pid_or_die, None, range(6), shared)
    assert marker.exists(), "the worker did die"
    # every batch once: those lost are retried on a fresh pool, which then stays
    assert len(retried) == 6 and set(retried) - set(first)
    assert not set(after) & set(first)
