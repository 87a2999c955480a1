"""What each model-form error does to the voltages of a design's built units, and its cost.

For ``--units`` built units of a design (default: the built-in default design; seed 0), each
is built once with the exact reference's physics (``model_form=None``) and once with each
option of :class:`reflector_opt.tolerance._model_form.ModelForm` alone at its default, with
all of them (``ModelForm()``) and with the two-Gaussian emitter. On a ``--grid`` × ``--grid``
pose grid over the workspace the table gives, pooled over the units and sensors, the mean
and RMS voltage change against the exact-physics unit, the largest change, and the RMS
residual after a per-sensor gain and offset fitted by least squares (what a calibration's
gain and offset cannot absorb), beside the design's σ_V; and the CPU time to build a unit.

Run from the repository root (about a minute with the defaults on one core):

    python benchmarks/model_form_effects.py [design.json] [--units 2] [--grid 31] [--seed 0]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import numpy as np  # noqa: E402

from reflector_opt import default_design  # noqa: E402
from reflector_opt.design._design import load_design  # noqa: E402
from reflector_opt.tolerance._builtunit import build_unit  # noqa: E402
from reflector_opt.tolerance._model_form import ModelForm  # noqa: E402


def _cases():
    default = ModelForm()
    cases = [(name, default.only(name)) for name in ModelForm.names()]
    cases.append(("all (ModelForm())", default))
    cases.append(("emitter_pattern two_gaussian", ModelForm(0.0, 0.0, "two_gaussian", 0.0, 0.0)))
    return cases


def _residual(base, other):
    """RMS of ``other`` minus a least-squares gain and offset of ``base``, per sensor."""
    out = []
    for k in range(base.shape[1]):
        a = np.stack([base[:, k], np.ones(len(base))], 1)
        fit, *_ = np.linalg.lstsq(a, other[:, k], rcond=None)
        out.append(other[:, k] - a @ fit)
    return np.stack(out, 1)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("design", nargs="?", help="design.json (default: the built-in design)")
    parser.add_argument("--units", type=int, default=2)
    parser.add_argument("--grid", type=int, default=31)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    design = default_design() if args.design is None else load_design(args.design)
    ws = design.workspace
    pp, rr = np.meshgrid(
        np.linspace(*ws.pitch_deg, args.grid), np.linspace(*ws.roll_deg, args.grid), indexing="ij"
    )
    pitch, roll = pp.ravel(), rr.ravel()
    rows = {name: [] for name, _ in _cases()}
    cost = {name: [] for name, _ in _cases()}
    cost["none"] = []
    for index in range(args.units):
        start = time.process_time()
        base = build_unit(design, index, seed=args.seed).volts(pitch, roll)
        cost["none"].append(time.process_time() - start)
        for name, model_form in _cases():
            start = time.process_time()
            unit = build_unit(design, index, seed=args.seed, model_form=model_form)
            cost[name].append(time.process_time() - start)
            volts = unit.volts(pitch, roll)
            rows[name].append((volts - base, _residual(base, volts)))
    sigma = design.noise.total_sigma_v
    print(f"{args.units} unit(s), seed {args.seed}, {args.grid} × {args.grid} poses, ", end="")
    print(f"σ_V = {1e3 * sigma:.2f} mV; exact physics: {np.mean(cost['none']):.2f} s a unit")
    print()
    print(
        "| form error | mean ΔV (mV) | RMS ΔV (mV) | max abs ΔV (mV) "
        "| RMS after gain and offset (mV) | CPU s a unit |"
    )
    print("| --- | --- | --- | --- | --- | --- |")
    for name, _ in _cases():
        change = np.concatenate([c for c, _ in rows[name]])
        residual = np.concatenate([r for _, r in rows[name]])
        print(
            f"| {name} | {1e3 * change.mean():+.2f} | {1e3 * np.sqrt(np.mean(change**2)):.2f} | "
            f"{1e3 * np.abs(change).max():.2f} | {1e3 * np.sqrt(np.mean(residual**2)):.3f} | "
            f"{np.mean(cost[name]):.2f} |"
        )


if __name__ == "__main__":
    main()
