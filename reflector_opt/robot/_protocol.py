"""The device protocol: frames of a unit's readings, as text lines or checksummed binary.

A frame holds a sample counter (0 … 65535, wrapping), each unit's readings (one per sensor:
volts, or raw ADC codes with the ADC's bits and reference, V = code · Vref / 2^bits as
:func:`reflector_opt.model._noise.quantise` reads them) and, optionally, one temperature per
unit (°C). Both forms are laid out in docs/robot.md:

* **text**, one line per frame: ``counter,r11,r12,…,rN1,rN2[,t1,…,tN]`` (unit by unit, then
  the temperatures), ``\\n`` ended; volts with 6 decimals, codes as integers, °C with 2;
* **binary**, little-endian: the sync word ``A5 5A``, the counter (uint16), the readings
  (float32 V or uint16 codes), the temperatures (int16, 0.01 °C) and a CRC-16/CCITT-FALSE
  (poly 0x1021, init 0xFFFF: :func:`binascii.crc_hqx`) of everything after the sync word.

:class:`Decoder` takes bytes as they arrive and returns the frames they complete. It never
raises on a bad frame: each fault is named and counted in :attr:`Decoder.faults`
(:data:`FAULTS`). The transports (:func:`open_link`) are thin: each gives the bytes as they
arrive.
"""

import binascii
import errno
import os
import socket
import struct
import sys
from dataclasses import dataclass

import numpy as np

from reflector_opt.util._errors import InputError

#: The binary frame's first two bytes.
SYNC = b"\xa5\x5a"

#: The counter's modulus: it wraps from 65535 to 0.
COUNTER_MODULUS = 1 << 16

#: The faults a decoder counts: a binary frame whose checksum fails; a text line that does not
#: parse; frames missing by the counter (its gap, modulo 65536); a counter that went back (a
#: device restarted, or frames reordered); an incomplete frame at the end of the stream; the
#: link lost (EOF is not a fault; EIO, a device unplugged, is).
FAULTS = ("checksum", "text", "dropped", "reordered", "truncated", "unplugged")


@dataclass(frozen=True)
class Frame:
    """One sample of every unit.

    Attributes
    ----------
    counter : int
        Sample counter, 0 … 65535.
    readings : numpy.ndarray
        Shape (n_units, n_sensors): V, or ADC codes (integers).
    temperature_c : numpy.ndarray or None
        Shape (n_units,), °C.
    """

    counter: int
    readings: np.ndarray
    temperature_c: np.ndarray | None = None


@dataclass(frozen=True)
class Protocol:
    """The layout both ends agree on: units, sensors, readings and temperature, and the form.

    Parameters
    ----------
    n_units : int
        Units per frame, base first.
    n_sensors : int
        Readings per unit (the design's sensors).
    temperature : bool
        Whether each unit sends a temperature.
    adc_bits : int or None
        None: readings in volts; else raw codes of an ADC of this many bits (1 … 16).
    adc_reference_v : float
        The ADC's reference, V (codes only).
    form : {"binary", "text"}
    """

    n_units: int
    n_sensors: int = 2
    temperature: bool = False
    adc_bits: int | None = None
    adc_reference_v: float = 3.3
    form: str = "binary"

    def __post_init__(self):
        if self.form not in ("binary", "text"):
            raise InputError(f"form: 'binary' or 'text', got {self.form!r}")
        for key in ("n_units", "n_sensors"):
            if not 1 <= getattr(self, key) <= 64:
                raise InputError(f"{key}: 1 to 64, got {getattr(self, key)}")
        if self.adc_bits is not None and not 1 <= self.adc_bits <= 16:
            raise InputError(f"adc_bits: 1 to 16 (uint16 codes), got {self.adc_bits}")

    @property
    def _layout(self):
        """struct layout of the binary frame after the sync word, checksum excluded."""
        reading = "f" if self.adc_bits is None else "H"
        return struct.Struct(
            f"<H{self.n_units * self.n_sensors}{reading}{self.n_units * self.temperature}h"
        )

    @property
    def frame_bytes(self):
        """Bytes of one binary frame: sync word, payload, checksum."""
        return len(SYNC) + self._layout.size + 2

    def volts(self, frame):
        """A frame's readings in volts, shape (n_units, n_sensors)."""
        readings = np.asarray(frame.readings, dtype=float)
        return (
            readings
            if self.adc_bits is None
            else readings * self.adc_reference_v / 2**self.adc_bits
        )

    def encode(self, frame):
        """The frame as bytes in this protocol's form.

        Parameters
        ----------
        frame : Frame

        Returns
        -------
        bytes
        """
        readings = np.asarray(frame.readings).reshape(-1)
        temps = [] if not self.temperature else np.asarray(frame.temperature_c).reshape(-1)
        counter = frame.counter % COUNTER_MODULUS
        if self.form == "text":
            shown = (f"{r:.6f}" if self.adc_bits is None else str(int(r)) for r in readings)
            return ",".join([str(counter), *shown, *(f"{t:.2f}" for t in temps)]).encode() + b"\n"
        values = readings.tolist() if self.adc_bits is None else [int(r) for r in readings]
        payload = self._layout.pack(counter, *values, *(round(t * 100) for t in temps))
        return SYNC + payload + struct.pack("<H", binascii.crc_hqx(payload, 0xFFFF))

    def decoder(self):
        """A new :class:`Decoder` of this protocol."""
        return Decoder(self)


class Decoder:
    """Frames from bytes as they arrive; each fault named and counted, never raised.

    Parameters
    ----------
    protocol : reflector_opt.robot._protocol.Protocol

    Attributes
    ----------
    faults : dict
        Count of each fault of :data:`FAULTS`.
    frames : int
        Frames decoded.
    """

    #: A text line longer than this without a newline is garbage, bytes.
    MAX_LINE = 4096

    def __init__(self, protocol):
        self.protocol = protocol
        self.faults = dict.fromkeys(FAULTS, 0)
        self.frames = 0
        self._buffer = bytearray()
        self._last = None

    def feed(self, data):
        """Decode what ``data`` completes.

        Parameters
        ----------
        data : bytes

        Returns
        -------
        list of Frame
            The frames completed, in order.
        """
        self._buffer += data
        parse = self._text if self.protocol.form == "text" else self._binary
        return [self._counted(frame) for frame in parse()]

    def close(self):
        """The end of the stream: an incomplete frame left is counted ``truncated``."""
        if self._buffer.strip(b"\r\n") if self.protocol.form == "text" else self._buffer:
            self.faults["truncated"] += 1
        self._buffer.clear()

    def read(self, chunks):
        """Frames from an iterable of byte chunks (:func:`open_link`) until it ends.

        An ``OSError`` from the link (EIO: the device unplugged) ends it, counted
        ``unplugged``; either way the decoder is closed (:meth:`close`). A reader that stops
        early (or is interrupted) leaves what is unread uncounted.

        Yields
        ------
        Frame
        """
        for frames in self.blocks(chunks):
            yield from frames

    def blocks(self, chunks):
        """As :meth:`read`, the frames each chunk completes as one list (maybe empty): those
        that arrived together."""
        try:
            for chunk in chunks:
                yield self.feed(chunk)
        except OSError:
            self.faults["unplugged"] += 1
        self.close()

    def _counted(self, frame):
        if self._last is not None:
            gap = (frame.counter - self._last - 1) % COUNTER_MODULUS
            if gap >= COUNTER_MODULUS // 2:
                self.faults["reordered"] += 1
            else:
                self.faults["dropped"] += gap
        self._last = frame.counter
        self.frames += 1
        return frame

    def _binary(self):
        protocol, buffer = self.protocol, self._buffer
        size, layout = protocol.frame_bytes, protocol._layout
        while True:
            start = buffer.find(SYNC)
            if start < 0:  # keep a last byte that may begin the sync word
                del buffer[: max(len(buffer) - 1, 0)]
                return
            del buffer[:start]
            if len(buffer) < size:
                return
            payload = bytes(buffer[len(SYNC) : size - 2])
            if struct.unpack("<H", buffer[size - 2 : size])[0] != binascii.crc_hqx(payload, 0xFFFF):
                self.faults["checksum"] += 1
                del buffer[:1]  # look for the next sync word within
                continue
            del buffer[:size]
            yield self._frame(layout.unpack(payload))

    def _text(self):
        buffer = self._buffer
        while (end := buffer.find(b"\n")) >= 0 or len(buffer) > self.MAX_LINE:
            line = bytes(buffer[: end if end >= 0 else len(buffer)]).strip()
            del buffer[: end + 1 if end >= 0 else len(buffer)]
            if not line:
                continue
            try:
                yield self._frame(self._fields(line))
            except ValueError:
                self.faults["text"] += 1

    def _fields(self, line):
        """The numbers of a text line, as :meth:`Protocol._layout` unpacks them; ValueError
        for a line that is not a frame."""
        p = self.protocol
        fields = line.decode("ascii").split(",")
        n_readings = p.n_units * p.n_sensors
        if len(fields) != 1 + n_readings + p.n_units * p.temperature:
            raise ValueError(line)
        counter = int(fields[0])
        read = float if p.adc_bits is None else int
        values = [read(f) for f in fields[1 : 1 + n_readings]]
        temps = [round(float(f) * 100) for f in fields[1 + n_readings :]]
        codes = p.adc_bits is None or all(0 <= v < 2**p.adc_bits for v in values)
        if not (0 <= counter < COUNTER_MODULUS and codes and np.isfinite(values).all()):
            raise ValueError(line)
        return (counter, *values, *temps)

    def _frame(self, numbers):
        """A :class:`Frame` of the numbers in the binary layout's order."""
        p = self.protocol
        n_readings = p.n_units * p.n_sensors
        readings = np.array(numbers[1 : 1 + n_readings], dtype=float).reshape(p.n_units, -1)
        temps = np.array(numbers[1 + n_readings :], dtype=float) / 100 if p.temperature else None
        return Frame(int(numbers[0]), readings, temps)


def open_link(address, *, baud=115200, chunk_bytes=4096):
    """The bytes a device sends, as they arrive, from a serial port, UDP or a file or pipe.

    Parameters
    ----------
    address : str
        ``serial:PORT`` (pyserial, the ``robot`` extra; e.g. ``serial:/dev/ttyACM0``),
        ``udp:HOST:PORT`` (bound and listened on), ``-`` (standard input) or a file, FIFO or
        pseudo-terminal path.
    baud : int
        The serial port's rate, Bd.
    chunk_bytes : int
        The most read at once.

    Returns
    -------
    iterator of bytes
        Ends at EOF; raises ``OSError`` when the link is lost (:meth:`Decoder.read` counts it).

    Raises
    ------
    InputError
        A link that cannot be opened (named), or pyserial missing.
    """
    kind, _, rest = address.partition(":")
    try:
        if kind == "serial":
            try:
                import serial
            except ImportError:
                raise InputError(
                    "serial: pyserial is not installed (pip install 'reflector-opt[robot]')"
                ) from None
            if baud not in serial.Serial.BAUDRATES:
                raise InputError(f"baud: {baud} is not a standard rate")
            port = serial.Serial(rest, baud, timeout=0.1)
            return _chunks(lambda: port.read(port.in_waiting or 1) or None, port.close)
        if kind == "udp":
            host, _, number = rest.rpartition(":")
            sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            sock.bind((host or "0.0.0.0", int(number)))
            return _chunks(lambda: sock.recv(65535) or None, sock.close)
        fd = sys.stdin.fileno() if address == "-" else os.open(address, os.O_RDONLY | os.O_NOCTTY)
        return _chunks(lambda: os.read(fd, chunk_bytes), lambda: address == "-" or os.close(fd))
    except (OSError, ValueError) as exc:
        if isinstance(exc, InputError):
            raise
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else exc
        raise InputError(f"{address}: cannot open ({reason})") from None


def _chunks(read, close):
    """Chunks of ``read()`` until it returns b"" (EOF); None is "nothing yet". A pseudo-terminal
    whose other end closed reads EIO: the link lost, raised as OSError."""
    try:
        while (data := read()) != b"":
            if data:
                yield data
    except OSError as exc:
        raise OSError(errno.EIO, f"link lost ({exc})") from exc
    finally:
        close()
