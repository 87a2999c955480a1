"""The identified units of one print batch, gathered from their ``AS_BUILT.json`` files.

Each identified unit gives its printed geometry as deviations from the design — the
reflecting sphere's radius and centre, each sensor seat's standoff, shifts and tilts — with
their posterior covariance (:mod:`reflector_opt.asbuilt._identification`). :class:`Batch` gathers
those of one batch from one or more files (:func:`load_batch`) or an identification in
memory, after checking that they belong together: one design (its ``predicted`` block
aside), one prior, one batch name, no file given twice and no unit in two files. Each file
is remembered by the SHA-256 of its canonical JSON, so that a design corrected from it can
be recognised (:mod:`reflector_opt.asbuilt._correction`). :mod:`reflector_opt.asbuilt._pooling`
separates what repeats from what scatters.
"""

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path

import msgspec
import numpy as np

from reflector_opt.asbuilt._asbuiltfile import (
    AsBuiltDocument,
    identification_to_dict,
    load_as_built,
)
from reflector_opt.asbuilt._parameters import REFERENCE_NAMES, ParameterLayout
from reflector_opt.design._design import Design
from reflector_opt.design._designfile import first_difference
from reflector_opt.util import _schema as schema
from reflector_opt.util._errors import InputError

_REFLECTOR = ("reflector_radius_mm", *(f"reflector_centre_{axis}_mm" for axis in "xyz"))
_SEAT = ("standoff_mm", "shift_led_detector_mm", "shift_sideways_mm")
_SEAT += ("tilt_led_detector_deg", "tilt_sideways_deg")


def geometry_names(n_sensors):
    """The printed geometry's parameters, in order: reflector, then each sensor's seat.

    Parameters
    ----------
    n_sensors : int

    Returns
    -------
    tuple of str
    """
    seats = (f"sensor_{k + 1}_{suffix}" for k in range(n_sensors) for suffix in _SEAT)
    return (*_REFLECTOR, *seats)


@dataclass(frozen=True)
class Source:
    """One identification pooled into a batch.

    Attributes
    ----------
    file : str or None
        Its file name (None: given in memory).
    digest : str
        SHA-256 of the document in canonical JSON (key order and spacing do not count).
    batch : str or None
        The batch it records.
    units : tuple of str
        Its units' ids.
    """

    file: str | None
    digest: str
    batch: str | None
    units: tuple

    def to_dict(self):
        """JSON-ready dict."""
        return {"file": self.file, "sha256": self.digest, "batch": self.batch,
                "units": list(self.units)}  # fmt: skip


@dataclass(frozen=True)
class Batch:
    """The identified units of one print batch.

    Attributes
    ----------
    design : reflector_opt.design._design.Design
        The design they were printed from.
    names : tuple of str
        The geometry parameters (:func:`geometry_names`).
    prior_std : numpy.ndarray
        Shape (g,): their prior std, the tolerance model's (mm, degrees).
    labels : tuple of str
        The units' ids, in order.
    deviations : numpy.ndarray
        Shape (n, g): each unit's identified geometry deviation (MAP), mm and degrees.
    covariances : numpy.ndarray
        Shape (n, g, g): its posterior covariance (marginal: surface and read-out integrated),
        statistical only — a model-form term the file records is in ``systematic``.
    blocks : numpy.ndarray
        Shape (n, block): each unit's whole block of deviations (read-out included), in the
        order of :class:`~reflector_opt.asbuilt._parameters.ParameterLayout`.
    surfaces : numpy.ndarray
        Shape (n, 2): the deviation of the surface (reflectance, specular fraction) found
        with each unit.
    sources : tuple of Source
    batch : str or None
        The batch name the files record.
    systematic : numpy.ndarray or None
        Shape (n, g, g): the model-form part of each unit's covariance as the files record it
        (common to the units of a batch; None or zeros: not recorded).
    prior : dict or None
        The identification's prior as the files record it (``tolerances``, ``surface_std``,
        ``reference_std``).
    reference : numpy.ndarray or None
        Shape (n, g, g): the part of each unit's (statistical) covariance that its angle
        reference's uncertainty explains, ``C_gr C_rr⁻¹ C_rg`` of the geometry g and the
        reference's parameters r (None: the files fitted no reference). A reference's error
        may be common to the units (one instrument, one fixture), so
        :func:`~reflector_opt.asbuilt._pooling.pool` does not let this part average out.
    """

    design: Design
    names: tuple
    prior_std: np.ndarray
    labels: tuple
    deviations: np.ndarray
    covariances: np.ndarray
    blocks: np.ndarray
    surfaces: np.ndarray
    sources: tuple
    batch: str | None
    prior: dict | None = None
    systematic: np.ndarray | None = None
    reference: np.ndarray | None = None

    @property
    def n_units(self):
        """Units in the batch."""
        return len(self.labels)

    def prior_options(self):
        """``tolerances`` and ``surface_std`` of
        :func:`~reflector_opt.asbuilt._identification.identify` that reproduce the batch's
        prior (empty when it is not recorded)."""
        if not self.prior:
            return {}
        from reflector_opt.tolerance._tolerances import Tolerances

        reference = self.prior.get("reference_std")
        return {
            "tolerances": Tolerances.from_dict(self.prior["tolerances"]),
            "surface_std": dict(self.prior["surface_std"]),
            "reference_std": None if reference is None else dict(reference),
        }

    def words(self, name):
        """A geometry parameter's name in plain words."""
        return ParameterLayout(self.design, 1).words(name)

    @classmethod
    def from_identification(cls, result, source=None, batch=None):
        """The batch of one identification in memory.

        Parameters
        ----------
        result : reflector_opt.asbuilt._result.Identification
        source : str, optional
            The calibration file's name, recorded.
        batch : str, optional
            The batch name, recorded.

        Returns
        -------
        Batch
        """
        document = identification_to_dict(result, source, batch)
        read = schema.convert(document, AsBuiltDocument, where="as-built")  # defaults filled
        return _from_documents([(None, msgspec.to_builtins(read))])


def _digest(document):
    text = json.dumps(document, sort_keys=True, separators=(",", ":"), ensure_ascii=False)
    return hashlib.sha256(text.encode()).hexdigest()


def _design_key(data):
    """A design document without what does not change the geometry (``predicted``)."""
    return {k: v for k, v in data.items() if k != "predicted"}


def _first_difference(a, b):
    """The first key path where two JSON-like trees differ, with both values, or None."""
    found = first_difference(a, b)
    return None if found is None else f"{found[0]}: {found[1]!r} against {found[2]!r}"


def _name(item):
    return item[0] if item[0] is not None else "the identification"


def _said(document):
    batch = document.get("batch")
    return "no batch recorded" if batch is None else f"batch {batch!r}"


def _check_together(items):
    """Refuse documents of different designs, priors or batches, repeats and unit clashes."""
    first_name, first = _name(items[0]), items[0][1]
    seen, labels = {}, {}
    for item in items:
        name, document = _name(item), item[1]
        digest = _digest(document)
        if digest in seen:
            raise InputError(f"{name}: the same identification as {seen[digest]}, given twice")
        seen[digest] = name
        difference = _first_difference(
            _design_key(first["design"]), _design_key(document["design"])
        )
        if difference:
            raise InputError(
                f"{name}: identified against another design than {first_name} "
                f"(design.{difference}); pool only units printed from one design"
            )
        if document["prior"] != first["prior"]:
            raise InputError(f"{name}: identified with another prior than {first_name}")
        if document.get("batch") != first.get("batch"):
            raise InputError(
                f"{name}: {_said(document)}, but {first_name}: {_said(first)}; pool only the "
                "units of one print batch (identify --batch records it)"
            )
        for unit in document["units"]:
            if unit["unit"] in labels:
                raise InputError(
                    f"{name}: unit {unit['unit']!r} is also in {labels[unit['unit']]}; "
                    "each unit may be pooled once"
                )
            labels[unit["unit"]] = name


def _unit_arrays(document, layout, names):
    """Per unit of a document: geometry deviation, its covariance, whole block, surface."""
    out = []
    shared = document["shared"]
    surface = [shared[k]["estimate"] - shared[k]["design"] for k in layout.shared_names]
    for unit in document["units"]:
        rows = unit["parameters"]
        if list(rows) != list(layout.unit_names):
            raise InputError(
                f"unit {unit['unit']}: its parameters are not those of this design's layout"
            )
        block = np.array([rows[k]["estimate"] - rows[k]["design"] for k in layout.unit_names])
        order = list(unit["covariance"]["names"])
        index = [order.index(k) for k in names]
        matrix = np.asarray(unit["covariance"]["matrix"], dtype=float)[np.ix_(index, index)]
        systematic = _systematic(unit, rows, names, index)
        deviation = np.array([rows[k]["estimate"] - rows[k]["design"] for k in names])
        statistical = _psd(matrix - systematic)
        reference = _reference_share(unit, order, index)
        out.append((unit["unit"], deviation, statistical, block, surface, systematic, reference))
    return out


def _reference_share(unit, order, index):
    """``C_gr C_rr⁺ C_rg`` of a unit's statistical covariance (geometry ``index``, the
    reference's parameters by name in ``order``), or None if the file fitted no reference."""
    if not set(REFERENCE_NAMES) <= set(order):
        return None
    matrix = np.asarray(unit["covariance"]["matrix"], dtype=float)
    form = unit["covariance"].get("model_form")
    if form is not None:
        matrix = matrix - np.asarray(form, dtype=float)
    reference = [order.index(k) for k in REFERENCE_NAMES]
    cross = matrix[np.ix_(index, reference)]
    return _psd(cross @ np.linalg.pinv(matrix[np.ix_(reference, reference)]) @ cross.T)


def _systematic(unit, rows, names, index):
    """The model-form (systematic) part of a unit's covariance the file records, (g, g).

    The whole matrix when the file gives it (``covariance.model_form``), else the diagonal
    of the rows' ``model_form_std``; zeros when neither is there.
    """
    matrix = unit["covariance"].get("model_form")
    if matrix is not None:
        return np.asarray(matrix, dtype=float)[np.ix_(index, index)]
    return np.diag([float(rows[k].get("model_form_std") or 0.0) ** 2 for k in names])


def _psd(matrix):
    """The nearest symmetric positive semi-definite matrix (eigenvalues clipped at 0)."""
    lam, vec = np.linalg.eigh(0.5 * (matrix + matrix.T))
    return (vec * np.clip(lam, 0.0, None)) @ vec.T


def _from_documents(items):
    """A Batch from [(file name or None, canonical document)] after the checks."""
    _check_together(items)
    document = items[0][1]
    design = Design.from_dict(document["design"])
    layout = ParameterLayout(design, 1)
    names = geometry_names(len(design.sensors))
    file_prior = document["units"][0]["parameters"]
    prior_std = np.array([file_prior[k]["prior_std"] for k in names], dtype=float)
    if not np.all(prior_std > 0):
        missing = [k for k, s in zip(names, prior_std, strict=True) if not s > 0]
        raise InputError(f"prior: {missing[0]} has no spread; the batch cannot be pooled")
    units, sources = [], []
    for name, doc in items:
        found = _unit_arrays(doc, layout, names)
        units += found
        sources.append(Source(name, _digest(doc), doc.get("batch"), tuple(u[0] for u in found)))
    return Batch(
        design=design,
        names=names,
        prior_std=prior_std,
        labels=tuple(u[0] for u in units),
        deviations=np.array([u[1] for u in units]),
        covariances=np.array([u[2] for u in units]),
        blocks=np.array([u[3] for u in units]),
        surfaces=np.array([u[4] for u in units], dtype=float),
        systematic=np.array([u[5] for u in units]),
        reference=_stacked([u[6] for u in units]),
        sources=tuple(sources),
        batch=document.get("batch"),
        prior=document["prior"],
    )


def _stacked(shares):
    """The units' reference shares as one array (zeros for a unit without), or None."""
    if all(share is None for share in shares):
        return None
    size = next(share for share in shares if share is not None).shape
    return np.array([np.zeros(size) if share is None else share for share in shares])


def load_batch(paths):
    """Read the ``AS_BUILT.json`` files of one print batch and pool their units.

    Parameters
    ----------
    paths : sequence of str or pathlib.Path
        One or more files (:func:`reflector_opt.asbuilt._asbuiltfile.load_as_built`).

    Returns
    -------
    Batch

    Raises
    ------
    InputError
        No file, a file that does not read, the same identification twice, files of
        different designs, priors or batches (a batch name recorded in one file and not in
        another counts as different), or a unit in two files.
    """
    paths = list(paths)
    if not paths:
        raise InputError("no as-built file given")
    return _from_documents([(str(Path(path)), load_as_built(path).document) for path in paths])


def check_design(batch, design, name="the design"):
    """Refuse a design other than the one the batch was printed from.

    Parameters
    ----------
    batch : Batch
    design : reflector_opt.design._design.Design
        The design to correct (its ``predicted`` block does not count).
    name : str
        The design's name in the message (e.g. its file).

    Raises
    ------
    InputError
        Naming the first key that differs.
    """
    difference = _first_difference(
        _design_key(design.to_dict()), _design_key(batch.design.to_dict())
    )
    if difference:
        files = ", ".join(s.file or "the identification" for s in batch.sources)
        raise InputError(
            f"{name} is not the design the units of {files} were printed from (design.{difference})"
        )
