"""Design report: its content, section by section, as blocks and the figures they refer to.

The files — a Markdown page with its figures as PNG files, one self-contained HTML file, and
the printable parts beside them — are written by :mod:`reflector_opt.report._outputs`.
The report is built once as a list of blocks (headings, paragraphs, tables, images) and
rendered to both formats from the same templates' input (:mod:`reflector_opt.report._render`),
so the two always say the same thing. It holds the design table, the interactive 3D view
of the parts and the sensors' beams (:mod:`reflector_opt.report._view3d`; in the HTML page),
the constraints and their slack (plain names, units, zero slack flagged), the sensor windows
with a section through each sensor's own plane, the resolution maps, the predicted
Table-I-style performance beside the paper's measured figures, the printability report with
links to the part files and their previews (or, for a design that cannot be printed, the
reason), and the print and material notes; given an ``AS_BUILT.json`` of the design, also how
each printed unit was built and what its deviations cost in resolution
(:mod:`reflector_opt.report._asbuilt`). The HTML page carries its images as base64 data
URIs, so it opens anywhere on its own; its links to the part files work beside them.
"""

import math
from pathlib import Path

from reflector_opt import __version__
from reflector_opt.analysis._metrics import evaluate_metrics
from reflector_opt.analysis._surface import surface_comparison
from reflector_opt.calibration._segment import AXES, simulate_segment
from reflector_opt.calibration._simulation import simulate_calibration
from reflector_opt.model._surface import MATERIALS
from reflector_opt.optimiser._evaluation import Evaluation
from reflector_opt.optimiser._problem import Problem
from reflector_opt.report._asbuilt import as_built_blocks, read_as_built
from reflector_opt.report._conditions import budget_in_use, conditions_blocks, in_use_block
from reflector_opt.report._correction import correction_blocks
from reflector_opt.report._frontier import frontier_blocks
from reflector_opt.report._in_use import in_use_lines
from reflector_opt.report._ranking import ranking_blocks
from reflector_opt.report._render import anchor
from reflector_opt.report._view3d import view_blocks
from reflector_opt.report.figures._calibration import (
    calibration_error_figure,
    segment_figure,
    tip_path_figure,
)
from reflector_opt.report.figures._resolution import (
    resolution_maps_figure,
    surface_resolution_figure,
)
from reflector_opt.report.figures._response import sensor_curve_figure, sensor_maps_figure
from reflector_opt.report.figures._sections import sensor_section_figure
from reflector_opt.tolerance._prediction import SEGMENT_MODEL, predicted_performance
from reflector_opt.util._errors import InputError

#: Section headings of the report, in order.
SECTIONS = (
    "Design",
    "3D view",
    "Constraints",
    "Sensor windows",
    "Resolution",
    "Predicted performance",
    "In use",
    "Printability",
    "Print and material",
)

#: Plain name of each of the optimiser's constraints (``reflector_opt.optimiser._constraints``).
CONSTRAINT_NAMES = {
    "distance_margin_mm": "distance window inside the usable range, at both ends",
    "axis_miss_fraction": "share of poses where an optical axis misses the reflector",
    "sensor_envelope_mm": "sensor and its backing, distance from the unit's axis",
    "reflector_envelope_mm": "reflector sphere, distance from the unit's axis",
    "bearing_clearance_mm": "gap between the shell's inner surface and the bearing",
    "wall_mm": "thinnest shell wall under the light spots",
    "window_wall_mm": "body wall above a sensor window",
    "fold_fraction": "share of poses where det J changes sign (a fold)",
    "separation_sigma": "smallest voltage separation of poses at least 1° apart",
    "printed_wall_mm": "thinnest wall of the printed parts",
}
#: Constraints on a share of poses that must be zero: their margin is always zero.
_SHARES = {"axis_miss_fraction", "fold_fraction"}
#: A margin smaller than this, times the constraint's scale, shows as zero (4 decimals).
_ZERO_MARGIN = 5e-5
#: Status of a met constraint with zero slack.
_ZERO_SLACK = "**met, zero slack**"


def _num(x, digits=3):
    if x is None:
        return "–"
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, int | float) and not math.isfinite(x):
        return "∞" if x > 0 else "−∞"
    return f"{x:.{digits}f}" if isinstance(x, float) else str(x)


def _vec(v, digits=3):
    return "(" + ", ".join(f"{c:.{digits}f}" for c in v) + ")"


def _design_blocks(design):
    r, ws, mech, noise = design.reflector, design.workspace, design.mechanics, design.noise
    rows = [
        ("reflector radius r_s", _num(r.radius_mm), "mm"),
        ("sphere centre s0", _vec(r.centre_mm), "mm"),
        ("shell inner radius", _num(r.inner_radius_mm), "mm"),
        ("reflectance", _num(r.reflectance), "–"),
        ("pitch range", f"{ws.pitch_deg[0]:g} to {ws.pitch_deg[1]:g}", "°"),
        ("roll range", f"{ws.roll_deg[0]:g} to {ws.roll_deg[1]:g}", "°"),
        ("grid step", f"{ws.step_deg:g}", "°"),
        ("unit diameter × height", f"{mech.unit_diameter_mm:g} × {mech.unit_height_mm:g}", "mm"),
        ("units × link length", f"{mech.n_units} × {mech.link_length_mm:g}", "mm"),
        ("minimum printable wall", f"{mech.min_wall_mm:g}", "mm"),
        ("voltage noise σ_V (total)", f"{noise.total_sigma_v * 1e3:.3f}", "mV"),
        ("ADC", f"{noise.adc_bits} bit, {noise.vref:g} V full scale", ""),
    ]
    sensors = [
        (s.name, m.name, _vec(s.position_mm), _vec(s.axis), f"{m.range_mm[0]:g}–{m.range_mm[1]:g}")
        for s, m in zip(design.sensors, design.models, strict=True)
    ]
    return [
        ("h2", "Design"),
        ("table", ("quantity", "value", "unit"), rows),
        (
            "table",
            ("sensor", "part", "position (mm)", "optical axis", "usable range (mm)"),
            sensors,
        ),
    ]


def _evaluate(design, step_deg):
    """The optimiser's evaluation of a design, and why its constraints do not apply, if so.

    The constraints come from a :class:`~reflector_opt.optimiser._problem.Problem` with the
    design's first sensor part, workspace, mechanics and noise; settings the optimiser rejects
    (e.g. a usable range too short for its margins) leave the metrics without constraints.
    """
    try:
        problem = Problem(
            sensor=design.models[0],
            workspace=design.workspace,
            mechanics=design.mechanics,
            noise=design.noise,
        )
    except InputError as exc:
        try:
            metrics = evaluate_metrics(design, step_deg)
        except InputError as err:
            return Evaluation(None, design, None, (), math.inf, error=str(err)), None
        return Evaluation(None, design, metrics, (), math.inf), str(exc)
    return problem.evaluate_design(design, step_deg), None


def _constraint_row(c):
    """Plain name, worst value, limit, slack, unit, status and key of one constraint."""
    share = c.name in _SHARES
    if not c.met:
        status = "**violated**"
    elif not share and abs(c.margin) < _ZERO_MARGIN * c.scale:
        status = _ZERO_SLACK
    else:
        status = "met"
    name, limit = CONSTRAINT_NAMES.get(c.name, c.name), f"{'≤' if c.upper else '≥'} {c.limit:g}"
    slack = "– (must be 0)" if share else _num(c.margin, 4)
    return (name, _num(c.value, 4), limit, slack, c.unit or "–", status, f"`{c.name}`")


def _constraint_blocks(evaluation, not_applicable):
    blocks = [("h2", "Constraints")]
    if evaluation.error is not None:
        return [*blocks, ("p", f"The design cannot be evaluated: {evaluation.error}.")]
    if not_applicable is not None:
        return [*blocks, ("p", f"The optimiser's constraints do not apply: {not_applicable}.")]
    verdict = (
        "Every constraint is met on the workspace grid."
        if evaluation.feasible
        else f"The design violates a constraint: {evaluation.describe_failure()}."
    )
    rows = [_constraint_row(c) for c in evaluation.constraints]
    blocks += [
        (
            "p",
            f"The optimiser's constraints on the {evaluation.metrics.step_deg:g}° workspace grid "
            "(worst value over the grid; slack: how far inside the limit, in the constraint's "
            "unit, negative when violated; key: the name in docs/optimiser.md). " + verdict,
        ),
        (
            "table",
            ("constraint", "worst value", "limit", "slack", "unit", "status", "key"),
            rows,
        ),
    ]
    zero = [row[0] for row in rows if row[5] == _ZERO_SLACK]
    if zero:
        blocks.append(
            (
                "p",
                f"**At the limit, with zero slack:** {'; '.join(zero)}. The design sits on "
                "these bounds: any build error in the wrong direction breaks them.",
            )
        )
    return blocks


def _window_blocks(design, metrics, figures):
    rows = [
        (
            s.name,
            f"{metrics.distance_min_mm[i]:.3f}–{metrics.distance_max_mm[i]:.3f}",
            _num(float(metrics.distance_margin_mm[i])),
            f"{metrics.volts_min[i]:.3f}–{metrics.volts_max[i]:.3f}",
        )
        for i, s in enumerate(design.sensors)
    ]
    blocks = [
        ("h2", "Sensor windows"),
        (
            "table",
            ("sensor", "distance d (mm)", "margin to usable range (mm)", "voltage (V)"),
            rows,
        ),
    ]
    for i, s in enumerate(design.sensors):
        name = f"sensor_curve_{i + 1}.png"
        figures[name] = sensor_curve_figure(design, i, metrics)
        blocks.append(("img", name, f"{s.name}: output voltage against distance, window shaded"))
    figures["sensor_maps.png"] = sensor_maps_figure(design)
    blocks.append(("img", "sensor_maps.png", "distance and voltage over pitch × roll"))
    blocks.append(
        (
            "p",
            "Each sensor in the vertical plane of its optical axis: the reflector sphere at the "
            "zero pose and at the poses of the sensor's smallest and largest distance d, the "
            "beam's 1/e radius up to the sphere, and along the axis the sensor part's usable "
            "range beside the distances the design uses.",
        )
    )
    for i, s in enumerate(design.sensors):
        name = f"section_{i + 1}.png"
        figures[name] = sensor_section_figure(design, i, metrics)
        blocks.append(("img", name, f"{s.name}: section through its own plane, beam and window"))
    return blocks


def _resolution_blocks(design, metrics, figures):
    rows = [
        ("worst 1σ pitch resolution", _num(metrics.worst_pitch_deg, 4), "°"),
        ("worst 1σ roll resolution", _num(metrics.worst_roll_deg, 4), "°"),
        ("worst condition number of J", _num(metrics.worst_condition, 2), "–"),
        ("fold fraction (det J changes sign)", _num(metrics.fold_fraction, 4), "–"),
        ("smallest separation of poses ≥ 1° apart", _num(metrics.min_separation_sigma, 1), "σ_V"),
    ]
    figures["resolution_maps.png"] = resolution_maps_figure(metrics, design)
    sweep = surface_comparison(design)
    figures["surface_resolution.png"] = surface_resolution_figure(sweep)
    surface_rows = [
        (
            _num(mine["specular_fraction"], 2),
            f"{_num(mine['worst_pitch_deg'], 4)} / {_num(mine['worst_roll_deg'], 4)}",
            f"{_num(base['worst_pitch_deg'], 4)} / {_num(base['worst_roll_deg'], 4)}",
        )
        for mine, base in zip(sweep["design"], sweep["default_design"], strict=True)
    ]
    reflector = design.reflector
    return [
        ("h2", "Resolution"),
        (
            "p",
            "Cramér–Rao 1σ resolution from the voltage Jacobian J and the design's noise "
            f"(σ_V = {metrics.sigma_v * 1e3:.3f} mV); see docs/optimiser.md.",
        ),
        ("table", ("quantity", "value", "unit"), rows),
        ("img", "resolution_maps.png", "resolution and condition number, worst pose marked"),
        ("h3", "Surface"),
        (
            "p",
            f"The reflector is modelled with reflectance ρ = {reflector.reflectance} of which "
            f"a share f = {reflector.specular_fraction} is mirror-like and the rest Lambertian "
            "(docs/model.md, surface model). The printed surface's f depends on the resin and "
            "the finish, so the worst-case resolution (1° grid) is shown against f, beside the "
            "default design's in the same unit (docs/optimiser.md).",
        ),
        (
            "table",
            ("f", "this design: pitch / roll (°)", "default design: pitch / roll (°)"),
            surface_rows,
        ),
        ("img", "surface_resolution.png", "worst-case resolution against the specular fraction"),
    ]


def _performance_blocks(design, seed, figures, predicted=None):
    blocks = [("h2", "Predicted performance")]
    if predicted is None:
        predicted = predicted_performance(design, seed=seed)
    calibration, segment = predicted.calibration, predicted.segment
    if calibration is None:
        return [*blocks, ("p", "Not predicted: the calibration models need exactly two sensors.")]
    blocks += _calibration_blocks(calibration, seed)
    result = simulate_calibration(design, SEGMENT_MODEL, seed=seed)
    figures["calibration_errors.png"] = calibration_error_figure(result)
    blocks.append(
        (
            "img",
            "calibration_errors.png",
            "Eq 6 estimation error over the workspace (a nominal unit on the forward model, "
            "for illustration)",
        )
    )
    if segment is None:
        return [*blocks, ("p", "No segment motion fits the workspace (it excludes 0°).")]
    blocks += _segment_blocks(segment, predicted.segment_recommended)
    for axis in AXES:
        errors = simulate_segment(
            design, result.model, axis, amplitude_deg=segment[axis]["amplitude_deg"], seed=seed
        )
        figures[f"segment_{axis}.png"] = segment_figure(errors)
        blocks.append(("img", f"segment_{axis}.png", f"estimated and actual tip {axis}"))
    figures["tip_paths.png"] = tip_path_figure(design, segment["pitch"]["amplitude_deg"])
    blocks.append(("img", "tip_paths.png", "segment and tip path over the motions"))
    return blocks


def _calibration_rows(calibration):
    """Error rows (model, angle, RMS, max, %, misfit, noise) of Eq 5, Eq 6 and the recommended."""
    rows = []
    for name in ("eq5", "eq6", "recommended"):
        c = getattr(calibration, name)
        label = f"{name} ({'/'.join(sorted(set(c.models)))})" if name == "recommended" else name
        for axis in AXES:
            rows.append(
                (
                    label,
                    axis,
                    _num(c.rms_deg[axis], 4),
                    _num(c.max_deg[axis], 4),
                    _num(c.percent_error[axis], 3),
                    _num(c.misfit_rms_deg[axis], 4),
                    _num(c.noise_rms_deg[axis], 4),
                )
            )
    return rows


def _calibration_blocks(calibration, seed):
    """The predicted calibration of built units: the protocol, the floor and the error table."""
    protocol, recommended = calibration.protocol, calibration.recommended
    floor = calibration.floor_rms_deg
    return [
        (
            "p",
            f"{protocol['n_units']} built units (drawn from the tolerance model, exact "
            "optics; docs/calibration.md) calibrated with Eq 5 and Eq 6 on the paper's "
            f"{protocol['step_deg']:g}° raster ({protocol['n_calibration']} poses) and with the "
            "recommended form, chosen by cross-validation, on a "
            f"{recommended.n_calibration}-pose {recommended.plan['pattern']}; each "
            f"validated at {protocol['n_validation']} random poses with the design's noise "
            f"and ADC and an angle reference of {protocol['reference_sigma_deg']:g}° RMS "
            f"(seed {seed}). The Cramér–Rao floor of these units is "
            f"{_num(floor.pitch, 4)}° / {_num(floor.roll, 4)}° RMS (pitch / roll); the "
            f"recommended form reaches {_num(recommended.floor_ratio.pitch, 3)}× / "
            f"{_num(recommended.floor_ratio.roll, 3)}× of it.",
        ),
        (
            "table",
            (
                "model",
                "angle",
                "RMS (°)",
                "max (°)",
                "% of span",
                "misfit RMS (°)",
                "noise RMS (°)",
            ),
            _calibration_rows(calibration),
        ),
    ]


def _segment_blocks(segment, recommended):
    """The predicted segment (Table I) of Eq 6 and of the recommended form, beside the paper's."""
    return [
        ("h3", "Segment (Table I)"),
        (
            "p",
            f"A segment of {segment['n_units']} built units, {segment['link_length_mm']:g} mm "
            "apart, each with its own calibration (Eq 6, then the recommended form), swept "
            "about each axis, beside the paper's measured figures (Osman et al. 2024, "
            "Table I). The prediction has the build errors, the calibration's error and the "
            "noise only: no hysteresis or cable effects.",
        ),
        (
            "table",
            (
                "model",
                "axis",
                "tip amplitude (°)",
                "RMS predicted (°)",
                "RMS paper (°)",
                "max predicted (°)",
                "max paper (°)",
                "% predicted",
                "% paper",
            ),
            [*_segment_rows(segment), *_segment_rows(recommended)],
        ),
    ]


#: Part files listed in the report, by key of the CAD report's file entries, in order.
_PART_FILES = {"stl": "STL", "3mf": "3MF", "step": "STEP"}


def _link(path):
    """A Markdown link to a file beside the report, named by its file name."""
    name = Path(path).name
    return f"[{name}]({name})"


def _file_rows(files):
    rows = []
    for part, entry in files.items():
        links = [
            f"{_link(entry[key])} ({label}, {entry[key + '_bytes'] / 1024:.0f} kB)"
            for key, label in _PART_FILES.items()
            if key in entry
        ]
        rows.append((part, "; ".join(links), str(entry["triangles"])))
    return rows


def _segment_rows(segment):
    """Table-I rows (model, axis, predicted and paper figures) of one segment block."""
    rows = []
    for axis in AXES:
        p, paper = segment[axis]["predicted"], segment[axis]["paper"]
        rows.append(
            (
                segment["model"],
                axis,
                f"±{segment[axis]['amplitude_deg']:g}",
                _num(p["rms_deg"], 3),
                _num(paper["rms_deg"], 2),
                _num(p["max_deg"], 3),
                _num(paper["max_deg"], 2),
                _num(p["percent_error"], 3),
                _num(paper["percent_error"], 2),
            )
        )
    return rows


def _printability_blocks(cad):
    blocks = [("h2", "Printability")]
    if cad is None:
        return [*blocks, ("p", "The CAD export was not run for this report.")]
    if cad.error is not None:
        return [
            *blocks,
            ("p", "**The design cannot be printed as it stands**; no parts were written:"),
            ("code", cad.error),
            ("p", "See docs/cad.md for the checks and printable variants."),
        ]
    rows = [
        (
            part,
            "yes" if r["ok"] else "**no**",
            "yes" if r["watertight"] and r["winding_consistent"] else "no",
            "yes" if r["inside_envelope"] else "no",
            f"{r['thinnest_wall_mm']:.3f} ({r['thinnest_wall']})",
            f"{r['min_wall_required_mm']:g}",
        )
        for part, r in cad.report["printability"].items()
    ]
    blocks += [
        ("p", "Every check passed; the parts are written beside this report."),
        (
            "table",
            ("part", "printable", "closed", "in envelope", "thinnest wall (mm)", "required (mm)"),
            rows,
        ),
        ("h3", "Part files"),
        (
            "p",
            "The files lie beside this report; the links work while the report stays in "
            f"their folder. The checks in full: {_link(cad.report['report'])}.",
        ),
        ("table", ("part", "files", "triangles"), _file_rows(cad.report["files"])),
    ]
    for part, entry in cad.report["files"].items():
        if "png" in entry:
            blocks.append(("img", Path(entry["png"]).name, f"{part} mesh preview"))
    return blocks


def _print_blocks(design):
    refl, mech = design.reflector, design.mechanics
    own = (refl.reflectance, refl.specular_fraction)
    material = next(
        (m for m in MATERIALS.values() if (m.reflectance, m.specular_fraction) == own), None
    )
    surface = (
        f"the `{material.name}` surface: {material.source}"
        if material is not None
        else "no preset surface: the values were set or measured for this design."
    )
    return [
        ("h2", "Print and material"),
        (
            "p",
            "The optics assume the printed reflector's surface; the rest of this section is "
            "practice for keeping it, not something the package checks.",
        ),
        (
            "table",
            ("assumption", "value", "where"),
            [
                (
                    "reflectance ρ of the printed surface",
                    _num(refl.reflectance, 3),
                    "`reflector.reflectance`",
                ),
                (
                    "mirror-like (specular) share f of ρ; the rest Lambertian",
                    _num(refl.specular_fraction, 3),
                    "`reflector.specular_fraction`",
                ),
                ("thinnest printable wall", f"{mech.min_wall_mm:g} mm", "`mechanics.min_wall_mm`"),
            ],
        ),
        ("p", f"Surface model (docs/model.md §2): {surface}"),
        (
            "p",
            "**Material.** The paper prints the reflector part in white resin on an SLA "
            "printer for its surface finish and the other parts in white PLA; the default "
            "surface is that white resin. Another resin, colour or finish changes ρ and f: "
            "measure a flat printed sample (`reflector-opt fit-sensor`, docs/guide.md) and "
            "put the values in design.json before trusting the predicted resolution.",
        ),
        (
            "p",
            "**Orientation and supports.** Print the reflector part with its flange on the "
            "build platform and the shaft pointing away from it, so that supports, where the "
            "slicer needs them, stand on the flange and the dome above the reflecting band. "
            "Keep every support and the platform off the reflecting patches (the spheres in "
            "the sensor sections): a support mark scatters light and changes ρ and f where "
            "the beam lands. Print the body on its bottom face; its sensor windows, strip "
            "channels and tendon holes then run along the build direction.",
        ),
        (
            "p",
            "**Resin and post-cure.** Wash and post-cure as the resin's maker specifies, "
            "then leave the patches as printed: no sanding, polishing or coating, which would "
            f"move f away from {_num(refl.specular_fraction, 2)}. A printer that cannot hold "
            f"{mech.min_wall_mm:g} mm walls needs a larger `mechanics.min_wall_mm` and a new "
            "design.",
        ),
    ]


def _title_blocks():
    """The report's title and what it is written by, in which units and frame."""
    return [
        ("h1", "Reflector design report"),
        (
            "p",
            f"Written by reflector-opt {__version__}. Lengths in mm, angles in degrees, pitch "
            "about y and roll about x (docs/conventions.md). Model and equations: "
            "Osman et al. (2024) and docs/model.md.",
        ),
    ]


def report_blocks(
    design, *, cad=None, seed=0, step_deg=None, predicted=None, as_built=None, conditions=None
):
    """The report's content as blocks, and the figures it refers to.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    cad : reflector_opt.report._outputs.CadOutcome, optional
        The CAD export's outcome (the printability section says it was not run if None).
    seed : int, optional
        Seed of the simulated calibration and segment motions.
    step_deg : float, optional
        Pose grid of the metrics, degrees (the workspace's step by default).
    predicted : reflector_opt.tolerance._prediction.Prediction, optional
        :func:`~reflector_opt.tolerance._prediction.predicted_performance` of the design, if
        already computed (with the same seed); computed here otherwise.
    as_built : str, pathlib.Path or reflector_opt.asbuilt._asbuiltfile.AsBuiltFile, optional
        ``AS_BUILT.json`` of units printed from this design: adds the as-built section
        (:func:`reflector_opt.report._asbuilt.as_built_blocks`) after the predicted performance.
    conditions : reflector_opt.design._conditions.Conditions, str or pathlib.Path, optional
        Operating conditions or their file (the default ones where None): the figures in use
        head the report (:func:`reflector_opt.report._in_use.in_use_lines`) and the "In
        use" section gives the error budget in them
        (:func:`reflector_opt.report._conditions.conditions_blocks`).

    Returns
    -------
    blocks : list of tuple
        ``("h1"|"h2"|"h3"|"p"|"code", text)``, ``("table", header, rows)``,
        ``("img", file name, caption)`` or ``("html", fragment, Markdown text)`` (the 3D
        view, :func:`reflector_opt.report._view3d.view_blocks`).
    figures : dict
        ``{file name: matplotlib.figure.Figure}``.

    Raises
    ------
    InputError
        The as-built file cannot be read or belongs to another design.
    """
    if as_built is not None:
        as_built = read_as_built(as_built, design)
    evaluation, not_applicable = _evaluate(design, step_deg)
    figures, head = {}, _title_blocks()
    if evaluation.error is None:
        budget = budget_in_use(design, conditions)
        in_use = in_use_block(design, conditions, budget)
        sentences = (line.strip() for line in in_use_lines(in_use))
        head += [("p", f"{text[0].upper()}{text[1:]}.") for text in sentences]
    blocks = [*_design_blocks(design), *view_blocks(design)]
    blocks += _constraint_blocks(evaluation, not_applicable)
    if evaluation.error is None:
        metrics = evaluation.metrics
        blocks += _window_blocks(design, metrics, figures)
        blocks += _resolution_blocks(design, metrics, figures)
        blocks += _performance_blocks(design, seed, figures, predicted)
    if as_built is not None:
        blocks += as_built_blocks(as_built, design, figures, step_deg)
    if evaluation.error is None:
        blocks += conditions_blocks(design, figures, budget)
    blocks += correction_blocks(design)
    blocks += ranking_blocks(design) + frontier_blocks(design, figures)
    blocks += _printability_blocks(cad)
    blocks += _print_blocks(design)
    headings = [b[1] for b in blocks if b[0] == "h2"]
    contents = ("p", "Contents: " + " · ".join(f"[{h}](#{anchor(h)})" for h in headings) + ".")
    return [*head, contents, *blocks], figures
