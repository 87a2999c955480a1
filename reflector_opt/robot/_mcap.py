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
"""

from __future__ import annotations

import numpy as np
from mcap_ros2.writer import Writer

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
    p, r = np.radians(pitch_deg) / 2, np.radians(roll_deg) / 2
    cp, sp, cr, sr = np.cos(p), np.sin(p), np.cos(r), np.sin(r)
    return np.stack([sr * cp, cr * sp, sr * sp, cr * cp], axis=-1)


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
        self._writer = Writer(self._file)
        self._schemas = {k: self._writer.register_msgdef(k, v) for k, v in SCHEMAS.items()}
        self.frames = [f"unit{u}" for u in units]
        self.names = [f"{frame}_{a}" for frame in self.frames for a in ("pitch", "roll")]
        self.link_m = link_length_mm / 1000

    def write(self, shape, time_ns):
        """Write a block's frames (an :class:`~reflector_opt.calibration._unit_calibration.
        EstimatedShape` keyed by counter), received at ``time_ns``."""
        stamp = {"sec": time_ns // 10**9, "nanosec": time_ns % 10**9}
        quaternions = unit_quaternion(shape.angles_deg[..., 0], shape.angles_deg[..., 1])
        parents = ["base", *self.frames]
        for counter, angles, rotations in zip(
            shape.instants, shape.angles_deg, quaternions, strict=True
        ):
            joints = {
                "header": {"stamp": stamp, "frame_id": "base"},
                "name": self.names,
                "position": np.radians(angles).ravel().tolist(),
                "velocity": [],
                "effort": [],
            }
            transforms = [
                {
                    "header": {"stamp": stamp, "frame_id": parent},
                    "child_frame_id": child,
                    "transform": {
                        "translation": {"x": 0.0, "y": 0.0, "z": 0.0 if j == 0 else self.link_m},
                        "rotation": dict(zip("xyzw", map(float, q), strict=True)),
                    },
                }
                for j, (parent, child, q) in enumerate(
                    zip(parents, [*self.frames, "tip"], [*rotations, (0, 0, 0, 1)], strict=True)
                )
            ]
            for topic, schema, message in (
                ("/joint_states", "sensor_msgs/msg/JointState", joints),
                ("/tf", "tf2_msgs/msg/TFMessage", {"transforms": transforms}),
            ):
                self._writer.write_message(
                    topic, self._schemas[schema], message, time_ns, sequence=int(counter)
                )
        self._writer._writer.flush()  # the block as a chunk on disk: a kill keeps it

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
