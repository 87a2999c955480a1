"""Per-unit calibrations fitted to a measured calibration CSV and written, as
``reflector-opt calibrate`` does it.

One calibration model is fitted per unit, its k-fold cross-validated error measured, and the
coefficients written (nothing is written if any unit fails). A ``temperature_c`` column that
spans at least 1 K makes every unit's form temperature-compensated.
"""

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Literal

from reflector_opt.calibration._choices import FITS
from reflector_opt.util._declared import Options, Seed, option, takes
from reflector_opt.util._display import Printed

#: Cross-validation folds of a calibration unless told otherwise (0 skips the validation).
DEFAULT_FOLDS = 5


@dataclass(frozen=True, repr=False)
class CalibrateRun(Printed):
    """The calibrations fitted by :func:`calibrate`, in memory; :meth:`write` writes them.

    Attributes
    ----------
    calibrations : list of reflector_opt.calibration._unit_calibration.UnitCalibration
        One per unit, in the file's order, each with its cross-validated error, degrees.
    fit : str
        The fit method (``lsq``, …).
    folds : int
        Cross-validation folds (0: not validated).
    source : str or None
        The name of the calibration data, recorded in the coefficients file.
    output : str or pathlib.Path or None
        The coefficients file, as given, once written.
    files : tuple of pathlib.Path
        Every file written (the coefficients; empty before :meth:`write`).
    """

    calibrations: list
    fit: str
    folds: int
    source: str | None = None
    output: object = None
    files: tuple = ()

    def write(self, output):
        """Write the coefficients (JSON, ``reflector-opt/calibration@1``), atomically.

        Parameters
        ----------
        output : str or pathlib.Path
            The coefficients file.

        Returns
        -------
        CalibrateRun
            This run, written: ``output`` and ``files`` filled in.
        """
        from reflector_opt.calibration._unit_calibration import save_calibrations

        save_calibrations(output, self.calibrations, source=self.source)
        return replace(self, output=output, files=(Path(output),))

    def to_dict(self):
        """JSON-ready (``calibrate --json``): per unit, the model, the samples, the
        cross-validated errors (degrees) and, when compensated, the ``temperature`` block of
        its coefficients (thermal parameters and their std)."""
        units = {}
        for c in self.calibrations:
            entry = c.to_dict()
            units[c.unit] = {
                "model": c.model.name,
                "samples": c.model.n_samples_,
                "cross_validation": entry["cross_validation"],
            }
            if "temperature" in entry["model"]:
                units[c.unit]["temperature"] = entry["model"]["temperature"]
        return {"fit": self.fit, "folds": self.folds, "units": units, "output": self.output}

    def text(self):
        """The table of the per-unit cross-validated errors and the thermal parameters."""
        calibrations = self.calibrations
        names = "/".join(sorted({c.model.name for c in calibrations}))
        thermal = [c for c in calibrations if hasattr(c.model, "gain_per_k_")]
        compensated = ", temperature-compensated" if thermal else ""
        lines = [f"{len(calibrations)} unit(s) calibrated with {names} ({self.fit}{compensated})"]
        if self.folds:
            lines.append(f"{self.folds}-fold cross-validated error (estimate − reference):")
            lines.append(
                f"  {'unit':<8}{'samples':>8}{'RMS pitch':>12}{'RMS roll':>11}"
                f"{'max pitch':>12}{'max roll':>11}"
            )
            for c in calibrations:
                rms, peak = c.cross_validation["rms_deg"], c.cross_validation["max_deg"]
                lines.append(
                    f"  {c.unit:<8}{c.model.n_samples_:>8}{rms[0]:>11.3f}°{rms[1]:>10.3f}°"
                    f"{peak[0]:>11.3f}°{peak[1]:>10.3f}°"
                )
        return "\n".join(lines + _thermal_lines(thermal))


def _thermal_lines(calibrations):
    """The thermal parameters of compensated units, ± one standard deviation."""
    if not calibrations:
        return []
    lines = [
        "temperature compensation (change per kelvin ± 1 std; T0 the mean calibration "
        "temperature):",
        f"  {'unit':<8}{'T0 °C':>7}{'range °C':>14}{'gain 1 %/K':>19}{'gain 2 %/K':>19}"
        f"{'offset 1 mV/K':>19}{'offset 2 mV/K':>19}",
    ]
    for c in calibrations:
        m = c.model
        low, high = m.temperature_range_c_
        cells = [
            f"{scale * v:+.4f} ± {scale * s:.4f}"
            for scale, values, stds in (
                (100, m.gain_per_k_, m.gain_per_k_std_),
                (1e3, m.offset_v_per_k_, m.offset_v_per_k_std_),
            )
            for v, s in zip(values, stds, strict=True)
        ]
        lines.append(
            f"  {c.unit:<8}{m.reference_temperature_c_:>7.2f}{f'{low:.1f}–{high:.1f}':>14}"
            + "".join(f"{cell:>19}" for cell in cells)
        )
    return lines


class CalibrateOptions(Options):
    """The options of ``reflector-opt calibrate``, declared once."""

    model: option(
        str,
        "eq5, eq6 (the paper's), polyN (e.g. poly4), auto (chosen per unit by "
        "cross-validation) or physical (the design's model fitted per unit; needs --design)",
    ) = "eq6"
    design: option(
        object,
        "the units' design (a Design or its design.json; needed by --model physical; its "
        "sensors' supply is the temperature compensation's pivot, 3.3 V without it)",
        metavar="DESIGN.json",
    ) = None
    fit: option(Literal[FITS], "the fit method") = "lsq"
    folds: option(int, "cross-validation folds; 0 skips the validation", ge=0, le=1000) = (
        DEFAULT_FOLDS
    )
    seed: option(Seed, "seed of the fold shuffle") = 0
    temperature_degree: option(
        Literal[1, 2],
        "the temperature compensation's gain in ΔT: 1 linear, 2 with each sensor's "
        "curvature too (data at three temperatures at least, as docs/conditions.md recommends "
        "for a dome-shaped light path)",
    ) = 1
    accept_units: option(
        bool,
        "take the calibration CSV's columns as given where they look like another unit "
        "(millivolts, radians) or lie beyond the sensors' supply; refused by default",
    ) = False


@takes(CalibrateOptions)
def calibrate(data, options, progress=None):
    """Fit one calibration per unit of a calibration CSV, in memory: ``reflector-opt
    calibrate``; :meth:`CalibrateRun.write` writes the coefficients.

    Parameters
    ----------
    data : str or pathlib.Path
        The calibration CSV (columns unit, v1, v2 in V, pitch_deg, roll_deg in degrees, and
        optionally temperature_c in °C).
    options : CalibrateOptions
        As keyword arguments (below).
    progress : callable, optional
        ``progress(fraction, message)`` as the units are fitted.

    Returns
    -------
    CalibrateRun

    Raises
    ------
    InputError
        A file that cannot be read, an unknown model or fit, a unit that cannot be fitted.
    """
    from reflector_opt.calibration._unit_calibration import calibrate_csv
    from reflector_opt.design import as_design

    design = None if options.design is None else as_design(options.design)
    calibrations = calibrate_csv(
        data,
        options.model,
        options.fit,
        options.folds,
        options.seed,
        design,
        progress,
        accept_units=options.accept_units,
        degree=options.temperature_degree,
    )
    return CalibrateRun(calibrations, options.fit, options.folds, source=Path(data).name)
