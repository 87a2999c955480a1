"""How far the closed-form optics is from a ray trace off the exact sphere.

For a sensor facing a sphere (or a flat mirror) at distance d, with the surface normal at the
axis hit tilted by i towards (+) or away from (−) the detector, prints the closed-form
coupling, the ray-traced one and their relative difference, and the worst case per radius.
The figures in docs/model.md come from this script.

Run:  python examples/model_vs_raytrace.py [--rays N]
"""

import argparse

import numpy as np

from reflector_opt.model.reference import closed_form_coupling, raytrace_coupling
from reflector_opt.model.sensors import NJL5901R_2


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rays", type=int, default=1_000_000)
    rays = parser.parse_args().rays
    sensor, axis = np.zeros(3), np.array([1.0, 0.0, 0.0])
    print("radius_mm  offset  tilt_deg  d_mm   closed    traced   rel_diff  (±MC σ)")
    for radius in (np.inf, 9.0, 6.0):
        worst = {}
        for label, offset in (("tang.", [0, 0, 0.5]), ("sag.", [0, 0.5, 0])):
            for tilt in (-15, -10, -5, 0, 5, 10, 15):
                for d in (0.5, 1.0, 2.0, 3.0):
                    r = 1e6 if np.isinf(radius) else radius
                    normal = np.array([-np.cos(np.deg2rad(tilt)), 0, np.sin(np.deg2rad(tilt))])
                    centre = np.array([d, 0.0, 0.0]) - r * normal
                    closed = closed_form_coupling(sensor, axis, offset, centre, r, NJL5901R_2)
                    traced, sigma = raytrace_coupling(
                        sensor, axis, offset, centre, r, NJL5901R_2, n_rays=rays
                    )
                    diff = closed / traced - 1.0
                    print(
                        f"{radius:9} {label:>7} {tilt:9} {d:5.1f} {closed:9.5f} {traced:9.5f}"
                        f" {diff:+9.3f}  ({sigma / traced:.3f})"
                    )
                    key = "|i| <= 10" if abs(tilt) <= 10 else "|i| <= 15"
                    worst[key] = max(worst.get(key, 0.0), abs(diff))
        summary = ", ".join(f"{k}: {v:.1%}" for k, v in sorted(worst.items()))
        print(f"worst |relative difference|, radius {radius}: {summary}")


if __name__ == "__main__":
    main()
