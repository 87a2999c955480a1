"""Fit the sensor catalogue's models to their datasheet figures, and print or write them.

    python benchmarks/fit_catalogue.py            # fit every part, print the table
    python benchmarks/fit_catalogue.py --write    # also write the models into the catalogue
    python benchmarks/fit_catalogue.py --part VCNT2020 --spacing-scale 1.25

Each part but the NJL5901R-2 (whose model is the preset, unchanged) is fitted by
:func:`reflector_opt.model._catalogue_fit.fit_part`: ω0, θ, G and — where the spacing is
assumed — e, to the peak distance, the range's ends and the output current at the test
condition, on the test target. Its load R2 is then matched to the NJL5901R-2 preset's output
swing, and its usable range set: from 1.25 × the model's peak distance (as the NJL5901R-2's
published 0.5 mm lies against its 0.39 mm peak) to the published far end, or, where no range
is published, to where the model's output falls to 20 % of its peak (Vishay's definition).
``--write`` rewrites the ``[part.model]`` tables and the ``usable_range_mm`` figures of
``reflector_opt/data/sensor_catalogue.toml`` in place; everything else in the file is kept.
"""

from __future__ import annotations

import argparse
import math
import re
import sys
import time
from pathlib import Path

from msgspec.structs import replace

from reflector_opt.model._catalogue import load_catalogue
from reflector_opt.model._catalogue_fit import (
    DIVERGENCE_PRIOR_DEG,
    fit_part,
    flat_peak,
    level_distances,
    matched_load_ohm,
)
from reflector_opt.model._sensors import get_preset

CATALOGUE = Path(__file__).resolve().parents[1] / "reflector_opt" / "data" / "sensor_catalogue.toml"
#: Parts whose usable range ends where the model's output falls to 20 % (no range published).
MODELLED_FAR = ("EE-SY193", "QRE1113", "ITR8307")
#: Parts whose model is a preset, not a fit.
PRESET_PARTS = ("NJL5901R-2",)
#: The near end of the usable range in units of the model's peak distance.
NEAR_FACTOR = 1.25


def fitted_model(part, spacing_scale=1.0, angle_scale=1.0):
    """The fitted model of a part (R2 matched, usable range set) and the fit.

    Parameters
    ----------
    part : reflector_opt.model._catalogue.CataloguePart
    spacing_scale : float, optional
        Factor on the assumed emitter–detector spacing (the prior's centre), for the
        sensitivity tables.
    angle_scale : float, optional
        Factor on the tangent of the assumed emitter angle (the prior's centre on θ).

    Returns
    -------
    (SensorModel, FitResult)
    """
    figures = dict(part.figures)
    spacing = figures["emitter_detector_mm"]
    figures["emitter_detector_mm"] = replace(spacing, value=spacing.value * spacing_scale)
    fit_spacing = spacing.kind not in ("published", "measured")
    base = get_preset("NJL5901R-2").with_(
        name=part.name,
        detector_area_mm2=part.model.detector_area_mm2,
        package_mm=part.model.package_mm,
    )
    theta = math.degrees(math.atan(angle_scale * math.tan(math.radians(DIVERGENCE_PRIOR_DEG))))
    fit = fit_part(figures, base, fit_spacing=fit_spacing, divergence_prior_deg=theta)
    model = fit.model
    model = model.with_(load_resistor_ohm=matched_load_ohm(model, get_preset("NJL5901R-2")))
    target = figures["test_target"].value
    peak = flat_peak(model, target)
    near = round(NEAR_FACTOR * peak[0], 2)
    usable = figures["usable_range_mm"]
    if usable.kind in ("published", "measured"):
        near, far = usable.value
    elif "range_mm" in figures:
        far = figures["range_mm"].value[1]
    elif part.name in MODELLED_FAR:
        far = round(level_distances(model, 0.2, target, peak)[1], 2)
    else:
        far = figures["usable_range_mm"].value[1]
    return model.with_(range_mm=(near, far)), fit


def _number(x):
    text = f"{x:.6g}"
    return text if any(c in text for c in ".e") else text + ".0"


def model_table(model):
    """The ``[part.model]`` table of a model, TOML lines."""
    d = model.to_dict()
    lines = ["[part.model]", f'name = "{d["name"]}"']
    for key, value in d.items():
        if key == "name":
            continue
        if isinstance(value, list):
            lines.append(f"{key} = [{', '.join(_number(v) for v in value)}]")
        else:
            lines.append(f"{key} = {_number(value)}")
    return lines


def write_models(models, path=CATALOGUE):
    """Rewrite the ``[part.model]`` tables and ``usable_range_mm`` values of the given parts."""
    text = path.read_text(encoding="utf-8")
    sections = re.split(r"(?m)^(?=\[\[part\]\])", text)
    out = []
    for section in sections:
        name = re.search(r'(?m)^name = "([^"]+)"', section)
        model = models.get(name.group(1)) if name and section.startswith("[[part]]") else None
        if model is not None:
            lo, hi = model.range_mm
            section = re.sub(
                r"(?m)^(usable_range_mm = \{ value = )\[[^\]]*\]",
                lambda m, lo=lo, hi=hi: f"{m.group(1)}[{_number(lo)}, {_number(hi)}]",
                section,
            )
            section = re.sub(
                r"(?ms)^\[part\.model\]\n.*?(?=^\[|\Z)",
                "\n".join(model_table(model)) + "\n\n",
                section,
            )
        out.append(section)
    path.write_text("".join(out), encoding="utf-8")


def main(argv=None):
    """Fit, print and optionally write the catalogue's models."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help="write the models into the file")
    parser.add_argument("--part", action="append", help="only these parts")
    parser.add_argument("--spacing-scale", type=float, default=1.0)
    args = parser.parse_args(argv)
    parts = load_catalogue(CATALOGUE, check=False)
    models = {}
    print(
        "| part | e (mm) | ω0 (mm) | θ (°) | G | R2 (kΩ) | usable (mm) | peak (mm) | range (mm) "
        "| I_test (mA) | worst residual (σ) | s |"
    )
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for part in parts:
        if part.name in PRESET_PARTS or (args.part and part.name not in args.part):
            continue
        t0 = time.perf_counter()
        model, fit = fitted_model(part, args.spacing_scale)
        models[part.name] = model
        p = fit.predicted
        fitted = {k: v for k, v in fit.residuals.items() if not k.startswith("prior")}
        worst = max(fitted, key=lambda k: abs(fitted[k]))
        span = "–".join(f"{v:.2f}" for v in p["range_mm"]) if "range_mm" in p else "—"
        print(
            f"| {part.name} | {model.emitter_detector_mm:.3f} | {model.source_radius_mm:.3f} | "
            f"{model.divergence_deg:.1f} | {model.current_gain:.3g} | "
            f"{model.load_resistor_ohm / 1e3:.2f} | "
            f"{model.range_mm[0]:.2f}–{model.range_mm[1]:.2f} | {p['peak_distance_mm']:.3f} | "
            f"{span} | {1e3 * p['output_current_a']:.3f} | "
            f"{worst} {fitted[worst]:+.2f} | {time.perf_counter() - t0:.1f} |"
        )
    if args.write:
        write_models(models)
        load_catalogue(CATALOGUE)  # every model reproduces its figures
        print(f"wrote {len(models)} models into {CATALOGUE}", file=sys.stderr)


if __name__ == "__main__":
    main()
