"""Unit and tip angles from a voltage log, as ``reflector-opt estimate`` makes them.

Every unit's pitch and roll are estimated with its calibration (a coefficients file written by
``calibrate``, or an ``AS_BUILT.json`` written by ``identify``) and, when the log holds every
calibrated unit, the tip's orientation and position; the angles go to a CSV.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from reflector_opt.util.display import Printed

__all__ = ["EstimateRun", "estimate_run"]


@dataclass(frozen=True, repr=False)
class EstimateRun(Printed):
    """The angles estimated and written by :func:`estimate_run`.

    Attributes
    ----------
    instants : int
        The instants of the log estimated.
    units : list of str
        The units, in the calibration's order (base first).
    tip : bool
        Whether the tip's angles and position were written.
    output : str or pathlib.Path
        The angles CSV, as given.
    files : tuple of pathlib.Path
        Every file written (the angles CSV).
    """

    instants: int
    units: list
    tip: bool
    output: object
    files: tuple

    def to_dict(self):
        """JSON-ready (``estimate --json``): instants, units, tip and the output file."""
        return {
            "instants": self.instants,
            "units": self.units,
            "tip": self.tip,
            "output": self.output,
        }

    def text(self):
        """One line: how many instants and units, with or without the tip."""
        tip = "with tip angles and position" if self.tip else "no tip"
        return f"{self.instants} instant(s) × {len(self.units)} unit(s) estimated ({tip})"


def load_unit_calibrations(path):
    """The unit calibrations of a coefficients file or of an ``AS_BUILT.json``.

    Parameters
    ----------
    path : str or pathlib.Path
        Written by ``calibrate``
        (:func:`~reflector_opt.calibration.unit_calibration.save_calibrations`) or by ``identify``.

    Returns
    -------
    list
        One calibration per unit, base first, each with ``estimate``.
    """
    from reflector_opt.asbuilt.asbuiltfile import is_as_built_file

    if is_as_built_file(path):  # the forward model (numba) only for these
        from reflector_opt.asbuilt.estimator import load_unit_calibrations as load
    else:
        from reflector_opt.calibration.unit_calibration import load_calibrations as load
    return load(path)


def estimate_run(coefficients, log, output, *, link_length_mm=None, accept_units=False):
    """Estimate unit and tip angles from a voltage log into a CSV: ``reflector-opt estimate``.

    Parameters
    ----------
    coefficients : str or pathlib.Path
        The calibrations: a coefficients file of ``calibrate`` or an ``AS_BUILT.json``.
    log : str or pathlib.Path
        The voltage log (columns unit, v1, v2 in V, optionally sample or time, and
        temperature_c in °C, which a temperature-compensated calibration needs).
    output : str or pathlib.Path
        The angles CSV to write.
    link_length_mm : float, optional
        Distance between rotation centres, mm (default: the built-in mechanics',
        :attr:`reflector_opt.design.components.Mechanics.link_length_mm`).
    accept_units : bool, optional
        Take voltages beyond the 3.3 V supply as they are instead of refusing them.

    Returns
    -------
    EstimateRun

    Raises
    ------
    InputError
        A file that cannot be read, a log unit without calibration, voltages in the wrong
        unit; nothing is written.
    """
    from reflector_opt.calibration.unit_calibration import estimate_to_csv
    from reflector_opt.design.components import Mechanics

    link_mm = Mechanics.link_length_mm if link_length_mm is None else link_length_mm
    done = estimate_to_csv(
        load_unit_calibrations(coefficients),
        log,
        output,
        link_mm,
        calibration=coefficients,
        accept_units=accept_units,
    )
    return EstimateRun(done["instants"], done["units"], done["tip"], output, (Path(output),))
