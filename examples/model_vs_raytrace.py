"""The fast coupling model against the exact reference and a Monte Carlo ray count.

One NJL5901R-2 sensor faces a sphere of radius R (or a flat target, R = 1e5 mm); its optical
axis meets the surface at distance d, where the surface normal is tilted by an angle i from
the axis: towards (+) or away from (−) the detector when the detector lies in the plane of
incidence ("tang."), sideways when it lies across it ("sag."). For a surface of reflectance 1
that is all mirror-like and one that is all Lambertian, the script prints the couplings
(detected over emitted power) of

* the fast model, :func:`reflector_opt.model._optics.surface_couplings` (what the forward
  model and the optimiser use);
* the exact reference, :func:`reflector_opt.model._exact.exact_coupling` (deterministic
  quadrature, converged to 1e-4);
* the Monte Carlo ray count, :func:`reflector_opt.model._reference.raytrace_coupling`, which
  shares no formula with either,

the relative difference of the fast model from the exact reference and that of the ray count
(with its Monte Carlo standard error), then the worst of each per radius, surface and range
of |i|. docs/model_vs_raytrace.txt is this script's output.

Run:  python examples/model_vs_raytrace.py [--rays N]
"""

import argparse

import numpy as np

from reflector_opt.model._exact import exact_coupling
from reflector_opt.model._optics import FLAT_RADIUS_MM, surface_couplings
from reflector_opt.model._reference import raytrace_coupling
from reflector_opt.model._sensors import NJL5901R_2

RADII_MM = (FLAT_RADIUS_MM, 9.0, 6.0)
TILTS_DEG = (-15, -10, -5, 0, 5, 10, 15)
DISTANCES_MM = (0.5, 1.0, 2.0, 3.0)
#: Where the detector lies: in the plane of incidence (u = z) or across it (u = y).
DETECTOR_SIDES = {"tang.": np.array([0.0, 0.0, 1.0]), "sag.": np.array([0.0, 1.0, 0.0])}
SURFACES = ("mirror", "lambertian")
#: Ranges of |i| summarised, degrees: (label, lower bound excluded, upper bound included).
TILT_BUCKETS = (
    ("|i| ≤ 5°", -1.0, 5.0),
    ("5° < |i| ≤ 10°", 5.0, 10.0),
    ("10° < |i| ≤ 15°", 10.0, 15.0),
)


def radius_label(radius):
    """How a radius is printed: the flat target by name."""
    return "flat" if radius == FLAT_RADIUS_MM else f"{radius:g}"


def compare(rays=1_000_000, radii=RADII_MM, tilts=TILTS_DEG, distances=DISTANCES_MM, seed=0):
    """Fast, exact and ray-counted couplings of every geometry.

    Parameters
    ----------
    rays : int, optional
        Rays of each Monte Carlo count.
    radii, tilts, distances : sequence of float, optional
        Sphere radii (mm), tilts i of the normal at the axis hit (degrees) and distances d
        along the axis (mm).
    seed : int, optional
        Seed of the ray counts.

    Returns
    -------
    list of dict
        One per geometry and surface: ``radius``, ``side``, ``tilt``, ``distance``,
        ``surface``, ``fast``, ``exact``, ``traced``, ``sigma`` (the count's standard error).
    """
    model = NJL5901R_2
    sensor, axis = np.zeros(3), np.array([1.0, 0.0, 0.0])
    rows = []
    for radius in radii:
        for side, u in DETECTOR_SIDES.items():
            offset = model.emitter_detector_mm * u
            w = np.cross(axis, u)
            for tilt in tilts:
                i = np.deg2rad(tilt)
                normal = np.array([-np.cos(i), 0.0, np.sin(i)])
                for d in distances:
                    centre = d * axis - radius * normal
                    frame = np.array([[[centre @ axis, centre @ u, centre @ w]]])
                    fast = surface_couplings(frame, radius, 0.5, [model])
                    exact = exact_coupling(sensor, axis, offset, centre, radius, model)
                    traced, sigma = raytrace_coupling(
                        sensor, axis, offset, centre, radius, model, n_rays=rays, seed=seed
                    )
                    for surface in SURFACES:
                        rows.append(
                            {
                                "radius": radius,
                                "side": side,
                                "tilt": tilt,
                                "distance": d,
                                "surface": surface,
                                "fast": float(getattr(fast, surface)[0, 0]),
                                "exact": float(getattr(exact, surface)),
                                "traced": float(getattr(traced, surface)),
                                "sigma": float(getattr(sigma, surface)),
                            }
                        )
    return rows


def summarise(rows):
    """Worst differences per radius, surface and range of |i|.

    Returns
    -------
    list of dict
        ``radius``, ``surface``, ``bucket`` and the largest ``fast`` (|fast/exact − 1|),
        ``traced`` (|traced/exact − 1|) and ``traced_sigma`` (|traced − exact| in Monte
        Carlo standard errors) over the geometries in it.
    """
    out = []
    for radius in dict.fromkeys(r["radius"] for r in rows):
        for surface in SURFACES:
            for label, lo, hi in TILT_BUCKETS:
                chosen = [
                    r
                    for r in rows
                    if r["radius"] == radius
                    and r["surface"] == surface
                    and lo < abs(r["tilt"]) <= hi
                ]
                if not chosen:
                    continue
                out.append(
                    {
                        "radius": radius,
                        "surface": surface,
                        "bucket": label,
                        "cases": len(chosen),
                        "fast": max(abs(r["fast"] / r["exact"] - 1) for r in chosen),
                        "traced": max(abs(r["traced"] / r["exact"] - 1) for r in chosen),
                        "traced_sigma": max(
                            abs(r["traced"] - r["exact"]) / r["sigma"] for r in chosen
                        ),
                    }
                )
    return out


def print_report(rows, rays):
    """Print the per-geometry table and the summary."""
    print(f"NJL5901R-2, reflectance 1; ray counts of {rays:,} rays")
    print(
        "R_mm  detector tilt_deg d_mm surface      fast       exact      traced    "
        "fast/exact-1 traced/exact-1 (MC σ)"
    )
    for r in rows:
        print(
            f"{radius_label(r['radius']):>4} {r['side']:>9} {r['tilt']:8} {r['distance']:4.1f}"
            f" {r['surface']:<10} {r['fast']:.4e} {r['exact']:.4e} {r['traced']:.4e}"
            f" {r['fast'] / r['exact'] - 1:+12.4%} {r['traced'] / r['exact'] - 1:+14.3%}"
            f" ({r['sigma'] / r['exact']:.3%})"
        )
    print()
    print("Worst |relative difference| from the exact reference, by radius, surface and |i|")
    print(
        "(detector in and across the plane of incidence, d = "
        + ", ".join(f"{d:g}" for d in dict.fromkeys(r["distance"] for r in rows))
        + " mm):"
    )
    print("R_mm  surface     |i| range        cases  fast model  ray count  ray count / MC σ")
    for s in summarise(rows):
        print(
            f"{radius_label(s['radius']):>4}  {s['surface']:<10}  {s['bucket']:<15}"
            f" {s['cases']:6} {s['fast']:10.3%} {s['traced']:10.2%} {s['traced_sigma']:10.1f}"
        )


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rays", type=int, default=1_000_000, help="rays per Monte Carlo count")
    rays = parser.parse_args().rays
    print_report(compare(rays), rays)


if __name__ == "__main__":
    main()
