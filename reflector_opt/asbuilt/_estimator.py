"""Angles from voltages through an identified unit's own model.

An identified unit (:meth:`reflector_opt.asbuilt._result.Identification.as_built`) is a
complete forward model of that unit: its as-built design and read-out. :class:`AsBuiltModel`
estimates pitch and roll by inverting it at every sample
(:func:`reflector_opt.calibration._physical.invert_model`), started from a cubic polynomial
fitted to the model's own voltages on a grid of the workspace, so that no calibration data
are needed beyond those the identification used. :func:`load_unit_calibrations` reads an
``AS_BUILT.json`` as the per-unit calibrations ``estimate`` uses.

**In the reference's frame.** When the identification fitted the angle reference's zero
offsets and twist, the model is that of the readings: voltages at the true pose of each
reading (:func:`reflector_opt.asbuilt._parameters.true_pose`), so the angles it estimates are
those the calibration's reference would read, as a calibration's are. The data determine
this map even where they cannot split it between a reference error and a print deviation
(the sphere rotated about the joint is the sphere moved); the estimated reference parameters
say how far that frame may lie from the unit's own.
"""

from functools import partial

import numpy as np

from reflector_opt.asbuilt._parameters import REFERENCE_NAMES, true_pose
from reflector_opt.asbuilt._spread import spread_voltages
from reflector_opt.calibration._models import Estimator, check_sample_pairs, make_model
from reflector_opt.calibration._physical import invert_model
from reflector_opt.calibration._unit_calibration import UnitCalibration
from reflector_opt.util._display import Summarised, vector

#: Grid points per axis of the warm start's fit over the workspace.
WARM_START_GRID = 21


class AsBuiltModel(Summarised, Estimator):
    """A unit's calibration as its identified forward model, inverted per sample.

    The calibration models' contract (:class:`reflector_opt.calibration._models.Estimator`):
    the constructor stores its parameters, :meth:`fit` prepares the inversion, ``predict``
    refuses to run before it, and ``get_params``/``clone`` give an unfitted copy. The
    identification has already fitted the model, so :meth:`fit` needs no calibration samples.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
        The unit as built.
    mismatch : reflector_opt.model._noise.Mismatch
        Its identified gain and offset per sensor.
    reference_deg : (float, float, float), optional
        The identified reference's pitch and roll zero offsets and twist, degrees: the
        angles are then in that reference's frame (module notes). Default: an exact
        reference.
    subsurface_mm : float, optional
        The identified sub-surface spread ℓ of the surface, mm
        (:func:`reflector_opt.asbuilt._spread.spread_voltages`). Default None: none.
    extra_volts : callable, optional
        ``extra_volts(pitch, roll)`` → voltages (n, sensors) the identification's model-form
        terms add at true poses (n,) (:meth:`reflector_opt.asbuilt._model_form_terms.ModelFormTerms.
        extra_volts`). Default None: none.

    Attributes
    ----------
    warm_start_ : Polynomial
        Cubic fitted to the model's voltages on the workspace grid (after :meth:`fit`).
    n_samples_ : int
        0: the model is fitted to no calibration samples of its own.
    """

    name = "as-built"

    def __init__(
        self, design, mismatch, reference_deg=(0.0, 0.0, 0.0), subsurface_mm=None, extra_volts=None
    ):
        self.design = design
        self.mismatch = mismatch
        self.reference_deg = reference_deg
        self.subsurface_mm = subsurface_mm
        self.extra_volts = extra_volts

    def fit(self, voltages=None, angles=None):
        """Fit the inversion's warm start: a cubic to the model's own voltages on a grid.

        Parameters
        ----------
        voltages, angles : array_like, optional
            Calibration samples, shapes (n, 2) in V and degrees. The identified model needs
            none; samples given are checked as every calibration model checks them (finite,
            paired) and otherwise not used.

        Returns
        -------
        self
        """
        if voltages is not None or angles is not None:
            check_sample_pairs(voltages, angles, "as-built")
        pitch, roll = np.meshgrid(
            np.linspace(*self.design.workspace.pitch_deg, WARM_START_GRID),
            np.linspace(*self.design.workspace.roll_deg, WARM_START_GRID),
            indexing="ij",
        )
        grid = np.column_stack([pitch.ravel(), roll.ravel()])
        self.warm_start_ = make_model("poly3").fit(self.volts(grid[:, 0], grid[:, 1]), grid)
        self.n_samples_ = 0
        return self

    def _summary(self):
        """Title and (label, value) rows of :class:`AsBuiltModel`."""
        design = self.design
        ws = design.workspace
        rows = [
            ("sphere radius", f"{design.reflector.radius_mm:.3f} mm"),
            ("sensors", ", ".join(s.name for s in design.sensors)),
            ("gain", vector(self.mismatch.gain, 4)),
            ("offset", vector(self.mismatch.offset_v, 4, "V")),
            (
                "workspace",
                f"pitch {ws.pitch_deg[0]:g} to {ws.pitch_deg[1]:g}°, "
                f"roll {ws.roll_deg[0]:g} to {ws.roll_deg[1]:g}°",
            ),
        ]
        reference = tuple(float(v) for v in self.reference_deg)
        if any(reference):
            rows.append(("reference (zeros, twist)", vector(reference, 3, "°")))
        return "AsBuiltModel: identified forward model, inverted per sample", rows

    def volts(self, pitch_deg, roll_deg):
        """The unit's noise-free voltages at the reference's readings, V, shape ``P + (2,)``."""
        pitch, roll = true_pose(pitch_deg, roll_deg, self.reference_deg)
        out = self.mismatch.apply(spread_voltages(self.design, pitch, roll, self.subsurface_mm))
        if self.extra_volts is not None:
            out = out + self.extra_volts(np.ravel(pitch), np.ravel(roll)).reshape(out.shape)
        return out

    def predict(self, voltages, return_cov=False):
        """Pitch and roll from voltages, degrees (see :func:`invert_model`).

        Parameters
        ----------
        voltages : array_like
            Shape ``P + (2,)``, V.
        return_cov : bool
            Also return each estimate's covariance, deg².

        Returns
        -------
        numpy.ndarray or (numpy.ndarray, numpy.ndarray)
        """
        self._check_fitted()
        return invert_model(
            self.volts,
            voltages,
            self.warm_start_,
            self.design.workspace,
            self.design.noise.total_sigma_v,
            return_cov,
        )


def load_unit_calibrations(path):
    """An ``AS_BUILT.json`` as per-unit calibrations (base unit first, in the file's order).

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    list of reflector_opt.calibration._unit_calibration.UnitCalibration
    """
    from reflector_opt.asbuilt._asbuiltfile import load_as_built

    found = load_as_built(path)
    spread = found.shared.get("subsurface_mm", {}).get("estimate")
    terms = _file_terms(found)
    out = []
    for unit in found.units:
        extra = None
        if terms is not None and unit.get("model_form"):
            amplitudes = np.array([row["estimate"] for row in unit["model_form"].values()])
            extra = partial(terms.extra_volts, amplitudes=amplitudes)
        model = AsBuiltModel(
            unit["as_built"],
            unit["read_out"],
            reference_of(unit.get("reference")),
            subsurface_mm=spread,
            extra_volts=extra,
        ).fit()
        out.append(UnitCalibration(unit["unit"], model))
    return out


def _file_terms(found):
    """The model-form terms an ``AS_BUILT.json`` was identified with, built again from the
    form error its prior records (None for files without them)."""
    from reflector_opt.asbuilt._model_form_terms import model_form_terms
    from reflector_opt.tolerance._model_form import ModelForm

    recorded = found.document["prior"].get("model_form")
    if not recorded:
        return None
    spread = found.document["prior"].get("subsurface_std") is not None
    return model_form_terms(found.design, [], ModelForm(**recorded), spread)


def reference_of(rows):
    """The reference's (pitch zero, roll zero, twist), degrees, from a unit's ``reference``
    rows of ``AS_BUILT.json`` or :meth:`~reflector_opt.asbuilt._result.Identification.
    reference_parameters` (zeros when there are none: an exact reference).

    Parameters
    ----------
    rows : dict or None

    Returns
    -------
    tuple of float
    """
    if not rows:
        return (0.0, 0.0, 0.0)
    return tuple(float(rows[name]["estimate"]) for name in REFERENCE_NAMES)
