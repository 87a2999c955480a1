"""Identification from the lab's files: a calibration CSV and the sensors' flat-target curves.

The calibration CSV is the one ``calibrate`` reads (columns unit, v1, v2, pitch_deg,
roll_deg; one or more units); each flat-target curve is the CSV ``fit-sensor`` reads
(columns distance_mm, volts), measured for one sensor of one unit before assembly against a
flat sample of the reflector's material. A curve is named ``UNIT:SENSOR=FILE`` on the command
line (SENSOR the sensor's name in the design, e.g. S1, or its number from 1; UNIT may be
left out when the data hold one unit).
"""

from reflector_opt.asbuilt._identification import identify
from reflector_opt.asbuilt._problem import Curve
from reflector_opt.calibration._files import read_calibration_csv
from reflector_opt.model._measured import read_curve_csv
from reflector_opt.util._errors import InputError


def parse_curve_spec(text):
    """Split ``[UNIT:]SENSOR=FILE`` into (unit or None, sensor, file).

    Parameters
    ----------
    text : str

    Returns
    -------
    tuple of (str or None, str, str)
    """
    target, sep, path = text.partition("=")
    if not sep or not target or not path:
        raise InputError(f"--curve {text!r}: expected [UNIT:]SENSOR=FILE, e.g. 1:S1=s1.csv")
    unit, _, sensor = target.rpartition(":")
    return (unit or None), sensor, path


def _sensor_index(design, sensor, text):
    names = [s.name for s in design.sensors]
    if sensor in names:
        return names.index(sensor)
    if sensor.isdigit() and 1 <= int(sensor) <= len(names):
        return int(sensor) - 1
    raise InputError(
        f"--curve {text!r}: no sensor {sensor!r} in the design (sensors: {', '.join(names)}, "
        f"or 1 to {len(names)})"
    )


def read_curves(design, specs, labels, *, accept_units=False):
    """Flat-target curves by unit label from ``[UNIT:]SENSOR=FILE`` specs.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    specs : sequence of str
    labels : sequence of str
        The units in the calibration data.
    accept_units : bool, optional
        Take the curves' columns as they are (``--accept-units``).

    Returns
    -------
    dict of str to list of Curve
    """
    curves, seen = {}, set()
    for text in specs:
        unit, sensor, path = parse_curve_spec(text)
        if unit is None:
            if len(labels) != 1:
                raise InputError(
                    f"--curve {text!r}: the data hold {len(labels)} units; name the unit, "
                    f"e.g. {labels[0]}:{sensor}={path}"
                )
            unit = labels[0]
        if unit not in labels:
            raise InputError(
                f"--curve {text!r}: unit {unit!r} is not in the calibration data "
                f"(units: {', '.join(labels)})"
            )
        index = _sensor_index(design, sensor, text)
        if (unit, index) in seen:
            raise InputError(f"--curve {text!r}: a second curve for unit {unit} sensor {sensor}")
        seen.add((unit, index))
        distance, volts = read_curve_csv(path, accept_units=accept_units)
        curves.setdefault(unit, []).append(Curve(index, distance, volts))
    return curves


def identify_files(design, data_path, curve_specs=(), *, accept_units=False, **options):
    """Identify the units of a calibration CSV, with optional flat-target curves.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    data_path : str or pathlib.Path
        Calibration CSV.
    curve_specs : sequence of str
        ``[UNIT:]SENSOR=FILE`` per measured curve.
    accept_units : bool, optional
        Take the files' columns as they are instead of refusing a column that reads as
        another unit (:mod:`reflector_opt.util._units`).
    **options
        Passed to :func:`reflector_opt.asbuilt._identification.identify`.

    Returns
    -------
    reflector_opt.asbuilt._result.Identification
    """
    samples = read_calibration_csv(data_path, accept_units=accept_units)
    labels = [str(label) for label in samples]
    curves = read_curves(design, curve_specs, labels, accept_units=accept_units)
    return identify(design, {str(k): v for k, v in samples.items()}, curves=curves, **options)
