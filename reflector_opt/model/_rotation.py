"""The reflector centre after the unit turns (paper Eq 1), as one scalar formula.

Plain Python arithmetic, so numpy evaluates it over arrays of poses and
:mod:`reflector_opt.model._kernel` compiles it into its loops; a caller that needs only the
formula does not import the compiler. numba's disk cache of the kernel is keyed by
``kernel.py`` alone: after editing this formula, touch ``kernel.py`` (or clear its
``__pycache__``) so that the compiled loops are rebuilt with it.
"""


def rotated_centre(x, y, z, cos_pitch, sin_pitch, cos_roll, sin_roll):
    """Reflector centre after rotation, s1 = Rx(α) Ry(γ) s0 (paper Eq 1), component-wise.

    ``Ry s0 = (x cos γ + z sin γ, y, −x sin γ + z cos γ)`` and then ``Rx`` mixes y and z.

    Parameters
    ----------
    x, y, z : float or numpy.ndarray
        Sphere centre s0 at zero pose, mm.
    cos_pitch, sin_pitch, cos_roll, sin_roll : float or numpy.ndarray
        cos γ, sin γ, cos α, sin α.

    Returns
    -------
    (float, float, float)
        s1, mm (arrays where the arguments are).

    References
    ----------
    Osman et al. (2024), Eq 1.
    """
    z_after_pitch = z * cos_pitch - x * sin_pitch
    return (
        x * cos_pitch + z * sin_pitch,
        y * cos_roll - z_after_pitch * sin_roll,
        y * sin_roll + z_after_pitch * cos_roll,
    )
