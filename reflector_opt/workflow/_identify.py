"""How printed units were built, identified from their calibration data and written to
``AS_BUILT.json``, as ``reflector-opt identify`` does it.

Each unit of a calibration CSV (with, optionally, its sensors' flat-target curves) is
identified (:func:`reflector_opt.asbuilt._identification.identify`): reflector radius and
centre, each sensor's seat, gain and offset, the batch's surface, each with its uncertainty
and whether the data determine it, and the angle reference's zero offsets and twist in each
unit's calibration. Nothing is written if any unit fails.
"""

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Literal

from reflector_opt.util._declared import Options, option, takes
from reflector_opt.util._display import Printed


@dataclass(frozen=True, repr=False)
class IdentifyRun(Printed):
    """The identification made by :func:`identify`, in memory; :meth:`write` writes it.

    Attributes
    ----------
    result : reflector_opt.asbuilt._result.Identification
        Every unit's parameters (lengths mm, angles degrees) with their std and covariance.
    source : str
        The calibration data, recorded in the file.
    batch : str or None
        The print batch the units came from, recorded in the file.
    output : str or pathlib.Path or None
        The ``AS_BUILT.json`` written, as given, once written.
    files : tuple of pathlib.Path
        Every file written (the ``AS_BUILT.json``; empty before :meth:`write`).
    """

    result: object
    source: str = ""
    batch: str | None = None
    output: object = None
    files: tuple = ()

    def write(self, output):
        """Write ``AS_BUILT.json``, atomically.

        Parameters
        ----------
        output : str or pathlib.Path

        Returns
        -------
        IdentifyRun
            This run, written: ``output`` and ``files`` filled in.
        """
        from reflector_opt.asbuilt._asbuiltfile import save_as_built

        save_as_built(self.result, output, source=self.source, batch=self.batch)
        return replace(self, output=output, files=(Path(output),))

    def to_dict(self):
        """JSON-ready (``identify --json``): the shared parameters; per unit, the determined
        parameters' deviations from the design (± std), the determined combinations and the
        reference's parameters; the run time, s."""
        result = self.result
        units = {}
        for u, label in enumerate(result.labels):
            rows = result.unit_parameters(u)
            units[label] = {
                "determined": {
                    name: {"deviation": r["estimate"] - r["design"], "std": r["std"]}
                    for name, r in rows.items()
                    if r["identifiable"]
                },
                "combinations": [c.name for c in result.combinations[u]],
                "reference": result.reference_parameters(u),
            }
        return {"shared": result.shared_parameters(), "units": units, "seconds": result.seconds}

    def text(self):
        """The surface, then each unit's determined deviations, its model-form amplitudes the
        data move and its reference."""
        result = self.result
        lines = [f"{len(result.labels)} unit(s) identified in {result.seconds:.1f} s"]
        for name, row in result.shared_parameters().items():
            state = "determined" if row["identifiable"] else "not determined by the data"
            lines.append(
                f"  {name}: {row['estimate']:.4g} ± {row['std']:.2g} (prior ± "
                f"{row['prior_std']:.2g}, {state})"
            )
        for u, label in enumerate(result.labels):
            lines.append(f"unit {label}: deviation from the design (± std), determined ones")
            for name, row in result.unit_parameters(u).items():
                if row["identifiable"]:
                    deviation = row["estimate"] - row["design"]
                    lines.append(f"    {name:<34}{deviation:+10.4f} ± {row['std']:.4f}")
            for combination in result.combinations[u][:6]:
                lines.append(
                    f"    determined: {combination.name} (std {combination.ratio:.2f}× prior)"
                )
            lines += _form_lines(result.model_form_parameters(u))
            lines += _reference_lines(result.reference_parameters(u))
        return "\n".join(lines + _closing_lines(result))


def _closing_lines(result):
    """The reference taken as exact, and the widening of a model that misses the data."""
    lines = []
    if not result.layout.reference_names:
        lines.append("the angle reference was taken as exact (--reference-zero fixed)")
    if result.inflation > 1.5:
        lines.append(
            f"note: each region of the workspace is predicted from the others "
            f"{result.inflation**0.5:.1f}× worse than the noise (block cross-validation); the "
            "model does not describe these units exactly, and the uncertainties are widened to "
            "match"
        )
    return lines


def _form_lines(rows):
    """The model-form amplitudes the data move from their prior (1 = the effect at its
    documented size), or none."""
    moved = [
        f"{name.removeprefix('form_')} {row['estimate']:+.2f} ± {row['std']:.2f}"
        for name, row in rows.items()
        if abs(row["estimate"]) > row["std"]
    ]
    if not moved:
        return []
    return ["    model form (effect sizes, prior 0 ± 1): " + ", ".join(moved)]


def _reference_lines(rows):
    """The reference's parameters of one unit: estimate ± std, and what they trade with."""
    lines = []
    for name, row in rows.items():
        state = "determined" if row["identifiable"] else "not determined"
        lines.append(
            f"    {name:<34}{row['estimate']:+10.4f} ± {row['std']:.4f} ({state}; "
            f"correlation {row['correlation']:+.2f} with {row['correlated_with']})"
        )
        if row["combination"] is not None:
            lines.append(f"        determined together: {row['combination']}")
    return lines


class IdentifyOptions(Options):
    """The options of ``reflector-opt identify``, declared once."""

    design: option(
        object,
        "the units' design (a Design or its design.json); the built-in design if left out",
        metavar="DESIGN.json",
    ) = None
    curves: option(
        tuple[str, ...],
        "a sensor's flat-target curve measured before assembly (the fit-sensor CSV, "
        "distance_mm in mm, volts in V); repeat for each sensor and unit, e.g. --curve "
        "1:S1=s1.csv",
        flag="--curve",
        metavar="[UNIT:]SENSOR=FILE",
        repeated=True,
    ) = ()
    tolerances: option(
        object,
        "tolerance config whose [tolerances] are the prior; the built-in ones if left out",
        metavar="FILE.toml",
    ) = None
    reference_sigma_deg: (
        option(
            float,
            "RMS noise of the angle reference at each pose, degrees; 0.05° if left out",
            flag="--reference-sigma",
            metavar="DEG",
            ge=0,
            le=5,
        )
        | None
    ) = None
    conditions: option(
        object,
        "operating conditions ([conditions] TOML) whose reference_zero_deg and "
        "reference_twist_deg are the prior std of the reference's zero offsets and twist; "
        "1.5°, 1.5° and 0.5° if left out",
        metavar="COND.toml",
    ) = None
    reference_zero: option(
        Literal["free", "fixed"],
        "free: fit each unit's reference zero offsets and twist; fixed: take the reference as "
        "exact (a known mechanical zero)",
    ) = "free"
    profiles: option(bool, "compute the profile-likelihood intervals") = True
    batch: option(
        str | None,
        "the print batch the units came from, recorded in AS_BUILT.json (correct pools only "
        "files of one batch)",
        metavar="NAME",
    ) = None
    accept_units: option(
        bool,
        "take the calibration CSV's and the curves' columns as given where they look like "
        "another unit (millivolts, radians, metres) or lie beyond the sensors' supply; "
        "refused by default",
    ) = False


@takes(IdentifyOptions)
def identify(data, options, progress=None):
    """Identify how the units of a calibration CSV were built, in memory: ``reflector-opt
    identify``; :meth:`IdentifyRun.write` writes ``AS_BUILT.json``.

    Parameters
    ----------
    data : str or pathlib.Path
        The calibration CSV (columns unit, v1, v2 in V, pitch_deg, roll_deg in degrees).
    options : IdentifyOptions
        As keyword arguments (below); the reference's noise and prior std default to
        :data:`reflector_opt.tolerance._builtunit.REFERENCE_SIGMA_DEG` and
        :data:`reflector_opt.asbuilt._parameters.REFERENCE_PRIOR_STD`.
    progress : callable, optional
        ``progress(fraction, message)`` as the work advances.

    Returns
    -------
    IdentifyRun

    Raises
    ------
    InputError
        A file that cannot be read or is in another unit, a bad curve spec or batch name,
        ``reference_zero`` fixed with ``conditions``, a unit that cannot be identified.
    """
    from reflector_opt.asbuilt._asbuiltfile import check_batch_name
    from reflector_opt.asbuilt._identify_files import identify_files
    from reflector_opt.design import as_design
    from reflector_opt.tolerance._builtunit import REFERENCE_SIGMA_DEG

    check_batch_name(options.batch)
    reference_std = _reference_prior(options.reference_zero, options.conditions)
    sigma_deg = options.reference_sigma_deg
    result = identify_files(
        as_design(options.design),
        data,
        options.curves,
        accept_units=options.accept_units,
        tolerances=_prior_tolerances(options.tolerances),
        reference_sigma_deg=REFERENCE_SIGMA_DEG if sigma_deg is None else sigma_deg,
        reference_std=reference_std,
        profiles=options.profiles,
        progress=progress,
    )
    return IdentifyRun(result, str(data), options.batch)


def _prior_tolerances(path):
    """The ``[tolerances]`` of a tolerance config, or None for the built-in ones."""
    from reflector_opt.tolerance._config import load_tolerance_config

    return None if path is None else load_tolerance_config(path).tolerances


def _reference_prior(reference_zero, conditions):
    """The reference's prior std from ``reference_zero`` and ``conditions`` (None: fixed)."""
    from reflector_opt.asbuilt._parameters import REFERENCE_PRIOR_STD, reference_std_of
    from reflector_opt.design._conditions import load_conditions
    from reflector_opt.util._errors import InputError

    if reference_zero == "fixed":
        if conditions is not None:
            raise InputError(
                "--reference-zero fixed takes the reference as exact, --conditions gives its "
                "errors; give one of them"
            )
        return None
    if conditions is None:
        return dict(REFERENCE_PRIOR_STD)
    return reference_std_of(load_conditions(conditions))
