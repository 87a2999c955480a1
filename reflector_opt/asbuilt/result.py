"""The result of an as-built identification and what follows from it.

:class:`Identification` holds the MAP estimate of a batch's as-built parameters with their
covariance; it gives each parameter's table row, each unit as built (a complete design and
its read-out mismatch), each sensor's as-built distance over the workspace with its
uncertainty, and the ``AS_BUILT.json`` document (:mod:`reflector_opt.asbuilt.asbuiltfile`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reflector_opt.asbuilt.uncertainty import DETERMINED_RATIO
from reflector_opt.model.geometry import sensor_distance
from reflector_opt.util.display import fmt, html_summary, text_summary

__all__ = ["Identification"]


@dataclass(frozen=True)
class Identification:
    """The as-built parameters of a batch of units, with their uncertainty.

    Long because it is the record of fourteen documented fields and the views of them the
    reports and files read; its tables and gradients are module functions.

    Attributes
    ----------
    layout : reflector_opt.asbuilt.parameters.Layout
        The parameter vector's layout (and the design and priors).
    labels : tuple of str
        The units' ids, in the data's order.
    x : numpy.ndarray
        MAP estimate of every parameter's deviation from the design.
    covariance : numpy.ndarray
        Its covariance: the posterior's (Laplace, inflated by the Birge ratio) plus the
        systematic term.
    systematic_covariance : numpy.ndarray
        The part of it from physics the model lacks (:mod:`~reflector_opt.asbuilt.modelform`;
        zeros when it was left out).
    inflation : float
        The Birge ratio s² ≥ 1 the data covariance was inflated by.
    residual_rms_v : numpy.ndarray
        Shape (units, sensors): RMS voltage misfit of each unit's calibration, V.
    combinations : list of list of Combination
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

    @property
    def design(self):
        """The design the units were printed from."""
        return self.layout.design

    @property
    def std(self):
        """Posterior standard deviation of every parameter, in vector order."""
        return np.sqrt(np.clip(np.diag(self.covariance), 0.0, None))

    def _rows(self, indices, names):
        return _parameter_rows(self, indices, names)

    def _full_name(self, i):
        return self.layout.names(list(self.labels))[i]

    def shared_parameters(self):
        """The batch's shared parameters: {name: {estimate, design, std, prior_std, ...}}."""
        indices = range(len(self.layout.shared_names))
        return self._rows(indices, self.layout.shared_names)

    def unit_parameters(self, u):
        """Unit ``u``'s parameters: {name: {estimate, design, std, prior_std, identifiable}}.

        Geometry entries are deviations from the design in mm or degrees (``design`` 0),
        except the radius (absolute, mm) and the gain (a factor, design 1).
        """
        block = self.layout.unit_slice(u)
        return self._rows(range(block.start, block.stop), self.layout.unit_names)

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
        (reflector_opt.design.design.Design, reflector_opt.model.noise.Mismatch)
        """
        return self.layout.unit_design(self.x, u)

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
        """The ``AS_BUILT.json`` document (see :mod:`reflector_opt.asbuilt.asbuiltfile`)."""
        from reflector_opt.asbuilt.asbuiltfile import identification_to_dict

        return identification_to_dict(self, source)

    def save(self, path, source=None):
        """Write ``AS_BUILT.json`` atomically."""
        from reflector_opt.util.fileio import write_json

        write_json(path, self.to_dict(source))

    def __repr__(self):
        return text_summary(*_summary(self))

    def _repr_html_(self):
        return html_summary(*_summary(self))


def _parameter_rows(result, indices, names):
    """Table rows (estimate, design, std, prior, determined, interval) of the parameters at
    ``indices`` of an :class:`Identification`, under ``names``."""
    prior = result.layout.prior_std()
    nominal = result.layout.nominal()
    std = result.std
    systematic = np.sqrt(np.clip(np.diag(result.systematic_covariance), 0.0, None))
    table = {}
    for i, name in zip(indices, names, strict=True):
        ratio = std[i] / prior[i] if prior[i] > 0 else 0.0
        table[name] = {
            "estimate": float(nominal[i] + result.x[i]),
            "design": float(nominal[i]),
            "std": float(std[i]),
            "model_form_std": float(systematic[i]),
            "prior_std": float(prior[i]),
            "posterior_prior_ratio": float(ratio),
            "identifiable": bool(prior[i] > 0 and ratio <= DETERMINED_RATIO),
        }
        profile = result.profiles.get(result._full_name(i))
        if profile is not None:
            table[name]["interval_90"] = profile.to_dict()
    return table


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


def _summary(result):
    """Title and rows: units, the surface, each unit's determined parameters."""
    shared = result.shared_parameters()
    rows = [
        (
            name,
            f"{fmt(row['estimate'], 4)} ± {fmt(row['std'], 2)} "
            f"({'determined' if row['identifiable'] else 'not determined'})",
        )
        for name, row in shared.items()
    ]
    for u, label in enumerate(result.labels):
        determined = [n for n, r in result.unit_parameters(u).items() if r["identifiable"]]
        rows.append((f"unit {label}", f"{len(determined)} determined: {', '.join(determined)}"))
    rows.append(("noise inflation s²", fmt(result.inflation, 3)))
    title = (
        f"Identification: {len(result.labels)} unit(s), "
        f"{sum(result.n_samples)} samples, {fmt(result.seconds, 2, 's')}"
    )
    return title, rows
