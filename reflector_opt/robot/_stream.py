"""Live angles: each frame to each unit's pitch and roll with a 1σ per angle, and the tip.

Unit j of a frame is the j-th calibration (base first, as ``calibrate`` lists them). The angles
are the calibration's ``predict`` of the frame's voltages (and temperatures, where the
calibration is compensated), as ``estimate`` computes them
(:func:`~reflector_opt.calibration._unit_calibration.unit_angles`), and each angle's 1σ is
``estimate``'s (:func:`~reflector_opt.calibration._unit_calibration.angle_sigma`: the
calibration's cross-validated error, the voltage noise through the calibration's gradient and,
given the units' in-use terms, the stated conditions' bias at the frame's angles and
temperature: :mod:`~reflector_opt.calibration._in_use`).
:func:`stream` gives them frame by frame; :func:`estimate_block` a block of frames at once, with
the tip's pose (``reflector-opt stream``, :mod:`reflector_opt.workflow._stream`).
"""

import csv
import io
from typing import NamedTuple

import numpy as np

from reflector_opt.calibration._in_use import units_bias_deg
from reflector_opt.calibration._segment import tip_angles, tip_pose
from reflector_opt.calibration._temperature import (
    TemperatureCompensated,
    check_temperatures,
    compensate,
)
from reflector_opt.calibration._unit_calibration import (
    STEP_V,
    EstimatedShape,
    error_variance,
    sigma_of,
    unit_angles,
    unit_jacobian,
)
from reflector_opt.util._errors import InputError


class Angles(NamedTuple):
    """One frame's estimate."""

    #: The frame's counter.
    counter: int
    #: Each unit's pitch and roll, degrees, shape (n_units, 2).
    angles_deg: np.ndarray
    #: Their 1σ, degrees, shape (n_units, 2).
    sigma_deg: np.ndarray


def streamed_units(protocol, calibrations):
    """The calibrations of the frames' units: the first ``protocol.n_units``.

    Raises
    ------
    InputError
        Frames with a unit the calibrations lack, or compensated units without temperatures.
    """
    if protocol.n_units > len(calibrations):
        raise InputError(
            f"frames: {protocol.n_units} units, but the calibration has {len(calibrations)} "
            f"({', '.join(c.unit for c in calibrations)})"
        )
    units = calibrations[: protocol.n_units]
    thermal = [c.unit for c in units if isinstance(c.model, TemperatureCompensated)]
    if thermal and not protocol.temperature:
        raise InputError(
            f"frames: no temperatures, but unit(s) {', '.join(thermal)} are compensated"
        )
    return units


#: The points of a reading that :class:`PreparedUnits` evaluates: the reading, then the
#: Jacobian's central differences (± :data:`STEP_V` in v1, then in v2), V.
POINTS_V = np.array([[0.0, 0.0], [1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]]) * STEP_V


class PreparedUnits:
    """The units' calibrations prepared once (at a stream's start): a block of frames is then
    one evaluation of every unit at the reading and at the Jacobian's four points.

    Each unit's angles are its polynomial form's ``predict`` (Eq 5, Eq 6, polyN:
    monomials((V − c)/s) · coefᵀ, :mod:`~reflector_opt.calibration._models`; the monomials
    u1^a·u2^b picked by the exponents' arrays from the powers u^0 … u^d as repeated products,
    not one array per term as :func:`~reflector_opt.calibration._terms.monomials` makes them,
    nor ``**``, whose ``pow`` would cost more than the rest of a frame), on its
    voltages compensated to the reference temperature where it is (Eq 2 of
    :mod:`~reflector_opt.calibration._temperature`, its :func:`compensate`), with the units'
    centres, scales, coefficients (over the union of their terms, zero where a unit lacks
    one) and thermal parameters stacked; the Jacobian ∂(pitch, roll)/∂(v1, v2) is
    :func:`~reflector_opt.calibration._unit_calibration.angle_sigma`'s central differences of
    :data:`STEP_V`. Other models (the physical one), and a block that a model refuses (a
    temperature it cannot take: the message names the unit), go unit by unit through
    :func:`~reflector_opt.calibration._unit_calibration.unit_angles` (and ``unit_jacobian``).

    Parameters
    ----------
    units : list of UnitCalibration
    """

    def __init__(self, units):
        self.units = units
        self.variance = np.array([error_variance(c) for c in units])  # e² of the 1σ, (units, 2)
        forms = [getattr(c.model, "form_", c.model) for c in units]
        self.stacked = all(hasattr(f, "scaled_coef_") for f in forms)
        if not self.stacked:
            return
        self.terms = tuple(sorted({t for f in forms for t in f.terms}))
        self.exponents = np.array(self.terms).T  # of v1, of v2
        self.degree = self.exponents.max()
        column = {t: k for k, t in enumerate(self.terms)}
        self.coef = np.zeros((len(units), len(self.terms), 2))
        for j, f in enumerate(forms):
            self.coef[j, [column[t] for t in f.terms]] = f.scaled_coef_.T
        self.centre = np.array([f.centre_v_ for f in forms])
        self.scale = np.array([f.scale_v_ for f in forms])
        hot = [c.model if isinstance(c.model, TemperatureCompensated) else None for c in units]
        self.thermal, self.compensated = np.array([m is not None for m in hot]), any(hot)

        def per_unit(key, plain):  # a parameter of every unit; ``plain`` where it has none
            return np.array(
                [plain if getattr(m, key, None) is None else getattr(m, key) for m in hot]
            )

        self.t0 = per_unit("reference_temperature_c_", 0.0)
        self.supply = per_unit("supply_v_", np.ones(2))
        self.gain, self.offset, self.q = (
            per_unit(k, np.zeros(2)) for k in ("gain_per_k_", "offset_v_per_k_", "gain_per_k2_")
        )

    def angles(self, volts, temperature_c=None):
        """Every unit's pitch and roll, degrees, shape ``P + (n_units, 2)``, of voltages
        (V, ``P + (n_units, 2)``) at temperatures (°C, ``P + (n_units,)``; read where a unit is
        compensated)."""
        if self.compensated:
            dt = check_temperatures(temperature_c) - self.t0
            warm = compensate(volts, dt, self.gain, self.offset, self.supply, self.q)
            volts = np.where(self.thermal[:, None], warm, volts)
        u = (volts - self.centre) / self.scale
        powers = np.ones((*u.shape, self.degree + 1))
        powers[..., 1:] = u[..., None]
        np.cumprod(powers, -1, out=powers)  # u^0, u^1, …, u^d
        x = powers[..., 0, self.exponents[0]] * powers[..., 1, self.exponents[1]]  # monomials
        return (x[..., None, :] @ self.coef)[..., 0, :]

    def estimate(self, volts, temperature_c=None, jacobian=True):
        """The units' angles of a block and, if asked, their Jacobians.

        Parameters
        ----------
        volts : numpy.ndarray
            Shape (n, n_units, 2), V.
        temperature_c : numpy.ndarray or None
            Shape (n, n_units), °C.
        jacobian : bool

        Returns
        -------
        angles : numpy.ndarray
            Shape (n, n_units, 2), degrees.
        jacobians : numpy.ndarray or None
            ∂(pitch, roll)/∂(v1, v2), deg/V, shape (n, n_units, 2, 2) (rows the angles); None
            if not asked.
        """
        n_units = len(self.units)
        if self.stacked:
            points = volts[:, None] + POINTS_V[: 5 if jacobian else 1, None]
            try:
                a = self.angles(points, None if temperature_c is None else temperature_c[:, None])
            except InputError:  # unit by unit, for the message naming the unit
                pass
            else:
                j = (a[:, 1::2] - a[:, 2::2]) / (2 * STEP_V)  # (n, v1 v2, units, angles)
                return a[:, 0], j.transpose(0, 2, 3, 1) if jacobian else None
        at = [None if temperature_c is None else temperature_c[:, j] for j in range(n_units)]
        angles = [unit_angles(c, volts[:, j], at[j]) for j, c in enumerate(self.units)]
        if not jacobian:
            return np.stack(angles, 1), None
        jac = [unit_jacobian(c, volts[:, j], at[j]) for j, c in enumerate(self.units)]
        return np.stack(angles, 1), np.stack(jac, 1)


def estimate_block(
    frames, protocol, units, *, noise_v=0.0, link_length_mm=None, in_use=None, prepared=None
):
    """A block of frames' angles and 1σ and, given a link length, the tip's pose.

    Parameters
    ----------
    frames : list of Frame
    protocol : reflector_opt.robot._protocol.Protocol
    units : list of UnitCalibration
        From :func:`streamed_units`.
    noise_v : float
        Voltage noise of one reading, V (1σ).
    link_length_mm : float or None
        Distance between the units' rotation centres, mm; None: no tip.
    in_use : list of InUseTerms, optional
        Each unit's in-use terms for the stated conditions
        (:func:`~reflector_opt.calibration._in_use.in_use_terms`, computed once), in its 1σ at
        the frame's angles and temperature; None: none.
    prepared : PreparedUnits, optional
        Of ``units``, made once for a stream (made here if not given).

    Returns
    -------
    EstimatedShape
        Keyed ``counter``; the tip's angles and position from the streamed units, base first;
        no 1σ where no calibration records its error (an ``AS_BUILT.json``).
    """
    volts = np.array([protocol.volts(f) for f in frames]).reshape(len(frames), len(units), -1)
    temps = np.array([f.temperature_c for f in frames]) if protocol.temperature else None
    prepared = prepared or PreparedUnits(units)
    angles, jac = prepared.estimate(volts, temps, jacobian=bool(noise_v))
    sigma = None  # where no calibration records its error (an AS_BUILT.json's)
    if not np.isnan(prepared.variance).all():
        bias = None if in_use is None else units_bias_deg(in_use[: len(units)], angles, temps)
        sigma = sigma_of(prepared.variance, angles.shape, noise_v, jac, bias)
    tip = position = None
    if link_length_mm is not None:
        rotation, position = tip_pose(angles[..., 0], angles[..., 1], link_length_mm)
        tip = tip_angles(rotation)
    counters = [str(f.counter) for f in frames]
    return EstimatedShape(
        "counter", counters, [c.unit for c in units], angles, tip, position, sigma
    )


def csv_rows(shape, header=False):
    """A block's rows of the angles CSV (after its header, if asked), as bytes: the columns of
    :meth:`~reflector_opt.calibration._unit_calibration.EstimatedShape.append_to`, each
    number in its shortest round-trip form (Python's ``repr``: ``0.0`` where ``estimate``'s
    CSV writer writes ``0``, the same floats read back), a line one format string."""
    table = shape.table()
    line = "%s" + ",%r" * table.shape[1] + "\n"
    text = io.StringIO()
    if header:
        csv.writer(text).writerow(shape.header())  # as append_to writes it
    text.writelines(line % (i, *row) for i, row in zip(shape.instants, table.tolist(), strict=True))
    return text.getvalue().encode()


def stream(frames, protocol, calibrations, *, noise_v=0.0, in_use=None):
    """Each frame's angles with their 1σ (module notes).

    Parameters
    ----------
    frames : iterable of Frame
        From :meth:`~reflector_opt.robot._protocol.Decoder.read` or ``feed``.
    protocol : reflector_opt.robot._protocol.Protocol
        Their layout (volts or codes, temperatures).
    calibrations : list of UnitCalibration
        One per unit of the frames, base first (more are allowed: the first ``n_units``).
    noise_v : float
        Voltage noise of one reading, V (1σ).
    in_use : list of InUseTerms, optional
        One per calibration (:func:`estimate_block`).

    Yields
    ------
    Angles

    Raises
    ------
    InputError
        Frames with a unit the calibrations lack, or compensated units without temperatures.
    """
    units = streamed_units(protocol, calibrations)
    prepared = PreparedUnits(units)
    for frame in frames:
        shape = estimate_block(
            [frame], protocol, units, noise_v=noise_v, in_use=in_use, prepared=prepared
        )
        yield Angles(frame.counter, shape.angles_deg[0], shape.sigma_deg[0])
