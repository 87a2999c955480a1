"""The as-built section of the design report: how printed units were built, and what it costs.

From an ``AS_BUILT.json`` of the report's design
(:mod:`reflector_opt.asbuilt._asbuiltfile`, written by ``reflector-opt identify``):

* **the print beside the design** — per unit and per parameter the design value, the
  estimated deviation with its standard uncertainty and its 90 % interval (the
  profile-likelihood interval where the identification computed one, else the normal
  approximation ±1.645 std), the prior std and whether the data determine it;
* **which deviations cost resolution** — the worst-case and RMS Cramér–Rao 1σ resolution
  (:func:`reflector_opt.analysis._resolution.resolution_over_poses`) of each unit as built
  (its geometry, the batch's surface and its sensors' gains) beside the nominal design's, and
  the determined deviations ranked by how much each one alone, applied to the nominal
  design, changes the worst-case resolution;
* **the determinable combinations**, in words, as the identification named them;
* **the angle reference** of each unit's calibration — its zero offsets and twist as found,
  whether the data determine them, the parameter each trades with (the posterior
  correlation) and the combination the data determine instead — or that it was taken as
  exact.

An offset shifts a voltage without changing its slope, so it never changes the resolution;
a gain scales the slope of its sensor's voltage while the noise stays.
"""

import functools
import math
from statistics import NormalDist

import numpy as np

from reflector_opt.analysis._jacobian import jacobian_from_stencil, stencil_poses
from reflector_opt.analysis._resolution import resolution_over_poses
from reflector_opt.asbuilt._asbuiltfile import AsBuiltFile, load_as_built
from reflector_opt.asbuilt._parameters import ParameterLayout
from reflector_opt.asbuilt._uncertainty import DETERMINED_RATIO
from reflector_opt.design._designfile import first_difference
from reflector_opt.model._forward import respond
from reflector_opt.report.figures._asbuilt import as_built_deviation_figure
from reflector_opt.util._errors import InputError

#: Heading of the section.
AS_BUILT_SECTION = "As built"

#: Half-width of the normal 90 % interval in standard deviations (1.645).
NORMAL_90 = NormalDist().inv_cdf(0.95)

#: Keys of ``design.json`` that may differ between the report's design and the as-built
#: file's: the free-form predictions, the record of a print correction (the geometry it
#: produced is compared) and the grid step (a choice of evaluation, not of print).
_IGNORED = {("predicted",), ("correction",), ("workspace", "step_deg")}

#: Relative tolerance of two numbers of a design that count as equal (JSON round trips).
_REL_TOL = 1e-9


def read_as_built(as_built, design):
    """An as-built file of the report's design, read and checked.

    Parameters
    ----------
    as_built : str, pathlib.Path or reflector_opt.asbuilt._asbuiltfile.AsBuiltFile
        A path to ``AS_BUILT.json`` or the file already read.
    design : reflector_opt.design._design.Design
        The report's design.

    Returns
    -------
    AsBuiltFile

    Raises
    ------
    InputError
        The file cannot be read, or it was identified for another design
        (:func:`check_same_design`).
    """
    if isinstance(as_built, AsBuiltFile):
        check_same_design(as_built, design)
        return as_built
    read = load_as_built(as_built)
    check_same_design(read, design, str(as_built))
    return read


def check_same_design(as_built, design, name="as-built file"):
    """Refuse an as-built file identified for another design than the report's.

    Every key of ``design.json`` must agree (numbers to a relative 1e-9), except the
    ``predicted`` and ``correction`` records and the workspace's grid step.

    Parameters
    ----------
    as_built : reflector_opt.asbuilt._asbuiltfile.AsBuiltFile
    design : reflector_opt.design._design.Design
        The report's design.
    name : str, optional
        The file's name in the message.

    Raises
    ------
    InputError
        One line naming the first key that differs and both values.
    """
    found = first_difference(
        design.to_dict(), as_built.design.to_dict(), ignored=_IGNORED, rel_tol=_REL_TOL
    )
    if found is not None:
        key, mine, theirs = found
        raise InputError(
            f"{name}: identified for another design ({key} is {theirs!r} there, {mine!r} in "
            "the report's design); report the design the units were printed from"
        )


def parameter_unit(name):
    """The unit of an as-built parameter from its name: mm, °, V or – (a number)."""
    units = (("_mm", "mm"), ("_deg", "°"), ("_v", "V"))
    return next((unit for suffix, unit in units if name.endswith(suffix)), "–")


def deviation_records(parameters):
    """Each parameter's deviation from the design, its uncertainty and its 90 % interval.

    Parameters
    ----------
    parameters : dict
        ``{name: {estimate, design, std, prior_std, identifiable, interval_90?}}`` as in
        ``AS_BUILT.json`` (values in the unit the name ends with).

    Returns
    -------
    list of dict
        Per parameter, in the file's order: ``name``, ``unit``, ``design``, ``deviation``
        (estimate − design), ``std``, ``low`` and ``high`` (the 90 % interval of the
        deviation), ``interval`` (``"profile"``, ``"profile, open"`` — the profile reached
        the fit's bound — or ``"normal"``: ±1.645 std), ``prior_std``, ``z`` (deviation over
        prior std), ``z_std`` (std over prior std) and ``determined``.
    """
    records = []
    for name, row in parameters.items():
        deviation, std, prior = row["estimate"] - row["design"], row["std"], row["prior_std"]
        profile = row.get("interval_90")
        if profile is not None:
            low, high = profile["low"] - row["design"], profile["high"] - row["design"]
            interval = "profile" if profile["closed"] else "profile, open"
        else:
            low, high, interval = deviation - NORMAL_90 * std, deviation + NORMAL_90 * std, "normal"
        records.append(
            {
                "name": name,
                "unit": parameter_unit(name),
                "design": row["design"],
                "deviation": deviation,
                "std": std,
                "low": low,
                "high": high,
                "interval": interval,
                "prior_std": prior,
                "z": deviation / prior if prior > 0 else 0.0,
                "z_std": std / prior if prior > 0 else 0.0,
                "determined": bool(row["identifiable"]),
            }
        )
    return records


def unit_resolution(design, mismatch=None, step_deg=None):
    """Worst-case and RMS Cramér–Rao 1σ resolution of a unit over its workspace grid.

    The voltage Jacobian of the fast model on the central-difference stencil (as
    :func:`reflector_opt.analysis._metrics.evaluate_metrics`), each sensor's row scaled by its
    gain, and the design's σ_V (noise and quantisation).

    Parameters
    ----------
    design : reflector_opt.design._design.Design
        The unit's geometry and surface.
    mismatch : reflector_opt.model._noise.Mismatch, optional
        Its read-out: the gains scale the Jacobian (the offsets do not enter). Default: none.
    step_deg : float, optional
        Pose grid step, degrees (the workspace's own by default).

    Returns
    -------
    dict
        ``worst_pitch_deg``, ``worst_roll_deg``, ``rms_pitch_deg``, ``rms_roll_deg`` and
        ``worst_deg`` (the larger worst case), degrees; ``inf`` without sensitivity.
    """
    step = design.workspace.step_deg if step_deg is None else float(step_deg)
    pitch, roll = design.workspace.grid(step)
    _, jacobian = jacobian_from_stencil(respond(design, *stencil_poses(pitch, roll)).volts)
    if mismatch is not None:
        jacobian = jacobian * np.asarray(mismatch.gain, dtype=float)[:, None]
    found = resolution_over_poses(jacobian, design.noise.total_sigma_v)
    (worst_pitch, worst_roll), (rms_pitch, rms_roll) = found.worst_deg, found.rms_deg
    return {
        "worst_pitch_deg": float(worst_pitch),
        "worst_roll_deg": float(worst_roll),
        "rms_pitch_deg": float(rms_pitch),
        "rms_roll_deg": float(rms_roll),
        "worst_deg": found.worst,
    }


def single_deviation(design, name, deviation):
    """The nominal design with one as-built parameter moved by ``deviation``.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    name : str
        A parameter of :class:`~reflector_opt.asbuilt._parameters.ParameterLayout` (shared or of a
        unit, e.g. ``sensor_1_standoff_mm``).
    deviation : float
        In the parameter's unit (the gain: the factor minus 1).

    Returns
    -------
    (reflector_opt.design._design.Design, reflector_opt.model._noise.Mismatch)
        Raises :class:`~reflector_opt.util._errors.InputError` if that unit cannot exist
        (e.g. a sensor inside the sphere).
    """
    layout = ParameterLayout(design, 1)
    names = [*layout.shared_names, *layout.unit_names]
    if name not in names:
        raise InputError(f"as-built parameter {name!r}: not a parameter of this design")
    x = np.zeros(layout.size)
    x[names.index(name)] = deviation
    return layout.unit_design(x, 0)


def _words(layout):
    """Parameter name → plain words (the name itself for a kind without words)."""

    def words(name):
        try:
            return layout.words(name)
        except (KeyError, ValueError):
            return name.replace("_", " ")

    return words


def _alone(design, step_deg, name, deviation):
    """Worst-case resolution of the nominal design with one deviation, and why not, if so."""
    try:
        built, mismatch = single_deviation(design, name, deviation)
        return unit_resolution(built, mismatch, step_deg)["worst_deg"], None
    except InputError as exc:
        return math.inf, str(exc)


def resolution_costs(as_built, design, step_deg=None):
    """Each unit's resolution as built beside the nominal design's, and what each deviation costs.

    Parameters
    ----------
    as_built : reflector_opt.asbuilt._asbuiltfile.AsBuiltFile
        Identified for ``design`` (:func:`check_same_design`).
    design : reflector_opt.design._design.Design
        The nominal design; its workspace gives the grid.
    step_deg : float, optional
        Pose grid step, degrees (the workspace's own by default).

    Returns
    -------
    dict
        ``nominal``: :func:`unit_resolution` of the design; ``units``: per unit ``unit`` (its
        label), ``resolution`` (as built: its geometry, the batch's surface and its gains)
        and ``costs``, the determined deviations (the batch's surface and the unit's) largest
        effect first, each with ``name``, ``deviation``, ``std``, ``unit``, ``worst_deg``
        (the nominal design with that deviation alone), ``change_deg`` (minus the nominal
        worst case), ``change_percent`` and ``error`` (why that unit could not be evaluated,
        or None).
    """
    step = design.workspace.step_deg if step_deg is None else float(step_deg)
    nominal = unit_resolution(design, step_deg=step)
    alone = functools.cache(functools.partial(_alone, design, step))  # each deviation once
    units = []
    for unit in as_built.units:
        built = unit["as_built"].replace(workspace=design.workspace)
        records = deviation_records({**as_built.shared, **unit["parameters"]})
        costs = []
        for record in (r for r in records if r["determined"]):
            worst, error = alone(record["name"], record["deviation"])
            change = worst - nominal["worst_deg"]
            costs.append(
                {
                    **{k: record[k] for k in ("name", "deviation", "std", "unit")},
                    "worst_deg": worst,
                    "change_deg": change,
                    "change_percent": 100.0 * change / nominal["worst_deg"],
                    "error": error,
                }
            )
        resolution = unit_resolution(built, unit["read_out"], step)
        # by the size of the change of the worst case (none where NaN), largest first
        costs.sort(key=lambda cost: abs(np.nan_to_num(cost["change_deg"], nan=0.0)), reverse=True)
        units.append({"unit": unit["unit"], "resolution": resolution, "costs": costs})
    return {"nominal": nominal, "units": units, "step_deg": step}


# --- the section's blocks ---------------------------------------------------------------------


def _number(x, digits=4, sign=False):
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "–"
    if not math.isfinite(x):
        return "∞" if x > 0 else "−∞"
    return f"{x:+.{digits}f}" if sign else f"{x:.{digits}f}"


def _interval(record):
    text = f"{_number(record['low'], sign=True)} to {_number(record['high'], sign=True)}"
    marks = {"profile": "", "profile, open": " (open)", "normal": " (normal)"}
    return text + marks[record["interval"]]


def parameter_rows(records, words):
    """Table rows of :func:`deviation_records`: the design beside the print.

    Parameters
    ----------
    records : list of dict
    words : callable
        Parameter name → plain words.

    Returns
    -------
    list of tuple
        parameter, unit, design value, deviation ± std, 90 % interval of the deviation,
        prior std, std over prior std, determined (yes/no), key.
    """
    return [
        (
            words(r["name"]),
            r["unit"],
            _number(r["design"]),
            f"{_number(r['deviation'], sign=True)} ± {_number(r['std'])}",
            _interval(r),
            _number(r["prior_std"]),
            _number(r["z_std"], 2),
            "**yes**" if r["determined"] else "no",
            f"`{r['name']}`",
        )
        for r in records
    ]


_PARAMETER_HEADER = (
    "parameter",
    "unit",
    "design",
    "deviation ± std",
    "90 % interval of the deviation",
    "prior std",
    "std / prior std",
    "determined",
    "key",
)


def _print_blocks(as_built, words, figures):
    """The batch's surface and each unit's parameters beside the design, and the figure."""
    shared = deviation_records(as_built.shared)
    blocks = [("h3", "Batch surface"), ("table", _PARAMETER_HEADER, parameter_rows(shared, words))]
    series = [("batch surface", shared)]
    for unit in as_built.units:
        records = deviation_records(unit["parameters"])
        series.append((f"unit {unit['unit']}", records))
        determined = sum(r["determined"] for r in records)
        residual = ", ".join(f"{v * 1e3:.2f}" for v in unit.get("residual_rms_v", []))
        blocks += [
            ("h3", f"Unit {unit['unit']}"),
            (
                "p",
                f"{unit.get('n_samples', 0)} calibration samples, "
                f"{unit.get('n_curves', 0)} flat-target curves; the data determine "
                f"{determined} of its {len(records)} parameters"
                + (f"; RMS voltage misfit per sensor {residual} mV." if residual else "."),
            ),
            ("table", _PARAMETER_HEADER, parameter_rows(records, words)),
            *_reference_blocks(unit["unit"], unit.get("reference"), words),
        ]
    names = {r["name"]: words(r["name"]) for _, records in series for r in records}
    figures["as_built_deviations.png"] = as_built_deviation_figure(series, names)
    blocks.append(
        (
            "img",
            "as_built_deviations.png",
            "deviations from the design in prior std, ±1 std bars; filled: determined",
        )
    )
    return blocks


def _reference_blocks(label, rows, words):
    """What unit ``label``'s calibration says about its angle reference, or that it was
    taken as exact."""
    heading = ("h3", f"Angle reference of unit {label}")
    if not rows:
        return [heading, ("p", "Taken as exact (its zero anchored): not fitted.")]
    found = []
    for name, row in rows.items():
        deviation = row["estimate"] - row["design"]
        if row["identifiable"]:
            found.append(f"{words(name)} {_number(deviation, 2, sign=True)}°")
    table = [
        (
            words(name),
            f"{_number(row['estimate'] - row['design'], 3, sign=True)} ± {_number(row['std'], 3)}",
            _number(row["prior_std"], 2),
            "**yes**" if row["identifiable"] else "no",
            f"{words(row['correlated_with'])} ({_number(row['correlation'], 2, sign=True)})",
            row["combination"] or "–",
        )
        for name, row in rows.items()
    ]
    said = "; ".join(found) if found else "none of its parameters on its own"
    return [
        heading,
        (
            "p",
            f"The reference this unit was calibrated against (degrees): the data determine {said}. "
            "Where a parameter is not determined, the data cannot tell it from the print "
            "parameter it is most correlated with (a zero offset of the reference is the "
            "sphere's centre rotated about the joint): only their combination is known.",
        ),
        (
            "table",
            ("reference", "found ± std (°)", "prior std (°)", "determined",
             "most correlated with", "determined together"),
            table,
        ),
    ]  # fmt: skip


def _resolution_row(label, resolution, nominal=None, costs=()):
    """One row of the resolution table: the change of the worst case against ``nominal``, and
    the sum of the changes of the determined deviations alone."""
    percent = None
    if nominal is not None:
        percent = 100.0 * (resolution["worst_deg"] / nominal["worst_deg"] - 1.0)
    summed = sum(c["change_percent"] for c in costs) if costs else None
    return (
        label,
        _number(resolution["worst_pitch_deg"]),
        _number(resolution["worst_roll_deg"]),
        _number(resolution["rms_pitch_deg"]),
        _number(resolution["rms_roll_deg"]),
        "–" if percent is None else f"{_number(percent, 1, sign=True)} %",
        "–" if summed is None else f"{_number(summed, 1, sign=True)} %",
    )


def _cost_blocks(costs, words):
    """The resolution of each unit as built, and its deviations ranked by their cost."""
    nominal = costs["nominal"]
    rows = [_resolution_row("design (nominal)", nominal)]
    rows += [
        _resolution_row(f"unit {u['unit']}", u["resolution"], nominal, u["costs"])
        for u in costs["units"]
    ]
    ranked = [
        (
            u["unit"],
            words(c["name"]),
            f"{_number(c['deviation'], sign=True)} ± {_number(c['std'])}"
            + ("" if c["unit"] == "–" else f" {c['unit']}"),
            _number(c["worst_deg"]),
            _number(c["change_deg"], sign=True),
            f"{_number(c['change_percent'], 2, sign=True)} %",
        )
        for u in costs["units"]
        for c in u["costs"]
    ]
    return [
        ("h3", "Resolution as built"),
        (
            "p",
            "Cramér–Rao 1σ resolution over the workspace grid "
            f"({costs['step_deg']:g}° step) of each unit as built — its geometry, the batch's "
            "surface and its sensors' gains — beside the nominal design's: the worst case over "
            "the grid and the RMS over it. The change is that of the worst case (the larger of "
            "pitch and roll); beside it, the sum of the changes the determined deviations make "
            "each alone (below). The rest comes from the deviations the data do not determine, "
            "whose estimates stay near the prior's zero, and from the deviations acting together.",
        ),
        (
            "table",
            (
                "",
                "worst pitch (°)",
                "worst roll (°)",
                "RMS pitch (°)",
                "RMS roll (°)",
                "change",
                "determined ones alone, summed",
            ),
            rows,
        ),
        ("h3", "Which deviations cost resolution"),
        (
            "p",
            "Each deviation the data determine, applied alone to the nominal design (the "
            "estimate), and the worst-case resolution it leaves; per unit, the largest change "
            "first. A deviation the data do not determine is not ranked: its estimate is "
            "mostly the prior's zero. An offset never changes the resolution.",
        ),
        (
            "table",
            ("unit", "deviation", "estimate ± std", "worst case alone (°)", "change (°)", "change"),
            ranked,
        ),
    ]


def _combination_blocks(as_built):
    rows = [
        (u["unit"], c["name"], _number(c["posterior_prior_ratio"], 3))
        for u in as_built.units
        for c in u.get("determined", [])
    ]
    return [
        ("h3", "Determinable combinations"),
        (
            "p",
            "The combinations of parameters the calibration data determine (posterior std at "
            f"most {DETERMINED_RATIO:g}× the prior's along them), strongest first, each named "
            "by its main terms with the sign of its weight (weights in prior-std units, "
            "AS_BUILT.json `determined`). The data fix such a combination even where they "
            "cannot tell its terms apart: there a single parameter stays near its prior.",
        ),
        ("table", ("unit", "combination", "std / prior std"), rows or [("–", "none", "–")]),
    ]


def as_built_blocks(as_built, design, figures, step_deg=None):
    """The report's as-built section.

    Parameters
    ----------
    as_built : reflector_opt.asbuilt._asbuiltfile.AsBuiltFile
        Identified for ``design`` (:func:`read_as_built` checks it).
    design : reflector_opt.design._design.Design
        The report's design.
    figures : dict
        ``{file name: Figure}``; the section's figure is added.
    step_deg : float, optional
        Pose grid of the resolution, degrees (the workspace's step by default).

    Returns
    -------
    list of tuple
        Report blocks (see :func:`reflector_opt.report._report.report_blocks`).
    """
    words = _words(ParameterLayout(as_built.design, len(as_built.units)))
    fit = as_built.document.get("fit", {})
    source = ", ".join(
        f"{key} {as_built.document[key]}"
        for key in ("batch", "source")
        if as_built.document.get(key)
    )
    blocks = [
        ("h2", AS_BUILT_SECTION),
        (
            "p",
            f"How {len(as_built.units)} printed unit(s) were built, identified from their "
            f"calibration data{f' ({source})' if source else ''} with the tolerance model as "
            "the prior (`reflector-opt identify`). Each parameter is a deviation from the "
            "design (the radius and the gain: the design value is absolute) with its standard "
            "uncertainty; its 90 % interval is the profile-likelihood interval where one was "
            "computed, else ±1.645 std (normal); (open): the profile reached the fit's bound. "
            f"Determined: the posterior std is at most {DETERMINED_RATIO:g}× the prior std. "
            f"Residuals were {math.sqrt(fit.get('noise_inflation', 1.0)):.2f}× the noise.",
        ),
    ]
    blocks += _print_blocks(as_built, words, figures)
    try:
        costs = resolution_costs(as_built, design, step_deg)
    except InputError as exc:
        blocks += [("h3", "Resolution as built"), ("p", f"Not evaluated: {exc}.")]
    else:
        blocks += _cost_blocks(costs, words)
    return blocks + _combination_blocks(as_built)
