"""The Jacobian of any pose model with respect to pitch and roll, by central differences.

J = ∂(f1, …, fn)/∂(γ, α) per degree, from one call of the model on a five-point stencil
around every pose: :func:`stencil_poses` lays the stencil out, :func:`jacobian_from_stencil`
takes the differences, :func:`values_and_jacobian` does both for any callable and
:func:`voltage_jacobian` for a design's output voltages (V/deg). :data:`JACOBIAN_STEP_DEG`
gives the step and why it is accurate enough.
"""

import numpy as np

from reflector_opt.model._forward import respond

#: Step of the central differences, degrees. The truncation error of a central difference is
#: h²/6·abs(f''') and its rounding error about ε·abs(f)/h. The voltages vary over angular scales of
#: a degree or more (abs(f''') ≲ abs(f')/(1°)²) and are at most a few volts, so at h = 0.01° the
#: truncation error is below 2·10⁻⁵ of abs(f') and the rounding error below 10⁻¹³ V/deg: both far
#: below what the Cramér–Rao bound needs. tests/analysis/test_jacobian.py bounds the error
#: against the analytic derivative of Eq 3 and a Richardson extrapolation of the voltages.
JACOBIAN_STEP_DEG = 0.01


def stencil_poses(pitch_deg, roll_deg, step_deg=JACOBIAN_STEP_DEG):
    """The five poses of a central-difference stencil around every pose.

    Parameters
    ----------
    pitch_deg, roll_deg : array_like
        Pitch γ and roll α, degrees, broadcast together to shape P.
    step_deg : float, optional
        Difference step h, degrees.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        Pitch and roll of shape ``(5,) + P``, in the order (γ, α), (γ + h, α), (γ − h, α),
        (γ, α + h), (γ, α − h). One call of the forward model on them gives everything
        :func:`jacobian_from_stencil` needs.
    """
    pitch, roll = np.broadcast_arrays(
        np.asarray(pitch_deg, dtype=float), np.asarray(roll_deg, dtype=float)
    )
    h = float(step_deg)
    shift = np.array([[0.0, 0.0], [h, 0.0], [-h, 0.0], [0.0, h], [0.0, -h]])
    shift = shift.reshape(5, 2, *(1,) * pitch.ndim)  # broadcast over the poses
    return pitch[None] + shift[:, 0], roll[None] + shift[:, 1]


def jacobian_from_stencil(values, step_deg=JACOBIAN_STEP_DEG):
    """Values at the centre and their Jacobian from values on :func:`stencil_poses`.

    ``∂f/∂γ ≈ (f(γ + h, α) − f(γ − h, α)) / 2h`` and likewise for α.

    Parameters
    ----------
    values : array_like, shape (5,) + P + (n,)
        A model's outputs (e.g. the voltages of n sensors) on the stencil.
    step_deg : float, optional
        The step h the stencil was built with, degrees.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        Values at the poses, shape ``P + (n,)``, and J of shape ``P + (n, 2)``:
        ``J[..., i, 0] = ∂f_i/∂γ`` and ``J[..., i, 1] = ∂f_i/∂α``, per degree.
    """
    v = np.asarray(values, dtype=float)
    two_h = 2.0 * float(step_deg)
    jac = np.stack([(v[1] - v[2]) / two_h, (v[3] - v[4]) / two_h], axis=-1)
    return v[0], jac


def values_and_jacobian(func, pitch_deg, roll_deg, step_deg=JACOBIAN_STEP_DEG):
    """Values and Jacobian of any pose model ``func(pitch_deg, roll_deg) -> P + (n,)``.

    Parameters
    ----------
    func : callable
        Takes broadcastable pitch and roll arrays (degrees) and returns outputs with the
        n outputs on the last axis; called once, on the stacked stencil.
    pitch_deg, roll_deg : array_like
        Poses, degrees, broadcast to shape P.
    step_deg : float, optional
        Central-difference step, degrees.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        Shapes ``P + (n,)`` and ``P + (n, 2)`` (per degree), see :func:`jacobian_from_stencil`.
    """
    pitch5, roll5 = stencil_poses(pitch_deg, roll_deg, step_deg)
    return jacobian_from_stencil(func(pitch5, roll5), step_deg)


def voltage_jacobian(design, pitch_deg, roll_deg, step_deg=JACOBIAN_STEP_DEG):
    """J = ∂(V1, …, Vn)/∂(γ, α) of a design's output voltages, V/deg.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    pitch_deg, roll_deg : array_like
        Poses, degrees, broadcast to shape P.
    step_deg : float, optional
        Central-difference step, degrees.

    Returns
    -------
    numpy.ndarray
        Shape ``P + (n_sensors, 2)``, V/deg.
    """
    return values_and_jacobian(
        lambda p, r: respond(design, p, r).volts, pitch_deg, roll_deg, step_deg
    )[1]
