"""Run batches of work through a :class:`concurrent.futures.Executor`, surviving lost workers.

The worker pools of the tolerance studies and the optimiser. Executors are made by
*factories*: callables returning a context manager that yields an executor and shuts it down
on exit. :func:`local_processes` makes a :class:`~concurrent.futures.ProcessPoolExecutor`
(started as :func:`~reflector_opt.util.workers.worker_context` says: spawned, forked where a
spawned worker would run the caller's script again, or the work in this process where
neither can start); :func:`~reflector_opt.util.dask_pool.dask_cluster` connects a
``distributed.Client`` to a running scheduler and uses ``client.get_executor()``.

:func:`run_batches` submits every batch, collects the results keyed by batch number, and
resubmits a batch whose worker died (a broken process pool, a killed Dask worker) on a fresh
executor, so the result is complete and every batch counted exactly once. An exception raised
by the work itself is not retried: it propagates.
"""

from __future__ import annotations

import contextlib
import os
import warnings
from concurrent.futures import (
    FIRST_COMPLETED,
    BrokenExecutor,
    Executor,
    Future,
    ProcessPoolExecutor,
    wait,
)

from reflector_opt.util.errors import InputError
from reflector_opt.util.workers import init_worker, live_workers, stop_processes, worker_context

__all__ = [
    "executor_factory",
    "in_this_process",
    "local_processes",
    "reused",
    "run_batches",
    "supplied",
]

#: Environment of local worker processes: one BLAS/OpenMP thread each, so that the processes,
#: not the threads inside them, share the cores (as Dask's nanny does for its workers). Without
#: it two workers' multi-threaded least-squares fits fight over two cores and run ~10× slower.
WORKER_ENVIRONMENT = {
    "OMP_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
}


@contextlib.contextmanager
def _worker_environment():
    """:data:`WORKER_ENVIRONMENT` set while the block runs, the caller's restored after.

    The pool starts workers as work arrives, so the environment is set while it lives.
    """
    saved = {key: os.environ.get(key) for key in WORKER_ENVIRONMENT}
    os.environ.update(WORKER_ENVIRONMENT)
    try:
        yield
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value


def _init_forked_worker(parent_pid):
    """Initializer of a forked worker: :func:`init_worker`, then one BLAS/OpenMP thread.

    A forked worker has the libraries this process loaded with their thread counts already
    set, so :data:`WORKER_ENVIRONMENT` alone would not reach them.
    """
    from threadpoolctl import threadpool_limits

    init_worker(parent_pid)
    threadpool_limits(1)


class _InThisProcess(Executor):
    """An executor that runs each call at once in this process (no worker can start)."""

    def submit(self, fn, /, *args, **kwargs):
        """Run ``fn(*args, **kwargs)`` now; a future holding its result or exception."""
        future = Future()
        try:
            future.set_result(fn(*args, **kwargs))
        except Exception as exc:  # the work's own error, raised by future.result()
            future.set_exception(exc)
        return future


@contextlib.contextmanager
def _process_pool(max_workers):
    """A process pool whose workers start with :data:`WORKER_ENVIRONMENT`.

    The workers are spawned, or forked where a spawned worker would run the caller's script
    again (:func:`~reflector_opt.util.workers.worker_context`); where neither is possible the
    work runs in this process, with one warning that says why.

    The workers ignore Ctrl-C and die with this process (:mod:`reflector_opt.util.workers`);
    if the block ends with an exception (Ctrl-C included) they are stopped at once instead of
    finishing the batches in hand, and the pool's thread is joined before the exception goes
    on: nothing of the pool runs on to the interpreter's exit.
    """
    context, reason = worker_context()
    if context is None:
        warnings.warn(
            f"reflector_opt: no worker processes ({reason}); the work runs in this process. "
            'Put the call under `if __name__ == "__main__":` to use workers.',
            RuntimeWarning,
            stacklevel=1,  # one place: shown once, however many runs
        )
        yield _InThisProcess()
        return
    forked = reason is not None
    before = live_workers()
    with _worker_environment():
        pool = ProcessPoolExecutor(
            max_workers,
            mp_context=context,
            initializer=_init_forked_worker if forked else init_worker,
            initargs=(os.getpid(),),
        )
        try:
            pool.submit(os.getpid).result()  # a worker now: a pool that cannot start fails here
            yield pool
        except BaseException:
            _detach_cancelled(pool)
            # The pool's workers, and one an interrupt caught between its start and the
            # pool's record of it: left running, the interpreter's exit would wait for it.
            listed = set((getattr(pool, "_processes", None) or {}).values())
            stop_processes(listed | (live_workers() - before))
            # Then join the pool's thread, which sees its workers gone, fails the work left
            # and closes its pipes. A shutdown without waiting first would drop the pool's
            # handle on that thread, so that no later shutdown joins it: still closing at
            # exit, it raced the interpreter's own wake-up of the thread (a traceback, "Bad
            # file descriptor", after the one line). No future is cancelled here: see
            # _detach_cancelled.
            pool.shutdown(wait=True)
            raise
    pool.shutdown(wait=True, cancel_futures=True)


def _detach_cancelled(pool):
    """Give each cancelled, still queued work item of ``pool`` a fresh future of its own.

    The pool's thread fails every queued item's future when its workers are gone, and on
    Python before 3.12 (CPython gh-107219) it raises ``InvalidStateError`` on one the caller
    has already cancelled, a traceback after the command's one line. The cancelled future
    stays cancelled for the caller; the thread fails the fresh one, which no one reads.
    Listing the items copies the dictionary under the interpreter lock, so the pool's
    thread cannot change it half-way.
    """
    for item in list(getattr(pool, "_pending_work_items", {}).values()):
        if item.future.cancelled():
            item.future = Future()


def local_processes(max_workers=2):
    """Factory of a local pool of worker processes (one BLAS thread each).

    Parameters
    ----------
    max_workers : int
        Worker processes.

    Returns
    -------
    callable
        ``factory()`` -> context manager yielding a ``ProcessPoolExecutor``; a broken pool
        is shut down without waiting.
    """
    if isinstance(max_workers, bool) or not isinstance(max_workers, int) or max_workers < 1:
        raise InputError(f"workers: must be a positive whole number, got {max_workers!r}")
    return lambda: _process_pool(max_workers)


def executor_factory(scheduler, workers):
    """The pool of a run: a Dask cluster at ``scheduler``, else ``workers`` local processes.

    Parameters
    ----------
    scheduler : str or None
        Dask scheduler address, e.g. ``tcp://host:8786``.
    workers : int
        Local worker processes when ``scheduler`` is None.

    Returns
    -------
    callable
        An executor factory: :func:`local_processes` or
        :func:`~reflector_opt.util.dask_pool.dask_cluster`.
    """
    if scheduler is None:
        return local_processes(workers)
    from reflector_opt.util.dask_pool import dask_cluster

    return dask_cluster(scheduler)


def in_this_process():
    """Factory of an executor that runs each task at once in this process.

    For work that is already one task of a pool (a worker process cannot start its own
    workers): the same batches, run in order here.

    Returns
    -------
    callable
        ``factory()`` -> context manager yielding the executor.
    """
    return lambda: contextlib.nullcontext(_InThisProcess())


def supplied(executor):
    """Factory that hands out an executor the caller owns (never shut down here)."""
    return lambda: contextlib.nullcontext(executor)


@contextlib.contextmanager
def reused(factory):
    """Keep one executor of ``factory`` open for several runs of :func:`run_batches`.

    Starting a pool of spawned processes costs seconds; a sequence of studies (the rounds of
    a robust optimisation, the points of a Pareto front) shares one, opened on entry (so
    an unreachable scheduler is reported at once). Before each run the
    executor is probed with a trivial task: one whose worker died (a broken process pool) is
    shut down and replaced, so :func:`run_batches` can still resubmit lost batches.

    Parameters
    ----------
    factory : callable
        Executor factory (:func:`local_processes`,
        :func:`~reflector_opt.util.dask_pool.dask_cluster`, :func:`supplied`).

    Yields
    ------
    callable
        A factory handing out the kept executor; it is shut down when the block ends.
    """
    with contextlib.ExitStack() as outer:
        kept = {}

        def open_fresh():
            if "stack" in kept:
                kept.pop("stack").close()
            stack = outer.enter_context(contextlib.ExitStack())
            kept.update(stack=stack, executor=stack.enter_context(factory()))

        @contextlib.contextmanager
        def hand_out():
            try:
                kept["executor"].submit(int).result()
            except BrokenExecutor:
                open_fresh()
            yield kept["executor"]

        open_fresh()  # now: an unreachable scheduler is reported before any other work
        yield hand_out


def _worker_lost_errors():
    """Exception types that mean a worker died (the batch is resubmitted)."""
    types = [BrokenExecutor]
    try:
        from distributed.scheduler import KilledWorker
    except ImportError:
        pass
    else:
        types.append(KilledWorker)
    return tuple(types)


def run_batches(fn, args, batches, factory, *, max_attempts=3, progress=None):
    """Call ``fn(args, batch)`` for every batch on executors from ``factory``.

    Parameters
    ----------
    fn : callable
        A picklable module-level function ``fn(args, batch) -> list``.
    args
        Its first argument, the same for every batch (picklable).
    batches : sequence
        Second arguments.
    factory : callable
        Executor factory (:func:`local_processes`,
        :func:`~reflector_opt.util.dask_pool.dask_cluster`, :func:`supplied`).
    max_attempts : int
        Submissions of one batch before a lost worker is reported as an error.
    progress : callable, optional
        ``progress(fraction, message)`` as the batches are submitted and after each
        finished batch.

    Returns
    -------
    list
        ``fn``'s results in batch order, each batch's exactly once.
    """
    lost = _worker_lost_errors()
    results = {}
    attempts = dict.fromkeys(range(len(batches)), 0)

    def report():
        if progress is not None:
            progress(len(results) / len(batches), f"{len(results)}/{len(batches)} batches")

    report()  # at once: the first batch may take long
    while len(results) < len(batches):
        todo = [i for i in range(len(batches)) if i not in results]
        with factory() as executor:
            futures = {}
            for i in todo:
                attempts[i] += 1
                futures[executor.submit(fn, args, batches[i])] = i
            _collect(futures, results, attempts, max_attempts, lost, report)
    return [results[i] for i in range(len(batches))]


def _collect(futures, results, attempts, max_attempts, lost, report):
    """Results of ``futures`` (future -> batch number) into ``results`` as they finish.

    Returns when every future is done, or early when the executor broke (a lost local
    worker: what is left goes to a fresh one); a batch lost ``max_attempts`` times, or any
    other exception, cancels the rest and raises.
    """
    broken = False
    pending = set(futures)
    try:
        while pending and not broken:
            done, pending = wait(pending, return_when=FIRST_COMPLETED)
            for future in done:
                i = futures[future]
                try:
                    results[i] = future.result()
                except lost as exc:
                    if attempts[i] >= max_attempts:
                        raise RuntimeError(
                            f"batch {i}: a worker died on each of {attempts[i]} attempts"
                        ) from exc
                    broken = broken or isinstance(exc, BrokenExecutor)
                    continue
                report()
    finally:
        for f in pending:  # none after a complete run
            f.cancel()
