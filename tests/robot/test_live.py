"""The live view's server (reflector_opt.robot._live) without a browser: the page over HTTP, the
newest shape as JSON over the WebSocket (older ones dropped), a client that never reads holding
neither the stream nor its end, the port released, and a bad ``--view`` refused."""

import json
import logging
import re
import socket
import threading
import urllib.error
import urllib.request

import numpy as np
import pytest
from numpy.testing import assert_allclose
from websockets.sync.client import connect

from reflector_opt.calibration._unit_calibration import EstimatedShape
from reflector_opt.cli import main
from reflector_opt.robot import Protocol
from reflector_opt.robot._live import LiveView, view_address
from reflector_opt.workflow._stream import stream
from tests.robot.test_stream_run import _chunks, coefficients  # noqa: F401 (a fixture)

PAGE = "<!DOCTYPE html><p>live</p>"


def _shape(counter, angles_deg):
    """One instant's shape of units at ``angles_deg`` ((pitch, roll) per unit, degrees)."""
    angles = np.array([angles_deg], dtype=float)
    return EstimatedShape("counter", [str(counter)], ["1", "2"], angles, None, None)


def _hand_rotation(pitch_deg, roll_deg):
    """Rx(roll)·Ry(pitch), paper Eq 1, written out."""
    a, g = np.radians(roll_deg), np.radians(pitch_deg)
    rx = [[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]]
    ry = [[np.cos(g), 0, np.sin(g)], [0, 1, 0], [-np.sin(g), 0, np.cos(g)]]
    return np.array(rx) @ np.array(ry)


def _released(port):
    """Whether the port can be listened on again."""
    with socket.create_server(("127.0.0.1", port)):
        return True


def test_the_page_and_the_newest_shape_as_json(caplog):
    """The page at ``/`` as HTML, 404 elsewhere; a client connecting after two shapes gets the
    newer only, its rotations Rx·Ry by hand (1e-12; the reversed product is 0.01 away); no
    message again until a new shape; a shape with a NaN angle is not sent."""
    caplog.set_level(logging.INFO, logger="reflector_opt")
    before = threading.enumerate()
    with LiveView("127.0.0.1:0", PAGE) as view:
        host, port = view.address
        assert f"live view: http://127.0.0.1:{port}/" in caplog.text
        with urllib.request.urlopen(f"http://{host}:{port}/") as response:
            assert response.headers["Content-Type"] == "text/html; charset=utf-8"
            assert response.read().decode() == PAGE
        with pytest.raises(urllib.error.HTTPError, match="404"):
            urllib.request.urlopen(f"http://{host}:{port}/other")
        view.show(_shape(1, [[1.0, 2.0], [3.0, 4.0]]))
        newest = _shape(2, [[10.0, -5.0], [-7.0, 12.0]])
        view.show(newest)
        with connect(f"ws://{host}:{port}/shape") as client:
            message = json.loads(client.recv(timeout=5))
            assert message["counter"] == "2" and message["angles_deg"] == [[10, -5], [-7, 12]]
            hand = [_hand_rotation(10.0, -5.0), _hand_rotation(-7.0, 12.0)]
            assert_allclose(message["rotations"], hand, rtol=0, atol=1e-12)
            reversed_order = _hand_rotation(10.0, 0) @ _hand_rotation(0, -5.0)
            assert np.abs(reversed_order - hand[0]).max() > 0.01
            view.show(newest)  # the same shape again: nothing new
            with pytest.raises(TimeoutError):
                client.recv(timeout=0.3)
            view.show(_shape(3, [[np.nan, 0.0], [0.0, 0.0]]))
            with pytest.raises(TimeoutError):
                client.recv(timeout=0.3)
            view.show(_shape(4, [[0.0, 0.0], [1.0, 1.0]]))
            assert json.loads(client.recv(timeout=5))["counter"] == "4"
    assert threading.enumerate() == before and _released(port)


def test_a_client_that_never_reads_holds_neither_the_stream_nor_ctrl_c(
    tmp_path,
    coefficients,  # noqa: F811
    caplog,
    monkeypatch,
):
    """A client that completes the handshake and never reads, sent 1 MB messages as fast as
    shapes come: the socket's buffers fill and its thread blocks in a send after a few (3 made
    here; of ~0.9 kB shapes, the buffers take about 1,500 of the 2,000 before one blocks), yet
    every one of the 2,000 frames is written, Ctrl-C ends the run, its thread and the server's
    are gone and the port is free."""
    caplog.set_level(logging.INFO, logger="reflector_opt")
    made = []
    monkeypatch.setattr("reflector_opt.robot._live.UPDATES_PER_S", 1e6)
    monkeypatch.setattr(
        "reflector_opt.robot._live.shape_message", lambda s: made.append(s) or "x" * 2**20
    )
    monkeypatch.setattr("reflector_opt.report._view3d.live_page", lambda *a: PAGE)
    chunks = _chunks(Protocol(3), 2000, per_chunk=1)
    stuck = socket.socket()
    stuck.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    before = threading.enumerate()
    address = {}

    def link():
        yield chunks[0]
        address["port"] = int(re.search(r"live view: http://127.0.0.1:(\d+)/", caplog.text)[1])
        stuck.connect(("127.0.0.1", address["port"]))
        stuck.sendall(
            b"GET /shape HTTP/1.1\r\nHost: x\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
            b"Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n"
        )
        stuck.recv(1, socket.MSG_PEEK)  # the handshake's answer is there, left unread
        yield from chunks[1:]
        raise KeyboardInterrupt

    try:
        run = stream(link(), coefficients, view="127.0.0.1:0").write(tmp_path / "a.csv")
    finally:
        stuck.close()
    assert run.interrupted and run.counts["frames"] == 2000 and len(made) < 20
    assert threading.enumerate() == before and _released(address["port"])


@pytest.mark.parametrize("bad", ["nowhere", "localhost:65536", ":8765", "127.0.0.1:x", "1:-1"])
def test_a_bad_view_is_one_line_exit_2_and_nothing_written(tmp_path, coefficients, capsys, bad):  # noqa: F811
    frames = tmp_path / "frames.bin"
    frames.write_bytes(b"".join(_chunks(Protocol(3), 5)))
    out = tmp_path / "a.csv"
    assert main(["stream", str(frames), str(coefficients), "-o", str(out), "--view", bad]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and ": error: --view: expected HOST:PORT" in err
    assert not out.exists()
    with pytest.raises(Exception, match="--view"):
        view_address(bad)


def test_a_port_in_use_is_refused_before_anything_is_written(
    tmp_path,
    coefficients,  # noqa: F811
    capsys,
    monkeypatch,
):
    monkeypatch.setattr("reflector_opt.report._view3d.live_page", lambda *a: PAGE)
    frames = tmp_path / "frames.bin"
    frames.write_bytes(b"".join(_chunks(Protocol(3), 5)))
    out = tmp_path / "a.csv"
    with socket.create_server(("127.0.0.1", 0)) as taken:
        view = f"127.0.0.1:{taken.getsockname()[1]}"
        assert main(["stream", str(frames), str(coefficients), "-o", str(out), "--view", view]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"--view: cannot listen on {view}" in err
    assert not out.exists()
