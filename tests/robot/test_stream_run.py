"""``reflector-opt stream`` (reflector_opt.workflow._stream): the virtual device's frames, fed
the independent truth, through a file to the angles CSV and the MCAP log, against ``estimate``
on the same voltages; faults, a stream faster than the estimator, bounds and Ctrl-C."""

import csv
import io
import json
import os
import threading

import numpy as np
import pytest
from mcap.exceptions import EndOfFile
from mcap.reader import make_reader
from mcap.records import Message
from mcap.stream_reader import StreamReader
from mcap_ros2.decoder import DecoderFactory

from reflector_opt.calibration import Eq6
from reflector_opt.calibration._segment import tip_pose
from reflector_opt.calibration._unit_calibration import save_calibrations
from reflector_opt.cli import main
from reflector_opt.robot import Protocol, VirtualDevice
from reflector_opt.robot._protocol import Frame
from reflector_opt.workflow._estimate import estimate
from reflector_opt.workflow._stream import stream
from tests.robot.test_stream import _calibrations
from tests.robot.test_virtual import RATE_HZ, FakeClock, trajectory, truth

NOISE_V = 5e-4
LINK_MM = 18.0


@pytest.fixture
def coefficients(tmp_path):
    path = tmp_path / "coefficients.json"
    save_calibrations(path, _calibrations(Eq6))
    return path


def _chunks(protocol, n, per_chunk=7):
    """The virtual device's n frames of the truth, cut into chunks of ``per_chunk`` frames."""
    clock = FakeClock()
    device = VirtualDevice(protocol, truth, trajectory, RATE_HZ, clock=clock, sleep=clock.sleep)
    frames = []
    device.run(frames.append, n)
    return [b"".join(frames[i : i + per_chunk]) for i in range(0, n, per_chunk)]


def _rows(path):
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))


def _mcap(path):
    with open(path, "rb") as handle:
        return [
            (channel.topic, message.sequence, decoded)
            for _, channel, message, decoded in make_reader(
                handle, decoder_factories=[DecoderFactory()]
            ).iter_decoded_messages()
        ]


def test_stream_gives_estimate_s_angles_and_sigma_and_reads_back_from_mcap(
    tmp_path, coefficients, capsys
):
    """60 binary frames through a file: every angle and 1σ equals ``estimate``'s on a log of the
    same float32 volts (written exactly: 1e-9°); the MCAP's JointState holds the unit names and
    the angles in radians (1e-12), and its TF chain composes to the CSV's tip position
    (1e-9 mm) and to ``tip_pose`` of the truth within 0.5 mm."""
    protocol = Protocol(3)
    frames_file = tmp_path / "frames.bin"
    frames_file.write_bytes(b"".join(_chunks(protocol, 60)))
    out, log = tmp_path / "angles.csv", tmp_path / "angles.mcap"
    argv = ["stream", str(frames_file), str(coefficients), "-o", str(out), "--json"]
    assert main([*argv, "--mcap", str(log), "--noise-v", str(NOISE_V)]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["frames"] == 60 and summary["stopped"] == "end"
    assert set(summary["faults"].values()) == {0}

    volts = tmp_path / "log.csv"
    decoded = protocol.decoder().feed(frames_file.read_bytes())
    with open(volts, "w") as handle:
        handle.write("sample,unit,v1,v2\n")
        for f in decoded:
            for j, (v1, v2) in enumerate(f.readings):
                handle.write(f"{f.counter},{j + 1},{float(v1)!r},{float(v2)!r}\n")
    expected = estimate(str(coefficients), volts, noise_v=NOISE_V).write(tmp_path / "e.csv")
    rows, reference = _rows(out), _rows(expected.output)
    assert len(rows) == len(reference) == 60 and "3_roll_sigma_deg" in reference[0]
    for row, ref in zip(rows, reference, strict=True):
        assert row["counter"] == ref["sample"]
        keys = [k for k in ref if k != "sample"]
        np.testing.assert_allclose(
            [float(row[k]) for k in keys], [float(ref[k]) for k in keys], rtol=0, atol=1e-9
        )

    messages = _mcap(log)
    joints = [m for t, _, m in messages if t == "/joint_states"]
    transforms = [m for t, _, m in messages if t == "/tf"]
    assert len(joints) == len(transforms) == 60
    assert list(joints[0].name) == [f"unit{j}_{a}" for j in (1, 2, 3) for a in ("pitch", "roll")]
    for row, joint, tf in zip(rows, joints, transforms, strict=True):
        degrees = [float(row[f"{j}_{a}_deg"]) for j in (1, 2, 3) for a in ("pitch", "roll")]
        np.testing.assert_allclose(joint.position, np.radians(degrees), rtol=0, atol=1e-12)
        chain = [(t.header.frame_id, t.child_frame_id) for t in tf.transforms]
        assert chain == [
            ("base", "unit1"),
            ("unit1", "unit2"),
            ("unit2", "unit3"),
            ("unit3", "tip"),
        ]
        position = _compose(tf.transforms) * 1000  # m → mm
        tip = [float(row[f"tip_{x}_mm"]) for x in "xyz"]
        np.testing.assert_allclose(position, tip, rtol=0, atol=1e-9)
        true = trajectory(int(row["counter"]) / RATE_HZ)
        _, true_tip = tip_pose(true[:, 0], true[:, 1], LINK_MM)
        assert np.abs(position - true_tip).max() < 0.5


def _compose(transforms):
    """The last frame's origin in the base frame, m, by quaternion rotations (an independent
    path to ``tip_pose``: q v q*)."""
    rotation, position = np.eye(3), np.zeros(3)
    for t in transforms:
        shift, q = t.transform.translation, t.transform.rotation
        position = position + rotation @ [shift.x, shift.y, shift.z]
        x, y, z, w = q.x, q.y, q.z, q.w
        rotation = rotation @ np.array(
            [
                [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
            ]
        )
    return position


def test_faults_are_counted_in_the_summary_line_and_the_json(tmp_path, coefficients, capsys):
    """Text frames with one line garbled and two frames lost: ``text`` 1 and ``dropped`` 3 (the
    garbled frame's counter is missing too), said in the line and in ``--json``."""
    protocol = Protocol(3, form="text")
    lines = b"".join(_chunks(protocol, 20)).splitlines(keepends=True)
    lines[5] = b"5,garbled\n"
    del lines[10:12]
    frames_file = tmp_path / "frames.txt"
    frames_file.write_bytes(b"".join(lines))
    argv = ["stream", str(frames_file), str(coefficients), "--form", "text"]
    assert main([*argv, "-o", str(tmp_path / "a.csv")]) == 0
    assert "faults: checksum 0, text 1, dropped 3, reordered 0" in capsys.readouterr().out
    assert main([*argv, "-o", str(tmp_path / "b.csv"), "--json"]) == 0
    faults = json.loads(capsys.readouterr().out)["faults"]
    assert (faults["text"], faults["dropped"], faults["unplugged"]) == (1, 3, 0)
    assert len(_rows(tmp_path / "b.csv")) == 17


def test_a_stream_faster_than_the_estimator_is_said_and_bounded(tmp_path, coefficients):
    """Chunks of 7 frames with ``keep_up=3``: 4 of each 7 skipped and counted, the newest 3
    estimated; the backlog (7) is reported either way."""
    protocol = Protocol(3)
    chunks = _chunks(protocol, 21)
    run = stream(iter(chunks), coefficients, keep_up=3).write(tmp_path / "a.csv")
    assert (run.counts["frames"], run.counts["skipped"], run.counts["max_backlog"]) == (9, 12, 7)
    assert [r["counter"] for r in _rows(tmp_path / "a.csv")][:3] == ["4", "5", "6"]
    assert "up to 7 frame(s) waited at once, 12 skipped" in run.text()
    every = stream(iter(chunks), coefficients).write(tmp_path / "b.csv")
    assert (every.counts["frames"], every.counts["skipped"]) == (21, 0)


def test_bounded_runs_stop_at_max_frames_and_at_the_duration(tmp_path, coefficients):
    """``max_frames=10`` writes exactly 10; ``duration_s`` on a clock that moves 0.1 s a read
    stops once 0.25 s passed (the third read)."""
    chunks = _chunks(Protocol(3), 35)
    run = stream(iter(chunks), coefficients, max_frames=10).write(tmp_path / "a.csv")
    assert run.counts["stopped"] == "max_frames" and len(_rows(tmp_path / "a.csv")) == 10
    clock = FakeClock()

    def ticking():
        for chunk in chunks:
            clock.sleep(0.1)
            yield chunk

    run = stream(ticking(), coefficients, duration_s=0.25, clock=clock).write(tmp_path / "b.csv")
    assert run.counts["stopped"] == "duration" and len(_rows(tmp_path / "b.csv")) == 21


def test_ctrl_c_mid_stream_leaves_the_csv_and_the_mcap_whole(tmp_path, coefficients):
    """Ctrl-C after three chunks: both files close whole, the CSV holds the 21 frames read (no
    torn line) and the MCAP reads back with the same 21 of each message. The files as they
    were on disk at that moment (what a kill would leave) hold the same 21 frames: the CSV in
    whole lines, the MCAP read in order without its index (``mcap.stream_reader``)."""
    chunks = _chunks(Protocol(3), 70)
    out, log = tmp_path / "a.csv", tmp_path / "a.mcap"
    killed = {}

    def interrupted():
        yield from chunks[:3]
        killed.update(csv=out.read_bytes(), mcap=log.read_bytes())
        raise KeyboardInterrupt

    run = stream(interrupted(), coefficients, mcap=str(log)).write(out)
    assert run.interrupted and run.counts["frames"] == 21
    text = out.read_text()
    assert text.endswith("\n") and len(_rows(out)) == 21
    sequences = [s for t, s, _ in _mcap(log) if t == "/joint_states"]
    assert sequences == list(range(21))

    assert killed["csv"] == out.read_bytes()
    messages = []
    with pytest.raises(EndOfFile):  # no footer: the stream ends inside the data section
        for record in StreamReader(io.BytesIO(killed["mcap"])).records:
            messages += [record.sequence] if isinstance(record, Message) else []
    assert messages == sorted(2 * list(range(21)))


def test_bad_input_is_one_line_exit_2_and_nothing_written(tmp_path, coefficients, capsys):
    frames_file = tmp_path / "frames.bin"
    four = Protocol(4)
    frames_file.write_bytes(b"".join(four.encode(Frame(k, np.full((4, 2), 2.3))) for k in range(5)))
    out, log = tmp_path / "a.csv", tmp_path / "a.mcap"
    argv = ["stream", str(frames_file), str(coefficients), "-o", str(out), "--mcap", str(log)]
    assert main([*argv, "--units", "4"]) == 2
    assert "frames: 4 units, but the calibration has 3 (1, 2, 3)" in capsys.readouterr().err
    assert main(["stream", str(tmp_path / "absent"), *argv[2:]]) == 2
    assert "cannot open" in capsys.readouterr().err
    assert not out.exists() and not log.exists()


def test_a_pipe_is_streamed_until_its_writer_closes(tmp_path, coefficients):
    """The virtual device writing into an OS pipe from a thread, ``stream`` reading its path
    (as a FIFO is read): 30 frames, the link's end, no fault."""
    read_end, write_end = os.pipe()
    chunks = _chunks(Protocol(3), 30, per_chunk=1)

    def device():
        for chunk in chunks:
            os.write(write_end, chunk)
        os.close(write_end)

    writer = threading.Thread(target=device)
    writer.start()
    try:
        run = stream(f"/dev/fd/{read_end}", coefficients).write(tmp_path / "a.csv")
    finally:
        writer.join()
        os.close(read_end)
    assert (run.counts["frames"], run.counts["stopped"]) == (30, "end")
    assert set(run.counts["faults"].values()) == {0}
    assert [r["counter"] for r in _rows(tmp_path / "a.csv")] == [str(k) for k in range(30)]


def test_the_mcap_messages_are_the_bytes_of_mcap_ros2_s_encoder(tmp_path):
    """The log's CDR, laid out once and filled per frame (reflector_opt.robot._mcap), is byte
    for byte what mcap-ros2-support's encoder makes of the same two frames' messages
    (``JointState`` of three units, the ``TFMessage`` chain to the tip)."""
    from mcap_ros2.writer import Writer

    from reflector_opt.calibration._unit_calibration import EstimatedShape
    from reflector_opt.robot._mcap import SCHEMAS, McapLog, unit_quaternion

    angles = np.array([[[3.0, -2.0], [1.5, 0.25], [-7.0, 4.0]], [[-1.0, 0.5], [2.0, 0.0], [0, 9]]])
    shape = EstimatedShape("counter", ["9", "10"], ["1", "2", "3"], angles, None, None)
    time_ns = 1_700_000_000_123_456_789
    with McapLog(tmp_path / "ours.mcap", shape.units, LINK_MM) as log:
        log.write(shape, time_ns)

    stamp = {"sec": time_ns // 10**9, "nanosec": time_ns % 10**9}
    frames = [f"unit{u}" for u in shape.units]
    with open(tmp_path / "theirs.mcap", "wb") as handle:
        writer = Writer(handle)
        schemas = {k: writer.register_msgdef(k, v) for k, v in SCHEMAS.items()}
        for counter, unit_angles in zip(shape.instants, angles, strict=True):
            joints = {
                "header": {"stamp": stamp, "frame_id": "base"},
                "name": [f"{f}_{a}" for f in frames for a in ("pitch", "roll")],
                "position": np.radians(unit_angles).ravel().tolist(),
                "velocity": [],
                "effort": [],
            }
            rotations = [*unit_quaternion(unit_angles[:, 0], unit_angles[:, 1]), (0, 0, 0, 1)]
            transforms = [
                {
                    "header": {"stamp": stamp, "frame_id": parent},
                    "child_frame_id": child,
                    "transform": {
                        "translation": {"x": 0.0, "y": 0.0, "z": 0.0 if j == 0 else LINK_MM / 1e3},
                        "rotation": dict(zip("xyzw", map(float, q), strict=True)),
                    },
                }
                for j, (parent, child, q) in enumerate(
                    zip(["base", *frames], [*frames, "tip"], rotations, strict=True)
                )
            ]
            for topic, schema, message in (
                ("/joint_states", "sensor_msgs/msg/JointState", joints),
                ("/tf", "tf2_msgs/msg/TFMessage", {"transforms": transforms}),
            ):
                writer.write_message(
                    topic, schemas[schema], message, time_ns, sequence=int(counter)
                )
        writer.finish()

    def messages(path):
        with open(path, "rb") as handle:
            return [
                (channel.topic, message.sequence, message.log_time, message.data)
                for _, channel, message in make_reader(handle).iter_messages()
            ]

    ours, theirs = messages(tmp_path / "ours.mcap"), messages(tmp_path / "theirs.mcap")
    assert len(ours) == 4 and ours == theirs
