"""Unit and tip angles from a voltage log, as ``reflector-opt estimate`` makes them.

Every unit's pitch and roll are estimated with its calibration (a coefficients file written by
``calibrate``, or an ``AS_BUILT.json`` written by ``identify``) and, when the log holds every
calibrated unit, the tip's orientation and position; the angles go to a CSV, each with its 1σ
(:func:`~reflector_opt.calibration._unit_calibration.angle_sigma`, as ``stream``'s, with
``--conditions`` the in-use terms of :mod:`~reflector_opt.calibration._in_use`) in the last
columns.
"""

from dataclasses import dataclass, replace
from functools import cached_property
from os import PathLike
from pathlib import Path

from reflector_opt.util._declared import Options, option, takes
from reflector_opt.util._display import Printed
from reflector_opt.util._errors import InputError
from reflector_opt.util._limits import MAX_LENGTH_MM


@dataclass(frozen=True, repr=False)
class EstimateRun(Printed):
    """Unit and tip angles of a voltage log (:func:`estimate`).

    The angles are estimated in memory the first time :attr:`shape` is read; :meth:`write`
    estimates them straight into a CSV in bounded memory instead (block by block), unless
    they are already in memory.

    Attributes
    ----------
    calibrations : list
        One calibration per unit, base first.
    log : str or pathlib.Path
        The voltage log.
    link_length_mm : float
        Distance between rotation centres, mm.
    accept_units : bool
        Voltages beyond the 3.3 V supply are taken as they are.
    noise_v : float
        Voltage noise of one reading, V (1σ), in each angle's 1σ.
    in_use : list or None
        Each calibration's in-use terms for ``--conditions``
        (:func:`~reflector_opt.calibration._in_use.in_use_terms`), in each angle's 1σ.
    coefficients : str or pathlib.Path or None
        The calibrations' file, named in messages.
    output : str or pathlib.Path or None
        The angles CSV, as given, once written.
    files : tuple of pathlib.Path
        Every file written (the angles CSV; empty before :meth:`write`).
    counts : dict or None
        ``instants``, ``units`` and ``tip`` of the angles written.
    """

    calibrations: list
    log: object
    link_length_mm: float
    accept_units: bool = False
    noise_v: float = 0.0
    in_use: list | None = None
    coefficients: object = None
    output: object = None
    files: tuple = ()
    counts: dict | None = None

    @cached_property
    def shape(self):
        """The estimated angles, in memory
        (:class:`~reflector_opt.calibration._unit_calibration.EstimatedShape`)."""
        from reflector_opt.calibration._unit_calibration import estimate_log

        return estimate_log(
            self.calibrations,
            self.log,
            self.link_length_mm,
            self.coefficients,
            accept_units=self.accept_units,
            noise_v=self.noise_v,
            in_use=self.in_use,
        )

    def _counts(self):
        if self.counts is not None:
            return self.counts
        shape = self.shape
        return {
            "instants": len(shape.instants),
            "units": shape.units,
            "tip": shape.tip_angles_deg is not None,
        }

    @property
    def instants(self):
        """The instants of the log estimated."""
        return self._counts()["instants"]

    @property
    def units(self):
        """The units, in the calibration's order (base first)."""
        return self._counts()["units"]

    @property
    def tip(self):
        """Whether the tip's angles and position are estimated (every unit in the log)."""
        return self._counts()["tip"]

    def write(self, output):
        """Write the angles CSV, atomically (estimated block by block when not yet in memory).

        Parameters
        ----------
        output : str or pathlib.Path

        Returns
        -------
        EstimateRun
            This run, written: ``output``, ``files`` and ``counts`` filled in.
        """
        from reflector_opt.calibration._unit_calibration import estimate_to_csv

        if "shape" in self.__dict__:
            self.shape.write(output)
            counts = self._counts()
        else:
            counts = estimate_to_csv(
                self.calibrations,
                self.log,
                output,
                self.link_length_mm,
                calibration=self.coefficients,
                accept_units=self.accept_units,
                noise_v=self.noise_v,
                in_use=self.in_use,
            )
        return replace(self, output=output, files=(Path(output),), counts=counts)

    def to_dict(self):
        """JSON-ready (``estimate --json``): instants, units, tip, the output file and what
        the 1σ holds of the in-use terms (None without ``--conditions``)."""
        return {**self._counts(), "output": self.output, "sigma_in_use": self._in_use_note()}

    def text(self):
        """One line: how many instants and units, with or without the tip (and a second on
        the in-use terms, with ``--conditions``)."""
        tip = "with tip angles and position" if self.tip else "no tip"
        line = f"{self.instants} instant(s) × {len(self.units)} unit(s) estimated ({tip})"
        note = self._in_use_note()
        return line if note is None else f"{line}\n{note}"

    def _in_use_note(self):
        from reflector_opt.calibration._in_use import in_use_note

        return None if self.in_use is None else in_use_note(self.in_use, None)


def load_unit_calibrations(path):
    """The unit calibrations of a coefficients file or of an ``AS_BUILT.json``.

    Parameters
    ----------
    path : str or pathlib.Path
        Written by ``calibrate``
        (:func:`~reflector_opt.calibration._unit_calibration.save_calibrations`) or by ``identify``.

    Returns
    -------
    list
        One calibration per unit, base first, each with ``estimate``.
    """
    from reflector_opt.asbuilt._asbuiltfile import is_as_built_file

    if is_as_built_file(path):  # the forward model (numba) only for these
        from reflector_opt.asbuilt._estimator import load_unit_calibrations as load
    else:
        from reflector_opt.calibration._unit_calibration import load_calibrations as load
    return load(path)


#: The distance between the units' rotation centres (``estimate``, ``stream``).
LinkLength = option(
    float,
    "distance between the units' rotation centres, mm; the built-in mechanics' if left out",
    metavar="MM",
    gt=0,
    le=MAX_LENGTH_MM,
)
#: The voltage noise of one reading, in each angle's 1σ (``estimate``, ``stream``).
NoiseV = option(
    float,
    "voltage noise of one reading, V (1σ), carried through the calibration's gradient into "
    "each angle's 1σ; 0 leaves the calibration's cross-validated error alone",
    metavar="V",
    ge=0,
    le=1,
)
#: The conditions whose in-use terms each angle's 1σ holds (``estimate``, ``stream``).
InUseConditions = option(
    object,
    "operating conditions (Conditions, or a [conditions] TOML file, docs/conditions.md) whose "
    "in-use error budget each angle's 1σ holds, at the readings' temperatures where they carry "
    "them (docs/robot.md); none if left out",
    metavar="COND.toml",
)
#: The units' design, for the in-use terms of a calibration that holds none.
InUseDesign = option(
    object,
    "the units' design (a Design or its design.json): for --conditions, where the calibration "
    "holds none (a polynomial one), and what stream's --view draws",
    metavar="DESIGN.json",
)


def in_use_of(calibrations, options, *, design_read=False):
    """Each calibration's in-use terms for ``options.conditions`` (None without).

    ``design_read``: the caller reads ``options.design`` for more than these terms (stream's
    ``--view`` draws it), so it is not refused alone.

    Raises
    ------
    InputError
        ``--design`` without ``--conditions`` (unless ``design_read``); a calibration without a
        design and no ``--design``; conditions or a design that cannot be read.
    """
    if options.conditions is None:
        if options.design is not None and not design_read:
            raise InputError("--design: read only for --conditions' in-use terms; give both")
        return None
    from reflector_opt.calibration._in_use import in_use_terms

    return in_use_terms(calibrations, options.conditions, options.design)


class EstimateOptions(Options):
    """The options of ``reflector-opt estimate``, declared once."""

    link_length_mm: LinkLength | None = None
    accept_units: option(
        bool,
        "take the log's voltages as given where they look like another unit (millivolts) or "
        "lie beyond the sensors' 3.3 V supply; refused by default",
    ) = False
    noise_v: NoiseV = 0.0
    conditions: InUseConditions = None
    design: InUseDesign = None


@takes(EstimateOptions)
def estimate(calibrations, log, options=None):
    """Unit and tip angles from a voltage log: ``reflector-opt estimate``;
    :meth:`EstimateRun.write` writes them to a CSV.

    Parameters
    ----------
    calibrations : CalibrateRun, list, str or pathlib.Path
        The calibrations: a :func:`~reflector_opt.workflow._calibrate.calibrate` run, its
        list of unit calibrations, a coefficients file of ``calibrate`` or an
        ``AS_BUILT.json``.
    log : str or pathlib.Path
        The voltage log (columns unit, v1, v2 in V, optionally sample or time, and
        temperature_c in °C, which a temperature-compensated calibration needs).
    options : EstimateOptions
        As keyword arguments (below); the link length's default is
        :attr:`reflector_opt.design._components.Mechanics.link_length_mm`.

    Returns
    -------
    EstimateRun

    Raises
    ------
    InputError
        A calibrations file that cannot be read; a log that cannot be read, a log unit
        without calibration or voltages in the wrong unit when the angles are estimated.
    """
    from reflector_opt.design._components import Mechanics

    link_mm = options.link_length_mm or Mechanics.link_length_mm  # given: > 0
    coefficients = None
    if isinstance(calibrations, str | PathLike):
        coefficients, calibrations = calibrations, load_unit_calibrations(calibrations)
    elif hasattr(calibrations, "calibrations"):
        calibrations = calibrations.calibrations
    calibrations = list(calibrations)
    in_use = in_use_of(calibrations, options)
    return EstimateRun(
        calibrations, log, link_mm, options.accept_units, options.noise_v, in_use, coefficients
    )
