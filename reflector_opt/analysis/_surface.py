"""How a design's angular resolution depends on its reflector's surface.

The printed surface's specular fraction f is uncertain (it depends on the resin, the print
and the post-processing), and mirror and Lambertian couplings change differently with the
pose, so the resolution — and which design is best — depends on f. This module evaluates the
worst-case Cramér–Rao resolution of a design with f swept over [0, 1], the table and the plot
``evaluate`` and the report show beside the default design's.
"""

from dataclasses import replace

from reflector_opt.analysis._metrics import evaluate_metrics
from reflector_opt.design._defaults import default_design

#: Specular fractions of the sweep.
SURFACE_FRACTIONS = (0.0, 0.05, 0.25, 0.5, 0.75, 1.0)


def resolution_against_surface(design, fractions=SURFACE_FRACTIONS, step_deg=1.0):
    """Worst-case 1σ pitch and roll resolution of a design for each specular fraction.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    fractions : sequence of float, optional
        Specular fractions f (0–1); the reflectance stays the design's.
    step_deg : float, optional
        Pose grid step of the evaluation, degrees.

    Returns
    -------
    list of dict
        One record per f: ``specular_fraction``, ``worst_pitch_deg``, ``worst_roll_deg`` and
        ``worst_deg`` (the larger), degrees (Cramér–Rao bound with the design's σ_V).
    """
    rows = []
    for f in fractions:
        variant = design.replace(reflector=replace(design.reflector, specular_fraction=float(f)))
        metrics = evaluate_metrics(variant, step_deg)
        rows.append(
            {
                "specular_fraction": float(f),
                "worst_pitch_deg": metrics.worst_pitch_deg,
                "worst_roll_deg": metrics.worst_roll_deg,
                "worst_deg": metrics.worst_resolution_deg,
            }
        )
    return rows


def surface_comparison(design):
    """A design's resolution against the specular fraction beside the default design's.

    The default design is the built-in geometry placed in the design's unit,
    ``default_design(design)`` (:func:`~reflector_opt.design._defaults.default_design`): the
    one ``optimise`` compares the design it writes with.

    Parameters
    ----------
    design : reflector_opt.design._design.Design

    Returns
    -------
    dict
        ``{"design": rows, "default_design": rows}``, rows of
        :func:`resolution_against_surface`.
    """
    return {
        "design": resolution_against_surface(design),
        "default_design": resolution_against_surface(default_design(design)),
    }
