"""The designs a problem builds: a candidate from its variables, and the built-in baseline.

Both carry the problem's part, workspace, envelope and noise, so that a candidate and the
baseline it is compared with are judged alike.
"""

from dataclasses import replace

from reflector_opt.design import Workspace, default_design
from reflector_opt.optimiser._variables import build_design


def candidate_design(problem, values, step_deg=None, *, checked=True):
    """The :class:`~reflector_opt.design._design.Design` at ``values`` under ``problem``.

    Parameters
    ----------
    problem : reflector_opt.optimiser._problem.Problem
    values : mapping of str to float
        Every design variable.
    step_deg : float, optional
        Grid step of the design's workspace (default: the problem's, 0.1°).
    checked : bool, optional
        False skips ``Design``'s construction checks (for search candidates, see
        :func:`~reflector_opt.optimiser._variables.build_design`).

    Returns
    -------
    reflector_opt.design._design.Design
        Raises :class:`~reflector_opt.util._errors.InputError` if ``values`` do not make a
        valid design.
    """
    workspace = problem.workspace
    if step_deg is not None:
        workspace = Workspace(workspace.pitch_deg, workspace.roll_deg, float(step_deg))
    return build_design(
        values,
        sensor=problem.sensor,
        workspace=workspace,
        mechanics=problem.mechanics,
        noise=problem.noise,
        inner_radius_mm=problem.inner_radius_mm,
        surface=problem.surface,
        checked=checked,
    )


def baseline_design(problem):
    """The design the optimiser compares with: the built-in geometry placed in the unit of the
    problem's candidates (:func:`~reflector_opt.design._defaults.default_design` ``like`` one of
    them), so that ``evaluate`` of the design it writes compares with the same one.

    Parameters
    ----------
    problem : reflector_opt.optimiser._problem.Problem

    Returns
    -------
    reflector_opt.design._design.Design
        Raises :class:`~reflector_opt.util._errors.InputError` if that geometry is not valid
        there (e.g. a sensor inside the sphere).
    """
    middle = {name: 0.5 * (lo + hi) for name, (lo, hi) in problem.search_bounds.items()}
    return default_design(candidate_design(problem, middle, checked=False))


def surface_variants(problem, design):
    """The design at each specular fraction the problem judges it at.

    Parameters
    ----------
    problem : reflector_opt.optimiser._problem.Problem
    design : reflector_opt.design._design.Design

    Returns
    -------
    tuple of Design
        ``(design,)`` without a ``specular_fraction_range``; else one design per fraction of
        :attr:`~reflector_opt.optimiser._problem.Problem.specular_fractions`, the design's
        reflector given that fraction.
    """
    if problem.specular_fraction_range is None:
        return (design,)
    return tuple(
        design.replace(reflector=replace(design.reflector, specular_fraction=f))
        for f in problem.specular_fractions
    )
