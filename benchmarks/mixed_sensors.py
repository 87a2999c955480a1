"""Does a unit with two different sensor parts do better than one with a pair of one part?

    python benchmarks/mixed_sensors.py

Each part that fits the default unit (NJL5901R-2 and VCNT2020) is optimised on the built-in
defaults as ``optimise --sensor PART`` does (``part_problem``: its package sets the body's
window and the room behind it; seed 0); then in each optimised geometry one
sensor is swapped for the other part and the worst-case 1σ resolution of the mixed unit is
evaluated on the same 0.1° grid, with each sensor's distance-window margin. The optimiser's
problem holds one sensor model, so this is not a joint optimisation of a mixed unit: it says
whether the pairs' optima leave room for a mixed unit near them, not that none exists.
"""

from __future__ import annotations

import dataclasses

from reflector_opt.analysis._metrics import evaluate_metrics
from reflector_opt.model._catalogue import get_part, sensor_model
from reflector_opt.optimiser import Problem, optimise
from reflector_opt.optimiser._sensor_choice import part_problem

PARTS = ("NJL5901R-2", "VCNT2020")


def mixed(design, index, model):
    """``design`` with sensor ``index`` replaced by the part ``model``, in the same seat."""
    sensors = list(design.sensors)
    sensors[index] = dataclasses.replace(sensors[index], model=model.name)
    models = {**design.sensor_models, model.name: model}
    return design.replace(sensors=sensors, sensor_models=models)


def main():
    """Print the pairs' optima and the mixed units in their geometries."""
    print("| geometry optimised for | sensors | worst-case 1σ (°) | window margins (mm) |")
    print("| --- | --- | --- | --- |")
    for part in PARTS:
        design = optimise(part_problem(Problem(), get_part(part)), seed=0).design
        other = sensor_model(next(p for p in PARTS if p != part))
        units = [(f"{part} × 2", design)] + [
            (f"sensor {i + 1} → {other.name}", mixed(design, i, other)) for i in (0, 1)
        ]
        for label, unit in units:
            metrics = evaluate_metrics(unit)
            margins = ", ".join(f"{m:.3f}" for m in metrics.distance_margin_mm)
            print(f"| {part} | {label} | {metrics.worst_resolution_deg:.4f} | {margins} |")


if __name__ == "__main__":
    main()
