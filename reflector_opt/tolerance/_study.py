"""A tolerance study of one design: Monte Carlo sample, yield, sensitivity, required margin.

Everything runs as batches of draws on one executor (:mod:`reflector_opt.util._pools`):
the Monte Carlo sample itself; one-at-a-time runs (each active tolerance alone on the same
draws, and a baseline with every tolerance off, so noise and calibration misfit alone); and
the Sobol pick-and-freeze sample (:mod:`reflector_opt.tolerance._sensitivity`), whose
matrices A and B are draws 0 … 2N − 1, as the sample's are: its records serve for the rows
it holds, and the rows of AB_i run for the sensitivity output alone. Records are keyed by
sample index, so results do not depend on the executor, its workers or the batches.

The output of the sensitivity analyses is the worse of the calibrated pitch and roll RMS
errors, degrees. The sample's statistics (yield and its interval, distributions, the required
margin) are :mod:`reflector_opt.tolerance._statistics`; the Sobol indices' summary is
:func:`reflector_opt.tolerance._sensitivity.sobol_summary`.
"""

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from reflector_opt.tolerance._analysis import (
    ASSESSED,
    Job,
    Settings,
    Targets,
    check_work,
    evaluate_part,
    passes,
)
from reflector_opt.tolerance._sensitivity import NOISE, check_rows, mix, sobol_summary
from reflector_opt.tolerance._statistics import COVERAGE, check_coverage, summarise
from reflector_opt.tolerance._tolerances import Tolerances, draw_sample
from reflector_opt.util._display import Summarised, fmt
from reflector_opt.util._errors import InputError
from reflector_opt.util._pools import local_processes, run_batches

#: Samples per batch: large enough that scheduling costs little next to the work (~1–2 s).
BATCH_SIZE = 32


def _count(value, where, minimum):
    if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
        raise InputError(f"{where}: must be a whole number ≥ {minimum}, got {value!r}")
    return value


def batched(items, size=BATCH_SIZE):
    """Consecutive slices of ``items`` of at most ``size``."""
    _count(size, "batch size", 1)
    return [items[i : i + size] for i in range(0, len(items), size)]


def output_of(record):
    """The sensitivity output of one record: the worse calibrated RMS error, degrees (NaN if
    the unit is invalid)."""
    return max(record["rms_pitch_deg"], record["rms_roll_deg"])


@dataclass(frozen=True, repr=False)
class ToleranceStudy(Summarised):
    """Results of :func:`run_study`.

    Attributes
    ----------
    records : list of dict
        One per Monte Carlo sample, in index order.
    nominal : dict
        The nominal design's record (every tolerance off, the noise of sample 0).
    summary : dict
        :func:`~reflector_opt.tolerance._statistics.summarise` of the records.
    one_at_a_time : list of dict
        Per active tolerance (and the baseline ``"none"``): mean and p95 of the output with
        that tolerance alone, its increase over the baseline, and the yield.
    sobol : dict or None
        :func:`~reflector_opt.tolerance._sensitivity.sobol_summary`: per group, the first-order
        and total index with 95 % bootstrap intervals.
    tolerances, targets, settings, seed
        The inputs.
    """

    records: list
    nominal: dict
    summary: dict
    one_at_a_time: list = field(default_factory=list)
    sobol: dict | None = None
    tolerances: Tolerances = field(default_factory=Tolerances)
    targets: Targets = field(default_factory=Targets)
    settings: Settings = field(default_factory=Settings)
    seed: int = 0

    def to_dict(self):
        """JSON-ready summary (without the per-sample records, which go to the CSV)."""
        return {
            "seed": self.seed,
            "tolerances": self.tolerances.to_dict(),
            "settings": dataclasses.asdict(self.settings),
            "nominal": {k: _json(v) for k, v in self.nominal.items()},
            **self.summary,
            "sensitivity_output": "max(rms_pitch_deg, rms_roll_deg)",
            "one_at_a_time": self.one_at_a_time,
            "sobol": self.sobol,
        }

    # -- display (equality is the dataclass's, field by field) --

    def _summary(self):
        """Title and (label, value) rows of the key figures of a self, units included."""
        s = self.summary
        y, t, d = s["yield"], s["targets"], s["distributions"]
        low, high = s["yield_interval"]["all"]
        title = (
            f"ToleranceStudy: {s['samples']} units (seed {self.seed}), yield {_percent(y['all'])} "
            f"(95% interval {_percent(low)} to {_percent(high)})"
        )
        active = self.tolerances.active()
        named = ", ".join(active[:_SHOWN_TOLERANCES])
        more = len(active) - _SHOWN_TOLERANCES
        rows = [
            ("units", f"{s['invalid']} not built (invalid), {s['unfit']} not calibratable"),
            (
                "yield by target",
                f"window kept {_percent(y['window'])}, RMS ≤ {fmt(t['rms_deg'], unit='°')} "
                f"{_percent(y['rms'])}, max ≤ {fmt(t['max_deg'], unit='°')} {_percent(y['max'])}",
            ),
            (
                "RMS error",
                f"pitch {_spread(d['rms_pitch_deg'], '°')}; roll {_spread(d['rms_roll_deg'], '°')}",
            ),
            (
                "max error",
                f"pitch {_spread(d['max_pitch_deg'], '°')}; roll {_spread(d['max_roll_deg'], '°')}",
            ),
            ("distance margin", _spread(d["distance_margin_mm"], "mm", "median", "p5")),
            (
                "tolerances",
                f"{len(active)} active"
                + (f": {named}" if active else "")
                + (f" and {more} more" if more > 0 else ""),
            ),
        ]
        if "required_margin_mm" in s:
            m = s["required_margin_mm"]
            bound = "95% upper bound" if m["confidence"] is not None else "estimate"
            rows.append(
                (
                    "margin lost",
                    f"{fmt(m['value'], unit='mm')} in {fmt(100 * m['coverage'], unit='%')} of "
                    f"units ({bound})",
                )
            )
        return title, rows + _sensitivity_rows(self)


#: Active tolerances named in the short display; more are counted.
_SHOWN_TOLERANCES = 4


def _percent(fraction):
    return "not assessed" if fraction is None else fmt(100.0 * fraction, unit="%")


def _spread(distribution, unit, low="median", high="p95"):
    """``median X, p95 Y`` of a distribution of
    :func:`~reflector_opt.tolerance._statistics.summarise`; ``n/a`` without units."""
    if distribution is None:
        return "n/a"
    return f"{low} {fmt(distribution[low], unit=unit)}, {high} {fmt(distribution[high], unit=unit)}"


def _sensitivity_rows(study):
    """Rows of the leading tolerance of each sensitivity analysis that ran."""
    rows = []
    effects = [e for e in study.one_at_a_time if e["tolerance"] != "none"]
    if effects:
        top = max(effects, key=lambda e: e["mean_increase_deg"])
        rows.append(
            (
                "one at a time",
                f"largest {top['tolerance']}: mean worse RMS error "
                f"{fmt(top['mean_increase_deg'], unit='°')} above none ({len(effects)} tolerances)",
            )
        )
    if study.sobol and "error" in study.sobol:
        rows.append(("Sobol indices", f"not computed: {study.sobol['error']}"))
    elif study.sobol:
        ranked = [g for g in study.sobol["groups"] if g["total"] is not None]
        top = max(ranked, key=lambda g: g["total"], default=None)
        text = "all undefined" if top is None else f"largest total {top['tolerance']} "
        text += "" if top is None else fmt(top["total"], 2)
        rows.append(("Sobol indices", f"{text} ({study.sobol['rows']} rows)"))
    return rows


def _json(value):
    return None if isinstance(value, float) and not math.isfinite(value) else value


def run_study(
    design,
    tolerances=None,
    *,
    samples=200,
    seed=0,
    settings=None,
    targets=None,
    oat_samples=0,
    sobol_samples=0,
    coverage=COVERAGE,
    factory=None,
    batch_size=BATCH_SIZE,
    progress=None,
):
    """Monte Carlo tolerance analysis of a design, with optional sensitivity analyses.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    tolerances : Tolerances, optional
        Default :class:`Tolerances()` (the documented defaults).
    samples : int
        Monte Carlo samples (≥ 1).
    seed : int
        Seed of every draw (≥ 0); sample i is drawn from ``(seed, i)``.
    settings : Settings, optional
    targets : Targets, optional
    oat_samples : int
        Samples of each one-at-a-time run (0: none); they reuse the first draws.
    sobol_samples : int
        Rows N of each Sobol matrix: 0 (none) or a power of two (scipy's estimator needs one);
        needs N (k + 2) runs for k active groups, of which the sample's own records give the
        rows of A and B it holds and the k N rows of AB_i run for the calibrated error alone.
    coverage : float
        Fraction of built units the required margin covers, strictly between 0 and 1.
    factory : callable, optional
        Executor factory; default two local processes.
    batch_size : int
        Samples per batch.
    progress : callable, optional
        ``progress(fraction, message)``.

    Returns
    -------
    ToleranceStudy
    """
    tolerances = Tolerances() if tolerances is None else tolerances
    settings = Settings() if settings is None else settings
    targets = Targets() if targets is None else targets
    coverage = _check_study(samples, seed, oat_samples, sobol_samples, coverage, settings, targets)
    units = planned_units(tolerances, samples, oat_samples, sobol_samples)
    check_work(design.workspace, settings, units, "samples (with the sensitivity runs)")
    plan = _StudyPlan(design, tolerances, settings, samples, seed, oat_samples, sobol_samples)
    tables = _run_parts(
        plan.parts, local_processes() if factory is None else factory, batch_size, progress
    )

    def ordered(key):
        table = tables[key]
        return [table[i] for i in sorted(table)]

    records = ordered("main")
    nominal = ordered("nominal")[0]
    nominal_margin = nominal["distance_margin_mm"] if nominal["status"] in ASSESSED else None
    sobol = None
    if plan.groups:
        known = {**tables["main"], **tables.get("sobol:rows", {})}  # A and B: full records
        n = sobol_samples
        sobol = sobol_summary(
            plan.groups,
            [output_of(known[i]) for i in range(n)],
            [output_of(known[n + i]) for i in range(n)],
            [
                [output_of(tables["sobol:AB"][(2 + g) * n + r]) for r in range(n)]
                for g in range(len(plan.groups))
            ],
            seed=seed,
        )
    return ToleranceStudy(
        records=records,
        nominal=nominal,
        summary=summarise(records, targets, coverage, nominal_margin_mm=nominal_margin),
        one_at_a_time=_one_at_a_time(plan.oat_names, ordered, targets),
        sobol=sobol,
        tolerances=tolerances,
        targets=targets,
        settings=settings,
        seed=seed,
    )


def _check_study(samples, seed, oat_samples, sobol_samples, coverage, settings, targets):
    """Refuse bad study parameters (InputError); return the checked coverage."""
    _count(samples, "samples", 1)
    _count(seed, "seed", 0)
    _count(oat_samples, "oat samples", 0)
    check_rows(sobol_samples)
    coverage = check_coverage(coverage)
    if not settings.calibrate:
        if oat_samples or sobol_samples:
            raise InputError(
                "settings.calibrate = false: the sensitivity analyses rank the calibrated "
                "error; set run.oat_samples and run.sobol_samples to 0"
            )
        if not targets.window:
            raise InputError(
                "settings.calibrate = false judges the distance window alone; "
                "targets.window must be true"
            )
    return coverage


def planned_units(tolerances, samples, oat_samples, sobol_samples):
    """Units a study simulates in all, counted before any is drawn.

    The Monte Carlo sample, the nominal unit, ``oat_samples`` per one-at-a-time run (one run
    per active tolerance and one with none) and, with Sobol rows N, the rows of A and B the
    sample does not hold plus N per group (active tolerances and the noise); as
    :class:`_StudyPlan` lays them out.

    Parameters
    ----------
    tolerances : Tolerances
    samples, oat_samples, sobol_samples : int
        The study's counts (:func:`run_study`).

    Returns
    -------
    int
    """
    active = len(tolerances.active())
    oat = (1 + active) * oat_samples if oat_samples else 0
    sobol = max(0, 2 * sobol_samples - samples) + sobol_samples * (active + 1)
    return samples + 1 + oat + (sobol if sobol_samples else 0)


class _StudyPlan:
    """The parts of a study: each a job and the draws it evaluates, by key.

    ``main`` (the Monte Carlo sample) and ``nominal`` (every tolerance off); with one-at-a-time
    runs ``oat:<tolerance>`` (and ``oat:none``); with Sobol rows N, the rows of A and B (draws
    0 … N − 1 and N … 2N − 1) that the Monte Carlo sample does not already hold, as
    ``sobol:rows`` — the sample's own records serve for the others, the same draws and job —
    and ``sobol:AB``: the rows of every AB_i (index (2 + i) N + r), row by row, evaluated for
    the sensitivity output alone (``Job.full`` false).
    """

    def __init__(self, design, tolerances, settings, samples, seed, oat_samples, sobol_samples):
        n_sensors = len(design.sensors)

        def draw(i):
            return draw_sample(tolerances, n_sensors, seed, i)

        full = Job(design, tolerances, settings)
        draws = [draw(i) for i in range(samples)]
        self.parts = {
            "main": (full, draws),
            "nominal": (Job(design, Tolerances.zero(), settings), draws[:1]),
        }
        self.oat_names = ("none", *tolerances.active()) if oat_samples else ()
        oat_draws = [draws[i] if i < samples else draw(i) for i in range(oat_samples)]
        for name in self.oat_names:
            only = (
                Tolerances.zero(tolerances.multiplexed) if name == "none" else tolerances.only(name)
            )
            self.parts[f"oat:{name}"] = (Job(design, only, settings), oat_draws)
        self.groups = (*tolerances.active(), NOISE) if sobol_samples else ()
        if sobol_samples:
            n = sobol_samples
            rows = [draws[i] if i < samples else draw(i) for i in range(2 * n)]
            if 2 * n > samples:
                self.parts["sobol:rows"] = (full, rows[samples:])
            output_only = dataclasses.replace(full, full=False)
            self.parts["sobol:AB"] = (
                output_only,
                [  # row by row, so that a batch holds a row's groups, many of one optics
                    mix(rows[r], rows[n + r], group, (2 + g) * n + r)
                    for r in range(n)
                    for g, group in enumerate(self.groups)
                ],
            )

    def units(self):
        """Units simulated in all."""
        return sum(len(part_draws) for _, part_draws in self.parts.values())


def _run_parts(parts, factory, batch_size, progress):
    """Every part's draws in batches on the executor: per part, the records by index."""
    batches, owners = [], []
    for key, (job, part_draws) in parts.items():
        for chunk in batched(part_draws, batch_size):
            batches.append((job, chunk))
            owners.append(key)
    results = run_batches(evaluate_part, None, batches, factory, progress=progress)
    tables = {key: {} for key in parts}
    for key, batch in zip(owners, results, strict=True):
        tables[key].update((r["index"], r) for r in batch)
    return tables


def _finite_or_none(values, statistic):
    """``statistic`` of the finite values, or None when there are none."""
    values = np.asarray(values, dtype=float)
    return (
        _json(float(statistic(values[np.isfinite(values)]))) if np.isfinite(values).any() else None
    )


def _one_at_a_time(names, ordered, targets):
    """Per one-at-a-time run: mean and p95 of the output, its increase over ``none``, yield."""
    if not names:
        return []
    base = np.array([output_of(r) for r in ordered("oat:none")])
    oat = []
    for name in names:
        recs = ordered(f"oat:{name}")
        y = np.array([output_of(r) for r in recs])
        oat.append(
            {
                "tolerance": name,
                "mean_deg": _finite_or_none(y, np.mean),
                "p95_deg": _finite_or_none(y, lambda v: np.percentile(v, 95)),
                "mean_increase_deg": _finite_or_none(y - base, np.mean),
                "yield": sum(passes(r, targets) for r in recs) / len(recs),
                "invalid": sum(r["status"] != "ok" for r in recs),
            }
        )
    return oat
