"""Executors on a running Dask distributed scheduler (the optional ``dask`` extra).

:func:`dask_cluster` is an executor factory for
:func:`~reflector_opt.util._pools.run_batches`: it checks that a scheduler answers at the
address before a ``distributed.Client`` exists, then hands out ``client.get_executor()``.
"""

import contextlib
from concurrent.futures import ThreadPoolExecutor

from reflector_opt.util._errors import InputError

#: Seconds to wait for a Dask scheduler to answer before giving up.
CONNECT_TIMEOUT_S = 5.0


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


def dask_cluster(address, timeout_s=CONNECT_TIMEOUT_S):
    """Factory of an executor on a running Dask distributed scheduler.

    Parameters
    ----------
    address : str
        Scheduler address, e.g. ``"tcp://10.0.0.5:8786"``.
    timeout_s : float
        Connection timeout, seconds; an unreachable scheduler raises
        :class:`~reflector_opt.util._errors.InputError` after it.

    Returns
    -------
    callable
        ``factory()`` -> context manager yielding a ``distributed`` client executor.
    """
    if not isinstance(address, str) or not address.strip():
        raise InputError(f"scheduler address: expected e.g. tcp://HOST:8786, got {address!r}")
    return lambda: _dask_executor(address.strip(), float(timeout_s))
