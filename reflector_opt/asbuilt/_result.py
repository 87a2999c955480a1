"""The result of an as-built identification and what follows from it.

:class:`Identification` holds the MAP estimate of a batch's as-built parameters with their
covariance; it gives each parameter's table row, each unit as built (a complete design and
its read-out mismatch), each sensor's as-built distance over the workspace with its
uncertainty, and the ``AS_BUILT.json`` document (:mod:`reflector_opt.asbuilt._asbuiltfile`).
"""

from dataclasses import dataclass
from functools import partial

import numpy as np

from reflector_opt.asbuilt._uncertainty import DETERMINED_RATIO
from reflector_opt.model._geometry import sensor_distance
from reflector_opt.util._display import Summarised, fmt

#: A reference parameter is said to enter a determined combination when its weight there
#: (prior-std units, the combination a unit vector) is at least this.
_COMBINATION_WEIGHT = 0.3


@dataclass(frozen=True, repr=False)
class Identification(Summarised):
    """The as-built parameters of a batch of units, with their uncertainty.

    Attributes
    ----------
    layout : reflector_opt.asbuilt._parameters.ParameterLayout
        The parameter vector's layout (and the design and priors).
    labels : tuple of str
        The units' ids, in the data's order.
    x : numpy.ndarray
        MAP estimate of every parameter's deviation from the design.
    covariance : numpy.ndarray
        Its covariance: the posterior's (Laplace, the data inflated by s²), the model-form
        amplitudes among the parameters (never above the prior).
    systematic_covariance : numpy.ndarray
        The part of it from physics the model lacks: the covariance less that with the
        model-form amplitudes known (:mod:`~reflector_opt.asbuilt._model_form_terms`; zeros when it
        was left out).
    inflation : float
        The block cross-validation ratio s² ≥ 1 the data covariance was inflated by.
    residual_rms_v : numpy.ndarray
        Shape (units, sensors): RMS voltage misfit of each unit's calibration, V.
    combinations : list of list of reflector_opt.asbuilt._uncertainty.Combination
        Per unit, the parameter combinations the data determine.
    profiles : dict of str to Profile
        Profile-likelihood intervals (90 %) by parameter name.
    evaluations : int
        Residual evaluations of the fit.
    seconds : float
        Wall time of the identification, s.
    n_samples, n_curves : tuple of int
        Per unit, calibration samples and flat-target curves used.
    reference_sigma_deg : float
        The angle reference's noise assumed, degrees.
    terms : reflector_opt.asbuilt._model_form_terms.ModelFormTerms or None
        The model-form bias and signatures the fit used (None: the fast model alone).
    """

    layout: object
    labels: tuple
    x: np.ndarray
    covariance: np.ndarray
    systematic_covariance: np.ndarray
    inflation: float
    residual_rms_v: np.ndarray
    combinations: list
    profiles: dict
    evaluations: int
    seconds: float
    n_samples: tuple
    n_curves: tuple
    reference_sigma_deg: float
    terms: object = None

    @property
    def design(self):
        """The design the units were printed from."""
        return self.layout.design

    @property
    def std(self):
        """Posterior standard deviation of every parameter, in vector order."""
        return np.sqrt(np.clip(np.diag(self.covariance), 0.0, None))

    def _rows(self, indices, names):
        """Table rows (estimate, design, std, prior, determined, interval) of the parameters at
        ``indices`` of an :class:`Identification`, under ``names``."""
        prior = self.layout.prior_std()
        nominal = self.layout.nominal()
        std = self.std
        systematic = np.sqrt(np.clip(np.diag(self.systematic_covariance), 0.0, None))
        table = {}
        for i, name in zip(indices, names, strict=True):
            ratio = std[i] / prior[i] if prior[i] > 0 else 0.0
            table[name] = {
                "estimate": float(nominal[i] + self.x[i]),
                "design": float(nominal[i]),
                "std": float(std[i]),
                "model_form_std": float(systematic[i]),
                "prior_std": float(prior[i]),
                "posterior_prior_ratio": float(ratio),
                "identifiable": bool(prior[i] > 0 and ratio <= DETERMINED_RATIO),
            }
            profile = self.profiles.get(self._full_name(i))
            if profile is not None:
                table[name]["interval_90"] = profile.to_dict()
        return table

    def _full_name(self, i):
        return self.layout.names(list(self.labels))[i]

    def shared_parameters(self):
        """The batch's shared parameters: {name: {estimate, design, std, prior_std, ...}}.

        Each estimate is the surface the model used: the fit's ρ, f and ℓ are taken into
        [0.001, 1], [0, 1] and [0, 1] mm
        (:meth:`~reflector_opt.asbuilt._parameters.ParameterLayout.unit_design`), so a fit that
        ends a rounding error beyond a bound reports the bound.
        """
        indices = range(len(self.layout.shared_names))
        rows = self._rows(indices, self.layout.shared_names)
        used = self.layout.unit_design(self.x, 0)[0].reflector
        for name, row in rows.items():
            if name == "subsurface_mm":
                row["estimate"] = self.layout.subsurface_mm(self.x)
            else:
                row["estimate"] = float(getattr(used, name))
        return rows

    def unit_parameters(self, u):
        """Unit ``u``'s parameters: {name: {estimate, design, std, prior_std, identifiable}}.

        Geometry entries are deviations from the design in mm or degrees (``design`` 0),
        except the radius (absolute, mm) and the gain (a factor, design 1).
        """
        block = self.layout.unit_slice(u)
        return self._rows(range(block.start, block.stop), self.layout.unit_names)

    def reference_parameters(self, u):
        """Unit ``u``'s angle-reference parameters, and what the data cannot tell them from.

        Empty when the reference was taken as exact. Each row is as
        :meth:`unit_parameters`' (deviations from an exact reference, degrees), with
        ``correlated_with`` and ``correlation``: the print, read-out or surface parameter its
        posterior is most correlated with; and ``combination``: the determined combination
        it weighs most in (:attr:`combinations`; None if none), named in words.

        Returns
        -------
        dict
        """
        span = self.layout.reference_slice(u)
        indices = range(span.start, span.stop)
        rows = self._rows(indices, self.layout.reference_names)
        for i, row in zip(indices, rows.values(), strict=True):
            row.update(_entanglement(self, u, i))
        return rows

    def model_form_parameters(self, u):
        """Unit ``u``'s model-form amplitudes, rows as :meth:`unit_parameters` (each in units
        of its effect's documented size; empty without them)."""
        span = self.layout.model_form_slice(u)
        return self._rows(range(span.start, span.stop), self.layout.model_form_names)

    def unit_covariance(self, u, systematic=False):
        """Covariance of the shared parameters and unit ``u``'s block, in that order (with
        ``systematic``, only its part from physics the model lacks)."""
        index = self.layout.unit_indices(u)
        matrix = self.systematic_covariance if systematic else self.covariance
        return matrix[np.ix_(index, index)]

    def as_built(self, u):
        """Unit ``u`` as built: a complete design and its read-out mismatch.

        Returns
        -------
        (reflector_opt.design._design.Design, reflector_opt.model._noise.Mismatch)
        """
        return self.layout.unit_design(self.x, u)

    def estimator(self, u):
        """Unit ``u``'s angles from voltages through its identified model, in the frame of
        the reference it was calibrated with.

        Returns
        -------
        reflector_opt.asbuilt._estimator.AsBuiltModel
        """
        from reflector_opt.asbuilt._estimator import AsBuiltModel, reference_of

        extra = None
        if self.terms is not None:
            amplitudes = self.x[self.layout.model_form_slice(u)]
            extra = partial(self.terms.extra_volts, amplitudes=amplitudes)
        return AsBuiltModel(
            *self.as_built(u),
            reference_of(self.reference_parameters(u)),
            subsurface_mm=self.layout.subsurface_mm(self.x),
            extra_volts=extra,
        ).fit()

    def distance_mm(self, u, pitch_deg, roll_deg):
        """Each sensor's as-built Eq 3 distance and its standard uncertainty, mm.

        Parameters
        ----------
        u : int
            The unit.
        pitch_deg, roll_deg : array_like
            Poses, degrees, broadcast to shape P.

        Returns
        -------
        (numpy.ndarray, numpy.ndarray)
            Distances and their posterior std, each of shape ``P + (n_sensors,)``.
        """
        index = self.layout.unit_indices(u)

        def distance(x):
            built, _ = self.layout.unit_design(x, u)
            return sensor_distance(
                built.positions_mm,
                built.reflector.centre_mm,
                built.reflector.radius_mm,
                pitch_deg,
                roll_deg,
            )

        value = distance(self.x)
        gradient = _central_gradient(distance, self.x, value, index, self.layout.steps())
        cov = self.unit_covariance(u)
        variance = np.einsum("...i,ij,...j->...", gradient, cov, gradient)
        return value, np.sqrt(np.clip(variance, 0.0, None))

    def to_dict(self, source=None):
        """The ``AS_BUILT.json`` document (see :mod:`reflector_opt.asbuilt._asbuiltfile`)."""
        from reflector_opt.asbuilt._asbuiltfile import identification_to_dict

        return identification_to_dict(self, source)

    def save(self, path, source=None):
        """Write ``AS_BUILT.json`` atomically."""
        from reflector_opt.util._fileio import write_json

        write_json(path, self.to_dict(source))

    def _summary(self):
        """Title and rows: units, the surface, each unit's determined parameters."""
        shared = self.shared_parameters()
        rows = [
            (
                name,
                f"{fmt(row['estimate'], 4)} ± {fmt(row['std'], 2)} "
                f"({'determined' if row['identifiable'] else 'not determined'})",
            )
            for name, row in shared.items()
        ]
        for u, label in enumerate(self.labels):
            determined = [n for n, r in self.unit_parameters(u).items() if r["identifiable"]]
            rows.append((f"unit {label}", f"{len(determined)} determined: {', '.join(determined)}"))
            reference = self.reference_parameters(u)
            if reference:
                rows.append((f"unit {label} reference", _reference_text(reference)))
        rows.append(("noise inflation s²", fmt(self.inflation, 3)))
        title = (
            f"Identification: {len(self.labels)} unit(s), "
            f"{sum(self.n_samples)} samples, {fmt(self.seconds, 2, 's')}"
        )
        return title, rows


def _entanglement(result, u, i):
    """The parameter of unit ``u`` (or shared) most correlated with parameter ``i`` in the
    posterior, the correlation, and the determined combination ``i`` weighs most in."""
    block = result.layout.unit_slice(u)
    others = [*range(len(result.layout.shared_names)), *range(block.start, block.stop)]
    cov = result.covariance
    scale = np.sqrt(np.clip(np.diag(cov), 1e-300, None))
    correlation = cov[i, others] / (scale[i] * scale[others])
    best = int(np.argmax(np.abs(correlation)))
    name = result._full_name(i)
    weights = [abs(c.weights.get(name, 0.0)) for c in result.combinations[u]]
    chosen = int(np.argmax(weights)) if weights and max(weights) >= _COMBINATION_WEIGHT else None
    return {
        "correlated_with": result._full_name(others[best]).split(": ")[-1],
        "correlation": float(correlation[best]),
        "combination": None if chosen is None else result.combinations[u][chosen].name,
    }


def _central_gradient(function, x, value, index, steps):
    """Central differences of ``function`` (whose value at x is ``value``) in the parameters
    ``index`` with their ``steps``, stacked along a new last axis."""
    gradient = np.zeros((*value.shape, len(index)))
    for k, j in enumerate(index):
        up, down = x.copy(), x.copy()
        up[j] += steps[j]
        down[j] -= steps[j]
        gradient[..., k] = (function(up) - function(down)) / (2 * steps[j])
    return gradient


def _reference_text(rows):
    """``pitch zero +0.84 ± 0.83°, …`` of a unit's reference rows."""
    return ", ".join(
        f"{name.removeprefix('reference_').removesuffix('_deg').replace('_', ' ')} "
        f"{fmt(row['estimate'] - row['design'], 2)} ± {fmt(row['std'], 2, '°')}"
        for name, row in rows.items()
    )
