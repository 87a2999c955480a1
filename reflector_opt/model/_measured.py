"""Sensor models from a measured voltage-versus-distance curve against a flat target.

The lab measurement the datasheet curve comes from (the paper's Fig. 2d): the sensor faces a
flat target of the reflector's material, the distance is stepped and the output voltage
recorded. :func:`read_curve_csv` reads it (columns ``distance_mm, volts``);
:func:`fit_sensor_model` fits the optical parameters and the current gain of a preset to it
by nonlinear least squares, and with ``method="interpolate"`` also keeps the measured points
so that the model reproduces them exactly (monotone PCHIP interpolation between them, see
:meth:`reflector_opt.model._sensors.SensorModel.flat_correction`). With the sensor so
fitted against a reference target of known reflectance and specular fraction, a curve
measured against a flat sample of the reflector's material gives the material's own values
(:func:`reflector_opt.model._material_fit.fit_material`).
"""

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from reflector_opt.model._flat_fit import FlatCurve, fit_flat_curves
from reflector_opt.model._flat_target import MeasuredCurve, signal_readings
from reflector_opt.model._sensors import SensorModel
from reflector_opt.util._display import Summarised, fmt
from reflector_opt.util._errors import InputError
from reflector_opt.util._fileio import read_csv
from reflector_opt.util._limits import MAX_LENGTH_MM, MAX_VOLTS, check_within
from reflector_opt.util._units import check_distances_mm, check_millivolts, check_supply_v

_COLUMNS = ("distance_mm", "volts")
#: The range of each column (± bound, unit); a distance of zero or below is refused after.
_RANGES = ((MAX_LENGTH_MM, " mm"), (MAX_VOLTS, " V"))
#: Readings this close to saturation or the supply count as clamped, V.
_CLAMP_MARGIN_V = 0.01


def read_curve_csv(path, *, supply_v=3.3, accept_units=False):
    """Read a measured flat-target curve.

    Parameters
    ----------
    path : str or pathlib.Path
        CSV with a header row holding ``distance_mm`` and ``volts`` (other columns ignored),
        one measurement per row, distances in mm and voltages in V.
    supply_v : float, optional
        The sensor's supply, V: a ``volts`` column beyond it is refused, as is a
        ``distance_mm`` column in metres or micrometres (:mod:`reflector_opt.util._units`).
    accept_units : bool, optional
        Take the columns as they are (``--accept-units``).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        Distances (mm, sorted increasing) and voltages (V).

    Raises
    ------
    InputError
        Unreadable file, missing columns, a row longer than the header, a non-numeric or
        non-finite cell, a column in another unit, a cell out of range (±1000 mm, ±1000 V;
        with its row number), repeated distances or fewer than 4 rows.
    """
    rows = read_csv(path)  # before Path(), which would read '' as the current folder
    path = Path(path)
    if not rows:
        raise InputError(f"{path}: empty file")
    header = [h.strip() for h in rows[0][1]]
    missing = [c for c in _COLUMNS if c not in header]
    if missing:
        raise InputError(f"{path}: missing column(s) {', '.join(missing)} (header: {header})")
    repeated = [c for c in _COLUMNS if header.count(c) > 1]
    if repeated:
        raise InputError(f"{path}: column(s) {', '.join(repeated)} appear more than once")
    index = [header.index(c) for c in _COLUMNS]
    values = []
    for line, row in rows[1:]:
        if any(cell.strip() for cell in row[len(header) :]):
            raise InputError(
                f"{path}: row {line}: {len(row)} cells, the header has {len(header)} columns"
            )
        try:
            pair = [float(row[i]) for i in index]
        except (ValueError, IndexError):
            raise InputError(f"{path}: row {line}: expected numbers in {_COLUMNS}") from None
        if not all(math.isfinite(x) for x in pair):
            raise InputError(f"{path}: row {line}: values must be finite")
        values.append((pair, line, [row[i].strip() for i in index]))
    values = _check_units(path, values, supply_v, accept_units)
    if len(values) < 4:
        raise InputError(f"{path}: needs at least 4 rows of data, found {len(values)}")
    data = np.array(sorted(values))
    if np.any(np.diff(data[:, 0]) <= 0):
        raise InputError(f"{path}: each distance_mm may appear only once")
    if np.any(data[:, 0] <= 0):
        raise InputError(f"{path}: distance_mm must be positive")
    return data[:, 0], data[:, 1]


def _check_units(path, values, supply_v, accept):
    """The curve's columns in their units, then each cell in its range, then each voltage
    within the supply; the ``[distance, volts]`` pairs of ``values`` ((pair, line, cells))."""
    pairs = np.array([pair for pair, _, _ in values]).reshape(-1, 2)
    if values:
        check_distances_mm(pairs[:, 0], path, accept=accept)
        check_millivolts(pairs[:, 1:], path, ("volts",), supply_v, accept=accept)
    for pair, line, cells in values:
        for column, value, cell, (bound, unit) in zip(_COLUMNS, pair, cells, _RANGES, strict=True):
            check_within(value, f"{path}: row {line}: {column}", bound, unit, given=cell)
    rows = [f"row {line}" for _, line, _ in values]
    check_supply_v(pairs[:, 1:], path, ("volts",), supply_v, accept=accept, rows=rows)
    return pairs.tolist()


@dataclass(frozen=True, repr=False)
class CurveFit(Summarised):
    """Result of :func:`fit_sensor_model`.

    Attributes
    ----------
    model : SensorModel
        The fitted sensor model.
    rms_residual_v : float
        RMS of measured minus fitted voltage over the points, V (before interpolation).
    max_residual_v : float
        Largest absolute residual, V.
    offset_v : float
        The read-out offset fitted with the curve (``fit_offset``; else 0), V.
    """

    model: SensorModel
    rms_residual_v: float
    max_residual_v: float
    offset_v: float = 0.0

    def _summary(self):
        """Title and (label, value) rows of :class:`CurveFit`."""
        m = self.model
        rows = [
            ("RMS residual", fmt(self.rms_residual_v, unit="V")),
            ("max residual", fmt(self.max_residual_v, unit="V")),
            ("source radius", fmt(m.source_radius_mm, unit="mm")),
            ("divergence", fmt(m.divergence_deg, unit="°")),
            ("current gain", fmt(m.current_gain)),
            ("range", f"{fmt(m.range_mm[0])} to {fmt(m.range_mm[1], unit='mm')}"),
        ]
        return f"CurveFit: {m.name}", rows


def fit_sensor_model(
    distance_mm,
    volts,
    base,
    *,
    method="fit",
    reflectance=0.9,
    specular_fraction=1.0,
    name=None,
    range_mm=None,
    fit_offset=False,
):
    """Fit a sensor model to a measured flat-target curve.

    Fits ``source_radius_mm``, ``divergence_deg`` and ``current_gain`` of ``base`` so that
    its flat-target voltage (paper Eq 4 with the emitter–detector offset,
    :meth:`SensorModel.flat_coupling`, through the electronics) matches the measurement in
    least squares (:func:`~reflector_opt.model._flat_fit.fit_flat_curves`, log parameters so
    they stay positive). The gain G acts on the collector current, so it scales the light
    and not the supply; with ``fit_offset`` a constant offset of the output is fitted too,
    which takes up the read-out's offset and any constant light (crosstalk in the package,
    ambient light) instead of letting them bend the beam.

    The emitter–detector spacing e is kept from ``base``: a flat-target curve cannot fix it,
    since scaling e, ω0 and tan θ by k and the gain by k² leaves the curve unchanged; take it
    from the package drawing. The electronics (supply, R1, R2, saturation) are kept too.

    Parameters
    ----------
    distance_mm, volts : array_like
        Measured curve: distances to a flat target (mm) and output voltages (V).
    base : SensorModel
        Starting point and source of the fixed parameters (usually a preset).
    method : {"fit", "interpolate"}
        ``"fit"`` returns the fitted model; ``"interpolate"`` also attaches the measured
        curve, so the model reproduces it exactly on a flat target.
    reflectance : float, optional
        Reflectance ρ of the measurement target.
    specular_fraction : float, optional
        Mirror-like share f of the target's reflectance: 1 (the default) for a mirror,
        0 for a white diffuse standard.
    name : str, optional
        Name of the new model (default: base name + "-measured").
    range_mm : tuple of float, optional
        Usable range of the new model (default: the base's).
    fit_offset : bool, optional
        Fit a constant offset of the output voltage as well (reported in
        :attr:`CurveFit.offset_v`; the model carries none). The offset moves the clamps
        too, so readings within 10 mV of them are then left out of the fit and of the
        residuals.

    Returns
    -------
    CurveFit

    Raises
    ------
    InputError
        An unknown method; a curve :class:`~reflector_opt.model._flat_target.MeasuredCurve`
        refuses; a curve that carries no signal: fewer than 4 readings between the clamps of
        ``base``'s circuit (at or near the supply: no light; at or near saturation), or those
        flat (:func:`~reflector_opt.model._flat_target.signal_readings`); a fit that does not
        converge.
    """
    if method not in ("fit", "interpolate"):
        raise InputError(f"method must be 'fit' or 'interpolate', not {method!r}")
    d = np.asarray(distance_mm, dtype=float)
    v = np.asarray(volts, dtype=float)
    curve = MeasuredCurve(tuple(d), tuple(v), reflectance, specular_fraction)  # validates
    used = signal_readings(v, base, "measured curve", clamp_margin_v=_CLAMP_MARGIN_V)
    if not fit_offset:  # the model's clamps are the readings' own: every reading fits
        used = np.ones(v.shape, dtype=bool)
    solution = fit_flat_curves(
        [FlatCurve(d[used], v[used], reflectance, specular_fraction)],
        base,
        fit_offsets=fit_offset,
        subsurface=False,
    )
    r = solution.residuals_v[0]
    fitted = solution.model.with_(
        name=name or f"{base.name}-measured",
        range_mm=tuple(range_mm) if range_mm is not None else base.range_mm,
        measured_curve=curve if method == "interpolate" else None,
    )
    offset = solution.value("offset_v_0") if fit_offset else 0.0
    return CurveFit(fitted, float(np.sqrt(np.mean(r * r))), float(np.max(np.abs(r))), offset)
