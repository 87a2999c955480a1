"""The fast crosstalk model against the exact reference, and what it costs.

    python benchmarks/crosstalk_agreement.py

Designs: the default unit (NJL5901R-2 on the 10 mm ring, sphere R = 9 mm centred 1.5 mm
below O) with its two sensors 15°, 20°, 25°, 30°, 35° and 40° apart, and with three sensors
at 0°, 20° and 40° whose LED-to-detector directions differ (up, along the ring, down). Poses:
a 5 × 5 grid over ±15° pitch and roll. At each pose and ordered pair j ≠ k the fast model
(:func:`reflector_opt.model._crosstalk.cross_surface_couplings`) is compared with the exact
quadrature (:func:`reflector_opt.model._exact.exact_design_cross_coupling`, orders source 4,
detector (2, 6), sphere (48, 48): within 4e-4 of the default orders on these designs), for
each share and for the default surface (ρ = 0.9, f = 0.05). The table gives, by the size of
the exact cross coupling over the exact own coupling of detector k (the crosstalk fraction),
the largest relative error / the largest error over the own coupling (the number of pairs);
last, the time of
:func:`~reflector_opt.model._crosstalk.crosstalk_fraction` on the 301 × 301 workspace grid.
"""

from __future__ import annotations

import time

import numpy as np

from reflector_opt.design import default_design
from reflector_opt.design._components import SensorPlacement
from reflector_opt.model._crosstalk import cross_surface_couplings, crosstalk_fraction
from reflector_opt.model._exact import exact_design_cross_coupling

ORDERS = {"source_order": 4, "detector_order": (2, 6), "sphere_order": (48, 48)}
#: Lower edges of the bins of the exact crosstalk fraction, in table order.
BINS = (1e-2, 1e-3, 1e-4, 0.0)


def ring_design(angles_deg, detector_directions=None):
    """The default unit with its sensors at these angles round the ring, looking inwards."""
    base = default_design()
    radius = np.linalg.norm(base.sensors[0].position_mm)
    directions = detector_directions or [(0.0, 0.0, 1.0)] * len(angles_deg)
    sensors = []
    for i, (angle, direction) in enumerate(zip(angles_deg, directions, strict=True)):
        c, s = np.cos(np.deg2rad(angle)), np.sin(np.deg2rad(angle))
        sensors.append(
            SensorPlacement(
                f"S{i + 1}", "NJL5901R-2", (radius * c, radius * s, 0.0), (-c, -s, 0.0), direction
            )
        )
    return base.replace(sensors=tuple(sensors))


def designs():
    """(label, design) of every design compared."""
    found = [(f"2 sensors {d}° apart", ring_design((0.0, d))) for d in (15, 20, 25, 30, 35, 40)]
    along = (-np.sin(np.deg2rad(20.0)), np.cos(np.deg2rad(20.0)), 0.0)
    three = ring_design((0.0, 20.0, 40.0), [(0.0, 0.0, 1.0), along, (0.0, 0.0, -1.0)])
    return [*found, ("3 sensors at 0°, 20°, 40°", three)]


def rows(design, pitch, roll):
    """(fraction, relative error, error over own) of every pair and pose, per share."""
    exact = exact_design_cross_coupling(design, pitch, roll, **ORDERS)
    fast = cross_surface_couplings(design, pitch, roll)
    reflector = design.reflector
    shares = {
        "mirror": (exact.mirror, fast.mirror),
        "Lambertian": (exact.lambertian, fast.lambertian),
        "default surface": (
            exact.total(reflector.reflectance, reflector.specular_fraction),
            fast.total(reflector.reflectance, reflector.specular_fraction),
        ),
    }
    off = ~np.eye(len(design.sensors), dtype=bool)
    out = {}
    for name, (e, f) in shares.items():
        own = np.diagonal(e, axis1=-2, axis2=-1)[..., :, None] * np.ones_like(e)
        safe = np.where(e > 0.0, e, 1.0)
        out[name] = np.stack(
            [
                (e / own)[..., off],
                np.abs(f / safe - 1.0)[..., off],
                np.abs(f - e)[..., off] / own[..., off],
            ],
            -1,
        ).reshape(-1, 3)
    return out


def table(collected):
    """Markdown rows: per share and fraction bin, the worst relative error, the worst error
    over the own coupling and the number of pairs."""
    uppers = (np.inf, *BINS[:-1])
    heads = [
        f"{lower:g} and above"
        if upper == np.inf
        else (f"{lower:g} to {upper:g}" if lower else f"below {upper:g}")
        for lower, upper in zip(BINS, uppers, strict=True)
    ]
    lines = [
        "| share | " + " | ".join(f"fraction {h}" for h in heads) + " |",
        "| --- |" + " --- |" * len(BINS),
    ]
    for name, values in collected.items():
        cells = []
        for lower, upper in zip(BINS, uppers, strict=True):
            inside = (values[:, 0] >= lower) & (values[:, 0] < upper)
            relative, over_own = values[inside, 1].max(), values[inside, 2].max()
            cells.append(f"{100 * relative:.1f} % / {over_own:.1e} ({int(inside.sum())})")
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main():
    """Print the agreement table and the fast model's time on the full workspace grid."""
    grid = np.linspace(-15.0, 15.0, 5)
    pitch, roll = np.meshgrid(grid, grid, indexing="ij")
    collected = {}
    for label, design in designs():
        for name, values in rows(design, pitch, roll).items():
            collected.setdefault(name, []).append(values)
        print(f"compared: {label}")
    print(table({name: np.concatenate(v) for name, v in collected.items()}))
    full = np.linspace(-15.0, 15.0, 301)
    pitch, roll = np.meshgrid(full, full, indexing="ij")
    for label, design in (designs()[1], ("default design (90° apart)", default_design())):
        start = time.perf_counter()
        fraction = crosstalk_fraction(design, pitch, roll)
        seconds = time.perf_counter() - start
        print(f"{label}: 301 × 301 poses in {seconds:.2f} s, worst fraction {fraction.max():.3g}")


if __name__ == "__main__":
    main()
