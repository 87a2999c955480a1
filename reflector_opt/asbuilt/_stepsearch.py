"""How far to correct: the step of least expected loss that keeps every constraint.

:func:`reflector_opt.asbuilt._correction.plan_correction` gives the shrunk correction c (step 1).
:func:`choose_step` applies the share α of it that the user of the next batch gains most
from, and that the process can print:

1. **Expected loss.** For each α on :data:`STEPS`, the next batch is the identified units
   printed again on the drawing corrected by α·c (their deviations kept:
   :func:`reflector_opt.asbuilt._batchforecast.predicted_units`), with the batch mean's remaining
   uncertainty added by the spherical cubature rule: 2k points ``±√k·s_i·v_i`` over the k
   determined directions (std s_i, direction v_i), weight 1/(2k) each (the mean and
   covariance of the posterior exactly). Each unit's loss is
   :func:`reflector_opt.asbuilt._userloss.loss_deg` (worst-case resolution, drift
   sensitivity, the margins' shortfall against the drawing's own); the expected loss is the
   mean over points and units. A step whose drawing is not a valid design, or whose next
   batch holds a unit (at a point) that is not one, is not weighed: the steps are taken up to
   the first such one and the largest step below it that can be weighed (bisection), and
   what was given up says where and why — never an error, unless step 0 itself cannot be.
2. **The decision.** α* is the step of least expected loss; steps within
   :data:`TIE_DEG` of it count as equal, and the largest of them is taken (the drawing
   printed as drawn is what the design asked for).
3. **The constraints**, judged on the part the process is predicted to print — the corrected
   drawing with the batch mean's deviation on it (:func:`predicted_print`) — not on the
   pre-compensated drawing. ``feasible(drawing)`` returns None or the first problem
   (default :func:`print_problem`: a valid design, every wall of the printed parts at least
   the printable minimum by the rules ``export`` checks). If α* fails, the largest feasible
   step below it is found by bisection (:data:`BISECTIONS` halvings); if none below is
   feasible, the feasible grid step of least expected loss; if no step is, InputError. Each
   step is judged once; ``correct`` hands in export's checks of the predicted print and of
   the drawing's own parts, made in memory (:mod:`reflector_opt.workflow._correct`).
"""

import numpy as np

from reflector_opt.asbuilt._batchforecast import predicted_units
from reflector_opt.asbuilt._correction import changed_geometry
from reflector_opt.asbuilt._userloss import STEP_DEG, loss_deg, unit_figures
from reflector_opt.design._layout import plan_layout
from reflector_opt.util._errors import InputError

#: The steps α compared.
STEPS = (0.0, 0.25, 0.5, 0.75, 1.0)

#: Expected losses closer than this count as equal, degrees.
TIE_DEG = 2e-4

#: Halvings of the interval when a step breaks a constraint.
BISECTIONS = 6


def predicted_print(drawing, mean):
    """The part the process is predicted to print from ``drawing``: its batch-mean deviation.

    Parameters
    ----------
    drawing : reflector_opt.design._design.Design
    mean : reflector_opt.asbuilt._pooling.BatchMean
        Its ``mean`` (posterior mean of the systematic deviation per parameter) is added.

    Returns
    -------
    reflector_opt.design._design.Design
        Raises InputError if the printed geometry is not a valid design.
    """
    return changed_geometry(drawing, mean.batch.names, mean.mean)


def print_problem(drawing, mean):
    """The first constraint the predicted print of ``drawing`` breaks, or None.

    Parameters
    ----------
    drawing : reflector_opt.design._design.Design
    mean : reflector_opt.asbuilt._pooling.BatchMean

    Returns
    -------
    str or None
        E.g. ``"reflector: the reflecting shell is 0.711 mm thick, below the printable
        minimum 0.8 mm"``.
    """
    try:
        printed = predicted_print(drawing, mean)
        layout = plan_layout(printed)
    except InputError as exc:
        return str(exc)
    for part, walls in (("reflector", layout.reflector_walls_mm), ("body", layout.body_walls_mm)):
        for name, wall in walls.items():
            if wall < layout.min_wall_mm - 1e-9:
                return (
                    f"{part}: the {name} is {wall:.3f} mm thick, below the printable minimum "
                    f"{layout.min_wall_mm:g} mm"
                )
    return None


def posterior_points(mean):
    """Shifts of the systematic part spanning the batch mean's uncertainty (cubature).

    Parameters
    ----------
    mean : reflector_opt.asbuilt._pooling.BatchMean

    Returns
    -------
    numpy.ndarray
        Shape (2k, g): ``±√k·s_i·v_i`` in mm and degrees, equal weights (none: one zero row).
    """
    prior, k = mean.batch.prior_std, len(mean.directions)
    rows = [
        sign * np.sqrt(k) * d.std * d.weights * prior
        for d in mean.directions
        for sign in (1.0, -1.0)
    ]
    return np.array(rows or [np.zeros(len(prior))])


def _shifted(units, names, shift):
    """The predicted units with their geometry moved by ``shift``."""
    return [(changed_geometry(built, names, shift), mismatch) for built, mismatch in units]


def _next_units(batch, drawing, points):
    """The batch's units printed on ``drawing``, moved by each point (InputError if one of
    them is not a valid design)."""
    units = predicted_units(batch, drawing)
    return [unit for shift in points for unit in _shifted(units, batch.names, shift)]


def _unprintable(batch, points):
    """``feasible(drawing)`` for the loss: why a unit of the next batch printed from the
    drawing is not a valid design, or None."""

    def problem(drawing):
        try:
            _next_units(batch, drawing, points)
        except InputError as exc:
            return f"a unit of the next batch printed from it is not a valid design: {exc}"
        return None

    return problem


def expected_loss(batch, drawing, points, targets, step_deg=STEP_DEG):
    """The next batch's expected loss on ``drawing``, degrees.

    Parameters
    ----------
    batch : reflector_opt.asbuilt._batch.Batch
    drawing : reflector_opt.design._design.Design
    points : numpy.ndarray
        (p, g) shifts of the systematic part (:func:`posterior_points`).
    targets : reflector_opt.asbuilt._userloss.UnitFigures
        The drawing's own figures (its margins are the targets).
    step_deg : float
        Pose-grid step, degrees.

    Returns
    -------
    float
        Raises InputError if a unit of the next batch (or one moved by a point) is not a
        valid design.
    """
    losses = [
        loss_deg(unit_figures(built, mismatch, step_deg), targets)
        for built, mismatch in _next_units(batch, drawing, points)
    ]
    return float(np.mean(losses))


def _drawing(design, correction, step):
    return changed_geometry(design, correction.mean.batch.names, -step * correction.full_change)


def _buildable(design, correction, step):
    """The drawing at ``step``, or why it cannot be built (a str)."""
    try:
        return _drawing(design, correction, step)
    except InputError as exc:
        return f"the corrected design cannot be built: {exc}"


def _judged(design, correction, feasible):
    """``problem(step)``: None if the drawing at ``step`` can be built and is feasible, else
    the first problem; each step judged once."""
    judged = {}

    def problem(step):
        if step not in judged:
            drawing = _buildable(design, correction, step)
            judged[step] = drawing if isinstance(drawing, str) else feasible(drawing)
        return judged[step]

    return problem


def _largest_feasible(problem, low, high, found=None):
    """Bisection for the largest feasible step in [low, high] (low feasible, high not, for
    ``found``): that step, and the least infeasible step found with its problem."""
    for _ in range(BISECTIONS):
        middle = 0.5 * (low + high)
        if (reason := problem(middle)) is None:
            low = middle
        else:
            high, found = middle, reason
    return low, (high, found)


def choose_step(design, correction, feasible=None, step_deg=STEP_DEG):
    """The step α of least expected loss that keeps every constraint (module docstring).

    Parameters
    ----------
    design : reflector_opt.design._design.Design
        The drawing the batch was printed from.
    correction : reflector_opt.asbuilt._correction.Correction
    feasible : callable, optional
        ``feasible(drawing)`` → None or the first problem of its predicted print (default
        :func:`print_problem` with the correction's batch mean), called once per step that
        changes the drawing; the drawing as drawn (step 0, or a correction that changes
        nothing) is judged by :func:`print_problem` alone, its parts being the design's own.
    step_deg : float
        Pose-grid step of the loss, degrees.

    Returns
    -------
    (Correction, dict)
        The correction with its step and what it gave up, and the expected loss per step
        (``{α: degrees}``).
    """
    mean = correction.mean
    if feasible is None:

        def feasible(drawing):
            return print_problem(drawing, mean)

    if not correction.changes_anything:
        problem = print_problem(design, mean)
        noted = () if problem is None else (f"the drawing's predicted print breaks: {problem}",)
        return correction.with_step(1.0, noted), {}
    losses, unbuilt = _step_losses(design, correction, step_deg)
    best = min(losses.values())
    chosen = max(a for a, value in losses.items() if value <= best + TIE_DEG)
    given_up = []
    if chosen < max(losses):
        given_up.append(f"step {chosen:g}: no expected gain from more (loss {best:.4f}°)")
    if unbuilt is not None:
        given_up.append(unbuilt)
    judged = _judged(design, correction, feasible)

    def problem(step):  # the drawing as drawn is the design: export checks it when written
        return print_problem(design, mean) if step == 0.0 else judged(step)

    if (reason := problem(chosen)) is not None:
        found = _feasible_step(problem, chosen, losses)
        given_up.append(f"step {chosen:g} → {found:.3f}: the predicted print breaks: {reason}")
        chosen = found
    return correction.with_step(chosen, given_up), losses


def _step_losses(design, correction, step_deg):
    """Expected loss of each step whose next batch can be weighed, and why the first that
    cannot be weighed cannot (None if all can).

    A step cannot be weighed if its drawing is not a design, or a unit of the next batch
    printed from it is not. The steps are :data:`STEPS` up to the first that cannot, and the
    largest step below it that can (bisection): a correction is taken as far as it can be
    drawn and printed.
    """
    mean = correction.mean
    points = posterior_points(mean)
    targets = unit_figures(design, None, step_deg)
    weighable = _unprintable(mean.batch, points)

    def loss(a):
        drawing = _buildable(design, correction, a)
        if isinstance(drawing, str):
            return drawing
        try:
            return expected_loss(mean.batch, drawing, points, targets, step_deg)
        except InputError:
            problem = weighable(drawing)
            if problem is None:
                raise
            return problem

    losses = {}
    for a in STEPS:  # step 0 is the design itself
        found = loss(a)
        if isinstance(found, str):
            if not losses:
                raise InputError(f"the batch's units cannot be weighed as drawn: {found}")
            edge, (beyond, problem) = _largest_feasible(
                _judged(design, correction, weighable), max(losses), a, found
            )
            if edge > max(losses):
                losses[edge] = loss(edge)
            return losses, f"step {beyond:.3f} and beyond: {problem}"
        losses[a] = found
    return losses, None


def _feasible_step(problem, chosen, losses):
    """The largest feasible step below ``chosen``, else the feasible step of least loss."""
    if problem(0.0) is None:
        return _largest_feasible(problem, 0.0, chosen)[0]
    for a in sorted(losses, key=losses.get):
        if problem(a) is None:
            return a
    raise InputError(
        "no step of the correction gives a printable part: the predicted print breaks: "
        f"{problem(chosen)}"
    )
