"""The figures of a design in use, as a record: what ``evaluate``, ``compare`` and the report
give first and what ``optimise`` writes to ``design.json``'s ``predicted.conditions``.

The figures are the error budget's
(:func:`reflector_opt.analysis._budget.error_budget`) over the workspace: the worst case of the
total error in use (per angle), its RMS and median, the white-noise floor beside them, the
sources where the total is worst, and the default design's in the same conditions. They are
made by :func:`reflector_opt.report._conditions.in_use_block` and
:func:`reflector_opt.optimiser._result.conditions_block`; this module only holds them, below
both, so that a design read from its file carries them typed.
"""

import warnings

from msgspec import UNSET, UnsetType

from reflector_opt.util._fileio import Kept


class InUseBaseline(Kept, kw_only=True):
    """The default design in the same unit and conditions, judged alike (degrees).

    Attributes
    ----------
    conditions : str
        ``optimise``'s: ``"as stated"`` (the conditions' own read-out, where the search chose
        another) or ``"the same"``.
    worst_case_deg, worst_pitch_deg, worst_roll_deg, rms_deg, median_deg : float
        As :class:`InUse`'s (pitch and roll in ``evaluate``'s only).
    budget : dict
        Its error budget (``optimise``'s only).
    binding : dict
        The sources where its total is worst.
    """

    conditions: str | UnsetType = UNSET
    worst_case_deg: float
    worst_pitch_deg: float | UnsetType = UNSET
    worst_roll_deg: float | UnsetType = UNSET
    rms_deg: float | UnsetType = UNSET
    median_deg: float
    budget: dict | UnsetType = UNSET
    binding: dict | UnsetType = UNSET


class InUse(Kept, kw_only=True):
    """A design's total error in use in operating conditions (degrees).

    Fields left ``msgspec.UNSET`` are those the command that made the block does not give
    (``evaluate``'s has no budget, ``optimise``'s no ``conditions_source``) or, in a file of an
    earlier release, did not yet write.

    Attributes
    ----------
    conditions : dict
        The conditions' table (``[conditions]`` of docs/conditions.md).
    conditions_source : str
        How the conditions are named: their file, the given ones, the defaults, or the ones
        the design records.
    objective, grid_deg : str, dict
        ``optimise``'s: the objective in words, and the search, polish and verified grids.
    worst_case_deg : float
        The worst case over the workspace of the total error (the larger angle): the figure
        to quote.
    worst_pitch_deg, worst_roll_deg : float
        The worst case of each angle.
    rms_deg, median_deg : float
        The RMS and the median of the total over the workspace.
    white_noise_floor_deg : float or None
        The worst-case 1σ resolution on the workspace grid, the limit where nothing drifts
        (None where infinite).
    budget : dict
        The error budget per source (``optimise``'s).
    binding : dict
        The sources where the total is worst: ``angle``, ``pose_deg``, ``sources_deg`` and
        their ``shares``.
    drive, joint, assumed_figures, drift_sensitivity, read_out : dict or list
        ``optimise``'s: the drive scheme, the joint's clearance, the assumed figures the
        budget leans on, the angle error per 1 % drift, and the read-out it chose.
    baseline : InUseBaseline
        The default design in the same unit and conditions.
    improvement, improvement_median : float or None
        The default design's worst case and median over this design's.
    baseline_read_out : dict
        ``optimise``'s: the default design in the read-out it chose.
    """

    conditions: dict
    conditions_source: str | UnsetType = UNSET
    objective: str | UnsetType = UNSET
    grid_deg: dict | UnsetType = UNSET
    worst_case_deg: float
    worst_pitch_deg: float
    worst_roll_deg: float
    rms_deg: float | UnsetType = UNSET
    median_deg: float | UnsetType = UNSET
    white_noise_floor_deg: float | UnsetType | None = UNSET
    budget: dict | UnsetType = UNSET
    binding: dict
    drive: dict | UnsetType = UNSET
    joint: dict | UnsetType = UNSET
    assumed_figures: list | UnsetType = UNSET
    drift_sensitivity: dict | UnsetType = UNSET
    read_out: dict | UnsetType = UNSET
    baseline: InUseBaseline | UnsetType = UNSET
    improvement: float | UnsetType | None = UNSET
    improvement_median: float | UnsetType | None = UNSET
    baseline_read_out: dict | UnsetType = UNSET

    def __getitem__(self, key):
        """``block["worst_case_deg"]``, as the block read when it was a dict: deprecated, read
        ``block.worst_case_deg`` (removed in the next release)."""
        warnings.warn(
            f"the figures in use are read by attribute: block.{key}, not block[{key!r}]",
            DeprecationWarning,
            stacklevel=2,
        )
        value = getattr(self, key, UNSET)
        if value is UNSET:
            raise KeyError(key)
        return value.to_dict() if isinstance(value, Kept) else value
