"""reflector_opt.util._dask_pool: an address is checked before a Dask client exists."""

import socket

import pytest

from reflector_opt.util._dask_pool import dask_cluster
from reflector_opt.util._errors import InputError


@pytest.mark.parametrize("address", ["", "   "])
def test_blank_scheduler_address(address):
    with pytest.raises(InputError, match="scheduler address"):
        dask_cluster(address)


def _closed_port():
    """A loopback port nothing listens on (bound, then released)."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


@pytest.mark.parametrize(
    ("address", "fragment"),
    [
        ("nonsense://x:1", "scheduler address 'nonsense://x:1': unknown address scheme"),
        ("tcp://", "scheduler address 'tcp://': missing port"),
        ("tcp://127.0.0.1:{port}", "cannot reach the Dask scheduler at tcp://127.0.0.1:{port}"),
    ],
)
def test_a_bad_or_silent_scheduler_is_an_input_error(address, fragment):
    pytest.importorskip("distributed")
    port = _closed_port()
    factory = dask_cluster(address.format(port=port), timeout_s=0.5)
    with pytest.raises(InputError, match=fragment.format(port=port)), factory():
        pass
