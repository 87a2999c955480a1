"""A segment of N units: kinematics to the tip, the paper's validation motions, tip errors.

Unit i rotates about its own centre O_i by R_i = Rx(roll_i)·Ry(pitch_i) (the convention of
Eq 1); the next unit's centre lies one link length along the rotated z axis. With the base
frame at O_1 the tip frame is R_tip = R_1·R_2·…·R_N and the tip point (the centre a unit N+1
would have) is p_tip = L·Σ_i (R_1…R_i)·ẑ. Tip angles are read back as
R_tip = Rx(roll)·Ry(pitch)·Rz(twist).

The paper's validation (Osman et al. 2024, §4.1, Fig. 9, Table I) sweeps the whole segment to
±60° in pure pitch and in pure roll over four cycles, the angle shared equally by the units.
:func:`simulate_segment` runs that motion on the forward model, estimates every unit's pose
from noisy voltages with a fitted calibration model, and compares the estimated tip with the
true one: the error on the moved axis (the Table I quantity), the full orientation error (the
angle of the relative rotation) and the tip position error.
"""

from dataclasses import dataclass

import numpy as np

from reflector_opt.model._geometry import pose_trig
from reflector_opt.util._errors import InputError
from reflector_opt.util._seeds import stream_rng

AXES = ("pitch", "roll")

#: Segment amplitude of the paper's validation motions, degrees.
PAPER_AMPLITUDE_DEG = 60.0

#: Osman et al. (2024) Table I: measured calibration validation error of the 4-unit
#: segment over ±60° (percent error undefined in the paper; RMS and maximum tip error, °).
PAPER_TABLE_I = {
    "pitch": {"percent_error": 0.77, "rms_deg": 2.45, "max_deg": 6.03},
    "roll": {"percent_error": 0.21, "rms_deg": 3.27, "max_deg": 6.86},
}


def unit_rotation(pitch_deg, roll_deg):
    """Rotation of one unit, Rx(roll)·Ry(pitch) (paper Eq 1 convention).

    Parameters
    ----------
    pitch_deg, roll_deg : array_like
        Degrees; broadcast to shape P.

    Returns
    -------
    numpy.ndarray
        Shape ``P + (3, 3)``: ``[[cγ, 0, sγ], [sα·sγ, cα, −sα·cγ], [−cα·sγ, sα, cα·cγ]]``
        with c, s the cosine and sine of pitch γ and roll α, filled entry by entry (the
        product of :func:`~reflector_opt.model._geometry.rotation_x` and ``rotation_y``, the
        same floats, takes twice the small operations: a live frame's cost).
    """
    cp, sp, cr, sr = pose_trig(pitch_deg, roll_deg)
    sr_sp, sr_cp, cr_sp, cr_cp = sr * sp, sr * cp, cr * sp, cr * cp
    r = np.empty((*cr_cp.shape, 3, 3))
    r[..., 0, 0], r[..., 0, 1], r[..., 0, 2] = cp, 0.0, sp
    r[..., 1, 0], r[..., 1, 1], r[..., 1, 2] = sr_sp, cr, -sr_cp
    r[..., 2, 0], r[..., 2, 1], r[..., 2, 2] = -cr_sp, sr, cr_cp
    return r


def tip_pose(pitch_deg, roll_deg, link_length_mm):
    """Forward kinematics of a chain of units.

    Parameters
    ----------
    pitch_deg, roll_deg : array_like
        Shape ``P + (n_units,)``: each unit's pitch and roll, degrees, base unit first.
    link_length_mm : float
        Distance between consecutive rotation centres, mm.

    Returns
    -------
    rotation : numpy.ndarray
        Shape ``P + (3, 3)``: the tip frame in the base frame.
    position_mm : numpy.ndarray
        Shape ``P + (3,)``: the tip point, mm, from the base unit's rotation centre.
    """
    chain = unit_rotation(pitch_deg, roll_deg)  # becomes R_1, R_1·R_2, …, R_1…R_N
    for i in range(1, chain.shape[-3]):
        np.matmul(chain[..., i - 1, :, :], chain[..., i, :, :], out=chain[..., i, :, :])
    return chain[..., -1, :, :], link_length_mm * chain[..., 2].sum(axis=-2)


#: The entries (row-major) of R whose arctan2 are roll and twist: −r12/r22 and −r01/r00.
_SINES, _COSINES = np.array([5, 1]), np.array([8, 0])


def tip_angles(rotation):
    """Pitch, roll and twist of a frame, R = Rx(roll)·Ry(pitch)·Rz(twist).

    Parameters
    ----------
    rotation : array_like
        Shape ``P + (3, 3)``.

    Returns
    -------
    numpy.ndarray
        Shape ``P + (3,)``: pitch, roll, twist in degrees (pitch within ±90°).
    """
    r = np.asarray(rotation, dtype=float)
    flat = r.reshape(*r.shape[:-2], 9)
    angles = np.empty(r.shape[:-1])
    angles[..., 0] = np.arcsin(np.minimum(np.maximum(flat[..., 2], -1.0), 1.0))
    angles[..., 1:] = np.arctan2(-flat[..., _SINES], flat[..., _COSINES])  # roll, twist
    return np.rad2deg(angles, out=angles)


def rotation_angle_deg(rotation_a, rotation_b):
    """Angle of the rotation taking frame a to frame b, degrees (0 to 180).

    Computed as atan2(‖axial vector‖, (trace − 1)/2) of Raᵀ·Rb, accurate for small angles.
    """
    rel = np.swapaxes(np.asarray(rotation_a), -1, -2) @ np.asarray(rotation_b)
    axial = rel[..., [2, 0, 1], [1, 2, 0]] - rel[..., [1, 2, 0], [2, 0, 1]]  # r21 − r12, …
    sine = 0.5 * np.linalg.norm(axial, axis=-1)
    cosine = 0.5 * (np.trace(rel, axis1=-2, axis2=-1) - 1.0)
    return np.rad2deg(np.arctan2(sine, cosine))


def validation_motion(axis, n_units, amplitude_deg=60.0, cycles=4, samples_per_cycle=200):
    """The paper's validation motion: the segment swept sinusoidally about one axis.

    Parameters
    ----------
    axis : {"pitch", "roll"}
    n_units : int
    amplitude_deg : float
        Segment (tip) amplitude, degrees; each unit takes amplitude / n_units.
    cycles : int
    samples_per_cycle : int

    Returns
    -------
    pitch_deg, roll_deg : numpy.ndarray
        Shape (cycles · samples_per_cycle, n_units): every unit's pose at each sample.
    """
    if axis not in AXES:
        raise InputError(f"axis: expected 'pitch' or 'roll', got {axis!r}")
    for name, value in (("cycles", cycles), ("samples_per_cycle", samples_per_cycle)):
        if isinstance(value, bool) or int(value) != value or value < 1:
            raise InputError(f"{name}: must be a positive whole number, got {value}")
    t = np.arange(int(cycles) * int(samples_per_cycle)) / samples_per_cycle
    per_unit = amplitude_deg / n_units * np.sin(2.0 * np.pi * t)
    moving = np.repeat(per_unit[:, None], int(n_units), axis=1)
    still = np.zeros_like(moving)
    return (moving, still) if axis == "pitch" else (still, moving)


@dataclass(frozen=True)
class SegmentErrors:
    """True and estimated tip over one validation motion.

    Attributes
    ----------
    axis : str
        The moved axis, "pitch" or "roll".
    span_deg : float
        Peak-to-peak tip angle of the motion, degrees.
    true_angles_deg, estimated_angles_deg : numpy.ndarray
        Shape (n, 3): tip pitch, roll, twist, degrees.
    orientation_error_deg : numpy.ndarray
        Shape (n,): angle between the true and estimated tip frames, degrees.
    position_error_mm : numpy.ndarray
        Shape (n,): distance between the true and estimated tip points, mm.
    """

    axis: str
    span_deg: float
    true_angles_deg: np.ndarray
    estimated_angles_deg: np.ndarray
    orientation_error_deg: np.ndarray
    position_error_mm: np.ndarray

    @property
    def axis_error_deg(self):
        """Estimate minus truth of the moved tip angle, degrees, shape (n,)."""
        j = AXES.index(self.axis)
        return self.estimated_angles_deg[:, j] - self.true_angles_deg[:, j]

    def summary(self):
        """Table-I-style figures (JSON-ready).

        Returns
        -------
        dict
            ``percent_error`` (100 × RMS / span), ``rms_deg`` and ``max_deg`` of the moved
            tip angle; ``orientation_rms_deg``, ``orientation_max_deg``; ``position_rms_mm``,
            ``position_max_mm``.
        """
        error = self.axis_error_deg
        rms = float(np.sqrt(np.mean(error**2)))
        return {
            "percent_error": 100.0 * rms / self.span_deg,
            "rms_deg": rms,
            "max_deg": float(np.abs(error).max()),
            "orientation_rms_deg": float(np.sqrt(np.mean(self.orientation_error_deg**2))),
            "orientation_max_deg": float(self.orientation_error_deg.max()),
            "position_rms_mm": float(np.sqrt(np.mean(self.position_error_mm**2))),
            "position_max_mm": float(self.position_error_mm.max()),
        }


def workspace_amplitude_deg(design, axis):
    """Largest segment amplitude about ``axis`` keeping every unit inside its workspace.

    n_units × the smaller distance from zero to either end of the workspace range, degrees
    (not positive when the range does not contain zero).
    """
    lo, hi = getattr(design.workspace, f"{axis}_deg")
    return design.mechanics.n_units * min(-lo, hi)


def _check_amplitude(design, axis, amplitude_deg):
    """InputError unless each unit's share of ``amplitude_deg`` lies in the ``axis`` workspace."""
    if not 0 < amplitude_deg <= workspace_amplitude_deg(design, axis) + 1e-9:
        n_units = design.mechanics.n_units
        lo, hi = getattr(design.workspace, f"{axis}_deg")
        raise InputError(
            f"amplitude_deg: {amplitude_deg:g}° over {n_units} units is "
            f"{amplitude_deg / n_units:g}° per unit, outside the {axis} workspace "
            f"[{lo:g}, {hi:g}]°"
        )


def simulate_segment(
    design,
    model,
    axis,
    *,
    amplitude_deg=PAPER_AMPLITUDE_DEG,
    cycles=4,
    samples_per_cycle=200,
    seed=0,
    units=None,
):
    """Run one validation motion on a segment of units and estimate the tip.

    Every unit records its voltages (with the design's noise and quantisation, fresh draws
    per unit and sample) and is estimated with the same fitted ``model`` — or, with
    ``units``, each unit is a different one, recorded and estimated by its own pair.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
        ``mechanics.n_units`` and ``mechanics.link_length_mm`` set the chain.
    model
        A fitted calibration model (e.g. ``simulate_calibration(design).model``).
    axis : {"pitch", "roll"}
    amplitude_deg : float
        Segment amplitude, degrees (the paper's 60).
    cycles, samples_per_cycle : int
    seed : int
        The run's seed (≥ 0): the noise of the motion about ``axis`` is drawn from the
        ``"segment_motion"`` stream's child for the axis (0 pitch, 1 roll;
        :func:`reflector_opt.util._seeds.stream_rng`).
    units : sequence of (callable, model), optional
        One pair per unit of the segment (``design.mechanics.n_units`` of them): a recorder
        ``record(poses, rng) -> volts`` (poses (n, 2) in degrees, voltages (n, 2)) and the
        unit's fitted model; ``model`` is then not used.

    Returns
    -------
    SegmentErrors
        Raises :class:`~reflector_opt.util._errors.InputError` if a unit's share of the motion
        leaves the workspace the model was calibrated over.
    """
    n_units = design.mechanics.n_units
    pitch, roll = validation_motion(axis, n_units, amplitude_deg, cycles, samples_per_cycle)
    _check_amplitude(design, axis, amplitude_deg)
    estimated = _estimated_angles(design, model, units, pitch, roll, seed, axis)
    link = design.mechanics.link_length_mm
    true_rotation, true_position = tip_pose(pitch, roll, link)
    est_rotation, est_position = tip_pose(estimated[..., 0], estimated[..., 1], link)
    return SegmentErrors(
        axis=axis,
        span_deg=2.0 * amplitude_deg,
        true_angles_deg=tip_angles(true_rotation),
        estimated_angles_deg=tip_angles(est_rotation),
        orientation_error_deg=rotation_angle_deg(true_rotation, est_rotation),
        position_error_mm=np.linalg.norm(est_position - true_position, axis=-1),
    )


def _estimated_angles(design, model, units, pitch, roll, seed, axis):
    """Every unit's estimated (pitch, roll) along the motion, degrees, shape pitch.shape + (2,).

    With ``units`` None the design's own voltages (noise drawn from the ``"segment_motion"``
    stream's child for ``axis``) go through ``model``; else each unit's recorder and model.
    """
    rng = stream_rng(seed, "segment_motion", AXES.index(axis))
    if units is None:
        from reflector_opt.calibration._simulation import record  # the forward model: numba

        poses = np.column_stack([pitch.ravel(), roll.ravel()])
        return model.predict(record(design, poses, rng).volts).reshape((*pitch.shape, 2))
    n_units = design.mechanics.n_units
    if len(units) != n_units:
        raise InputError(f"units: {len(units)} given for a segment of {n_units}")
    return np.stack(
        [
            unit_model.predict(recorder(np.column_stack([pitch[:, j], roll[:, j]]), rng))
            for j, (recorder, unit_model) in enumerate(units)
        ],
        axis=1,
    )


def table_one(design, model, *, seed=0, units=None, **motion_options):
    """Predicted Table-I figures beside the paper's measured ones.

    Each axis is swept to ±60° (the paper's motion), or to the largest amplitude the
    workspace allows if that is smaller (:func:`workspace_amplitude_deg`).

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    model
        A fitted calibration model.
    seed : int
        The run's seed (each axis's motion draws its noise from its own stream, see
        :func:`simulate_segment`).
    units : sequence of (callable, model), optional
        A segment of distinct units (see :func:`simulate_segment`).
    **motion_options
        ``cycles``, ``samples_per_cycle`` (see :func:`simulate_segment`).

    Returns
    -------
    dict
        ``{"pitch": {"amplitude_deg": ..., "predicted": {...}, "paper": {...}}, "roll": ...}``
        with the keys of :meth:`SegmentErrors.summary` (predicted) and of
        :data:`PAPER_TABLE_I` (paper).
    """
    table = {}
    for axis in AXES:
        amplitude = min(PAPER_AMPLITUDE_DEG, workspace_amplitude_deg(design, axis))
        errors = simulate_segment(
            design,
            model,
            axis,
            amplitude_deg=amplitude,
            seed=seed,
            units=units,
            **motion_options,
        )
        table[axis] = {
            "amplitude_deg": amplitude,
            "predicted": errors.summary(),
            "paper": dict(PAPER_TABLE_I[axis]),
        }
    return table
