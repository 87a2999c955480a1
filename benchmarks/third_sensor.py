"""What a third sensor on the same sphere buys in use: the sample design with a copy of S1 at
another azimuth (same radius and height, its axis radial), in the default conditions with the
angle reference's zero stated 0 (the term every design shares), read with ``dc``.

    python benchmarks/third_sensor.py

Prints, per layout, the worst case in use on the budget's 1° grid, the white-noise floor on a
1° grid and each sensor's smallest distance over the workspace. The figures of
docs/optimiser.md, "The design space for use".
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from reflector_opt.analysis._budget import error_budget
from reflector_opt.analysis._metrics import evaluate_metrics
from reflector_opt.design import load_design
from reflector_opt.design._conditions import Conditions

DESIGN = Path(__file__).resolve().parents[1] / "examples" / "data" / "design.json"
#: Azimuths of the third sensor tried, degrees.
AZIMUTHS_DEG = (90.0, 180.0)


def with_third(design, azimuth_deg):
    """The design with a copy of its first sensor at ``azimuth_deg``, its axis radial."""
    first = design.sensors[0]
    position = np.asarray(first.position_mm, dtype=float)
    radius, a = float(np.hypot(*position[:2])), np.radians(azimuth_deg)
    inward = np.array([-np.cos(a), -np.sin(a), 0.0]) * np.hypot(*first.axis[:2])
    third = dataclasses.replace(
        first,
        name="S3",
        position_mm=(radius * np.cos(a), radius * np.sin(a), float(position[2])),
        axis=(float(inward[0]), float(inward[1]), float(first.axis[2])),
    )
    return design.replace(sensors=(*design.sensors, third))


def main():
    design = load_design(DESIGN)
    conditions = Conditions(reference_zero_deg=[0.0, 0.0])
    layouts = {"2 sensors": design}
    layouts |= {f"3 sensors, S3 at {az:g}°": with_third(design, az) for az in AZIMUTHS_DEG}
    for name, layout in layouts.items():
        worst = error_budget(layout, conditions).worst_case_deg
        coarse = layout.replace(workspace=dataclasses.replace(layout.workspace, step_deg=1.0))
        metrics = evaluate_metrics(coarse)
        nearest = np.round(metrics.distance_mm.min(axis=(0, 1)), 3).tolist()
        print(
            f"{name} | in use {worst:.4f}° | white-noise floor "
            f"{metrics.worst_resolution_deg:.4f}° | smallest distances {nearest} mm"
        )


if __name__ == "__main__":
    main()
