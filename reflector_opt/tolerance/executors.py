"""Run batches of work through a :class:`concurrent.futures.Executor`, surviving lost workers.

Executors are made by *factories*: callables returning a context manager that yields an
executor and shuts it down on exit. :func:`local_processes` makes a
:class:`~concurrent.futures.ProcessPoolExecutor`; :func:`dask_cluster` connects a
``distributed.Client`` to a running scheduler and uses ``client.get_executor()``.

:func:`run_batches` submits every batch, collects the results keyed by batch number, and
resubmits a batch whose worker died (a broken process pool, a killed Dask worker) on a fresh
executor, so the result is complete and every batch counted exactly once. An exception raised
by the work itself is not retried: it propagates.
"""

from __future__ import annotations

import contextlib
import os
from concurrent.futures import (
    FIRST_COMPLETED,
    BrokenExecutor,
    ProcessPoolExecutor,
    ThreadPoolExecutor,
    wait,
)

from reflector_opt.util.errors import InputError
from reflector_opt.util.workers import init_worker, spawn_context, stop_processes

__all__ = ["dask_cluster", "local_processes", "reused", "run_batches", "supplied"]

#: Seconds to wait for a Dask scheduler to answer before giving up.
CONNECT_TIMEOUT_S = 5.0

#: Environment of local worker processes: one BLAS/OpenMP thread each, so that the processes,
#: not the threads inside them, share the cores (as Dask's nanny does for its workers). Without
#: it two workers' multi-threaded least-squares fits fight over two cores and run ~10× slower.
WORKER_ENVIRONMENT = {
    "OMP_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
}


@contextlib.contextmanager
def _process_pool(max_workers):
    """A spawned process pool whose workers start with :data:`WORKER_ENVIRONMENT`.

    The environment is set while the pool lives, as the pool starts workers as work arrives.

    The workers ignore Ctrl-C and die with this process (:mod:`reflector_opt.util.workers`);
    if the block ends with an exception (Ctrl-C included) they are stopped at once instead of
    finishing the batches in hand, and the pool's thread is joined before the exception goes
    on: nothing of the pool runs on to the interpreter's exit.
    """
    saved = {key: os.environ.get(key) for key in WORKER_ENVIRONMENT}
    os.environ.update(WORKER_ENVIRONMENT)  # while the pool lives: it spawns workers on demand
    pool = ProcessPoolExecutor(
        max_workers,
        mp_context=spawn_context(),
        initializer=init_worker,
        initargs=(os.getpid(),),
    )
    try:
        pool.submit(os.getpid).result()  # a worker now: a pool that cannot start fails here
        yield pool
    except BaseException:
        stop_processes(list((getattr(pool, "_processes", None) or {}).values()))
        # Then join the pool's thread, which sees its workers gone and closes its pipes. A
        # shutdown without waiting first would drop the pool's handle on that thread, so that
        # no later shutdown joins it: still closing at exit, it raced the interpreter's own
        # wake-up of the thread (a traceback, "Bad file descriptor", after the one line).
        pool.shutdown(wait=True, cancel_futures=True)
        raise
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value
    pool.shutdown(wait=True, cancel_futures=True)


def local_processes(max_workers=2):
    """Factory of a local pool of spawned processes (one BLAS thread each).

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


def supplied(executor):
    """Factory that hands out an executor the caller owns (never shut down here)."""
    return lambda: contextlib.nullcontext(executor)


def _probe_scheduler(address, timeout_s):
    """Open and close one connection to ``address`` with Dask's handshake.

    An address where no Dask scheduler answers is refused here, before a ``Client`` exists:
    a client that fails to start still tries to close on garbage collection, which waits 10 s
    and prints a traceback; and what fails depends on what answers (nothing, a server of
    another protocol whose reply is read as a frame of exabytes, TLS without its
    configuration), so any failure of this one connection is the address's.
    """
    import asyncio

    from distributed.comm import connect

    async def touch():
        comm = await connect(address, timeout=timeout_s)
        await comm.close()

    # In a thread of its own: the caller's thread may run an event loop (a notebook).
    with ThreadPoolExecutor(1) as thread:
        try:
            thread.submit(asyncio.run, touch()).result()
        except Exception as exc:  # any failure of this connection is the address's
            reason = str(exc).splitlines()[0] if str(exc) else ""
            raise InputError(
                f"cannot reach the Dask scheduler at {address} within {timeout_s:g} s "
                f"({type(exc).__name__}{': ' + reason[:120] if reason else ''})"
            ) from None


@contextlib.contextmanager
def _dask_executor(address, timeout_s):
    try:
        from distributed import Client
    except ImportError:
        raise InputError(
            "--scheduler needs the 'distributed' package: pip install 'reflector-opt[dask]'"
        ) from None
    try:  # a malformed address fails here, before a Client exists whose teardown would fail
        from distributed.comm import resolve_address

        resolve_address(address)
    except ValueError as exc:
        raise InputError(f"scheduler address {address!r}: {exc}") from None
    except OSError as exc:
        raise InputError(f"cannot reach the Dask scheduler at {address} ({exc})") from None
    _probe_scheduler(address, timeout_s)
    try:
        client = Client(address, timeout=timeout_s, set_as_default=False)
    except (OSError, TimeoutError) as exc:
        raise InputError(
            f"cannot reach the Dask scheduler at {address} within {timeout_s:g} s "
            f"({type(exc).__name__})"
        ) from None
    except ValueError as exc:
        raise InputError(f"scheduler address {address!r}: {exc}") from None
    try:
        yield client.get_executor(pure=False)
    finally:
        client.close()


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
        Executor factory (:func:`local_processes`, :func:`dask_cluster`, :func:`supplied`).

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


def dask_cluster(address, timeout_s=CONNECT_TIMEOUT_S):
    """Factory of an executor on a running Dask distributed scheduler.

    Parameters
    ----------
    address : str
        Scheduler address, e.g. ``"tcp://10.0.0.5:8786"``.
    timeout_s : float
        Connection timeout, seconds; an unreachable scheduler raises
        :class:`~reflector_opt.util.errors.InputError` after it.

    Returns
    -------
    callable
        ``factory()`` -> context manager yielding a ``distributed`` client executor.
    """
    if not isinstance(address, str) or not address.strip():
        raise InputError(f"scheduler address: expected e.g. tcp://HOST:8786, got {address!r}")
    return lambda: _dask_executor(address.strip(), float(timeout_s))


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
        Executor factory (:func:`local_processes`, :func:`dask_cluster`, :func:`supplied`).
    max_attempts : int
        Submissions of one batch before a lost worker is reported as an error.
    progress : callable, optional
        ``progress(fraction, message)`` after each finished batch.

    Returns
    -------
    list
        ``fn``'s results in batch order, each batch's exactly once.
    """
    lost = _worker_lost_errors()
    results = {}
    attempts = dict.fromkeys(range(len(batches)), 0)
    while len(results) < len(batches):
        todo = [i for i in range(len(batches)) if i not in results]
        with factory() as executor:
            futures = {}
            for i in todo:
                attempts[i] += 1
                futures[executor.submit(fn, args, batches[i])] = i
            broken = False
            pending = set(futures)
            while pending:
                done, pending = wait(pending, return_when=FIRST_COMPLETED)
                for future in done:
                    i = futures[future]
                    try:
                        results[i] = future.result()
                    except lost as exc:
                        if attempts[i] >= max_attempts:
                            for f in pending:
                                f.cancel()
                            raise RuntimeError(
                                f"batch {i}: a worker died on each of {attempts[i]} attempts"
                            ) from exc
                        broken = broken or isinstance(exc, BrokenExecutor)
                        continue
                    except BaseException:
                        for f in pending:
                            f.cancel()
                        raise
                    if progress is not None:
                        progress(
                            len(results) / len(batches), f"{len(results)}/{len(batches)} batches"
                        )
                if broken:  # the pool is unusable: start a fresh one for what is left
                    for f in pending:
                        f.cancel()
                    break
    return [results[i] for i in range(len(batches))]
