"""Simulated units a plan for identification is checked on.

* :class:`ModelUnit` — a unit made by the identification's own model, its parameters drawn
  from the prior (the Fisher prediction's own assumptions);
* :func:`simulated_units` — model units, or built units
  (:func:`reflector_opt.tolerance._builtunit.build_unit`: exact optics the fast model lacks);
* :func:`true_parameters` — the parameter vector an identification of either should find.
"""

from dataclasses import dataclass, replace

import numpy as np

from reflector_opt.asbuilt._parameters import true_deviations
from reflector_opt.asbuilt._problem import CHECK_STEP_DEG
from reflector_opt.calibration._simulation import rig_record
from reflector_opt.model._forward import voltages
from reflector_opt.tolerance._builtunit import REFERENCE_SIGMA_DEG, build_unit
from reflector_opt.util._errors import InputError
from reflector_opt.util._seeds import stream_rng


@dataclass(frozen=True)
class ModelUnit:
    """A unit made by the identification's own model: its parameters drawn from the prior.

    The Fisher prediction is exact for such units up to the model's nonlinearity, so
    identifying them checks the prediction itself; a built unit
    (:class:`reflector_opt.tolerance._builtunit.BuiltUnit`) adds the model-form error of the
    exact optics. Duck-types a built unit for
    :func:`~reflector_opt.tolerance._builtunit.built_unit_protocol` and
    :func:`~reflector_opt.tolerance._builtunit.crlb_floor_deg`.

    Attributes
    ----------
    design : reflector_opt.design._design.Design
        The unit's geometry and surface (fast model).
    mismatch : reflector_opt.model._noise.Mismatch
    index : int
    x : numpy.ndarray
        Its parameter vector (deviations from the design,
        :class:`~reflector_opt.asbuilt._parameters.ParameterLayout` with one unit).
    """

    design: object
    mismatch: object
    index: int
    x: np.ndarray

    @classmethod
    def draw(cls, layout, index, seed=0):
        """Unit ``index`` of ``seed``: x ~ N(0, prior), clipped to the fit's bounds."""
        rng = stream_rng(seed, "model_unit", index)
        lower, upper = layout.bounds()
        x = np.clip(layout.prior_std() * rng.standard_normal(layout.size), lower, upper)
        design = layout.design
        working = design.replace(workspace=replace(design.workspace, step_deg=CHECK_STEP_DEG))
        built, mismatch = layout.unit_design(x, 0, working)
        return cls(built, mismatch, int(index), x)

    def volts(self, pitch_deg, roll_deg):
        """Noise-free output voltages (gain and offset applied), V, shape ``P + (S,)``."""
        return self.mismatch.apply(voltages(self.design, pitch_deg, roll_deg))

    def record(self, angles_deg, rng, reference_sigma_deg=REFERENCE_SIGMA_DEG):
        """What a rig logs: the design's noise and ADC, the reference's noise on the angles
        (:func:`~reflector_opt.calibration._simulation.rig_record`, as a built unit's)."""
        return rig_record(self.volts, self.design, angles_deg, rng, reference_sigma_deg)


def true_parameters(design, unit):
    """The parameter vector (deviations: surface, then block) of a built or model unit.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
        The nominal design the deviations are from.
    unit : ModelUnit or reflector_opt.tolerance._builtunit.BuiltUnit

    Returns
    -------
    numpy.ndarray
        The vector of :class:`~reflector_opt.asbuilt._parameters.ParameterLayout` with one unit.
    """
    if isinstance(unit, ModelUnit):
        return unit.x
    surface = [
        unit.design.reflector.reflectance - design.reflector.reflectance,
        unit.design.reflector.specular_fraction - design.reflector.specular_fraction,
    ]
    return np.r_[surface, true_deviations(design, unit.design, unit.mismatch)]


def simulated_units(layout, truth, n_units, seed):
    """The units a check identifies: built units or units of the model.

    Parameters
    ----------
    layout : reflector_opt.asbuilt._parameters.ParameterLayout
        One unit's parameters (design and tolerances).
    truth : {"built", "model"}
        ``built``: :func:`~reflector_opt.tolerance._builtunit.build_unit`; ``model``:
        :meth:`ModelUnit.draw`.
    n_units : int
    seed : int

    Returns
    -------
    list of ModelUnit or BuiltUnit
    """
    if truth == "built":
        design, tolerances = layout.design, layout.tolerances
        return [build_unit(design, i, seed=seed, tolerances=tolerances) for i in range(n_units)]
    if truth == "model":
        return [ModelUnit.draw(layout, i, seed) for i in range(n_units)]
    raise InputError(f"truth: expected 'built' or 'model', got {truth!r}")
