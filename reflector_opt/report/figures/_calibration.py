"""Calibration: the estimation error over the validation poses, estimated against actual angles
over a motion (a unit's, a segment's), the segment's tip path, and the calibration plan's
predicted error against its size."""

import numpy as np

from reflector_opt.calibration._segment import AXES, tip_pose, validation_motion
from reflector_opt.report.figures._base import PITCH_LABEL, ROLL_LABEL, new_figure, side_view


def calibration_error_figure(result):
    """Estimation error of a simulated calibration over the validation poses.

    Parameters
    ----------
    result : reflector_opt.calibration._simulation.CalibrationResult

    Returns
    -------
    matplotlib.figure.Figure
        Two maps (pitch and roll error, degrees) with each validation pose coloured by the
        estimate minus the truth.
    """
    val = result.protocol.validation
    error = result.estimate(val.volts) - val.angles_deg
    limit = float(np.max(np.abs(error)))
    fig = new_figure((10.0, 4.2))
    for ax, j, name in zip(fig.subplots(1, 2), (0, 1), AXES, strict=True):
        points = ax.scatter(
            val.angles_deg[:, 0],
            val.angles_deg[:, 1],
            c=error[:, j],
            s=3,
            cmap="coolwarm",
            vmin=-limit,
            vmax=limit,
            linewidths=0,
        )
        fig.colorbar(points, ax=ax, label=f"{name} error (°)")
        rms = result.total.rms_deg[j]
        ax.set_title(f"{result.model.name}: {name} error, RMS {rms:.3f}°")
        ax.set_xlabel(PITCH_LABEL)
        ax.set_ylabel(ROLL_LABEL)
        ax.set_aspect("equal")
    return fig


def angle_traces_figure(true_deg, estimated_deg, title="", names=AXES):
    """Estimated against actual angles over a motion (the paper's Fig. 5 view).

    Parameters
    ----------
    true_deg, estimated_deg : array_like
        Shape (n, k): the true and estimated angles at each sample, degrees.
    title : str, optional
    names : sequence of str, optional
        Name of each of the k angles.

    Returns
    -------
    matplotlib.figure.Figure
        One panel per angle, truth and estimate against sample, with the RMS error.
    """
    true_deg = np.asarray(true_deg, dtype=float)
    estimated_deg = np.asarray(estimated_deg, dtype=float)
    k = true_deg.shape[1]
    fig = new_figure((8.0, 2.6 * k))
    axes = fig.subplots(k, 1, sharex=True, squeeze=False)[:, 0]
    for j, (ax, name) in enumerate(zip(axes, names, strict=True)):
        rms = float(np.sqrt(np.mean((estimated_deg[:, j] - true_deg[:, j]) ** 2)))
        ax.plot(true_deg[:, j], color="tab:orange", label=f"actual {name}")
        ax.plot(estimated_deg[:, j], color="tab:blue", linestyle="--", label=f"estimated {name}")
        ax.set_ylabel(f"{name} (°)")
        ax.set_title(f"{name}: RMS error {rms:.3f}°", fontsize=10)
        ax.legend(loc="upper right", fontsize=8)
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel("sample (–)")
    if title:
        fig.suptitle(title)
    return fig


def segment_figure(errors):
    """Estimated against actual tip angle of a segment motion (the paper's Fig. 9 view).

    Parameters
    ----------
    errors : reflector_opt.calibration._segment.SegmentErrors
        From :func:`reflector_opt.calibration._segment.simulate_segment`.

    Returns
    -------
    matplotlib.figure.Figure
        The moved tip angle, actual and estimated, against sample, and the error below.
    """
    j = AXES.index(errors.axis)
    summary = errors.summary()
    fig = new_figure((8.0, 5.0))
    top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=(2, 1))
    top.plot(errors.true_angles_deg[:, j], color="tab:orange", label="actual")
    top.plot(errors.estimated_angles_deg[:, j], color="tab:blue", linestyle="--", label="estimated")
    top.set_ylabel(f"tip {errors.axis} (°)")
    top.set_title(
        f"segment {errors.axis} motion ±{errors.span_deg / 2:g}°: RMS error "
        f"{summary['rms_deg']:.3f}°, max {summary['max_deg']:.3f}°"
    )
    top.legend(loc="upper right", fontsize=8)
    bottom.plot(errors.axis_error_deg, color="tab:red")
    bottom.set_ylabel(f"{errors.axis} error (°)")
    bottom.set_xlabel("sample (–)")
    for ax in (top, bottom):
        ax.grid(True, alpha=0.3)
    return fig


def tip_path_figure(design, amplitude_deg=60.0, samples=200):
    """The segment and the path of its tip over the ±amplitude pitch and roll motions.

    The chain of ``design.mechanics.n_units`` units, ``link_length_mm`` apart, bends evenly
    (each unit takes amplitude / n_units) as in the paper's validation motions; drawn in the
    x–z plane for the pitch motion and the y–z plane for the roll motion.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    amplitude_deg : float, optional
        Tip amplitude, degrees.
    samples : int, optional
        Samples of one cycle.

    Returns
    -------
    matplotlib.figure.Figure
    """
    mech = design.mechanics
    fig = new_figure((10.0, 4.8))
    for ax, axis, plane in zip(fig.subplots(1, 2), AXES, ((0, "x"), (1, "y")), strict=True):
        pitch, roll = validation_motion(axis, mech.n_units, amplitude_deg, 1, samples)
        column, name = plane
        _, tip = tip_pose(pitch, roll, mech.link_length_mm)
        ax.plot(tip[:, column], tip[:, 2], color="tab:blue", label="tip path")
        for k in (samples // 4, 3 * samples // 4, 0):  # the two extremes and the straight pose
            joints = [
                tip_pose(pitch[k, :n], roll[k, :n], mech.link_length_mm)[1]
                for n in range(1, mech.n_units + 1)
            ]
            chain = np.vstack([np.zeros(3), *joints])
            ax.plot(chain[:, column], chain[:, 2], "o-", color="grey", markersize=4)
        ax.plot([], [], "o-", color="grey", label="segment at 0° and the extremes")
        side_view(ax, name, f"{axis} motion ±{amplitude_deg:g}° ({mech.n_units} units)")
        ax.legend(loc="lower center", fontsize=8)
    return fig


def calibration_plan_figure(study):
    """Predicted RMS error against the number of calibration poses, per pattern and form.

    Parameters
    ----------
    study : reflector_opt.tolerance._planning.PlanStudy

    Returns
    -------
    matplotlib.figure.Figure
        One panel per angle, log-log, the units' Cramér–Rao floor as a line.
    """
    fig = new_figure(figsize=(10.0, 4.0))
    axes = fig.subplots(1, 2, sharey=True)
    styles = {"raster": "*", "grid": "o", "sobol": "s", "spiral": "^"}
    forms = sorted({p.form for p in study.predictions})
    for k, (ax, angle) in enumerate(zip(axes, AXES, strict=True)):
        for c, form in enumerate(forms):
            for pattern, marker in styles.items():
                points = sorted(
                    (p.n_poses, p.rms_deg[k])
                    for p in study.predictions
                    if p.form == form and p.pattern == pattern
                )
                if points:
                    n, rms = zip(*points, strict=True)
                    ax.plot(n, rms, f"{marker}-", color=f"C{c}", label=f"{form}, {pattern}")
        floor = study.floor_rms_deg[k]
        ax.axhline(floor, color="k", lw=1)
        ax.axhline(1.1 * floor, color="k", lw=1, ls=":")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("calibration poses")
        ax.set_title(f"{angle} (floor — , +10 % ···)")
        ax.grid(True, alpha=0.3, which="both")
    axes[0].set_ylabel("predicted RMS error over built units (°)")
    axes[1].legend(fontsize=6, ncol=2)
    return fig
