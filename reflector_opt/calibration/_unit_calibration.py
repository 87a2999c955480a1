"""Calibrating a built segment from measured data, and estimating its shape from voltage logs.

The lab workflow after printing: record every unit over its workspace with a reference (the
paper used an IMU) into a calibration CSV, fit one model per unit
(:func:`calibrate_csv`, with k-fold cross-validated error), save the coefficients
(:func:`save_calibrations`), then turn voltage logs into unit and tip angles
(:func:`estimate_log`). Units are listed base first, in the order they first appear in the
calibration CSV; the tip is composed in that order (:func:`~.segment.tip_pose`). A
calibration CSV with a ``temperature_c`` column that spans at least 1 K gives every unit a
temperature-compensated form (:mod:`~reflector_opt.calibration._temperature`), whose logs then
need that column too.
"""

import csv
import io
import os
import stat
from dataclasses import dataclass

import numpy as np

from reflector_opt.calibration._coefficients import model_from_dict, model_to_dict
from reflector_opt.calibration._estimators import make_estimator, selected
from reflector_opt.calibration._files import read_calibration_csv, read_voltage_log
from reflector_opt.calibration._models import ANGLES
from reflector_opt.calibration._physical import PhysicalModel
from reflector_opt.calibration._segment import tip_angles, tip_pose
from reflector_opt.calibration._temperature import (
    DEFAULT_SUPPLY_V,
    MIN_SPAN_K,
    TemperatureCompensated,
)
from reflector_opt.calibration._validation import cross_validate
from reflector_opt.design._validation import reject_unknown
from reflector_opt.util._display import Summarised, fmt
from reflector_opt.util._errors import InputError
from reflector_opt.util._fileio import atomic_path, read_json, write_json
from reflector_opt.util._limits import MAX_ANGLE_DEG, MAX_LENGTH_MM, check_count
from reflector_opt.util._progress import no_progress
from reflector_opt.util._units import check_supply_v

FORMAT = "reflector-opt/calibration@1"


@dataclass(frozen=True, repr=False)
class UnitCalibration(Summarised):
    """The fitted calibration of one unit.

    Attributes
    ----------
    unit : str
        The unit's label in the CSV.
    model
        Fitted :class:`~reflector_opt.calibration._models.Eq5`, ``Eq6`` or ``Polynomial``,
        :class:`~reflector_opt.calibration._temperature.TemperatureCompensated` or
        :class:`~reflector_opt.calibration._physical.PhysicalModel`.
    cross_validation : dict or None
        ``folds``, ``rms_deg`` and ``max_deg`` (pitch, roll) from
        :func:`~reflector_opt.calibration._validation.cross_validate`.
    """

    unit: str
    model: object
    cross_validation: dict | None = None

    def to_dict(self):
        """JSON-ready entry of a calibration file."""
        cv = None
        if self.cross_validation is not None:
            cv = {"folds": self.cross_validation["folds"]}
            for key in ("rms_deg", "max_deg"):
                cv[key] = dict(zip(ANGLES, map(float, self.cross_validation[key]), strict=True))
        return {"unit": self.unit, "cross_validation": cv, "model": model_to_dict(self.model)}

    def _summary(self):
        rows = [("model", type(self.model).__name__), ("samples", self.model.n_samples_)]
        if _thermal(self.model):
            rows += thermal_rows(self.model)
        if self.cross_validation is not None:
            cv = self.cross_validation
            rows.append(("folds", cv["folds"]))
            for key, label in (("rms_deg", "CV RMS error"), ("max_deg", "CV max error")):
                pitch, roll = (fmt(v, 3, "°") for v in cv[key])
                rows.append((f"{label} (pitch, roll)", f"{pitch}, {roll}"))
        return f"UnitCalibration of unit {self.unit!r}", rows


def thermal_rows(model):
    """(label, value) rows of a compensated model's thermal parameters, with their std."""
    low, high = model.temperature_range_c_
    rows = [
        (
            "temperature",
            f"{model.form_.name} compensated to {model.reference_temperature_c_:.4g} °C "
            f"(calibrated {low:.4g} to {high:.4g} °C)",
        )
    ]
    for k in range(len(model.gain_per_k_)):
        gain, gain_std = 100 * model.gain_per_k_[k], 100 * model.gain_per_k_std_[k]
        offset, offset_std = 1e3 * model.offset_v_per_k_[k], 1e3 * model.offset_v_per_k_std_[k]
        rows.append(
            (
                f"sensor {k + 1} gain, offset",
                f"{gain:+.4f} ± {gain_std:.4f} %/K, {offset:+.4f} ± {offset_std:.4f} mV/K",
            )
        )
    return rows


def calibrate_units(
    samples, model="eq6", fit="lsq", folds=5, seed=0, design=None, progress=None, degree=1
):
    """Fit one calibration model per unit.

    Parameters
    ----------
    samples : dict
        Unit label -> :class:`~reflector_opt.calibration._files.UnitSamples`. With
        temperatures that span at least
        :data:`~reflector_opt.calibration._temperature.MIN_SPAN_K` in any unit, every unit gets
        the temperature-compensated form
        (:class:`~reflector_opt.calibration._temperature.TemperatureCompensated`, each unit's
        samples then needing that span too); otherwise the plain form.
    model : str
        ``"eq5"``, ``"eq6"``, ``"polyN"``, or ``"auto"``: the form chosen per unit by
        cross-validation (:class:`~reflector_opt.calibration._selection.AutoModel`); the
        chosen form is what is kept and written.
    fit : {"lsq", "huber", "minimax"}
    folds : int
        Folds of the cross-validation; 0 skips it (``auto`` then still selects with 5).
    seed : int
        Seed of the cross-validation shuffle.
    design : reflector_opt.design._design.Design, optional
        The units' design; needed by ``model="physical"``
        (:class:`~reflector_opt.calibration._physical.PhysicalModel`, least squares only);
        its sensors' supply is the compensation's pivot (default 3.3 V).
    progress : callable, optional
        ``progress(fraction, message)`` before each unit's fit and cross-validation
        (:class:`reflector_opt.util._progress.Progress`).
    degree : {1, 2}
        The temperature compensation's gain in ΔT: 2 fits each sensor's curvature too (data
        at three temperatures at least; docs/conditions.md, "Temperature compensation").

    Returns
    -------
    list of UnitCalibration
        In the order of ``samples``. Raises :class:`~reflector_opt.util._errors.InputError` naming
        the unit if its data cannot be fitted; nothing is returned then.
    """
    if isinstance(folds, bool) or int(folds) != folds or folds < 0 or folds == 1:
        raise InputError(f"folds: must be 0 (no cross-validation) or at least 2, got {folds}")
    name = str(model).strip().lower()
    template = _template(name, fit, folds, seed, design, is_thermal(samples), degree)
    fitted, progress = [], progress or no_progress
    for i, (unit, data) in enumerate(samples.items()):
        progress(i / len(samples), f"unit {unit}: fitting {name}")
        try:
            fitted.append(
                _fit_unit(unit, template, data, folds, seed, progress, (i + 0.5) / len(samples))
            )
        except InputError as exc:
            raise type(exc)(f"unit {unit}: {exc}") from None
    return fitted


def is_thermal(samples):
    """Whether calibration samples call for temperature compensation: a ``temperature_c``
    column spanning at least :data:`~reflector_opt.calibration._temperature.MIN_SPAN_K` in
    some unit (one temperature: the plain form)."""
    return any(
        data.temperature_c is not None and np.ptp(data.temperature_c) >= MIN_SPAN_K
        for data in samples.values()
    )


def _template(name, fit, folds, seed, design, thermal, degree):
    """The unfitted model every unit starts from."""
    if thermal and name == PhysicalModel.name:
        raise InputError(
            "temperature_c: --model physical is not temperature-compensated; choose eq5, "
            "eq6, polyN or auto for data at several temperatures"
        )
    form = make_estimator(name, fit=fit, design=design, folds=folds or 5, seed=seed)
    if not thermal:
        if degree != 1:
            raise InputError(
                f"--temperature-degree {degree}: the data have no temperature_c column spanning "
                "at least 1 K, so there is no temperature compensation to curve"
            )
        return form
    supply = DEFAULT_SUPPLY_V if design is None else tuple(m.supply_v for m in design.models)
    return TemperatureCompensated(form, supply_v=supply, degree=degree)


def _fit_unit(unit, template, data, folds, seed, progress, fraction):
    """One unit's :class:`UnitCalibration`: the fit and its cross-validation."""
    thermal = isinstance(template, TemperatureCompensated)
    extra = (data.temperature_c,) if thermal else ()
    model = selected(template.clone().fit(data.volts, data.angles_deg, *extra))
    cv = None
    if folds:
        progress(fraction, f"unit {unit}: {folds}-fold cross-validation")
        again = model.fixed_form() if thermal else model.clone()  # auto's choice kept
        cv = cross_validate(again, data.volts, data.angles_deg, folds, seed, *extra)
    return UnitCalibration(unit, model, cv)


def calibrate_csv(
    path,
    model="eq6",
    fit="lsq",
    folds=5,
    seed=0,
    design=None,
    progress=None,
    *,
    accept_units=False,
    degree=1,
):
    """Read a calibration CSV and fit every unit (see :func:`calibrate_units`).

    The voltages are checked against the supply of the design's sensors (3.3 V without one)
    and the angles for radians, unless ``accept_units``
    (:func:`~reflector_opt.calibration._files.read_calibration_csv`).
    """
    supply = DEFAULT_SUPPLY_V if design is None else max(m.supply_v for m in design.models)
    samples = read_calibration_csv(path, supply_v=supply, accept_units=accept_units)
    return calibrate_units(samples, model, fit, folds, seed, design, progress, degree)


def save_calibrations(path, calibrations, source=None):
    """Write fitted unit calibrations as JSON (``reflector-opt/calibration@1``), atomically.

    Parameters
    ----------
    path : str or pathlib.Path
    calibrations : list of UnitCalibration
        Base unit first.
    source : str, optional
        Where the data came from (recorded in the file).
    """
    write_json(
        path,
        {"format": FORMAT, "source": source, "units": [c.to_dict() for c in calibrations]},
    )


def load_calibrations(path):
    """Read a file written by :func:`save_calibrations`.

    A key the format does not have is refused, naming it and the allowed ones.

    Returns
    -------
    list of UnitCalibration
    """
    data = read_json(path)
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise InputError(f"{path}: not a calibration file (format {FORMAT!r})")
    reject_unknown(data, ("format", "source", "units"), str(path))
    units = data.get("units")
    if not isinstance(units, list) or not units:
        raise InputError(f"{path}: units: expected a non-empty list")
    calibrations = []
    for i, entry in enumerate(units):
        where = f"{path}: units[{i}]"
        if not isinstance(entry, dict) or not isinstance(entry.get("unit"), str):
            raise InputError(f"{where}: expected an object with a unit label")
        reject_unknown(entry, ("unit", "cross_validation", "model"), where)
        cv = entry.get("cross_validation")
        if cv is not None:
            cv = _cross_validation(cv, f"{where}.cross_validation")
        model = model_from_dict(entry.get("model"), f"{where}.model")
        calibrations.append(UnitCalibration(entry["unit"], model, cv))
    labels = [c.unit for c in calibrations]
    if len(set(labels)) != len(labels):
        raise InputError(f"{path}: unit labels must be unique, got {labels}")
    return calibrations


def _cross_validation(cv, where):
    """The ``cross_validation`` entry of a calibration file: folds, rms_deg and max_deg."""
    expected = "expected an object with folds, rms_deg and max_deg (pitch and roll)"
    if not isinstance(cv, dict) or {"folds", "rms_deg", "max_deg"} - set(cv):
        raise InputError(f"{where}: {expected}")
    reject_unknown(cv, ("folds", "rms_deg", "max_deg"), where)
    out = {"folds": check_count(cv["folds"], f"{where}.folds", 2, 10**12)}
    for key in ("rms_deg", "max_deg"):
        block = cv[key]
        if not isinstance(block, dict) or not all(a in block for a in ANGLES):
            raise InputError(f"{where}.{key}: {expected}")
        reject_unknown(block, ANGLES, f"{where}.{key}")
        values = [block[a] for a in ANGLES]
        if not all(isinstance(v, int | float) and not isinstance(v, bool) for v in values):
            raise InputError(f"{where}.{key}: expected numbers, got {values!r}")
        out[key] = np.array(values, dtype=float)
    return out


@dataclass(frozen=True)
class EstimatedShape:
    """Unit and tip angles estimated from a voltage log.

    Attributes
    ----------
    key : str
        Name of the instant column (``"sample"`` or ``"time"``).
    instants : list of str
    units : list of str
        Units of the log, in calibration (base-to-tip) order.
    angles_deg : numpy.ndarray
        Shape (n_instants, n_units, 2): pitch, roll of every unit, degrees.
    tip_angles_deg : numpy.ndarray or None
        Shape (n_instants, 3): tip pitch, roll, twist, degrees (None unless the log holds
        every calibrated unit).
    tip_position_mm : numpy.ndarray or None
        Shape (n_instants, 3): tip point from the base unit's rotation centre, mm.
    sigma_deg : numpy.ndarray or None
        Shape (n_instants, n_units, 2): each angle's 1σ (:func:`angle_sigma`), degrees; the
        CSV's last columns, ``{unit}_pitch_sigma_deg`` and ``{unit}_roll_sigma_deg`` (None,
        and no columns, where no calibration records its error: an ``AS_BUILT.json``).
    """

    key: str
    instants: list
    units: list
    angles_deg: np.ndarray
    tip_angles_deg: np.ndarray | None
    tip_position_mm: np.ndarray | None
    sigma_deg: np.ndarray | None = None

    def header(self):
        """Column names of the angles CSV."""
        columns = [self.key, *(f"{u}_{a}_deg" for u in self.units for a in ("pitch", "roll"))]
        if self.tip_angles_deg is not None:
            columns += ["tip_pitch_deg", "tip_roll_deg", "tip_twist_deg"]
            columns += ["tip_x_mm", "tip_y_mm", "tip_z_mm"]
        if self.sigma_deg is not None:
            columns += [f"{unit}_{a}_sigma_deg" for unit in self.units for a in ("pitch", "roll")]
        return columns

    def table(self):
        """The numbers of the angles CSV, shape (n_instants, n_columns - 1)."""
        values = [self.angles_deg.reshape(len(self.instants), -1)]
        if self.tip_angles_deg is not None:
            values += [self.tip_angles_deg, self.tip_position_mm]
        if self.sigma_deg is not None:
            values.append(self.sigma_deg.reshape(len(self.instants), -1))
        return np.concatenate(values, axis=1)

    def write(self, path):
        """Write the angles CSV atomically."""
        with atomic_path(path, suffix=".csv") as tmp, open(tmp, "wb") as handle:
            self.append_to(handle, header=True)

    def append_to(self, handle, header=False):
        """Write the rows (after the header, if asked) to an open binary file."""
        if header:
            text = io.StringIO()
            csv.writer(text).writerow(self.header())
            handle.write(text.getvalue().encode("utf-8"))
        from reflector_opt.calibration._logstream import write_angles  # pyarrow, when needed

        write_angles(handle, self.instants, self.table())


def check_link(link_length_mm):
    """Refuse a link length that is not a positive length in mm within the package's limit."""
    if not 0 < link_length_mm <= MAX_LENGTH_MM:
        raise InputError(
            f"link_length_mm: must be positive and at most {MAX_LENGTH_MM:g} mm, "
            f"got {link_length_mm}"
        )


def _thermal(model):
    return isinstance(model, TemperatureCompensated)


def unit_angles(calibration, volts, temperature_c=None):
    """Pitch and roll of one unit's readings, degrees, shape (n, 2).

    Parameters
    ----------
    calibration : UnitCalibration
    volts : numpy.ndarray
        Shape (n, 2), V.
    temperature_c : numpy.ndarray or None
        Shape (n,), °C; read only where the calibration is temperature-compensated.
    """
    if not _thermal(calibration.model):
        return calibration.model.predict(volts)
    try:
        return calibration.model.predict(volts, np.broadcast_to(temperature_c, volts.shape[:-1]))
    except InputError as exc:
        raise InputError(f"unit {calibration.unit}: {exc}") from None


#: The voltage step of the Jacobian's central differences, V.
STEP_V = 1e-6


def unit_jacobian(calibration, volts, temperature_c):
    """∂(pitch, roll)/∂(v1, v2) at each reading, deg/V, shape (n, 2, 2): rows the angles."""
    steps = np.array([[STEP_V, 0.0], [-STEP_V, 0.0], [0.0, STEP_V], [0.0, -STEP_V]])
    shifted = (volts[:, None, :] + steps).reshape(-1, 2)
    if temperature_c is not None:
        temperature_c = np.repeat(np.broadcast_to(temperature_c, volts.shape[:-1]), 4)
    a = unit_angles(calibration, shifted, temperature_c).reshape(-1, 4, 2)
    return np.stack([a[:, 0] - a[:, 1], a[:, 2] - a[:, 3]], axis=-1) / (2 * STEP_V)


def angle_sigma(
    calibration, volts, temperature_c=None, noise_v=0.0, *, bias_deg=None, jacobian=None
):
    """Each reading's 1σ of pitch and roll, degrees, shape (n, 2).

    σ_k² = e_k² + σ_V² · (J_k1² + J_k2²) + B_k², with e_k the calibration's cross-validated RMS
    error of angle k (its training RMS where it holds no cross-validation; NaN where it
    records neither, an ``AS_BUILT.json``'s): the error of the map itself against the
    reference; σ_V the voltage noise of one reading; J = ∂(pitch, roll)/∂(v1, v2) at the
    reading (central differences of :data:`STEP_V`), which carries that noise to the angles
    (first order); B_k the in-use budget's bias of angle k for the stated conditions, of
    unknown sign, as its standard deviation (``bias_deg``,
    :meth:`~reflector_opt.calibration._in_use.InUseTerms.bias_deg`; 0 without). e_k already
    holds the calibration readings' own noise, so σ leans high by up to that part where σ_V
    is the same noise.

    Parameters
    ----------
    calibration : UnitCalibration
    volts : numpy.ndarray
        Shape (n, 2), V.
    temperature_c : numpy.ndarray or None
        Shape (n,), °C (compensated calibrations).
    noise_v : float
        Voltage noise of one reading, V (1σ).
    bias_deg : numpy.ndarray, optional
        Shape (n, 2): each reading's in-use bias B, degrees.
    jacobian : numpy.ndarray, optional
        J at the readings, deg/V, shape (n, 2, 2), if already evaluated (a stream evaluates
        every unit's at once: :class:`~reflector_opt.robot._stream.PreparedUnits`).
    """
    if noise_v and jacobian is None:
        jacobian = unit_jacobian(calibration, volts, temperature_c)
    return sigma_of(error_variance(calibration), volts.shape, noise_v, jacobian, bias_deg)


def error_variance(calibration):
    """e_k² of :func:`angle_sigma`, deg², shape (2,)."""
    cv, model = calibration.cross_validation, calibration.model
    fitted = getattr(model, "form_", model)
    error = cv["rms_deg"] if cv is not None else getattr(fitted, "training_rms_deg_", [np.nan] * 2)
    return np.asarray(error, dtype=float) ** 2


def sigma_of(variance, shape, noise_v=0.0, jacobian=None, bias_deg=None):
    """:func:`angle_sigma`'s σ from its terms, for one unit or several at once (a stream's).

    Parameters
    ----------
    variance : numpy.ndarray
        e², deg², shape (..., 2) (:func:`error_variance`).
    shape : tuple
        Of the result, ``P + (2,)``, to which the terms broadcast.
    noise_v : float
        σ_V, V.
    jacobian : numpy.ndarray, optional
        J, deg/V, shape ``P + (2, 2)``; read where ``noise_v``.
    bias_deg : numpy.ndarray, optional
        B, degrees, shape ``P + (2,)``.
    """
    total = variance + (0.0 if bias_deg is None else bias_deg**2)
    if noise_v:
        total = total + noise_v**2 * (jacobian**2).sum(axis=-1)
    return np.sqrt(total if total.shape == shape else np.broadcast_to(total, shape))


def _shape(calibrations, log, link_length_mm, log_path, name=None, noise_v=0.0, in_use=None):
    """The :class:`EstimatedShape` of a :class:`~.files.VoltageLog`, with each angle's 1σ
    (:func:`angle_sigma`, with the bias of ``in_use``, one per calibration); refuses angles
    that are not finite or not strictly within ±:data:`~reflector_opt.util._limits.
    MAX_ANGLE_DEG`, and a log without temperatures for a compensated calibration (``name``:
    its file, for the message)."""
    by_unit = {c.unit: c for c in calibrations}
    unknown = [u for u in log.units if u not in by_unit]
    if unknown:
        raise InputError(
            f"{log_path}: unit(s) {', '.join(unknown)} have no calibration "
            f"(calibrated: {', '.join(by_unit)})"
        )
    order = [c.unit for c in calibrations if c.unit in log.units]
    columns = [log.units.index(u) for u in order]
    volts = log.volts[:, columns]
    if log.temperature_c is None:  # refused if a unit's calibration is compensated
        thermal = [u for u in order if _thermal(by_unit[u].model)]
        if thermal:
            where = "" if name is None else f" in {name}"
            t0 = by_unit[thermal[0]].model.reference_temperature_c_
            raise InputError(
                f"{log_path}: no temperature_c column, but the calibration of unit(s) "
                f"{', '.join(thermal)}{where} is temperature-compensated (reference "
                f"{t0:.4g} °C) and needs each row's temperature"
            )
        temperature = None
    else:
        temperature = log.temperature_c[:, columns]

    def column(j):
        return None if temperature is None else temperature[:, j]

    with np.errstate(over="ignore", invalid="ignore"):  # refused below, with the instant
        angles = np.stack(
            [unit_angles(by_unit[u], volts[:, j], column(j)) for j, u in enumerate(order)], 1
        )
    bad = np.argwhere(~(np.abs(angles) < MAX_ANGLE_DEG))  # NaN too
    if bad.size:
        i, j, k = bad[0]
        raise InputError(
            f"{log_path}: {log.key} {log.instants[int(i)]}: the calibration of unit {order[j]} "
            f"gives a {ANGLES[k]} of {angles[i, j, k]:.6g} for ({volts[i, j, 0]:g}, "
            f"{volts[i, j, 1]:g}) V, outside what it covers (a pose lies within "
            f"±{MAX_ANGLE_DEG:g}°)"
        )
    tip, position = None, None
    if len(order) == len(calibrations):
        rotation, position = tip_pose(angles[..., 0], angles[..., 1], link_length_mm)
        tip = tip_angles(rotation)
    terms = dict(zip(by_unit, in_use or [None] * len(by_unit), strict=True))

    def unit_sigma(j, u):  # the unit's angle_sigma, with its in-use bias where given
        bias = None if terms[u] is None else terms[u].bias_deg(angles[:, j], column(j))
        return angle_sigma(by_unit[u], volts[:, j], column(j), noise_v, bias_deg=bias)

    sigma = np.stack([unit_sigma(j, u) for j, u in enumerate(order)], 1)
    sigma = None if np.isnan(sigma).all() else sigma  # no calibration records its error
    return EstimatedShape(log.key, log.instants, order, angles, tip, position, sigma)


def estimate_log(
    calibrations,
    log_path,
    link_length_mm=18.0,
    calibration=None,
    *,
    accept_units=False,
    noise_v=0.0,
    in_use=None,
):
    """Estimate unit and tip angles from a voltage log, read whole into memory.

    Parameters
    ----------
    calibrations : list of UnitCalibration
        Base unit first.
    log_path : str or pathlib.Path
        Voltage log (see :func:`~reflector_opt.calibration._files.read_voltage_log`).
    link_length_mm : float
        Distance between consecutive rotation centres, mm.
    calibration : str, optional
        The calibrations' file, named in a message (a compensated calibration needs the log's
        ``temperature_c`` column).
    accept_units : bool, optional
        Take voltages beyond the 3.3 V supply as they are (``--accept-units``).
    noise_v : float, optional
        Voltage noise of one reading, V (1σ), in each angle's σ (:func:`angle_sigma`).
    in_use : list of InUseTerms, optional
        One per calibration: the stated conditions' in-use terms in each angle's σ
        (:func:`~reflector_opt.calibration._in_use.in_use_terms`), at each row's
        ``temperature_c`` where the log has it.

    Returns
    -------
    EstimatedShape
    """
    check_link(link_length_mm)
    log = read_voltage_log(log_path, accept_units=accept_units)
    return _shape(calibrations, log, link_length_mm, log_path, calibration, noise_v, in_use)


def estimate_to_csv(
    calibrations,
    log_path,
    output,
    link_length_mm=18.0,
    calibration=None,
    *,
    accept_units=False,
    noise_v=0.0,
    in_use=None,
):
    """Estimate unit and tip angles from a voltage log into an angles CSV, in bounded memory.

    A log file whose rows of one instant are together is streamed block by block
    (:mod:`~reflector_opt.calibration._logstream`); any other, and a log that can be read
    only once (a pipe), is read whole, as by :func:`estimate_log`. The output is the same
    either way, written atomically.

    Parameters
    ----------
    calibrations : list of UnitCalibration
        Base unit first.
    log_path : str or pathlib.Path
        Voltage log.
    output : str or pathlib.Path
        Angles CSV to write (:meth:`EstimatedShape.write`'s format).
    link_length_mm : float
        Distance between consecutive rotation centres, mm.
    calibration : str, optional
        The calibrations' file, for messages (:func:`estimate_log`).
    accept_units : bool, optional
        Take voltages beyond the 3.3 V supply as they are (``--accept-units``); else they are
        refused, in every block, before anything is written.
    noise_v : float, optional
        Voltage noise of one reading, V (1σ), in each angle's σ (:func:`angle_sigma`).
    in_use : list of InUseTerms, optional
        As :func:`estimate_log`'s.

    Returns
    -------
    dict
        ``instants`` (how many), ``units`` (in calibration order), ``tip`` (whether the tip
        columns were written).
    """
    from reflector_opt.calibration._logstream import Unordered, log_blocks  # pyarrow, when needed

    check_link(link_length_mm)
    try:
        if not _rereadable(log_path):  # a pipe (e.g. <(…)) can be read once: whole
            raise Unordered
        with atomic_path(output, suffix=".csv") as tmp, open(tmp, "wb") as handle:
            count = 0
            for block in log_blocks(log_path):
                check_supply_v(
                    block.volts, log_path, ("v1", "v2"), DEFAULT_SUPPLY_V, accept=accept_units
                )
                shape = _shape(
                    calibrations, block, link_length_mm, log_path, calibration, noise_v, in_use
                )
                shape.append_to(handle, header=count == 0)
                count += len(shape.instants)
    except Unordered:
        log = read_voltage_log(log_path, accept_units=accept_units)  # as estimate_log reads it
        shape = _shape(calibrations, log, link_length_mm, log_path, calibration, noise_v, in_use)
        shape.write(output)
        count = len(shape.instants)
    return {"instants": count, "units": shape.units, "tip": shape.tip_angles_deg is not None}


def _rereadable(path):
    """True unless ``path`` is a pipe or a device: the stream reads a log more than once."""
    try:
        return stat.S_ISREG(os.stat(path).st_mode)
    except (OSError, ValueError):  # the reader reports it
        return True
