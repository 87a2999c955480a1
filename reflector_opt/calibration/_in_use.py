"""The in-use part of each angle's 1σ: the error budget's terms for the stated conditions.

A calibration's own error (cross-validated) and the reading's noise are random from frame to
frame; what the stated conditions add (docs/conditions.md) is systematic: a unit 5 K warmer
than at calibration reads every pose shifted by the same amount each time it is there. The
error budget (:func:`~reflector_opt.analysis._budget.error_budget`) gives each source's signed
error pose by pose for each of its scenarios; here, once per unit, they become two tables over
the budget's grid of the workspace:

* each source's size at a pose, b_i, its worst scenario there (the budget's ``maps``; ±x:
  abs(x)), and B_fixed² = Σ b_i² over every source but ``noise`` and ``form`` (already in the
  random part) and, for a calibration that is not temperature-compensated, ``temperature``
  and ``expansion``;
* for such a calibration, the thermal error at ΔT = +R and −R (R the conditions'
  ``temperature_range_k``; 1 K where it is 0): the ``temperature`` and ``expansion`` terms of
  the same scenario added signed (one ΔT moves both), and per reading scaled by abs(ΔT)/R with
  ΔT = T − ``calibration_temperature_c`` of the reading's temperature (the side of its sign);
  without a temperature, abs(ΔT) = the stated range, its unfavourable end.

A reading's bias size is B = sqrt(B_fixed² + (thermal · abs(ΔT)/R)²) at the nearest grid pose
of its estimated angles (sources of independent sign in quadrature). Whether the calibration is
compensated is its own (a :class:`~reflector_opt.calibration._temperature.TemperatureCompensated`
model: the budget's compensated residue, the thermometer's error, the strip's gradient and the
curvature, in B_fixed), not the conditions' key.

What 1σ means with a bias: the reading's error is e = ±B + n, the sign unknown (the
budget's figures are assumed, at the unfavourable end of ranges that may span zero), n the
random part, of standard deviation σ_r (the calibration's cross-validated error and the noise).
B enters σ as the standard deviation of its two signs, B, so σ² = σ_r² + B² (the GUM's
combination of a systematic effect of unknown sign): the error's standard deviation over what
is not known. Where B dominates, ±σ then holds the errors of a unit whose bias is below the
budget's and misses those of a unit whose bias is above it; a unit at the budget's figures
exactly lies at the edge (half within). The budget takes each assumed figure at its
unfavourable end, so a unit with milder figures lies within; docs/robot.md gives the coverage
measured on the virtual device.
"""

from dataclasses import dataclass

import numpy as np

from reflector_opt.util._errors import InputError

#: The budget's sources the random part of σ holds already.
_RANDOM = ("noise", "form")
_THERMAL = ("temperature", "expansion")


@dataclass(frozen=True)
class InUseTerms:
    """One calibration's in-use bias tables over the budget's grid (module notes).

    Attributes
    ----------
    pitch_deg, roll_deg : numpy.ndarray
        The grid's axes, degrees.
    fixed_sq : numpy.ndarray
        B_fixed², shape (n_pitch, n_roll, 2), deg².
    thermal_deg : numpy.ndarray or None
        The signed thermal error at ΔT = +R and −R, shape (2, n_pitch, n_roll, 2), degrees;
        None for a compensated calibration.
    range_k : float
        R of the tables, K.
    stated_k : float
        The conditions' ``temperature_range_k``, K: abs(ΔT) of a reading without a temperature.
    calibration_c : float
        The calibration's temperature, °C.
    assumed : tuple of dict
        The assumed figures the budget leaned on.
    """

    pitch_deg: np.ndarray
    roll_deg: np.ndarray
    fixed_sq: np.ndarray
    thermal_deg: np.ndarray | None
    range_k: float
    stated_k: float
    calibration_c: float
    assumed: tuple

    @classmethod
    def of(cls, design, conditions, compensated):
        """The tables of a unit of ``design`` in ``conditions``, its calibration compensated or
        not (:func:`~reflector_opt.analysis._budget.error_budget`, once)."""
        from reflector_opt.analysis._budget import error_budget

        stated_k = conditions.temperature_range_k
        range_k = stated_k if stated_k or compensated else 1.0  # a plain one's per-K table
        conditions = conditions.replace(
            temperature_compensated=compensated, temperature_range_k=range_k
        )
        budget = error_budget(design, conditions)
        shape = (*budget.pitch_deg.shape, 2)
        kept = {k: v for k, v in budget.maps.items() if k not in _RANDOM}
        thermal = None
        if not compensated:
            thermal = sum(budget.scenarios[k] for k in _THERMAL).reshape(2, *shape)
            kept = {k: v for k, v in kept.items() if k not in _THERMAL}
        fixed = sum(np.square(m) for m in kept.values())
        return cls(
            budget.pitch_deg[:, 0],
            budget.roll_deg[0],
            fixed,
            thermal,
            range_k,
            stated_k,
            conditions.calibration_temperature_c,
            budget.assumed,
        )

    def bias_deg(self, angles_deg, temperature_c=None):
        """Each reading's bias size B, degrees, shape ``P + (2,)``.

        Parameters
        ----------
        angles_deg : numpy.ndarray
            The estimated (pitch, roll), shape ``P + (2,)``, degrees: B at the nearest grid
            pose.
        temperature_c : numpy.ndarray or None
            Shape ``P``, °C; None: abs(ΔT) = R, the stated range's unfavourable end.
        """
        i = _nearest(self.pitch_deg, angles_deg[..., 0])
        j = _nearest(self.roll_deg, angles_deg[..., 1])
        square = self.fixed_sq[i, j]
        if self.thermal_deg is not None:
            if temperature_c is None:
                delta = np.full(i.shape, self.stated_k)
            else:
                delta = np.asarray(temperature_c, float) - self.calibration_c
            side = (delta < 0).astype(int)
            square = (
                square + (self.thermal_deg[side, i, j] * (delta / self.range_k)[..., None]) ** 2
            )
        return np.sqrt(square)


def units_bias_deg(terms, angles_deg, temperature_c=None):
    """Each unit's :meth:`InUseTerms.bias_deg`, shape (n, n_units, 2), of its angles (n, n_units,
    2) and temperatures (°C, (n, n_units) or None), the units of one table (one design and
    kind: :func:`in_use_terms` makes it once) in one call."""
    out = np.empty(angles_deg.shape)
    for table in {id(t): t for t in terms}.values():
        cols = [j for j, t in enumerate(terms) if t is table]
        at = None if temperature_c is None else temperature_c[:, cols]
        out[:, cols] = table.bias_deg(angles_deg[:, cols], at)
    return out


def _nearest(axis, values):
    step = axis[1] - axis[0] if len(axis) > 1 else 1.0
    # fmax/fmin rather than np.clip (its Python wrapper costs more than the rest): NaN to 0
    return np.rint(np.fmin(np.fmax((values - axis[0]) / step, 0), len(axis) - 1)).astype(int)


def in_use_terms(calibrations, conditions, design=None):
    """Each calibration's :class:`InUseTerms` in ``conditions``, computed once per kind.

    Parameters
    ----------
    calibrations : list of UnitCalibration
    conditions : Conditions, str or pathlib.Path
        The stated conditions or their TOML file.
    design : Design, str or pathlib.Path, optional
        The units' design or its design.json; needed where a calibration holds none (a
        polynomial one; a physical or as-built calibration holds its own).

    Returns
    -------
    list of InUseTerms
    """
    from reflector_opt.calibration._temperature import TemperatureCompensated
    from reflector_opt.design import Design, load_design
    from reflector_opt.design._conditions import as_conditions

    conditions = as_conditions(conditions)
    if design is not None and not isinstance(design, Design):
        design = load_design(design)
    found, terms = {}, []
    for c in calibrations:
        own = getattr(c.model, "design", None) or design
        if own is None:
            raise InputError(
                f"--design: unit {c.unit}'s calibration holds no design, and the in-use terms "
                "of --conditions need the units' design.json"
            )
        key = (id(own), isinstance(c.model, TemperatureCompensated))
        if key not in found:
            found[key] = InUseTerms.of(own, conditions, key[1])
        terms.append(found[key])
    return terms


def in_use_note(terms, temperature):
    """What the 1σ holds of the in-use terms and what it leans on: one line for a run's output.

    Parameters
    ----------
    terms : list of InUseTerms
    temperature : bool or None
        The readings carry temperatures (True), none (False), or each where given (None: a
        log not read yet).

    Returns
    -------
    str
    """
    parts = ["each 1σ holds the stated conditions' in-use terms"]
    plain = [t for t in terms if t.thermal_deg is not None]
    if plain:
        worst = f"±{plain[0].stated_k:g} K from calibration, the stated range's unfavourable end"
        parts.append(
            {
                True: "the temperature's at each reading's",
                False: f"the temperature's at {worst} (the readings carry none)",
                None: f"the temperature's at each row's temperature_c, else at {worst}",
            }[temperature]
        )
    assumed = sorted({f["figure"] for t in terms for f in t.assumed})
    if assumed:
        parts.append(f"leaning on {len(assumed)} assumed figure(s): {', '.join(assumed)}")
    return "; ".join(parts)
