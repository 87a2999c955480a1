"""Random streams of a run: named children of SeedSequence(seed).spawn."""

import numpy as np
import pytest

from reflector_opt.util._errors import InputError
from reflector_opt.util._seeds import STREAMS, stream_rng, stream_seed


def test_a_stream_is_the_spawned_child_of_the_seed():
    """The independent path: numpy's own spawn, stream k then unit i."""
    k = STREAMS.index("thermal_plan")
    spawned = np.random.SeedSequence(42).spawn(k + 1)[k].spawn(8)[7]
    assert stream_seed(42, "thermal_plan", 7).generate_state(4).tolist() == (
        spawned.generate_state(4).tolist()
    )
    expected = np.random.default_rng(spawned).standard_normal(5)
    assert np.array_equal(stream_rng(42, "thermal_plan", 7).standard_normal(5), expected)


def test_streams_units_and_seeds_draw_apart():
    first = [stream_rng(0, name, 0).integers(2**62) for name in STREAMS]
    assert len(set(first)) == len(STREAMS)
    units = [stream_rng(0, "model_unit", i).integers(2**62) for i in range(50)]
    assert len(set(units)) == 50
    assert (
        stream_rng(1, "reference_poses", 3).random() != stream_rng(0, "reference_poses", 3).random()
    )
    assert (
        stream_rng(5, "reference_poses", 3).random() == stream_rng(5, "reference_poses", 3).random()
    )


@pytest.mark.parametrize(
    ("seed", "stream", "indices", "message"),
    [
        (0, "noise", (), "stream: expected one of"),
        (-1, "thermal_plan", (0,), "seed: expected a whole number"),
        (1.5, "thermal_plan", (0,), "seed: expected a whole number"),
        (True, "thermal_plan", (0,), "seed: expected a whole number"),
        (0, "thermal_plan", (-2,), "seed: expected a whole number"),
    ],
)
def test_bad_seeds_and_streams_are_refused(seed, stream, indices, message):
    with pytest.raises(InputError, match=message):
        stream_seed(seed, stream, *indices)


def test_streams_are_only_appended():
    """A stream's place is its spawn index: the streams named before keep their places (and
    their draws) as new ones are added at the end."""
    assert STREAMS[:10] == (
        "model_unit",
        "thermal_plan",
        "thermal_truth_poses",
        "thermal_truth_noise",
        "reference_poses",
        "tolerance_draw",
        "built_surface",
        "built_protocol",
        "batch_calibration",
        "segment_motion",
    )
    assert len(set(STREAMS)) == len(STREAMS)
