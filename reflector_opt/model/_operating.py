"""The one voltage pipeline: from optical coupling, or the voltages at calibration, to what a
unit reads in the state it is used in.

Per sensor, the paper's circuit (Fig. 2f, :mod:`.electronics`) is held as a :class:`Circuit`
— R2 times the photocurrent, R2 times the current added since calibration, the supply and the
read-out's scale — and the output is

    V = clip(Vcc − R2 · (I_photo + I_dark + I_added), V_CE(sat), Vcc) · s

(s = 1 but for a ratiometric ADC after a supply change). :func:`readings` starts from the
coupling η, I_photo = G · I_F · η; :func:`apply_state` from the noise-free voltages at
calibration, I_photo = (Vcc − V)/R2 − I_dark (exact for unclamped voltages). Between the two
ends, every change in use is a term of :mod:`reflector_opt.model.terms` — the junctions'
temperature, a change of the light (LED ageing), a switched drive's unsettled detectors, stray
light (ambient, crosstalk), the supply and the ADC reference — registered once and applied in
one place. The forward model, the built units, the error budget and the report all take their
voltages from here; read-out gain and offset, noise and the ADC come after, as on the bench.
"""

from dataclasses import dataclass, field, fields

import numpy as np

from reflector_opt.model._electronics import ADC_REFERENCES, output_voltage
from reflector_opt.model._temperature import ThermalCoefficients
from reflector_opt.model.terms import TERMS
from reflector_opt.util._errors import InputError


@dataclass(frozen=True, eq=False)
class OperatingState:
    """What differs in use from the calibration, for every sensor of a unit.

    A per-sensor field takes one value for all sensors, a tuple of one per sensor, or (the
    signed light changes) an array whose last axis is the sensors, broadcast with the poses.

    Parameters
    ----------
    delta_t_k : float or tuple of float
        Junction temperature change since calibration, K.
    thermal : ThermalCoefficients or tuple of ThermalCoefficients
        The parts' temperature coefficients.
    dark_current_changes : bool
        False for a read-out that cancels the dark current (LED on/off differencing).
    light_change : float, tuple or array_like
        Relative change of each sensor's own light path (−0.03: 3 % less light).
    ambient_v : float or tuple of float
        Drop of each output from ambient light not present at calibration, V (≥ 0: light only
        adds current, lowering the output).
    crosstalk_v : float, tuple or array_like
        Drop of each output from the change of other LEDs' light since calibration, V (signed).
    flicker_v : float, tuple or array_like
        Drop of each output from the ambient light's flicker at the instant it is read, V
        (signed about the light's mean).
    supply_change_v : float
        Change of the supply since calibration, V.
    adc_reference : {"fixed", "ratiometric"}
        What the ADC reads against: its own reference, or the supply.
    settled_share : float
        Share of its own LED's light a switched drive's reading keeps, in (0, 1]: the drive's,
        at calibration as in use (:func:`~reflector_opt.model._settling.settled_share`).
    """

    delta_t_k: float | tuple = 0.0
    thermal: ThermalCoefficients | tuple = field(default_factory=ThermalCoefficients)
    dark_current_changes: bool = True
    light_change: float | tuple | np.ndarray = 0.0
    ambient_v: float | tuple = 0.0
    crosstalk_v: float | tuple | np.ndarray = 0.0
    flicker_v: float | tuple | np.ndarray = 0.0
    supply_change_v: float = 0.0
    adc_reference: str = "fixed"
    settled_share: float = 1.0

    def __post_init__(self):
        signed = ("delta_t_k", "light_change", "ambient_v", "crosstalk_v", "flicker_v")
        for name in (*signed, "supply_change_v"):
            values = np.asarray(getattr(self, name), dtype=float)
            if not np.isfinite(values).all():
                raise InputError(f"{name}: must be finite, got {getattr(self, name)}")
        if np.any(np.asarray(self.ambient_v, dtype=float) < 0.0):
            raise InputError(f"ambient_v: light only lowers the output; got {self.ambient_v}")
        if np.any(np.abs(np.asarray(self.delta_t_k, dtype=float)) > 150.0):
            raise InputError(
                f"delta_t_k: expected a change within ±150 K, got {self.delta_t_k} "
                "(kelvin of change, not an absolute temperature)"
            )
        if np.any(np.asarray(self.light_change, dtype=float) <= -1.0):
            raise InputError(f"light_change: a relative change above −1, got {self.light_change}")
        if not 0.0 < self.settled_share <= 1.0:
            raise InputError(f"settled_share: a share in (0, 1], got {self.settled_share}")
        if self.adc_reference not in ADC_REFERENCES:
            raise InputError(
                f"adc_reference: expected one of {', '.join(ADC_REFERENCES)}, "
                f"got {self.adc_reference!r}"
            )

    def per_sensor(self, name, n_sensors):
        """One value of a field for each of ``n_sensors`` sensors (a tuple or array is checked)."""
        value = getattr(self, name)
        if isinstance(value, np.ndarray) and value.ndim:
            if value.shape[-1] != n_sensors:
                raise InputError(f"{name}: {value.shape[-1]} values for {n_sensors} sensors")
            return tuple(value[..., k] for k in range(n_sensors))
        if isinstance(value, tuple):
            if len(value) != n_sensors:
                raise InputError(f"{name}: {len(value)} values for {n_sensors} sensors")
            return value
        return (value,) * n_sensors

    def sensors(self, n_sensors):
        """Each sensor's view of the state: one dict of field → value per sensor."""
        columns = {f.name: self.per_sensor(f.name, n_sensors) for f in fields(self)}
        return [{name: column[k] for name, column in columns.items()} for k in range(n_sensors)]


@dataclass(frozen=True)
class Circuit:
    """One sensor's circuit in the pipeline, as voltages across the load R2.

    Attributes
    ----------
    photo_v : numpy.ndarray
        R2 · photocurrent (I_photo = G · I_F · η), V, one per pose.
    dark_v : float
        R2 · the model's own dark current at calibration, V.
    supply_v : float
        The supply Vcc, V.
    added_v : float or numpy.ndarray
        R2 · collector current added since calibration (dark current's growth, stray light), V.
    read_scale : float
        Factor of the ADC's reading (a ratiometric reference after a supply change).
    """

    photo_v: np.ndarray
    dark_v: float
    supply_v: float
    added_v: float | np.ndarray = 0.0
    read_scale: float = 1.0

    def output(self, model):
        """The reading, V: ``clip(Vcc − R2 · I_C, V_CE(sat), Vcc) · s``
        (:func:`~reflector_opt.model._electronics.output_voltage`)."""
        r2 = model.load_resistor_ohm
        volts = output_voltage(
            (self.photo_v + self.dark_v + self.added_v) / r2,
            supply_v=self.supply_v,
            load_resistor_ohm=r2,
            saturation_v=model.saturation_v,
        )
        return volts * self.read_scale


def _through_terms(photo_v, model, state):
    circuit = Circuit(
        photo_v=photo_v,
        dark_v=model.load_resistor_ohm * model.dark_current_a,
        supply_v=model.supply_v,
    )
    if state is not None:
        for term in TERMS:
            circuit = term.apply(circuit, model, state)
    return circuit.output(model)


def _sensor_states(models, n, state):
    if len(models) != n:
        raise InputError(f"voltage pipeline: {len(models)} sensor models for {n} outputs")
    return [None] * n if state is None else state.sensors(n)


def _through_pipeline(photo_v, models, states):
    """Each sensor's R2 · photocurrent (last axis, V) through the terms of its state."""
    out = np.empty_like(photo_v)
    for k, (model, sensor_state) in enumerate(zip(models, states, strict=True)):
        out[..., k] = _through_terms(photo_v[..., k], model, sensor_state)
    return out


def readings(coupling, models, state=None):
    """Noise-free output voltages of sensors at couplings η, in ``state``, V.

    Parameters
    ----------
    coupling : array_like
        Shape ``P + (n_sensors,)``: detected over emitted optical power η (dimensionless).
    models : sequence of reflector_opt.model._sensors.SensorModel
        One per last-axis entry.
    state : OperatingState, optional
        What differs from calibration; None: as calibrated.

    Returns
    -------
    numpy.ndarray
        Shape of ``coupling``, V (before read-out gain and offset).
    """
    eta = np.asarray(coupling, dtype=float)
    states = _sensor_states(models, eta.shape[-1], state)
    gain = np.array([m.load_resistor_ohm * m.current_gain * m.led_current_a for m in models])
    return _through_pipeline(gain * eta, models, states)


def photocurrent_v(volts, models):
    """R2 · photocurrent of each output at calibration, V: ``Vcc − V − R2 · I_dark``.

    Parameters
    ----------
    volts : array_like
        Shape ``P + (n_sensors,)``: noise-free outputs, V.
    models : sequence of reflector_opt.model._sensors.SensorModel

    Returns
    -------
    numpy.ndarray
        Same shape, V.
    """
    v = np.asarray(volts, dtype=float)
    return np.array([m.supply_v - m.load_resistor_ohm * m.dark_current_a for m in models]) - v


def apply_state(volts, models, state):
    """Noise-free voltages of a unit in ``state``, from its voltages at calibration.

    Parameters
    ----------
    volts : array_like
        Shape ``P + (n_sensors,)``: noise-free output at calibration, V (before read-out gain
        and offset).
    models : sequence of reflector_opt.model._sensors.SensorModel
        The sensors' models, one per last-axis entry.
    state : OperatingState

    Returns
    -------
    numpy.ndarray
        Same shape, V.
    """
    v = np.asarray(volts, dtype=float)
    states = _sensor_states(models, v.shape[-1], state)
    return _through_pipeline(photocurrent_v(v, models), models, states)
