"""Run work through a :class:`concurrent.futures.Executor`, surviving lost workers.

The one executor path of the package: the tolerance studies, the optimiser's starts and its
search's population (:func:`ordered_map`), and the export's work beside the main work
(:mod:`reflector_opt.cad._background`). Executors are made by *factories*: callables
returning a context manager that yields an executor and shuts it down on exit.
:func:`local_processes` makes a :class:`~concurrent.futures.ProcessPoolExecutor`;
:func:`~reflector_opt.util._dask_pool.dask_cluster` connects a ``distributed.Client`` to a
running scheduler and uses ``client.get_executor()``.

Local workers are forked on Linux (:data:`START_METHOD`: nothing is imported again, so a
plain script, one piped to ``python -`` and a notebook all work, and the compiled kernels
this process loaded are inherited) and spawned elsewhere, where a spawned worker imports
``__main__`` again: a script whose work is not under ``if __name__ == "__main__":`` then
breaks the pool, which is reported as one :class:`~reflector_opt.util._errors.InputError`.
The workers leave Ctrl-C to their parent: they start with SIGINT blocked and then ignore it,
end at once on SIGTERM, and end when their parent does, even on SIGKILL (a thread waits on
the parent's sentinel, :func:`multiprocessing.parent_process`). If the block of a pool ends
with an exception (Ctrl-C included), its workers are stopped at once (:func:`stop`).

:func:`run_batches` submits every batch, collects the results keyed by batch number, and
resubmits a batch whose worker died (a broken process pool, a killed Dask worker) on a fresh
executor, so the result is complete and every batch counted exactly once. An exception raised
by the work itself is not retried: it propagates.
"""

import contextlib
import multiprocessing
import multiprocessing.connection
import os
import signal
import sys
import threading
from concurrent.futures import FIRST_COMPLETED, BrokenExecutor, Executor, Future, wait

from reflector_opt.util._errors import InputError

#: How local workers start: forked on Linux, spawned where forking is unsafe.
START_METHOD = "fork" if sys.platform.startswith("linux") else "spawn"

#: Environment of local worker processes: one BLAS/OpenMP thread each, so that the processes,
#: not the threads inside them, share the cores (as Dask's nanny does for its workers). Without
#: it two workers' multi-threaded least-squares fits fight over two cores and run ~10× slower.
WORKER_ENVIRONMENT = {
    "OMP_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
}


def _exit_with(sentinel):
    """End this process once ``sentinel`` (its parent's) is readable: the parent is gone."""
    multiprocessing.connection.wait([sentinel])
    os._exit(1)


def _init_worker():
    """Initializer of a local worker: deaf to Ctrl-C, ended by SIGTERM and by its parent's
    end, one BLAS/OpenMP thread (the environment for libraries loaded later, threadpoolctl
    for those a forked worker inherits loaded)."""
    from threadpoolctl import threadpool_limits

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    # A forked worker inherits the command's SIGTERM handler (reflector_opt.util._interrupts),
    # which would make the parent's stop (SIGTERM) a traceback in the worker: end quietly.
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    parent = multiprocessing.parent_process()
    threading.Thread(target=_exit_with, args=(parent.sentinel,), daemon=True).start()
    os.environ.update(WORKER_ENVIRONMENT)
    threadpool_limits(1)


def _stop_processes(processes, timeout_s=5.0):
    """Terminate worker processes and wait for them (SIGKILL after ``timeout_s`` seconds)."""
    processes = [p for p in processes if p.is_alive()]
    for p in processes:
        p.terminate()
    for p in processes:
        p.join(timeout_s)
        if p.is_alive():
            p.kill()
            p.join()


class _InThisProcess(Executor):
    """An executor that runs each call at once in this process."""

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
    """A process pool of :data:`START_METHOD` workers, started now and deaf to Ctrl-C.

    Its workers are started at once, with SIGINT blocked (the mask is inherited, so even a
    worker still starting is deaf to it); a pool whose workers cannot start (a spawned
    worker that runs an unguarded script again) is an InputError. If the block ends with an
    exception (Ctrl-C included) the workers are stopped at once instead of finishing the
    batches in hand (:func:`stop`).
    """
    from concurrent.futures import ProcessPoolExecutor
    from concurrent.futures.process import BrokenProcessPool

    context = multiprocessing.get_context(START_METHOD)
    before = set(multiprocessing.active_children())
    pool = ProcessPoolExecutor(max_workers, mp_context=context, initializer=_init_worker)
    try:
        blocked = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
        try:  # one task a worker starts them all (spawned ones start as tasks come)
            probes = [pool.submit(os.getpid) for _ in range(max_workers)]
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
        try:
            for probe in probes:
                probe.result()
        except BrokenProcessPool:
            raise InputError(
                "workers: the worker processes could not start; a spawned worker imports "
                '__main__ again, so a script must do its work under `if __name__ == "__main__":`'
            ) from None
        yield pool
    except BaseException:
        # The pool's workers, and one an interrupt caught between its start and the pool's
        # record of it: left running, the interpreter's exit would wait for it.
        stop(pool, set(multiprocessing.active_children()) - before)
        raise
    pool.shutdown(wait=True, cancel_futures=True)


def stop(pool, others=()):
    """Stop the workers of a process pool at once and join its thread.

    Parameters
    ----------
    pool : concurrent.futures.ProcessPoolExecutor
    others : iterable of multiprocessing.Process, optional
        Further processes to stop with them.

    Notes
    -----
    The workers are stopped first, then the pool's thread joined, which sees its workers
    gone, fails the work left and closes its pipes. A shutdown without waiting first would
    drop the pool's handle on that thread, so that no later shutdown joins it: still closing
    at exit, it raced the interpreter's own wake-up of the thread (a traceback, "Bad file
    descriptor", after the command's one line). No future is cancelled here: see
    :func:`_detach_cancelled`.
    """
    _detach_cancelled(pool)
    _stop_processes(set((getattr(pool, "_processes", None) or {}).values()) | set(others))
    pool.shutdown(wait=True)


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


def ordered_map(executor, workers):
    """``map`` over ``executor``, in about four chunks per worker as ``multiprocessing``'s.

    Parameters
    ----------
    executor : concurrent.futures.Executor
    workers : int
        Its worker processes.

    Returns
    -------
    callable
        ``map_(function, items)``, ordered like the builtin ``map`` (for SciPy's
        ``differential_evolution(workers=...)`` and the polish's forward differences).
    """

    def map_(function, items):
        items = list(items)
        return executor.map(function, items, chunksize=max(1, -(-len(items) // (4 * workers))))

    return map_


def local_processes(max_workers=2):
    """Factory of a local pool of worker processes (one BLAS thread each).

    Parameters
    ----------
    max_workers : int
        Worker processes.

    Returns
    -------
    callable
        ``factory()`` -> context manager yielding a ``ProcessPoolExecutor`` whose workers
        have started; if its block raises, they are stopped at once (:func:`stop`).
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
        :func:`~reflector_opt.util._dask_pool.dask_cluster`.
    """
    if scheduler is None:
        return local_processes(workers)
    from reflector_opt.util._dask_pool import dask_cluster

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
        :func:`~reflector_opt.util._dask_pool.dask_cluster`, :func:`supplied`).

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
    try:
        from distributed.scheduler import KilledWorker
    except ImportError:
        return (BrokenExecutor,)
    return (BrokenExecutor, KilledWorker)


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
        :func:`~reflector_opt.util._dask_pool.dask_cluster`, :func:`supplied`).
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
