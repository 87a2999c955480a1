"""The live view of ``reflector-opt stream --view HOST:PORT``: the segment's newest shape, pushed
over a WebSocket to the 3D view in a browser.

One thread serves ``http://HOST:PORT/`` (the page,
:func:`reflector_opt.report._view3d.live_page`) and the WebSocket at :data:`PATH`
(``websockets.sync.server``, one more thread per client). The stream loop only hands the
newest :class:`~reflector_opt.calibration._unit_calibration.EstimatedShape` over
(:meth:`LiveView.show`, one assignment): each client's thread sends the newest shape it has not
sent yet, at most :data:`UPDATES_PER_S` a second, and drops the ones between, so a slow or gone
browser never blocks or queues anything inside the stream. Leaving the ``with`` (the stream's
end, Ctrl-C, a fault) closes the listening socket and every client's, and joins the threads.
"""

import json
import logging
import socket
import threading

import numpy as np

from reflector_opt.calibration._segment import unit_rotation
from reflector_opt.util._errors import InputError

_log = logging.getLogger(__name__)

#: The WebSocket's path on the page's host.
PATH = "/shape"

#: Most messages a client is sent per second; shapes between are dropped.
UPDATES_PER_S = 30.0


def view_address(text):
    """``--view HOST:PORT`` as (host, port); port 0: any free port.

    Raises
    ------
    InputError
        Not a host, a colon and a port from 0 to 65535.
    """
    host, _, port = str(text).rpartition(":")
    if not (host.strip("[]") and port.isdigit() and int(port) <= 65535):
        raise InputError(f"--view: expected HOST:PORT with a port from 0 to 65535, got {text!r}")
    return host.strip("[]"), int(port)


def shape_message(shape):
    """A shape's newest instant as the page's JSON message, or None where an angle is not finite.

    Parameters
    ----------
    shape : EstimatedShape

    Returns
    -------
    str or None
        ``counter``, ``angles_deg`` (per unit: pitch, roll, degrees), ``rotations`` (each unit's
        R = Rx(roll)·Ry(pitch), paper Eq 1) and ``tip_mm`` (the stream's tip position, or null).
    """
    angles = shape.angles_deg[-1]
    if not np.isfinite(angles).all():
        return None
    tip = None if shape.tip_position_mm is None else shape.tip_position_mm[-1].tolist()
    message = {
        "counter": shape.instants[-1],
        "angles_deg": angles.tolist(),
        "rotations": unit_rotation(angles[:, 0], angles[:, 1]).tolist(),
        "tip_mm": tip,
    }
    return json.dumps(message)


class LiveView:
    """The page and the newest shape, served while in a ``with``.

    Parameters
    ----------
    address : str
        ``HOST:PORT`` (:func:`view_address`).
    page : str
        The page served at ``/``.

    Attributes
    ----------
    address : (str, int)
        Where it listens, the chosen port once entered; logged (the command shows it on stderr).
    newest : EstimatedShape or None
        The shape the clients are sent next.
    """

    def __init__(self, address, page):
        self.address, self.page = view_address(address), page
        self.newest, self._clients = None, {}
        self._closing = threading.Event()

    def __enter__(self):
        from websockets.sync.server import serve

        try:
            self._server = serve(
                self._client, *self.address, process_request=self._http, compression=None
            )
        except OSError as exc:
            host, port = self.address
            raise InputError(f"--view: cannot listen on {host}:{port}: {exc.strerror}") from None
        self.address = self._server.socket.getsockname()[:2]
        self._thread = threading.Thread(target=self._server.serve_forever, name="live view")
        self._thread.start()
        _log.info("live view: http://%s:%s/", *self.address)
        return self

    def show(self, shape):
        """Make ``shape`` the newest (the stream loop's one call: no I/O, no wait)."""
        self.newest = shape

    def __exit__(self, *exc):
        self._closing.set()
        for connection in list(self._clients):  # first: a send blocked on a client unblocks
            try:
                connection.socket.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass
        self._server.shutdown()
        self._thread.join()
        for thread in list(self._clients.values()):
            thread.join()

    def _http(self, connection, request):
        if request.path == PATH:
            return None  # the WebSocket's handshake
        pages = {"/": (200, self.page), "/favicon.ico": (204, "")}  # no icon, and no 404 said
        response = connection.respond(*pages.get(request.path, (404, "not found\n")))
        if response.status_code == 200:
            del response.headers["Content-Type"]
            response.headers["Content-Type"] = "text/html; charset=utf-8"
        return response

    def _client(self, connection):
        """One client's thread: the newest shape not yet sent, every 1/UPDATES_PER_S s."""
        from websockets.exceptions import ConnectionClosed

        self._clients[connection] = threading.current_thread()
        shown = None
        try:
            while not self._closing.wait(1 / UPDATES_PER_S):
                shape = self.newest
                message = None if shape is shown else shape_message(shape)
                if message is not None:
                    connection.send(message)
                shown = shape
        except (ConnectionClosed, OSError):
            pass  # the browser went away, or the view closed under a blocked send
