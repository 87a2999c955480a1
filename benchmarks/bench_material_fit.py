"""How well ``fit-sensor --material`` finds a coupon's reflectance, on built units.

For ``--units`` built units of the sample design (examples/data/design.json, print seed 29:
the sample data's tolerances and read-out gains and offsets), each physics case of
:class:`reflector_opt.tolerance._model_form.ModelForm` — the defaults, the defaults with a
0.3 mm sub-surface spread, the defaults with a two-Gaussian LED — gives sensor S1's curve on
a coupon of the unit's resin (ρ 0.90, the unit's drawn f) and on two references: a white card
(ρ 0.90, f 0, opaque) and a first-surface mirror (ρ 0.87, f 1), each with the LED and the
in-package light of the case, at the sample data's distances and with the design's noise.
:func:`reflector_opt.model._material_fit.fit_material` fits the coupon jointly with each
reference. The table gives, per case and reference, how many fits were refused (misfit or
f not determined), and of the others the largest |ρ − 0.90|, the share whose 90 % interval
of ρ holds 0.90, the median interval width, and the share whose interval of f holds the
unit's f.

The built units' flat curves are computed with the sub-surface spread's quadrature refined
to 12 × 12 nodes (``tolerance.builtunit.FLAT_CURVE_ORDERS`` leaves the exact reference's default
4 × 8, which at ℓ = 0.3 mm puts a coupon's reading at 0.3 mm 112 mV off, and at ℓ = 0.1 mm
under 2 mV; docs/model.md, "Measuring the material").

Run from the repository root (about four minutes with the defaults on one core):

    python benchmarks/bench_material_fit.py [--units 5]
"""

from __future__ import annotations

import argparse
import os
import sys
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import numpy as np  # noqa: E402

from reflector_opt.design import load_design  # noqa: E402
from reflector_opt.model._flat_target import MeasuredCurve  # noqa: E402
from reflector_opt.model._material_fit import fit_material  # noqa: E402
from reflector_opt.model._measured import read_curve_csv  # noqa: E402
from reflector_opt.tolerance._builtunit import FLAT_CURVE_ORDERS, build_unit  # noqa: E402
from reflector_opt.tolerance._model_form import ModelForm  # noqa: E402

SAMPLE = ROOT / "examples" / "data"
CASES = {
    "defaults": ModelForm(),
    "spread 0.3 mm": ModelForm(subsurface_mm=0.3),
    "two-Gaussian LED": ModelForm(emitter_pattern="two_gaussian"),
}
REFERENCES = {"white card": (0.9, 0.0), "mirror": (0.87, 1.0)}


def _facing(unit, reflectance, fraction, model_form):
    """The unit with its sensor facing a reference: the case's LED and in-package light."""
    reflector = replace(unit.design.reflector, reflectance=reflectance, specular_fraction=fraction)
    only = model_form.only("emitter_pattern", "crosstalk_coupling", "ambient_current_ua")
    return replace(unit, design=unit.design.replace(reflector=reflector), model_form=only)


def _one(unit, model_form, distance, rng):
    """Per reference: the fit of the coupon with it, or the refusal's text."""
    sigma_v = unit.design.noise.total_sigma_v
    coupon = replace(unit, model_form=model_form).flat_curve(0, distance, rng)
    out = {}
    for name, (reflectance, fraction) in REFERENCES.items():
        volts = _facing(unit, reflectance, fraction, model_form).flat_curve(0, distance, rng)
        reference = MeasuredCurve(tuple(distance), tuple(volts), reflectance, fraction)
        try:
            out[name] = fit_material(
                distance, coupon, unit.design.models[0], reference=reference, sigma_v=sigma_v
            )
        except ValueError as exc:
            out[name] = str(exc)
    return out


def _row(case, name, results, fractions):
    fits = [(r, f) for r, f in zip(results, fractions, strict=True) if not isinstance(r, str)]
    refused = len(results) - len(fits)
    if not fits:
        return f"| {case} | {name} | {refused} of {len(results)} | — | — | — | — |"
    error = max(abs(r.reflectance - 0.9) for r, _ in fits)
    holds = np.mean(
        [r.reflectance_interval[0] <= 0.9 <= r.reflectance_interval[1] for r, _ in fits]
    )
    width = np.median([np.subtract(*r.reflectance_interval[::-1]) for r, _ in fits])
    f_holds = np.mean(
        [r.specular_fraction_interval[0] <= f <= r.specular_fraction_interval[1] for r, f in fits]
    )
    return (
        f"| {case} | {name} | {refused} of {len(results)} | {error:.3f} | {100 * holds:.0f} % "
        f"| {width:.3f} | {100 * f_holds:.0f} % |"
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--units", type=int, default=5)
    args = parser.parse_args()
    FLAT_CURVE_ORDERS["spread_order"] = (12, 12)
    design = load_design(SAMPLE / "design.json")
    distance = read_curve_csv(SAMPLE / "s1.csv")[0]
    units = [build_unit(design, i, seed=29, nodes=2) for i in range(args.units)]
    header = ("physics", "reference", "refused", "max abs(ρ − 0.9)", "90 % interval of ρ holds")
    header += ("its median width", "interval of f holds f")
    print("| " + " | ".join(header) + " |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for case, model_form in CASES.items():
        rng = np.random.default_rng(2026)
        runs = [_one(unit, model_form, distance, rng) for unit in units]
        fractions = [unit.design.reflector.specular_fraction for unit in units]
        for name in REFERENCES:
            print(_row(case, name, [run[name] for run in runs], fractions), flush=True)


if __name__ == "__main__":
    main()
