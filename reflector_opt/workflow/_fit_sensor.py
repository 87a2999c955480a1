"""A sensor model, or a material, fitted to a measured curve, as ``reflector-opt fit-sensor``
does it.

Without ``material`` the curve was measured against a reference target of known reflectance
and specular fraction (``target`` by name, or ``reflectance`` and ``specular_fraction``), and
the sensor's ω0, θ and gain, with the read-out's offset, are fitted
(:func:`reflector_opt.model._measured.fit_sensor_model`) and written into a design. With
``material`` the curve was measured against a flat sample of the reflector's material, and the
sample's reflectance, specular fraction and sub-surface spread are fitted
(:func:`reflector_opt.model._material_fit.fit_material`): with the sensor held (a design's
fitted model, or a preset), or, with ``reference``, fitted jointly from the same sensor's curve
against a reference target. The parameters are named after the command's options, and so are
the refusals of a combination that does not apply.
"""

import contextlib
import logging
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Literal

from reflector_opt.util._declared import Options, fields, option, takes
from reflector_opt.util._display import Printed
from reflector_opt.util._errors import InputError

_log = logging.getLogger(__name__)

#: The sensor fitted unless another is named: a preset, or a part of the sensor catalogue.
DEFAULT_BASE = "NJL5901R-2"
#: The reference target's reflectance unless given.
DEFAULT_REFLECTANCE = 0.9
#: The reference target's mirror-like share of its reflectance unless given (1: a mirror).
DEFAULT_SPECULAR_FRACTION = 1.0
#: The largest standard error of a material's specular fraction accepted unless given.
DEFAULT_MAX_SIGMA_F = 0.1


@dataclass(frozen=True, repr=False)
class FitSensorRun(Printed):
    """A sensor or a material fitted by :func:`fit_sensor`, in memory; :meth:`write` writes
    the design and the part.

    Attributes
    ----------
    fit : reflector_opt.model._measured.SensorFit or reflector_opt.model._material_fit.MaterialFit
        The sensor fit (``material`` False) or the material fit.
    material : bool
        A material was fitted.
    sensor : reflector_opt.model._sensors.SensorModel or None
        The sensor a material was fitted against (None for a sensor fit).
    reference : reflector_opt.model._flat_target.MeasuredCurve or None
        The reference curve a material's sensor was fitted jointly on.
    reference_path : str or pathlib.Path or None
        Its file, as given.
    points : int
        The curve's points.
    design : reflector_opt.design._design.Design
        The design with the fitted sensor model, or (``material``) with the fitted reflectance
        and specular fraction.
    part : reflector_opt.model._catalogue.CatalogueEntry or str
        A sensor fit's sensor-catalogue part (the fitted model with the base part's figures),
        or why it has none (a fit against a target that is not one of the catalogue's).
    output : str or pathlib.Path or None
        The design written, as given, once written.
    files : tuple
        Every file written, as given: the design, then the part file.
    """

    fit: object
    material: bool
    sensor: object
    reference: object
    reference_path: object
    points: int
    design: object
    part: object = None
    output: object = None
    files: tuple = ()

    def write(self, output=None, part_file=None):
        """Write the design to ``output`` and, for a sensor fit, its part to ``part_file``.

        Parameters
        ----------
        output : str or pathlib.Path, optional
            The design file; required for a sensor fit.
        part_file : str or pathlib.Path, optional
            The sensor-catalogue part file (``PARTS.toml``), for ``optimise --sensor``.

        Returns
        -------
        FitSensorRun
            This run with ``output`` and ``files`` filled in.

        Raises
        ------
        InputError
            Outputs the fit cannot have (:func:`check_outputs`), or a part asked of a fit
            against a target that is not one of the catalogue's.
        """
        check_outputs(self.material, output, part_file)
        if part_file is not None and isinstance(self.part, str):
            raise InputError(f"--part-file: {self.part}")
        if output is not None:
            self.design.save(output)
        if part_file is not None:
            from reflector_opt.model._catalogue import part_to_toml
            from reflector_opt.util._fileio import write_text

            write_text(part_file, part_to_toml(self.part))
        files = tuple(f for f in (output, part_file) if f is not None)
        return replace(self, output=output, files=files)

    def to_dict(self):
        """JSON-ready (``fit-sensor --json``): the fitted model or material, the output."""
        fit = self.fit
        if self.material:
            return {**fit.to_dict(), "sensor": fit.sensor.name, "output": self.output}
        return {
            "sensor_model": fit.model.to_dict(),
            "rms_residual_v": fit.rms_residual_v,
            "max_residual_v": fit.max_residual_v,
            "offset_v": fit.offset_v,
            "points": self.points,
            "output": self.output,
        }

    def text(self):
        """The fitted sensor in one line, or the fitted material in three (and a warning)."""
        if self.material:
            return _material_text(self)
        fit, m = self.fit, self.fit.model
        return (
            f"{m.name}: emitter–detector {m.emitter_detector_mm:.3f} mm, source radius "
            f"{m.source_radius_mm:.3f} mm, divergence {m.divergence_deg:.1f}°, gain "
            f"{m.current_gain:.3g}, output offset {1e3 * fit.offset_v:+.1f} mV; residual RMS "
            f"{1e3 * fit.rms_residual_v:.2f} mV, max {1e3 * fit.max_residual_v:.2f} mV over "
            f"{self.points} points"
        )


def _material_text(run):
    """The fitted material: values, intervals, residuals, and the misfit's warning."""
    fit, reference = run.fit, run.reference
    against = f"material against {run.sensor.name}"
    if reference is not None:
        against += (
            f" (fitted with it on {run.reference_path}: reflectance {reference.reflectance:g}, "
            f"specular fraction {reference.specular_fraction:g})"
        )
    spread = (
        "sub-surface spread not resolved"
        if fit.subsurface_mm is None
        else f"sub-surface spread ℓ = {fit.subsurface_mm:.3f} mm"
    )
    reference_rms = (
        "" if fit.reference_rms_v is None else f"; reference RMS {1e3 * fit.reference_rms_v:.2f} mV"
    )
    lines = [
        f"{against}: reflectance ρ = {fit.reflectance:.3f} ± {fit.reflectance_sigma:.3f}, "
        f"specular fraction f = {fit.specular_fraction:.3f} ± {fit.specular_fraction_sigma:.3f} "
        f"(1σ statistical; correlation {fit.correlation:+.2f}); {spread}",
        _interval_line(fit),
        f"residual RMS {1e3 * fit.rms_residual_v:.2f} mV, max {1e3 * fit.max_residual_v:.2f} mV "
        f"over {fit.points} points ({fit.clamped} clamped, left out){reference_rms}; noise "
        f"σ_V {1e3 * fit.sigma_v:.2f} mV; output offset {1e3 * fit.offset_v:+.1f} mV",
    ]
    if fit.misfit:
        lines.append(
            "warning: a curve's residual exceeds 3x the noise (--accept-misfit): the model does "
            "not describe it and these are effective values"
        )
    return "\n".join(lines)


def _interval_line(fit):
    """The 90 % intervals, with the LED-pattern model-form std they include."""
    rho, f = fit.reflectance_interval, fit.specular_fraction_interval
    line = (
        f"90 % intervals (statistical and LED-pattern model form, ± "
        f"{fit.reflectance_model_form_sigma:.3f} in ρ, ± "
        f"{fit.specular_fraction_model_form_sigma:.3f} in f): ρ {rho[0]:.3f}–{rho[1]:.3f}, "
        f"f {f[0]:.3f}–{f[1]:.3f}"
    )
    if fit.subsurface_interval_mm is not None:
        low, high = fit.subsurface_interval_mm
        line += f", ℓ {low:.3f}–{high:.3f} mm"
    return line


class FitSensorOptions(Options):
    """The options of ``reflector-opt fit-sensor``, declared once."""

    design: option(
        object,
        "the design to update (a Design or its design.json); the built-in design if left out; "
        "with --material also the source of the sensor model",
        metavar="DESIGN.json",
    ) = None
    base: option(
        str | None,
        f"sensor preset, or part of the sensor catalogue, to fit; {DEFAULT_BASE} if left out "
        "(an unknown name lists the presets); with --material, the sensor to use instead of "
        "the design's",
        metavar="PRESET",
    ) = None
    method: option(
        Literal["fit", "interpolate"] | None,
        "fit (the default): parametric model; interpolate: also reproduce the points exactly",
    ) = None
    target: option(
        str | None,
        "the reference target by name: white-card (Kodak grey card's white side, reflectance "
        "0.9, diffuse), aluminium (evaporated mirror, 0.9) or mirror (ideal, 1)",
        metavar="NAME",
    ) = None
    reflectance: (
        option(
            float,
            f"reflectance of the reference target; {DEFAULT_REFLECTANCE:g} if left out",
            gt=0,
            le=1,
        )
        | None
    ) = None
    specular_fraction: (
        option(
            float,
            "mirror-like share of the reference target's reflectance; "
            f"{DEFAULT_SPECULAR_FRACTION:g} (a mirror) if left out, 0 for a white diffuse "
            "standard",
            ge=0,
            le=1,
        )
        | None
    ) = None
    material: option(
        bool,
        "fit the sample's reflectance, specular fraction and sub-surface spread instead of "
        "the sensor",
    ) = False
    reference: option(
        object,
        "with --material: the same sensor's curve against a reference target (named by "
        "--target, or --reflectance and --specular-fraction); the sensor is then fitted "
        "jointly with the material instead of taken from the design",
        metavar="REFERENCE.csv",
    ) = None
    max_sigma_f: (
        option(
            float,
            "with --material: largest accepted standard error of the specular fraction; "
            f"{DEFAULT_MAX_SIGMA_F:g} if left out",
            gt=0,
            le=1,
        )
        | None
    ) = None
    accept_misfit: option(
        bool,
        "with --material: fit even when a curve's RMS residual exceeds 3x the design's noise "
        "(the model does not describe it; the values are then effective ones)",
    ) = False
    accept_units: option(
        bool,
        "take the curves as given where a column looks like another unit (millivolts) or lies "
        "beyond the sensor's supply; refused by default",
    ) = False


@takes(FitSensorOptions)
def fit_sensor(curve, options=None):
    """Fit a sensor model, or a material, to a measured curve, in memory: ``reflector-opt
    fit-sensor``; :meth:`FitSensorRun.write` writes the design (and the part).

    Parameters
    ----------
    curve : str or pathlib.Path
        CSV with columns distance_mm (mm) and volts (V).
    options : FitSensorOptions
        As keyword arguments (below); defaults :data:`DEFAULT_BASE`,
        :data:`DEFAULT_REFLECTANCE`, :data:`DEFAULT_SPECULAR_FRACTION` and
        :data:`DEFAULT_MAX_SIGMA_F` (the reference target by name:
        :data:`reflector_opt.model._catalogue_fit.TARGETS`).

    Returns
    -------
    FitSensorRun

    Raises
    ------
    InputError
        A curve or design that cannot be read, a fit that fails or is refused, an option that
        does not apply (named as the command's option).
    """
    import msgspec

    options = msgspec.structs.asdict(options)
    if options.pop("material"):
        return _fit_material(curve, options)
    return _fit_sensor(curve, options)


def check_outputs(material, output, part_file):
    """Refuse the outputs a fit cannot have, before any work: a sensor fit writes a design
    (``output`` required) and may write its part; a material fit writes no part.

    Raises
    ------
    InputError
        Naming the command's option.
    """
    if material and part_file is not None:
        raise InputError("--part-file: not with --material (it writes a fitted sensor)")
    if not material and output is None:
        raise InputError("-o/--out is required (unless --material)")
    if part_file is not None and Path(part_file).is_dir():
        raise InputError(f"--part-file {part_file} is a folder; give the name of a file to write")


def _fit_sensor(curve, options):
    """A sensor fit: the model against the reference target, the design and its part."""
    from reflector_opt.design import as_design
    from reflector_opt.model._measured import fit_sensor_model

    _check_sensor_options(options)
    design = as_design(options["design"])
    base = _base_model(_base_name(options))
    distance, volts = _read_curve(curve, base, options)
    target = _target(options)
    with _naming(curve):
        fit = fit_sensor_model(
            distance,
            volts,
            base,
            method=options["method"] or "fit",
            reflectance=target[0],
            specular_fraction=target[1],
            fit_offset=True,
        )
    part = _part(curve, options, fit, distance, volts, target)
    _warn_misfit(fit.rms_residual_v, design.noise.total_sigma_v)
    design = design.with_sensor_model(fit.model)
    return FitSensorRun(fit, False, None, None, None, int(distance.size), design, part)


def _check_sensor_options(options):
    """Refuse the options a sensor fit (no ``material``) cannot take."""
    flags = {f.name: f.flag for f in fields(FitSensorOptions)}
    for key in ("max_sigma_f", "reference", "accept_misfit"):
        if options[key] not in (None, False):
            raise InputError(f"{flags[key]} applies to --material only")


def _read_curve(path, model, options):
    """A curve's distances and voltages, its units checked against ``model``'s supply."""
    from reflector_opt.model._measured import read_curve_csv

    return read_curve_csv(path, supply_v=model.supply_v, accept_units=options["accept_units"])


def _target(options, required=False):
    """(ρ, f) of the reference target: ``target``, else ``reflectance`` and
    ``specular_fraction`` (defaults :data:`DEFAULT_REFLECTANCE` and
    :data:`DEFAULT_SPECULAR_FRACTION`, unless ``required``)."""
    from reflector_opt.model._catalogue_fit import TARGETS

    name, rho, f = options["target"], options["reflectance"], options["specular_fraction"]
    if name is not None:
        if rho is not None or f is not None:
            raise InputError(
                "--target names the reference's reflectance and specular fraction; give it "
                "or --reflectance and --specular-fraction, not both"
            )
        if name not in TARGETS:
            raise InputError(f"--target {name!r}: unknown; known: {', '.join(TARGETS)}")
        return TARGETS[name]
    if required and (rho is None or f is None):
        raise InputError(
            "--reference: name its target, --target (e.g. white-card) or --reflectance and "
            "--specular-fraction"
        )
    return (
        DEFAULT_REFLECTANCE if rho is None else rho,
        DEFAULT_SPECULAR_FRACTION if f is None else f,
    )


def _warn_misfit(rms_v, sigma_v):
    """A warning when a sensor fit leaves residuals above 3× the noise."""
    from reflector_opt.model._material_fit import MAX_MISFIT

    if rms_v > MAX_MISFIT * sigma_v:
        _log.warning(
            f"residual RMS {1e3 * rms_v:.2f} mV is {rms_v / sigma_v:.1f}x the design's noise "
            f"({1e3 * sigma_v:.2f} mV): the model does not describe this curve (the target, its "
            "distance zero, the LED's pattern)"
        )


def _base_name(options):
    """The sensor to fit: ``base`` as given (an empty name is refused by name), else
    :data:`DEFAULT_BASE`."""
    return DEFAULT_BASE if options["base"] is None else options["base"]


def _base_model(name):
    """The preset of that name, else the sensor catalogue's part (its model)."""
    from reflector_opt.model._catalogue import get_part
    from reflector_opt.model._sensors import PRESETS, get_preset

    if name in PRESETS:
        return get_preset(name)
    try:
        return get_part(name).model
    except InputError:
        get_preset(name)  # the presets' message, which lists them
        raise


def _part(curve, options, fit, distance, volts, target):
    """The fitted sensor as a catalogue part (the fitted model with the base part's figures),
    or why it cannot be one."""
    from reflector_opt.model._catalogue import get_part, measured_part
    from reflector_opt.model._catalogue_fit import TARGETS

    names = [k for k, v in TARGETS.items() if v == target]
    if not names:
        return "the target must be one of the catalogue's test targets " + ", ".join(
            f"{k} (reflectance {r:g}, specular fraction {f:g})" for k, (r, f) in TARGETS.items()
        )
    try:
        base = get_part(_base_name(options))
        return measured_part(fit.model, base, curve, distance, volts, names[0], fit.rms_residual_v)
    except InputError as exc:  # a base that is not a catalogue part
        return str(exc)


@contextlib.contextmanager
def _naming(curve):
    """Name the curve file in a refusal of its readings (e.g. a curve without signal)."""
    try:
        yield
    except InputError as exc:
        raise InputError(f"{curve}: {exc}") from None


def _fit_material(curve, options):
    """``material``: fit ρ, f and ℓ of the sample, the sensor held or fitted jointly."""
    from reflector_opt.design import as_design
    from reflector_opt.model._material_fit import fit_material

    _check_material_options(options)
    design = as_design(options["design"])
    model, reference = _material_sensor(options["base"], design), None
    distance, volts = _read_curve(curve, model, options)
    if options["reference"] is not None:
        from reflector_opt.model._flat_target import MeasuredCurve

        target = _target(options, required=True)
        points = _read_curve(options["reference"], model, options)
        with _naming(options["reference"]):
            reference = MeasuredCurve(*map(tuple, points), *target)
    with _naming(curve):
        fit = fit_material(
            distance,
            volts,
            model,
            reference=reference,
            sigma_v=design.noise.total_sigma_v,
            max_sigma_f=options["max_sigma_f"] or DEFAULT_MAX_SIGMA_F,  # given: > 0
            accept_misfit=options["accept_misfit"],
        )
    reflector = replace(
        design.reflector, reflectance=fit.reflectance, specular_fraction=fit.specular_fraction
    )
    if reference is not None:
        design = design.with_sensor_model(fit.sensor.with_(name=f"{model.name}-measured"))
    design = design.replace(reflector=reflector)
    where = options["reference"]
    return FitSensorRun(fit, True, model, reference, where, int(distance.size), design)


def _check_material_options(options):
    """Refuse what a material fit cannot take: the sensor fit's method, and a reference
    target without a reference curve."""
    if options["method"] is not None:
        raise InputError("--method describes a sensor fit; with --material it does not apply")
    if options["reference"] is None:
        flags = {f.name: f.flag for f in fields(FitSensorOptions)}
        for key in ("reflectance", "specular_fraction", "target"):
            if options[key] is not None:
                raise InputError(
                    f"{flags[key]} describes the reference target of a sensor fit; with --material "
                    "it needs the reference's curve (--reference), else the sample's "
                    "reflectance and specular fraction are fitted with the sensor held"
                )


def _material_sensor(base, design):
    """The sensor of a material fit: ``base``, else the design's one sensor model."""
    from reflector_opt.model._sensors import get_preset

    if base is not None:
        return get_preset(base)
    models = {m.name: m for m in design.models}
    if len(models) != 1:
        raise InputError(
            f"the design's sensors use different models ({', '.join(sorted(models))}); "
            "fit the material with one of them (--base)"
        )
    (model,) = models.values()
    return model
