"""The state a unit is used in, against the state it was calibrated in, applied to its voltages.

A unit is calibrated at one temperature, in one light, and used in others. An
:class:`OperatingState` holds what has changed since calibration — the junction temperature
ΔT, the ambient light's drop of each output, and whether the read-out cancels the dark
current (LED on/off differencing) — and :func:`apply_state` turns a sensor's noise-free
voltages at calibration into those it gives in that state
(:mod:`reflector_opt.model.temperature` for ΔT; an ambient collector current I_amb lowers
the output by R2 · I_amb, given here directly as volts at the output). Read-out gain and
offset, noise and the ADC come after, as on the bench.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from reflector_opt.model.temperature import ThermalCoefficients, volts_at_temperature
from reflector_opt.util.errors import InputError

__all__ = ["OperatingState", "apply_state"]


@dataclass(frozen=True)
class OperatingState:
    """What differs in use from the calibration, for every sensor of a unit.

    Parameters
    ----------
    delta_t_k : float or tuple of float
        Junction temperature change since calibration, K: one for all sensors, or one each.
    ambient_v : float or tuple of float
        Drop of each output from ambient light not present at calibration, V (≥ 0: light only
        adds current, lowering the output).
    thermal : ThermalCoefficients or tuple of ThermalCoefficients
        The parts' temperature coefficients: one for all sensors, or one each.
    dark_current_changes : bool
        False for a read-out that cancels the dark current (LED on/off differencing).
    """

    delta_t_k: float | tuple = 0.0
    ambient_v: float | tuple = 0.0
    thermal: ThermalCoefficients | tuple = field(default_factory=ThermalCoefficients)
    dark_current_changes: bool = True

    def __post_init__(self):
        for name in ("delta_t_k", "ambient_v"):
            values = np.atleast_1d(np.asarray(getattr(self, name), dtype=float))
            if not np.isfinite(values).all():
                raise InputError(f"{name}: must be finite, got {getattr(self, name)}")
        if np.any(np.asarray(self.ambient_v, dtype=float) < 0.0):
            raise InputError(f"ambient_v: light only lowers the output; got {self.ambient_v}")
        if np.any(np.abs(np.asarray(self.delta_t_k, dtype=float)) > 150.0):
            raise InputError(
                f"delta_t_k: expected a change within ±150 K, got {self.delta_t_k} "
                "(kelvin of change, not an absolute temperature)"
            )

    def per_sensor(self, name, n_sensors):
        """One value of a field for each of ``n_sensors`` sensors (a tuple is checked)."""
        value = getattr(self, name)
        if isinstance(value, tuple):
            if len(value) != n_sensors:
                raise InputError(f"{name}: {len(value)} values for {n_sensors} sensors")
            return value
        return (value,) * n_sensors


def apply_state(volts, models, state):
    """Noise-free voltages of a unit in ``state``, from its voltages at calibration.

    Parameters
    ----------
    volts : array_like
        Shape ``P + (n_sensors,)``: noise-free output at calibration, V (before read-out gain
        and offset).
    models : sequence of reflector_opt.model.sensors.SensorModel
        The sensors' models, one per last-axis entry.
    state : OperatingState

    Returns
    -------
    numpy.ndarray
        Same shape, V.
    """
    v = np.asarray(volts, dtype=float)
    n = v.shape[-1]
    if len(models) != n:
        raise InputError(f"operating state: {len(models)} sensor models for {n} voltages")
    out = np.empty_like(v)
    parts = zip(
        models,
        state.per_sensor("delta_t_k", n),
        state.per_sensor("ambient_v", n),
        state.per_sensor("thermal", n),
        strict=True,
    )
    for k, (model, dt, ambient, thermal) in enumerate(parts):
        warm = volts_at_temperature(
            v[..., k], model, thermal, dt, dark_current_changes=state.dark_current_changes
        )
        out[..., k] = np.maximum(warm - ambient, model.saturation_v)
    return out
