"""Built-unit truth: calibration and validation data of a unit the forward model did not make.

A predicted calibration error is only honest if the data it is measured on were not made by
the model the calibration assumes. Here they come from

* a **built unit**: the design perturbed as the tolerance model perturbs it
  (:func:`reflector_opt.tolerance._tolerances.as_built`: reflector radius and centre, sensor
  positions and tilts, per-sensor gain and offset) and with its reflector's specular fraction
  drawn about the design's (:data:`SURFACE_FRACTION_SIGMA`);
* the **exact reference** optics (:func:`reflector_opt.model._exact.exact_design_coupling`,
  deterministic quadrature, none of the fast model's approximations), evaluated at the n × n
  Chebyshev points of the workspace (:class:`reflector_opt.model._interpolation.PoseBox`) and
  interpolated in between. tests/tolerance/test_builtunit.py bounds the interpolation error
  against the exact model at poses off the nodes (docs/calibration.md gives the figure);
* the recorded **noise**: the design's voltage noise and ADC
  (:func:`reflector_opt.calibration._simulation.measure_with_design_noise`), and the angle
  reference's own noise on the calibration poses (:data:`REFERENCE_SIGMA_DEG`).

Crosstalk between sensors and a change of ambient light between calibration and use (the
tolerance model's other two) are left out: the first is removed by driving the sensors in
turn, the second is the tolerance study's business, not the calibration's.

**Model-form error.** With ``model_form`` (:class:`reflector_opt.tolerance._model_form.ModelForm`)
a unit also carries physics the fast model lacks — a rough specular lobe, sub-surface spread
in the resin, a non-Gaussian emitter, in-package crosstalk and constant ambient light
(:func:`reflector_opt.model._exact_model_form.exact_model_form_design_coupling`) — so that a
calibration or identification validated on it meets an error of its model's form, as a printed
unit's would. With ``surface`` the units of one print batch share a reflectance and specular
fraction instead of drawing their own.
"""

from dataclasses import dataclass, field, replace

import numpy as np

from reflector_opt.analysis._jacobian import values_and_jacobian
from reflector_opt.analysis._resolution import resolution_over_poses
from reflector_opt.calibration._simulation import (
    measure_with_design_noise,
    rig_record,
    simulate_protocol,
)
from reflector_opt.model._exact import exact_design_coupling
from reflector_opt.model._exact_model_form import (
    exact_model_form_coupling,
    exact_model_form_design_coupling,
)
from reflector_opt.model._forward import respond
from reflector_opt.model._interpolation import PoseBox, fit_coefficients, interpolate
from reflector_opt.model._operating import readings
from reflector_opt.model._optics import FLAT_RADIUS_MM
from reflector_opt.tolerance._model_form import ModelForm
from reflector_opt.tolerance._tolerances import Tolerances, as_built, draw_sample
from reflector_opt.util._display import Summarised, fmt, vector
from reflector_opt.util._errors import InputError
from reflector_opt.util._seeds import stream_rng

#: RMS noise of the angle reference at each calibration pose, degrees (per angle). The
#: order of the short-term noise of a calibrated MEMS attitude reference held at each pose
#: (the paper's LPMS-B quotes a resolution below 0.01° and a static accuracy below 0.5°; the
#: latter is mostly a slowly varying bias). An assumption: docs/calibration.md shows its effect.
REFERENCE_SIGMA_DEG = 0.05

#: Standard deviation of the built reflector's specular fraction about the design's
#: (absolute, clipped to [0, 1]): the printed finish varies from part to part.
SURFACE_FRACTION_SIGMA = 0.02

#: Quadrature orders of the exact reference used for the truth, lower than the default
#: (:data:`reflector_opt.model._exact.DEFAULT_ORDERS`) for speed (about 5× faster).
#: tests/tolerance/test_builtunit.py bounds the change of the voltages from the default orders
#: (below 0.01 σ_V).
EXACT_ORDERS = {"source_order": 4, "detector_order": (2, 6), "sphere_order": (24, 24)}


#: Quadrature orders of the exact reference for a flat-target curve. The lit cap of a flat
#: target seen from 0.5 mm needs finer polar and azimuth rules than the reflector does:
#: :data:`EXACT_ORDERS` there is 15 mV off the default orders at 0.5 mm, these within
#: 0.13 mV (0.07 σ_V) from 0.5 to 3 mm.
FLAT_CURVE_ORDERS = {"source_order": 4, "detector_order": (2, 6), "sphere_order": (48, 48)}


@dataclass(frozen=True, repr=False)
class BuiltUnit(Summarised):
    """One built unit: its geometry, read-out errors and exact optics over the workspace.

    Attributes
    ----------
    design : reflector_opt.design._design.Design
        The as-built geometry, with the built reflectance and specular fraction.
    mismatch : reflector_opt.model._noise.Mismatch
        The unit's per-sensor gain and offset.
    box : reflector_opt.model._interpolation.PoseBox
        The workspace box of the interpolant.
    coefficients : numpy.ndarray
        Chebyshev coefficients of the optical coupling (exact, or extended by the form
        error's optics), shape (n, n, n_sensors). Crosstalk and ambient light are not in
        them: :meth:`volts` adds them.
    index : int
        The unit's draw index.
    model_form : reflector_opt.tolerance._model_form.ModelForm
        The physics beyond the fast model the unit was built with (``ModelForm.none()``: the
        exact reference's).
    """

    design: object
    mismatch: object
    box: PoseBox
    coefficients: np.ndarray
    index: int
    model_form: ModelForm = field(default_factory=ModelForm.none)

    def _summary(self):
        """Title and rows of a built unit's display: its geometry, read-out and physics."""
        reflector = self.design.reflector
        physics = {k: v for k, v in self.model_form.to_dict().items() if v not in (0.0, "gaussian")}
        rows = [
            ("reflector radius", f"{reflector.radius_mm:.4f} mm"),
            ("reflector centre", vector(reflector.centre_mm, 4, "mm")),
            ("surface", f"ρ {fmt(reflector.reflectance)}, f {fmt(reflector.specular_fraction)}"),
            ("gain", ", ".join(fmt(g, 4) for g in self.mismatch.gain)),
            ("offset", ", ".join(fmt(1e3 * o, 3, "mV") for o in self.mismatch.offset_v)),
            ("optics", "exact reference" + "".join(f", {k} {v}" for k, v in physics.items())),
        ]
        return f"BuiltUnit #{self.index}: {len(self.design.sensors)} sensors", rows

    def volts(self, pitch_deg, roll_deg, state=None):
        """Noise-free output voltages of the unit (gain and offset applied), V.

        The form error's crosstalk and ambient light are included.

        Parameters
        ----------
        pitch_deg, roll_deg : array_like
            Poses inside the workspace, degrees, broadcast to shape P.
        state : reflector_opt.model._operating.OperatingState, optional
            What differs in use from the calibration (temperature, ambient light), applied to
            the sensors' outputs before the read-out's gain and offset
            (the voltage pipeline, :func:`~reflector_opt.model._operating.readings`). None: as
            calibrated.

        Returns
        -------
        numpy.ndarray
            Shape ``P + (n_sensors,)``.
        """
        eta = np.maximum(interpolate(self.box, self.coefficients, pitch_deg, roll_deg), 0.0)
        extra = [self.model_form.extra_coupling(m) for m in self.design.models]
        return self.mismatch.apply(readings(eta + extra, self.design.models, state))

    def flat_curve(self, sensor, distance_mm, rng):
        """A sensor's flat-target curve, as measured before assembly.

        The sensor faces, squarely, a flat sample of the reflector's material (the unit's
        reflectance, specular fraction and form error) at each distance, read out through
        the unit's own electronics (its gain and offset), with the design's voltage noise and
        ADC. The optics are the exact reference's (extended by the form error's), a sphere
        of :data:`~reflector_opt.model._optics.FLAT_RADIUS_MM` standing in for the flat
        target; the distances are taken as exact (a micrometre stage).

        Parameters
        ----------
        sensor : int
            The sensor's index in the design.
        distance_mm : array_like
            Emitter-to-target distances, mm.
        rng : numpy.random.Generator or None
            Source of the noise; None gives the noise-free curve.

        Returns
        -------
        numpy.ndarray
            Measured voltages, V, one per distance.
        """
        model = self.design.models[sensor]
        offset = np.array([0.0, 0.0, model.emitter_detector_mm])
        reflector = self.design.reflector
        eta = []
        for d in np.asarray(distance_mm, dtype=float):
            parts = exact_model_form_coupling(
                np.zeros(3),
                np.array([1.0, 0.0, 0.0]),
                offset,
                np.array([d + FLAT_RADIUS_MM, 0.0, 0.0]),
                FLAT_RADIUS_MM,
                model,
                **self.model_form.optics(),
                **FLAT_CURVE_ORDERS,
            )
            eta.append(parts.total(reflector.reflectance, reflector.specular_fraction))
        eta = np.array(eta) + self.model_form.extra_coupling(model)
        volts = readings(eta[:, None], (model,))[:, 0]
        clean = self.mismatch.gain[sensor] * volts + self.mismatch.offset_v[sensor]
        if rng is None:
            return clean
        return measure_with_design_noise(self.design, clean[:, None], rng)[:, 0]

    def record(self, angles_deg, rng, reference_sigma_deg=REFERENCE_SIGMA_DEG, state=None):
        """What a calibration rig logs at the given poses.

        Parameters
        ----------
        angles_deg : array_like
            Shape (n, 2): the true pitch and roll, degrees.
        rng : numpy.random.Generator
        reference_sigma_deg : float
            RMS noise of the angle reference, degrees (0 for the true angles).
        state : reflector_opt.model._operating.OperatingState, optional
            The unit's operating state (:meth:`volts`); None: as calibrated.

        Returns
        -------
        reflector_opt.calibration._simulation.Samples
            ``angles_deg`` as the reference reads them, ``volts_true`` the unit's noise-free
            voltages, ``volts`` with the design's noise and ADC
            (:func:`~reflector_opt.calibration._simulation.rig_record`).
        """
        return rig_record(
            lambda p, r: self.volts(p, r, state), self.design, angles_deg, rng, reference_sigma_deg
        )


def _exact_coupling(design, pitch, roll, model_form=None):
    """Exact total coupling of every sensor, flat-target correction included: (n, n, S).

    With a form error that has optics, the extended reference's; crosstalk and ambient light
    are left to :meth:`BuiltUnit.volts`.
    """
    if model_form is not None and model_form.has_optics:
        parts = exact_model_form_design_coupling(
            design, pitch, roll, **model_form.optics(), **EXACT_ORDERS
        )
    else:
        parts = exact_design_coupling(design, pitch, roll, **EXACT_ORDERS)
    reflector = design.reflector
    eta = parts.total(reflector.reflectance, reflector.specular_fraction)
    axial = respond(design, pitch, roll).axial_distance_mm
    for k, model in enumerate(design.models):
        if model.measured_curve is not None:
            hit = np.isfinite(axial[..., k])
            eta[..., k][hit] *= model.flat_correction(axial[..., k][hit])
    return eta


def _shared_surface(surface):
    """Check a ``(reflectance, specular_fraction)`` pair; return it as floats."""
    try:
        reflectance, fraction = (float(v) for v in surface)
    except (TypeError, ValueError):
        raise InputError(
            f"surface: expected (reflectance, specular_fraction), got {surface!r}"
        ) from None
    for name, value in (("reflectance", reflectance), ("specular_fraction", fraction)):
        if not 0.0 <= value <= 1.0:
            raise InputError(f"surface {name}: expected 0 to 1, got {value!r}")
    return reflectance, fraction


def build_unit(
    design, index, *, seed=0, tolerances=None, nodes=None, model_form=None, surface=None
):
    """Draw one built unit of a design and compute its exact optics over the workspace.

    Parameters
    ----------
    design : reflector_opt.design._design.Design
    index : int
        Unit index (with ``seed``, fixes every draw).
    seed : int
    tolerances : reflector_opt.tolerance._tolerances.Tolerances, optional
        Default: the tolerance model's defaults.
    nodes : int, optional
        Chebyshev points per axis (default :class:`PoseBox`'s for the workspace span).
    model_form : reflector_opt.tolerance._model_form.ModelForm, optional
        Physics beyond the fast model (``ModelForm()`` for the moderate defaults). Default
        None: the exact reference's physics, the same unit as ``ModelForm.none()``. The
        optics cost about 4× the exact reference's (1.7 s of CPU a unit of the default design).
    surface : (float, float), optional
        ``(reflectance, specular_fraction)`` of the unit's reflector, each 0–1: a surface
        shared by the units of one print batch. Default None: the design's reflectance and a
        specular fraction drawn about the design's (:data:`SURFACE_FRACTION_SIGMA`).

    Returns
    -------
    BuiltUnit
        Its ``design`` holds the true geometry and surface; its ``model_form`` the options.
    """
    tolerances = Tolerances() if tolerances is None else tolerances
    model_form = ModelForm.none() if model_form is None else model_form
    if not isinstance(model_form, ModelForm):
        raise InputError(f"model_form: expected a ModelForm, got {type(model_form).__name__}")
    draw = draw_sample(tolerances, len(design.sensors), seed, index)
    built, electrical = as_built(design, tolerances, draw)
    if surface is None:
        noise = stream_rng(seed, "built_surface", index).standard_normal()
        reflectance = built.reflector.reflectance
        fraction = float(
            np.clip(design.reflector.specular_fraction + SURFACE_FRACTION_SIGMA * noise, 0.0, 1.0)
        )
    else:
        reflectance, fraction = _shared_surface(surface)
    built = built.replace(
        reflector=replace(built.reflector, reflectance=reflectance, specular_fraction=fraction)
    )
    workspace = design.workspace
    box = PoseBox(workspace.pitch_deg, workspace.roll_deg, nodes)
    pitch, roll = box.points()
    coefficients = fit_coefficients(box, _exact_coupling(built, pitch, roll, model_form))
    return BuiltUnit(built, electrical.mismatch, box, coefficients, int(index), model_form)


def built_unit_protocol(
    unit,
    calibration_poses,
    *,
    n_validation=20000,
    seed=0,
    reference_sigma_deg=REFERENCE_SIGMA_DEG,
):
    """Calibration data at given poses and independent validation data of one built unit.

    Parameters
    ----------
    unit : BuiltUnit
    calibration_poses : array_like
        Shape (n, 2): pitch, roll of the calibration plan, degrees.
    n_validation : int
        Validation poses, uniform over the workspace; their angles are the true ones.
    seed : int
        Seed of the validation poses and of every noise draw.
    reference_sigma_deg : float
        RMS noise of the angle reference on the calibration poses, degrees.

    Returns
    -------
    reflector_opt.calibration._simulation.Protocol
        The protocol of :func:`~reflector_opt.calibration._simulation.simulate_protocol`;
        ``step_deg`` is NaN (the plan need not be a grid).
    """
    poses = np.asarray(calibration_poses, dtype=float)
    if poses.ndim != 2 or poses.shape[1] != 2 or not np.isfinite(poses).all():
        raise InputError(f"calibration poses: expected finite (n, 2) angles, got {poses.shape}")

    def recorder(angles_deg, rng, in_use):
        return unit.record(angles_deg, rng, 0.0 if in_use else reference_sigma_deg)

    rng = stream_rng(seed, "built_protocol", unit.index)
    return simulate_protocol(recorder, unit.design.workspace, poses, n_validation, rng, seed=seed)


def crlb_floor_deg(unit, angles_deg):
    """RMS over poses of the unit's Cramér–Rao bound, per angle (pitch, roll), degrees.

    The bound over poses (:func:`reflector_opt.analysis._resolution.resolution_over_poses`)
    with the unit's own voltage Jacobian (exact optics, its gain) and the design's σ_V with
    quantisation.

    Parameters
    ----------
    unit : BuiltUnit
    angles_deg : array_like
        Shape (n, 2): the poses to average over (e.g. the validation poses), degrees.

    Returns
    -------
    numpy.ndarray
        Shape (2,).
    """
    angles = np.asarray(angles_deg, dtype=float)
    _, jacobian = values_and_jacobian(unit.volts, angles[:, 0], angles[:, 1])
    return resolution_over_poses(jacobian, unit.design.noise.total_sigma_v).rms_deg
