"""Random streams of a run: one seed, named children spawned by numpy's ``SeedSequence``.

A run has one seed. An independent random draw (a unit drawn from the identification's
model, a unit's calibrations at several temperatures, …) takes a generator of its own
**stream**, a child of
``numpy.random.SeedSequence(seed)`` named in :data:`STREAMS`, and within a stream one child
per unit index: the generator of stream ``name`` for unit ``i`` is the one of
``SeedSequence(seed).spawn(k + 1)[k].spawn(i + 1)[i]``, ``k`` the stream's place in
:data:`STREAMS`. Children of a ``SeedSequence`` are independent by construction (numpy's
seeding guarantees distinct, well-mixed states), so no stream needs a hand-picked salt such
as ``[seed, index, 11]`` to stay apart from another, and adding a stream at the end of
:data:`STREAMS` changes no other stream's draws.

The child is built from its spawn key directly (``SeedSequence(seed, spawn_key=(k, i))``,
the same sequence ``spawn`` returns) so that unit 100,000 costs no more than unit 0.
"""

import numpy as np

from reflector_opt.util._errors import InputError

#: The named streams of a run's seed, in spawn order (append only: a stream's place is its
#: spawn index, so inserting one would change the draws of those after it).
STREAMS = (
    "model_unit",  # a unit made by the identification's model (asbuilt.modelunit)
    "thermal_plan",  # a unit's calibration at several temperatures (tolerance.thermalplan)
    "thermal_truth_poses",  # its validation poses in use
    "thermal_truth_noise",  # the noise of its validation readings
    "reference_poses",  # the poses a design's calibration plans are compared on
    "tolerance_draw",  # a sample's tolerances (tolerance.tolerances.draw_sample), built units too
    "built_surface",  # a built unit's specular fraction when no batch surface is given
    "built_protocol",  # a built unit's calibration and validation (tolerance.builtunit)
    "batch_calibration",  # a batch forecast's calibration of each unit (asbuilt.batchforecast)
    "segment_motion",  # the noise of a segment's motion, one child per axis (calibration.segment)
    "batch_surface",  # a print batch's shared surface, one child per batch (benchmarks)
    "random_design",  # a random design of the search space, children (part, index) (benchmarks)
)


def stream_seed(seed, stream, *indices):
    """The ``SeedSequence`` of one stream of a run (and of one unit in it).

    Parameters
    ----------
    seed : int
        The run's seed (≥ 0).
    stream : str
        One of :data:`STREAMS`.
    *indices : int
        Further children, e.g. the unit's index (≥ 0 each).

    Returns
    -------
    numpy.random.SeedSequence
        The child ``SeedSequence(seed).spawn(…)[k]`` (then ``.spawn(…)[i]`` per index).
    """
    if stream not in STREAMS:
        raise InputError(f"stream: expected one of {', '.join(STREAMS)}, got {stream!r}")
    key = (STREAMS.index(stream), *(int(i) for i in indices))
    if isinstance(seed, bool) or int(seed) != seed or seed < 0 or min(key) < 0:
        raise InputError(f"seed: expected a whole number ≥ 0, got {seed!r} (indices {indices})")
    return np.random.SeedSequence(int(seed), spawn_key=key)


def stream_rng(seed, stream, *indices):
    """A generator of one stream of a run (:func:`stream_seed`).

    Parameters
    ----------
    seed : int
        The run's seed (≥ 0).
    stream : str
        One of :data:`STREAMS`.
    *indices : int
        Further children, e.g. the unit's index.

    Returns
    -------
    numpy.random.Generator
    """
    return np.random.default_rng(stream_seed(seed, stream, *indices))
