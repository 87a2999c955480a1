"""The joint in use: where the bearing's clearance lets the sphere's centre sit, and what of it
a calibration learns.

A radial spherical plain bearing has a radial internal clearance c (ISO 12240-1 classes C2,
normal, C3; the bearing catalogue, :mod:`reflector_opt.design._bearings`). The sensors see only
the centre of the sphere, so a shift δ of the centre reads as a rotation of about δ/|OC|
(docs/conditions.md, "The joint"). Taken as a sphere in a spherical seat, the centre may sit
anywhere within c/2 of the seat's centre. Where it sits depends on the load (derived):

* **free joint** (no preload) or **a load that reverses** (the robot lying sideways, a
  contact): the ball crosses its clearance as the load turns; no calibration learns where it
  is, and the bound is ±c/2 along each axis (:func:`joint_shifts`, ``stays``).
* **a steady preload** (the tendons press the ball against its seat, ``tendon_preload_n`` > 0):
  the ball rests where its contact normal lies within the friction cone of the load, of half
  angle φ = atan μ. Seated along the load, the centre is offset by c/2 towards it — the same at
  every visit of a pose, so the calibration learns it (``learned``) — and where in the cone it
  rests depends on the way it came there: across the load ±(c/2)·sin φ, along it
  (c/2)(1 − cos φ), a hysteresis that stays (``stays``). The load is taken along the unit's
  axis (the tendons' compression of the stack).

μ is :data:`FRICTION`, the unfavourable end of its guideline range; the default clearance the
upper end of the bearing's normal class (:func:`clearance_um`).
"""

import math
from dataclasses import dataclass

from reflector_opt.design._bearings import design_bearing

#: Coefficient of friction of a steel/steel spherical plain bearing, with its kind and source.
FRICTION = {
    "value": 0.2,
    "kind": "assumed",
    "range": [0.08, 0.2],
    "source": "SKF, Spherical plain bearings and rod ends (publication 4407), guideline values "
    "of the coefficient of friction for steel/steel, relubricated (the table was not read "
    "here; 0.08-0.20 is the range commonly quoted): 0.2, the unfavourable end (the widest "
    "friction cone)",
}


@dataclass(frozen=True)
class JointShifts:
    """The centre's shift a calibrated unit meets in use, µm, in the lower body's frame.

    Attributes
    ----------
    clearance_um : float
        The bearing's radial internal clearance c, µm.
    learned_um : float
        The repeatable seating along the load (z) that the calibration learns, µm.
    stays_um : tuple of float
        The amplitude of the shift left after calibration along x, y and z, µm (each taken
        with both signs).
    seated : bool
        True when the preload seats the ball (steady preload, the load not reversing).
    """

    clearance_um: float
    learned_um: float
    stays_um: tuple
    seated: bool

    def to_dict(self):
        """The shifts as plain values (the ``--json`` block)."""
        return {
            "clearance_um": self.clearance_um,
            "seated": self.seated,
            "learned_um": self.learned_um,
            "stays_um": list(self.stays_um),
        }


def clearance_um(conditions, mechanics):
    """The joint's clearance: the conditions' ``joint_clearance_um``, else the upper end of the
    normal class of the design's bearing (a described joint's own clearance; the GE 6 E for a
    design naming none), µm.

    Parameters
    ----------
    conditions : reflector_opt.design._conditions.Conditions
    mechanics : reflector_opt.design._components.Mechanics

    Returns
    -------
    float
    """
    if conditions.joint_clearance_um is not None:
        return float(conditions.joint_clearance_um)
    return design_bearing(mechanics).clearance_um("normal")[1]


def joint_shifts(conditions, mechanics, friction=FRICTION["value"]):
    """What of the joint's clearance the calibration learns and what stays (module notes).

    Parameters
    ----------
    conditions : reflector_opt.design._conditions.Conditions
        ``joint_clearance_um``, ``tendon_preload_n`` and ``load_reverses``.
    mechanics : reflector_opt.design._components.Mechanics
        The design's bearing (for the default clearance).
    friction : float, optional
        The coefficient of friction μ of the sliding surfaces.

    Returns
    -------
    JointShifts
    """
    c = clearance_um(conditions, mechanics)
    half = 0.5 * c
    if conditions.tendon_preload_n <= 0.0 or conditions.load_reverses:
        return JointShifts(c, 0.0, (half, half, half), seated=False)
    phi = math.atan(friction)
    across = half * math.sin(phi)
    return JointShifts(c, half, (across, across, half * (1.0 - math.cos(phi))), seated=True)
