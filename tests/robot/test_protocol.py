"""The device protocol (docs/robot.md): both forms round-trip, and every fault is counted."""

import binascii
import os
import socket
import struct

import numpy as np
import pytest

from reflector_opt.robot import Protocol
from reflector_opt.robot._protocol import FAULTS, SYNC, Frame, open_link
from reflector_opt.util._errors import InputError

PROTOCOLS = [
    Protocol(3),
    Protocol(3, temperature=True, form="text"),
    Protocol(2, n_sensors=3, temperature=True),
    Protocol(3, adc_bits=12, form="text"),
    Protocol(3, adc_bits=12, temperature=True),
]


def _frames(protocol, counters):
    rng = np.random.default_rng(4)
    shape = (protocol.n_units, protocol.n_sensors)
    for c in counters:
        if protocol.adc_bits is None:
            readings = np.round(rng.uniform(0.2, 3.1, shape), 6)
        else:
            readings = rng.integers(0, 2**protocol.adc_bits, shape).astype(float)
        temps = (
            np.round(rng.uniform(-20, 60, protocol.n_units), 2) if protocol.temperature else None
        )
        yield Frame(c, readings, temps)


def test_the_checksum_is_crc16_ccitt_false():
    """The published check value of CRC-16/CCITT-FALSE ("123456789" → 0x29B1), and a
    frame's last two bytes are that CRC of its bytes after the sync word."""
    assert binascii.crc_hqx(b"123456789", 0xFFFF) == 0x29B1
    data = Protocol(1).encode(Frame(7, np.array([[1.5, 2.25]])))
    assert data[:2] == SYNC and len(data) == Protocol(1).frame_bytes == 2 + 2 + 8 + 2
    assert struct.unpack("<HffH", data[2:]) == (7, 1.5, 2.25, binascii.crc_hqx(data[2:-2], 0xFFFF))


@pytest.mark.parametrize("protocol", PROTOCOLS, ids=repr)
def test_frames_round_trip_byte_by_byte(protocol):
    """Fed one byte at a time, the decoder gives back every frame (volts to float32's or the
    text's 6 decimals, codes exactly, °C to 0.01) and counts no fault."""
    frames = list(_frames(protocol, range(65530, 65530 + 12)))  # the counter wraps
    data = b"".join(map(protocol.encode, frames))
    decoder = protocol.decoder()
    out = [f for byte in data for f in decoder.feed(bytes([byte]))]
    decoder.close()
    assert [f.counter for f in out] == [c % 65536 for c in range(65530, 65542)]
    for a, b in zip(frames, out, strict=True):
        np.testing.assert_allclose(b.readings, a.readings, rtol=0, atol=2e-7 * 3.1)
        if protocol.temperature:
            np.testing.assert_allclose(b.temperature_c, a.temperature_c, atol=1e-9)
    assert not any(decoder.faults.values()), decoder.faults
    if protocol.adc_bits:
        np.testing.assert_allclose(protocol.volts(out[0]), out[0].readings * 3.3 / 4096)


def _faulty_run(protocol):
    """Frame 3 garbled (one byte changed), frames 6 and 7 dropped, noise between frames, then a
    restart at counter 0 and a frame cut off by the end: the counters decoded and the faults."""
    frames = list(_frames(protocol, [*range(10), 0, 1]))
    chunks = [protocol.encode(f) for f in frames]
    bad = bytearray(chunks[3])
    bad[len(bad) // 2] = (bad[len(bad) // 2] ^ 0x11) if protocol.form == "binary" else ord("x")
    chunks[3] = bytes(bad)
    del chunks[6:8]
    chunks.insert(2, b"\x00\xa5junk" if protocol.form == "binary" else b"junk line\n")
    decoder = protocol.decoder()
    out = [f.counter for c in chunks for f in decoder.feed(c)]
    out += [f.counter for f in decoder.feed(protocol.encode(frames[0])[:-3])]
    decoder.close()
    return out, decoder.faults


def _expected(protocol):
    garbled = "checksum" if protocol.form == "binary" else "text"
    counts = {garbled: 1 + (protocol.form == "text"), "dropped": 3, "reordered": 1, "truncated": 1}
    return [0, 1, 2, 4, 5, 8, 9, 0, 1], {
        k: counts.get(k, 0) for k in counts | dict.fromkeys(FAULTS)
    }


@pytest.mark.parametrize("protocol", PROTOCOLS, ids=repr)
def test_each_fault_is_named_and_counted(protocol):
    """Every good frame decoded; 1 checksum fault (text: 2, the garbled line and the junk line),
    3 dropped (every frame not delivered: 3, garbled, and 6 and 7), 1 reordered (the restart),
    1 truncated (the cut frame)."""
    assert _faulty_run(protocol) == _expected(protocol)


def test_the_fault_count_fails_when_the_checksum_is_not_checked(monkeypatch):
    """The guard: with every checksum equal (the CRC function broken), the garbled binary frame
    is decoded as good and the comparison above fails."""
    monkeypatch.setattr(binascii, "crc_hqx", lambda data, init: 0)
    assert _faulty_run(Protocol(3)) != _expected(Protocol(3))


def test_the_links_read_a_pipe_and_udp_and_refuse_a_missing_port(tmp_path):
    """A file gives its bytes and ends; UDP gives each datagram; a port that is not there is
    refused in one line naming it; pyserial reads a pseudo-terminal as a serial port."""
    protocol = Protocol(2)
    data = b"".join(protocol.encode(f) for f in _frames(protocol, range(5)))
    (tmp_path / "log.bin").write_bytes(data)
    decoder = protocol.decoder()
    assert [f.counter for f in decoder.read(open_link(str(tmp_path / "log.bin")))] == [*range(5)]
    receiver = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    receiver.bind(("127.0.0.1", 0))
    port = receiver.getsockname()[1]
    receiver.close()
    chunks = open_link(f"udp:127.0.0.1:{port}")
    sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sender.sendto(data, ("127.0.0.1", port))
    assert next(chunks) == data
    chunks.close()
    with pytest.raises(InputError, match="/dev/nonexistent-port: cannot open"):
        open_link("serial:/dev/nonexistent-port")
    with pytest.raises(InputError, match="baud: 12345"):
        open_link("serial:/dev/null", baud=12345)


def test_pyserial_reads_a_pseudo_terminal():
    pytest.importorskip("serial", reason="pyserial (the robot extra) is not installed")
    import tty

    protocol = Protocol(1, form="text")
    master, slave = os.openpty()
    tty.setraw(slave)
    chunks = open_link(f"serial:{os.ttyname(slave)}")
    os.write(master, b"".join(protocol.encode(f) for f in _frames(protocol, range(3))))
    decoder = protocol.decoder()
    out = []
    for chunk in chunks:
        out += decoder.feed(chunk)
        if len(out) == 3:
            break
    chunks.close()
    os.close(master)
    os.close(slave)
    assert [f.counter for f in out] == [0, 1, 2]
