"""Live angles as an MCAP log with ROS 2 schemas, which Foxglove and ``ros2 bag`` read.

Two topics (the ``mcap`` and ``mcap-ros2-support`` packages, the ``robot`` extra):

* ``/joint_states``, ``sensor_msgs/msg/JointState``: ``unit{label}_pitch`` and
  ``unit{label}_roll`` per unit, base first, position in radians (velocity and effort empty);
* ``/tf``, ``tf2_msgs/msg/TFMessage``: the chain ``base`` → ``unit{first}`` → … →
  ``unit{last}`` → ``tip``, each unit's frame rotated Rx(roll)·Ry(pitch) about its centre
  (:func:`~reflector_opt.calibration._segment.tip_pose`'s convention), one link length along
  its parent's z axis (none for the base unit), the tip one link along the last unit's z;
  translations in metres, as ROS wants.

Each message is stamped with the time its frame was received (ns since the epoch). Each block
is flushed to the file as a chunk of its own (mcap's ``Writer.flush``), so a killed run leaves
every block written before it readable in order (``mcap.stream_reader``; ``mcap recover``
rebuilds the index), where a closed one is whole.

The messages are encoded here, not by ``mcap-ros2-support``'s encoder (which walks the
message definition field by field, most of a live frame's cost): each topic's CDR bytes (ROS 2's
little-endian XCDR1, each number aligned to its size after the 4-byte encapsulation header)
are laid out once with their constant fields (names, frame ids, translations) and a frame's
numbers written into them at their offsets (:class:`Cdr`); tests/robot/test_stream_run.py
checks them byte for byte against that encoder and reads them back with its decoder.
"""

import struct

import numpy as np
from mcap.writer import CompressionType, Writer

from reflector_opt.model._geometry import pose_trig

_RULE = "=" * 80 + "\n"
_HEADER = (
    f"{_RULE}MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n"
    f"{_RULE}MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"
)
#: The message definitions, with their dependencies, as ROS 2 writes them into a bag.
SCHEMAS = {
    "sensor_msgs/msg/JointState": "std_msgs/Header header\nstring[] name\nfloat64[] position\n"
    "float64[] velocity\nfloat64[] effort\n" + _HEADER,
    "tf2_msgs/msg/TFMessage": f"geometry_msgs/TransformStamped[] transforms\n{_RULE}"
    "MSG: geometry_msgs/TransformStamped\nstd_msgs/Header header\nstring child_frame_id\n"
    f"geometry_msgs/Transform transform\n{_RULE}MSG: geometry_msgs/Transform\n"
    f"geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation\n{_RULE}"
    f"MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n{_RULE}"
    "MSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w\n" + _HEADER,
}


def unit_quaternion(pitch_deg, roll_deg):
    """Rx(roll)·Ry(pitch) as a quaternion (x, y, z, w), shape P + (4,).

    q = (cos r/2, sin r/2 x̂) ⊗ (cos p/2, sin p/2 ŷ) = (sr·cp, cr·sp, sr·sp, cr·cp), with
    r, p the half angles' sines s and cosines c.
    """
    cp, sp, cr, sr = pose_trig(np.multiply(pitch_deg, 0.5), np.multiply(roll_deg, 0.5))
    q = np.empty((*np.shape(cr * cp), 4))
    q[..., 0], q[..., 1], q[..., 2], q[..., 3] = sr * cp, cr * sp, sr * sp, cr * cp
    return q


class Cdr:
    """A ROS 2 message's CDR bytes laid out once (module notes): :meth:`put` appends numbers,
    :meth:`string` a string; :meth:`filled` is a copy with a frame's numbers in the slots."""

    def __init__(self):
        self.data = bytearray(b"\x00\x01\x00\x00")  # CDR_LE encapsulation, options 0
        self.slots = []

    def put(self, code, *values, slot=False):
        """Append ``values`` packed as ``code`` (one struct type, e.g. ``"4d"``), aligned to
        its size; a ``slot`` is where :meth:`filled` writes a frame's values."""
        self.data += bytes(-(len(self.data) - 4) % struct.calcsize(code[-1]))
        if slot:
            self.slots.append((struct.Struct(f"<{code}"), len(self.data)))
        self.data += struct.pack(f"<{code}", *values)

    def string(self, text):
        """Append a string: its length with the terminating NUL, its UTF-8 bytes, NUL."""
        raw = text.encode() + b"\0"
        self.put("I", len(raw))
        self.data += raw

    def filled(self, *values):
        """The message's bytes with each slot's ``values`` (a sequence each), in order."""
        data = bytearray(self.data)
        for (layout, offset), numbers in zip(self.slots, values, strict=True):
            layout.pack_into(data, offset, *numbers)
        return bytes(data)


def joint_state(names):
    """A ``sensor_msgs/msg/JointState``'s :class:`Cdr`, frame ``base``: slots the stamp (s,
    ns) and the positions."""
    cdr = Cdr()
    cdr.put("iI", 0, 0, slot=True)
    cdr.string("base")
    cdr.put("I", len(names))
    for name in names:
        cdr.string(name)
    cdr.put("I", len(names))
    cdr.put(f"{len(names)}d", *[0.0] * len(names), slot=True)
    cdr.put("2I", 0, 0)  # velocity and effort: empty
    return cdr


def tf_message(frames, link_m):
    """A ``tf2_msgs/msg/TFMessage``'s :class:`Cdr` of the chain (module notes): slots each
    transform's stamp and, but the tip's, its rotation (x, y, z, w)."""
    cdr, parents = Cdr(), ["base", *frames]
    cdr.put("I", len(parents))
    for j, (parent, child) in enumerate(zip(parents, [*frames, "tip"], strict=True)):
        cdr.put("iI", 0, 0, slot=True)
        cdr.string(parent)
        cdr.string(child)
        cdr.put("3d", 0.0, 0.0, 0.0 if j == 0 else link_m)
        cdr.put("4d", 0.0, 0.0, 0.0, 1.0, slot=j < len(frames))
    return cdr


class McapLog:
    """An MCAP file of live angles (module notes); a context manager that closes it whole.

    Parameters
    ----------
    path : str or pathlib.Path
    units : list of str
        The units' labels, base first.
    link_length_mm : float
        Distance between the units' rotation centres, mm.
    """

    def __init__(self, path, units, link_length_mm):
        self._file = open(path, "wb")
        self._writer = Writer(self._file, compression=CompressionType.NONE)
        self._writer.start(profile="ros2")
        self.frames = [f"unit{u}" for u in units]
        self.names = [f"{frame}_{a}" for frame in self.frames for a in ("pitch", "roll")]
        self.link_m = link_length_mm / 1000
        self._messages = {}
        for topic, schema, cdr in (
            ("/joint_states", "sensor_msgs/msg/JointState", joint_state(self.names)),
            ("/tf", "tf2_msgs/msg/TFMessage", tf_message(self.frames, self.link_m)),
        ):
            schema_id = self._writer.register_schema(schema, "ros2msg", SCHEMAS[schema].encode())
            self._messages[topic] = (self._writer.register_channel(topic, "cdr", schema_id), cdr)

    def write(self, shape, time_ns):
        """Write a block's frames (an :class:`~reflector_opt.calibration._unit_calibration.
        EstimatedShape` keyed by counter), received at ``time_ns``."""
        stamp = (time_ns // 10**9, time_ns % 10**9)
        quaternions = unit_quaternion(shape.angles_deg[..., 0], shape.angles_deg[..., 1])
        positions = np.radians(shape.angles_deg).reshape(len(shape.instants), -1).tolist()
        (joints, joint_cdr), (tf, tf_cdr) = self._messages.values()
        for counter, position, rotations in zip(
            shape.instants, positions, quaternions.tolist(), strict=True
        ):
            chain = [x for q in rotations for x in (stamp, q)]
            for channel, data in (
                (joints, joint_cdr.filled(stamp, position)),
                (tf, tf_cdr.filled(*chain, stamp)),
            ):
                self._writer.add_message(channel, time_ns, data, time_ns, sequence=int(counter))
        self._writer.flush()  # the block as a chunk on disk: a kill keeps it

    def close(self):
        """Write the summary and close the file."""
        try:
            self._writer.finish()
        finally:
            self._file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
