"""What a third or fourth sensor buys in use: on the same sphere, or on a spherical cap of its own.

    python benchmarks/third_sensor.py

The sample design (examples/data/design.json), read with ``dc`` as stated, in the default
conditions with the angle reference's zero stated 0 (the term every design shares) and in
examples/conditions.toml. The layouts:

* the pair, and the pair with a thermometer (``temperature_compensated``: no extra sensor);
* a copy of S1 at 90° or 180° on the same sphere (the estimator: least squares on the angles);
* a reference R at 180° on a cap of its own centred on the joint's rotation centre O. A
  rotation about O maps that sphere onto itself, so R reads only what the pair reads in
  common (temperature, supply, ageing) and the joint's shift along its line of sight. The
  estimator ratios the pair's drops by R's, V'_k = Vcc − (Vcc − V_k)·(Vcc − R_cal)/(Vcc − R);
  linearised, a common gain g fitted beside the angles, ∂V/∂ln g = V − Vcc (:func:`gain`).
  The cap's radius sets R's gap along its axis: at the response's peak (the shift and the
  cap's expansion reach R only at second order; for the NJL5901R-2 below its usable range of
  0.5–3 mm) or at the usable range's near end;
* four sensors: R at the peak and Y at 90° on a cap of its own centred on O at the usable
  range's near end, reading the joint's shift along y; the estimator fits g and that shift.

The package models one sphere per unit, so a cap's sensor is judged here with the budget's own
terms (:func:`reflector_opt.analysis._budget.error_budget` with its ``nuisance`` columns) and
the forward model replaced, for the cap's sensors only, by the same model with their cap as
the sphere, expanded and shifted with the unit (:func:`own_caps`). Prints per layout: sensors,
the in-use worst case on the budget's 1° grid, the white-noise floor (the budget's 1σ noise at
its worst pose, the fitted nuisance included), the frame rate and the terms it moves. Then
the reference's terms against the independent truth (tests/independent/inuse.py, the exact
ratio of :func:`ratio_truth`) in examples/conditions.toml on a 5° grid. The figures of
docs/optimiser.md, "The design space for use".
"""

from __future__ import annotations

import dataclasses
import logging
import sys
from contextlib import contextmanager, nullcontext
from pathlib import Path
from unittest import mock

import numpy as np
from scipy.optimize import minimize_scalar

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from reflector_opt.analysis import _budget  # noqa: E402
from reflector_opt.design import load_design  # noqa: E402
from reflector_opt.design._conditions import Conditions, load_conditions  # noqa: E402
from reflector_opt.model._forward import voltages  # noqa: E402

DESIGN = ROOT / "examples" / "data" / "design.json"
CONDITIONS = ROOT / "examples" / "conditions.toml"
#: Grid step of the comparison with the truth, degrees (7 × 7 poses on ±15°).
TRUTH_STEP_DEG = 5.0
#: The terms printed beside the worst case (their largest over the workspace).
TERMS = ("temperature", "expansion", "play", "supply")


def with_sensor(design, azimuth_deg, name="S3"):
    """The design with a copy of its first sensor at ``azimuth_deg``, its axis radial."""
    first = design.sensors[0]
    position = np.asarray(first.position_mm, dtype=float)
    radius, a = float(np.hypot(*position[:2])), np.radians(azimuth_deg)
    inward = np.array([-np.cos(a), -np.sin(a), 0.0]) * np.hypot(*first.axis[:2])
    added = dataclasses.replace(
        first,
        name=name,
        position_mm=(radius * np.cos(a), radius * np.sin(a), float(position[2])),
        axis=(float(inward[0]), float(inward[1]), float(first.axis[2])),
    )
    return design.replace(sensors=(*design.sensors, added))


def cap_radii_mm(layout, gaps_mm):
    """Radii of caps centred on O that the last sensors of ``layout`` meet at ``gaps_mm`` along
    their axes: |p + d·a|, mm."""
    ends = layout.sensors[len(layout.sensors) - len(gaps_mm) :]
    return [
        float(np.linalg.norm(np.add(s.position_mm, d * np.asarray(s.axis))))
        for s, d in zip(ends, gaps_mm, strict=True)
    ]


def cap_outputs(design, radius_mm, pitch, roll, **forward):
    """Every sensor's output with a cap of ``radius_mm`` centred on O as the sphere, V."""
    cap = dataclasses.replace(design.reflector, radius_mm=radius_mm, centre_mm=(0.0, 0.0, 0.0))
    return voltages(design.replace(reflector=cap), pitch, roll, **forward)


@contextmanager
def own_caps(layout, gaps_mm):
    """The budget's forward model with the last ``len(gaps_mm)`` sensors of ``layout`` each on
    a cap of its own centred on O, at that gap along its axis: the cap scales with the unit's
    reflector (the resin's expansion) and moves with it (the joint's shift)."""
    n0, radii = len(layout.sensors) - len(gaps_mm), cap_radii_mm(layout, gaps_mm)
    base = layout.reflector.radius_mm

    def model(design, pitch, roll, **forward):
        k = design.reflector.radius_mm / base
        own = [
            cap_outputs(design, k * r, pitch, roll, **forward)[..., n0 + i]
            for i, r in enumerate(radii)
        ]
        return np.concatenate(
            [voltages(design, pitch, roll, **forward)[..., :n0], np.stack(own, -1)], -1
        )

    with mock.patch.object(_budget, "voltages", model):
        yield


def gain(grid):
    """∂V/∂ln g of V = Vcc − g·(Vcc − V): the common gain a reference's ratio fits, V."""
    return (grid.volts - [m.supply_v for m in grid.design.models])[..., None]


def shift_along(axis, step_mm=1e-3):
    """∂V/∂δ of the joint's shift δ along ``axis``, V/mm, by a forward difference."""
    delta = step_mm * np.asarray(axis, dtype=float)
    return lambda grid: ((grid.outputs(reflector_shift_mm=delta) - grid.reread) / step_mm)[
        ..., None
    ]


def peak_gap_mm(layout):
    """The gap along the axis at which the last sensor's response on its cap peaks, mm."""
    found = minimize_scalar(
        lambda d: cap_outputs(layout, cap_radii_mm(layout, [d])[0], 0.0, 0.0)[-1],
        bounds=(0.1, 1.0),
        method="bounded",
        options={"xatol": 1e-4},
    )
    return float(found.x)


def layouts(design):
    """Name → (layout, gaps of its own-cap sensors, nuisance columns or None, compensated)."""
    ref = with_sensor(design, 180.0, "R")
    near = design.models[0].range_mm[0]
    peak = peak_gap_mm(ref)
    four = with_sensor(ref, 90.0, "Y")
    both = lambda grid: np.concatenate([gain(grid), shift_along((0, 1, 0))(grid)], -1)  # noqa: E731
    return {
        "pair": (design, [], None, False),
        "pair, thermometer": (design, [], None, True),
        "S3 at 90°, same sphere": (with_sensor(design, 90.0), [], None, False),
        "S3 at 180°, same sphere": (with_sensor(design, 180.0), [], None, False),
        f"R on its cap at {peak:.2f} mm (peak), ratio": (ref, [peak], gain, False),
        f"R on its cap at {near:.2f} mm, ratio": (ref, [near], gain, False),
        f"R at the peak + Y at {near:.2f} mm, gain and y shift": (four, [peak, near], both, False),
    }


def budget_of(layout, gaps, nuisance, conditions, **kwargs):
    """The layout's error budget, its own-cap sensors on their caps."""
    with own_caps(layout, gaps) if gaps else nullcontext():
        return _budget.error_budget(layout, conditions, nuisance=nuisance, **kwargs)


def ratio_truth(layout, gap_mm, states, pitch, roll):
    """The truth's error of the exact ratio to R (the last sensor, on its cap at ``gap_mm``):
    the pair's readings and R's from tests/independent/inuse.py in each state, the pair's
    drops divided by R's relative to calibration, inverted by the truth. Shape (states, P, 2)."""
    from tests.independent.inuse import InUse, read_angles, readings

    pair = layout.replace(sensors=layout.sensors[:-1])
    (radius,) = cap_radii_mm(layout, [gap_mm])
    cap = dataclasses.replace(layout.reflector, radius_mm=radius, centre_mm=(0.0, 0.0, 0.0))
    on_cap = layout.replace(reflector=cap)
    vcc = np.array([m.supply_v for m in pair.models])
    poses = np.stack([pitch, roll], axis=-1)
    drop_cal = layout.models[-1].supply_v - readings(on_cap, pitch, roll, InUse())[:, -1]
    out = []
    for state in states:
        drop = layout.models[-1].supply_v - readings(on_cap, pitch, roll, state)[:, -1]
        corrected = vcc - (vcc - readings(pair, pitch, roll, state)) * (drop_cal / drop)[:, None]
        out.append(read_angles(pair, corrected, poses) - poses)
    return np.stack(out)


def truth_states(budget):
    """The truth's states of the budget's temperature (uncompensated), play and supply
    scenarios, in their order (the NJL5901R-2's output taken linear, 0.4 %/K, as assumed)."""
    from tests.independent.inuse import InUse

    c = budget.conditions
    stays = 1e-3 * np.asarray(budget.joint.stays_um)
    return {
        "temperature": [
            InUse(delta_t_k=s * c.temperature_range_k, linear_output_per_k=0.004) for s in (1, -1)
        ],
        "play": [
            InUse(centre_shift_mm=tuple(stays * a)) for a in np.vstack([np.eye(3), -np.eye(3)])
        ],
        "supply": [InUse(supply_change_v=s * 1e-3 * c.supply_change_mv) for s in (1, -1)],
    }


def gap(predicted, truth):
    """Relative RMS of the signed difference over scenarios, poses and angles."""
    return float(np.sqrt(np.mean((predicted - truth) ** 2) / np.mean(truth**2)))


def main():
    logging.disable(logging.WARNING)  # the bearing's rated tilt, once per design
    design = load_design(DESIGN)
    stated = {
        "default conditions, reference zero 0": Conditions(reference_zero_deg=[0.0, 0.0]),
        "examples/conditions.toml": load_conditions(CONDITIONS),
    }
    found = layouts(design)
    for label, conditions in stated.items():
        print(f"{label}:")
        for name, (layout, gaps, nuisance, compensated) in found.items():
            c = conditions.replace(temperature_compensated=compensated)
            b = budget_of(layout, gaps, nuisance, c)
            terms = " ".join(f"{t} {b.maps[t].max():.3f}°" for t in TERMS)
            print(
                f"  {name} | {len(layout.sensors)} sensors | in use {b.worst_case_deg:.4f}° | "
                f"white-noise floor {b.maps['noise'].max():.4f}° | "
                f"{b.drive.frame_rate_hz:.0f} frames/s | {terms}"
            )
    print(
        f"the reference's terms against the truth, examples/conditions.toml, "
        f"{TRUTH_STEP_DEG:g}° grid:"
    )
    for name, (layout, gaps, nuisance, _) in found.items():
        if nuisance is not gain:
            continue
        b = budget_of(
            layout, gaps, gain, stated["examples/conditions.toml"], step_deg=TRUTH_STEP_DEG
        )
        pitch, roll = b.pitch_deg.ravel(), b.roll_deg.ravel()
        for term, states in truth_states(b).items():
            truth = ratio_truth(layout, gaps[0], states, pitch, roll)
            predicted = b.scenarios[term]
            print(
                f"  {name}: {term} budget {np.abs(predicted).max():.4f}° truth "
                f"{np.abs(truth).max():.4f}° gap {100 * gap(predicted, truth):.1f} %"
            )


if __name__ == "__main__":
    main()
