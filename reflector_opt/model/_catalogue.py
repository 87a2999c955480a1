"""The sensor catalogue: reflective sensors as data, one file format for shipped and user parts.

A catalogue file (TOML, format ``reflector-opt/sensor-catalogue@1``; the shipped one is
``reflector_opt/data/sensor_catalogue.toml``, its JSON Schema ``docs/sensor-catalogue.schema.json``)
lists parts, each with

* ``figures`` — the datasheet's figures, each a table ``{value, kind, source}`` (``kind`` one
  of ``published``, ``measured``, ``assumed``, ``fitted``; ``source`` the datasheet and where
  in it, or the basis of an assumption), with a ``tolerance`` where the model must reproduce
  it: the package (across the emitter–detector line, along it, deep; mm), the assumed or
  published emitter–detector spacing, the wavelength, the peak distance and the range on the
  test target (with the ``level`` that defines the range), the output current at the test
  condition (LED current, distance, target), and the usable range the design uses; and,
  optionally, the temperature figures (the keys of
  :class:`~reflector_opt.model._temperature.ThermalCoefficients`: LED output and detector gain
  per kelvin, forward voltage per kelvin, dark current, its doubling, thermal resistance) that
  :func:`thermal_coefficients` turns into the coefficients of
  :mod:`reflector_opt.model._temperature`;
* ``model`` — the sensor model fitted to those figures, in the sensor-model schema
  (``docs/sensor-model.schema.json``, the ``sensor_models`` of ``design.json``), its package
  included;
* ``basis`` — for each model parameter (and ``circuit``), its kind and source.

:func:`load_catalogue` reads and checks a file: the schema (one line naming the key at
fault), the relations between figures and model, and that the model reproduces every figure
that has a tolerance (:func:`check_part`, through the flat-target model of
:mod:`~reflector_opt.model._catalogue_fit`). :func:`resolve_parts` turns ``--sensor``'s
argument (``auto``, part names, catalogue files) into parts.
"""

import functools
import json
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Annotated, Literal

import msgspec
from msgspec import Meta

from reflector_opt.model._catalogue_fit import CHECKED, TARGETS, predicted_figures
from reflector_opt.model._sensor_file import SensorDocument
from reflector_opt.model._sensors import PRESETS, SensorModel
from reflector_opt.model._temperature import ThermalCoefficients
from reflector_opt.util import _schema as schema
from reflector_opt.util._catalogues import find_named, read_catalogue
from reflector_opt.util._display import Summarised, fmt, more_rows
from reflector_opt.util._errors import InputError

FORMAT = "reflector-opt/sensor-catalogue@1"
#: The catalogue shipped with the package (a resource of :mod:`reflector_opt`).
SHIPPED = "data/sensor_catalogue.toml"
#: Largest package side, and largest distance, a part may state, mm.
MAX_PART_MM = 100.0
#: Keys of ``basis`` every part states (``circuit``: supply, V_F, R1 and V_CE(sat) together).
BASIS_KEYS = (
    "emitter_detector_mm",
    "source_radius_mm",
    "divergence_deg",
    "detector_area_mm2",
    "current_gain",
    "load_resistor_ohm",
    "circuit",
)
#: The temperature figures a part may state: the fields of ``ThermalCoefficients``.
THERMAL_FIGURES = tuple(f.name for f in fields(ThermalCoefficients))

_Kind = Literal["published", "measured", "derived", "assumed", "fitted"]
_Source = Annotated[str, Meta(min_length=1, description="datasheet and place, or the basis")]
_Size = Annotated[float, Meta(gt=0, le=MAX_PART_MM, description="mm")]
_Tolerance = Annotated[float, Meta(gt=0, description="the figure's unit")]


class _Figure(schema.Table):
    kind: _Kind
    source: _Source


class LengthFigure(_Figure):
    """A length or distance, mm, with an optional tolerance (mm)."""

    value: _Size
    tolerance: _Tolerance | None = None


class RangeFigure(_Figure):
    """A distance range [near, far], mm; ``level``: the relative output at its ends."""

    value: Annotated[
        list[Annotated[float, Meta(ge=0, le=MAX_PART_MM)]], Meta(min_length=2, max_length=2)
    ]
    tolerance: _Tolerance | None = None
    level: Annotated[float, Meta(gt=0, lt=1, description="share of the peak output")] | None = None


class PackageFigure(_Figure):
    """The package: across the emitter–detector line, along it, along the optical axis, mm."""

    value: Annotated[list[_Size], Meta(min_length=3, max_length=3)]


class CurrentFigure(_Figure):
    """A current, A, with an optional tolerance (A)."""

    value: Annotated[float, Meta(gt=0, le=1, description="A")]
    tolerance: _Tolerance | None = None


class WavelengthFigure(_Figure):
    """The emitter's peak wavelength, nm (recorded; the model has no wavelength)."""

    value: Annotated[float, Meta(ge=200, le=2000, description="nm")]


class TargetFigure(_Figure):
    """The flat target of the datasheet's test (a key of ``catalogue_fit.TARGETS``)."""

    value: Literal[tuple(TARGETS)]


class TemperatureFigure(_Figure):
    """A temperature figure in the unit its key names: 1/K, 1/K², V/K, A (at 25 °C), K or
    K/W; an assumed one states its plausible ``range`` [low, high] (its value the
    unfavourable end)."""

    value: float
    range: Annotated[list[float], Meta(min_length=2, max_length=2)] | None = None


class SwitchingFigure(_Figure):
    """A switching time of the phototransistor, s, at the test load ``load_ohm`` (Ω); an
    assumed one states its plausible ``range``."""

    value: Annotated[float, Meta(gt=0, le=0.1, description="s")]
    load_ohm: Annotated[float, Meta(gt=0, le=1e7, description="Ω")]
    range: Annotated[list[float], Meta(min_length=2, max_length=2)] | None = None


class Figures(schema.Table):
    """The datasheet figures of one part; the six temperature figures are optional."""

    package_mm: PackageFigure
    emitter_detector_mm: LengthFigure
    wavelength_nm: WavelengthFigure
    peak_distance_mm: LengthFigure
    usable_range_mm: RangeFigure
    test_target: TargetFigure
    range_mm: RangeFigure | None = None
    output_current_a: CurrentFigure | None = None
    test_led_current_a: CurrentFigure | None = None
    test_distance_mm: LengthFigure | None = None
    led_output_per_k: TemperatureFigure | None = None
    detector_gain_per_k: TemperatureFigure | None = None
    forward_voltage_v_per_k: TemperatureFigure | None = None
    dark_current_a: TemperatureFigure | None = None
    dark_doubling_k: TemperatureFigure | None = None
    thermal_resistance_k_per_w: TemperatureFigure | None = None
    output_per_k: TemperatureFigure | None = None
    output_per_k2: TemperatureFigure | None = None
    rise_time_s: SwitchingFigure | None = None
    fall_time_s: SwitchingFigure | None = None


class Basis(schema.Table):
    """Where a model parameter comes from."""

    kind: _Kind
    source: _Source


class PartDocument(schema.Table):
    """One part of a catalogue file."""

    name: Annotated[str, Meta(min_length=1, max_length=64)]
    maker: Annotated[str, Meta(min_length=1)]
    datasheet: _Source
    figures: Figures
    model: SensorDocument
    basis: dict[str, Basis]
    notes: str = ""


class CatalogueDocument(schema.Table):
    """A sensor catalogue file (TOML)."""

    format: Literal["reflector-opt/sensor-catalogue@1"]
    part: Annotated[list[PartDocument], Meta(min_length=1, description="the parts ([[part]])")]


@dataclass(frozen=True, repr=False)
class CataloguePart(Summarised):
    """One part of the sensor catalogue.

    Attributes
    ----------
    name, maker, datasheet : str
    figures : dict
        The datasheet figures by name (``value``, ``kind``, ``source`` and, where stated,
        ``tolerance`` and ``level``).
    model : reflector_opt.model._sensors.SensorModel
        The fitted model, its package included.
    basis : dict
        Kind and source of each model parameter.
    origin : str
        The catalogue file the part was read from (``"shipped"`` for the package's own).
    notes : str
    """

    name: str
    maker: str
    datasheet: str
    figures: dict
    model: SensorModel
    basis: dict
    origin: str
    notes: str = ""

    def _summary(self):
        """Title and (label, value) rows of :class:`CataloguePart`."""
        package = self.package_mm
        rows = [
            ("package", " × ".join(fmt(v) for v in package) + " mm" if package else "n/a"),
            ("range", f"{fmt(self.model.range_mm[0])} to {fmt(self.model.range_mm[1], unit='mm')}"),
            ("origin", self.origin),
            ("datasheet", self.datasheet),
        ]
        names = list(self.figures)
        for name in names[:SHOWN_FIGURES]:
            rows.append((name, str(getattr(self.figures[name], "value", self.figures[name]))))
        rows += more_rows(len(names), SHOWN_FIGURES, "figures")
        return f"CataloguePart: {self.name} ({self.maker})", rows

    @property
    def package_mm(self):
        """(across, along, depth) of the package, mm."""
        return self.model.package_mm

    def record(self):
        """The part as a JSON-ready dict (what ``design.json`` records of its sensor choice).

        Returns
        -------
        dict
        """
        return {
            "name": self.name,
            "maker": self.maker,
            "datasheet": self.datasheet,
            "origin": self.origin,
            "figures": {k: msgspec.to_builtins(v) for k, v in self.figures.items()},
            "basis": {k: msgspec.to_builtins(v) for k, v in self.basis.items()},
        }


def json_schema():
    """The JSON Schema of a catalogue file (``docs/sensor-catalogue.schema.json``).

    Returns
    -------
    dict
    """
    return schema.json_schema(CatalogueDocument, f"sensor catalogue ({FORMAT})")


def _part(document, origin, where, *, check):
    """A checked :class:`CataloguePart` from its document, its model checked against its
    figures if asked (:func:`check_part`)."""
    figures = {k: v for k, v in msgspec.structs.asdict(document.figures).items() if v is not None}
    model = SensorModel.from_dict(msgspec.to_builtins(document.model), f"{where}.model")
    part = CataloguePart(
        name=document.name,
        maker=document.maker,
        datasheet=document.datasheet,
        figures=figures,
        model=model,
        basis=dict(document.basis),
        origin=origin,
        notes=document.notes,
    )
    _check_relations(part, where)
    if check:
        check_part(part, where)
    return part


def _check_relations(part, where):
    """Refuse figures and model that do not fit together (one line naming the key)."""
    f, m = part.figures, part.model
    missing = [k for k in BASIS_KEYS if k not in part.basis]
    if missing:
        raise InputError(f"{where}.basis: missing {', '.join(missing)}")
    if m.name != part.name:
        raise InputError(f"{where}.model.name: {m.name!r} is not the part's name {part.name!r}")
    if m.package_mm is None or list(m.package_mm) != list(f["package_mm"].value):
        raise InputError(f"{where}.model.package_mm: must equal figures.package_mm")
    if list(m.range_mm) != list(f["usable_range_mm"].value):
        raise InputError(f"{where}.model.range_mm: must equal figures.usable_range_mm")
    for name in ("range_mm", "usable_range_mm"):
        if name in f and not f[name].value[0] < f[name].value[1]:
            raise InputError(f"{where}.figures.{name}: needs near < far, got {f[name].value}")
    if "range_mm" in f and (f["range_mm"].level is None or f["range_mm"].tolerance is None):
        raise InputError(f"{where}.figures.range_mm: needs its level and tolerance")
    if f["peak_distance_mm"].tolerance is None:
        raise InputError(f"{where}.figures.peak_distance_mm: needs a tolerance")
    try:
        thermal_coefficients(part)
    except InputError as exc:  # ThermalCoefficients names the key; place it in the file
        raise InputError(f"{where}.figures.{exc}") from None
    for key in THERMAL_FIGURES:
        figure = f.get(key)
        if figure is None or figure.kind != "assumed":
            continue
        if figure.range is None or figure.value not in figure.range:
            raise InputError(
                f"{where}.figures.{key}: an assumed figure states its plausible range and "
                "takes one end of it (the unfavourable one), e.g. range = [-0.003, 0.003]"
            )
    if "output_current_a" in f:
        absent = [k for k in ("test_led_current_a", "test_distance_mm") if k not in f]
        absent += ["output_current_a"] if f["output_current_a"].tolerance is None else []
        if absent:
            raise InputError(
                f"{where}.figures: an output current needs its tolerance and the test's "
                f"LED current and distance ({', '.join(absent)})"
            )


def check_part(part, where=None):
    """Check that a part's model reproduces its peak distance and output current.

    The figures of :data:`~reflector_opt.model._catalogue_fit.CHECKED`, each within its
    tolerance, through the flat-target model on the test target; the range's ends are fitted
    with their tolerance as a weight but not checked (a one-beam model cannot draw every
    datasheet's curve: docs/model.md).

    Parameters
    ----------
    part : CataloguePart
    where : str, optional
        The part's place, for the message (default its name and origin).

    Returns
    -------
    dict
        :func:`~reflector_opt.model._catalogue_fit.predicted_figures` of the model. Raises
        :class:`~reflector_opt.util._errors.InputError` naming the first figure the model misses
        by more than its tolerance, with both values.
    """
    where = where or f"sensor part {part.name!r} ({part.origin})"
    predicted = predicted_figures(part.model, part.figures)
    for name in CHECKED:
        if name not in predicted:
            continue
        figure, got = part.figures[name], predicted[name]
        if abs(got - figure.value) > figure.tolerance * (1 + 1e-9):
            raise InputError(
                f"{where}: figures.{name}: the model gives {got:.4g}, the figure says "
                f"{figure.value:.4g} ± {figure.tolerance:g}; refit the model to the figures"
            )
    return predicted


def load_catalogue(path=None, *, check=True):
    """Read and check a sensor catalogue file.

    Parameters
    ----------
    path : str or pathlib.Path, optional
        A catalogue file (TOML); default the shipped catalogue.
    check : bool, optional
        Also check that each model reproduces its figures (:func:`check_part`).

    Returns
    -------
    tuple of CataloguePart
        In the file's order. Raises :class:`~reflector_opt.util._errors.InputError` with one line
        naming the file and the key at fault.
    """
    build = functools.partial(_part, check=check)
    return read_catalogue(path, SHIPPED, CatalogueDocument, "part", build)


@functools.cache
def shipped_catalogue():
    """The shipped catalogue, read once (:func:`load_catalogue` without a path).

    Returns
    -------
    tuple of CataloguePart
    """
    return load_catalogue()


def get_part(name):
    """A part of the shipped catalogue by name.

    Parameters
    ----------
    name : str

    Returns
    -------
    CataloguePart
        Raises :class:`~reflector_opt.util._errors.InputError` listing the known parts.
    """
    return find_named(
        shipped_catalogue(),
        name,
        "sensor part",
        hint="or give a catalogue file, PARTS.toml",
    )


def thermal_coefficients(name_or_part):
    """The temperature coefficients of a part, from its temperature figures.

    Each of :data:`THERMAL_FIGURES` the part states (``figures.<key>.value``) is taken as it
    is: ``output_per_k`` (the datasheet's relative output against ambient temperature at a
    constant I_F, LED and detector together) in 1/K and its curvature ``output_per_k2`` in
    1/K², or the split ``led_output_per_k`` and ``detector_gain_per_k`` in 1/K;
    ``forward_voltage_v_per_k`` in V/K, ``dark_current_a`` (I_CEO at 25 °C) in A,
    ``dark_doubling_k`` in K and ``thermal_resistance_k_per_w`` in K/W, each about 25 °C
    (the equations and their source are in :mod:`reflector_opt.model._temperature`). A part
    without a figure — a user's part file may leave any of them out — gets the documented
    generic default of :class:`~reflector_opt.model._temperature.ThermalCoefficients` for it
    (the split −0.5 %/K and +0.2 %/K, −1.8 mV/K, 10 nA, 10 K, 500 K/W); every part of the
    shipped catalogue states ``output_per_k``, ``output_per_k2`` and the other four, each
    published, derived from a published curve, or assumed at the unfavourable end of its
    stated range (:func:`assumed_temperature_figures`).

    Parameters
    ----------
    name_or_part : str or CataloguePart
        A part of the shipped catalogue by name, or a part (e.g. from a user's file).

    Returns
    -------
    ThermalCoefficients
        Raises :class:`~reflector_opt.util._errors.InputError` for an unknown name, or naming
        the key of a non-finite or implausible figure.
    """
    part = get_part(name_or_part) if isinstance(name_or_part, str) else name_or_part
    given = {k: part.figures[k].value for k in THERMAL_FIGURES if k in part.figures}
    return ThermalCoefficients(**given)


def assumed_temperature_figures(name_or_part):
    """The temperature figures of a part that are assumed, not read in its datasheet.

    Parameters
    ----------
    name_or_part : str or CataloguePart

    Returns
    -------
    dict
        ``{key: {"value", "range", "source"}}`` for each assumed figure of
        :data:`THERMAL_FIGURES` (each at the unfavourable end of its range); a figure the
        part leaves out (a user's file) is the generic default, reported with the range None.
    """
    part = get_part(name_or_part) if isinstance(name_or_part, str) else name_or_part
    split = ("led_output_per_k", "detector_gain_per_k")
    unused = split if "output_per_k" in part.figures else ("output_per_k",)
    found = {}
    for key in (k for k in THERMAL_FIGURES if k not in unused):
        figure = part.figures.get(key)
        if figure is None:
            default = getattr(ThermalCoefficients(), key)
            found[key] = {"value": default, "range": None, "source": "the generic default"}
        elif figure.kind == "assumed":
            found[key] = {
                "value": figure.value,
                "range": list(figure.range),
                "source": figure.source,
            }
    return found


#: The switching times of a part whose datasheet gives none (the unfavourable end of the
#: published ones of this construction: 10-40 µs at 100 Ω): (t_r, t_f, test load), s and Ω.
GENERIC_SWITCHING = (40e-6, 40e-6, 100.0)


def switching_times(name_or_part):
    """A part's phototransistor rise and fall times and the test load they are stated at.

    Parameters
    ----------
    name_or_part : str or CataloguePart

    Returns
    -------
    (float, float, float, bool)
        t_r (s), t_f (s), the test load (Ω), and whether any of them is assumed
        (:data:`GENERIC_SWITCHING` for a part that states none).
    """
    part = get_part(name_or_part) if isinstance(name_or_part, str) else name_or_part
    rise, fall = part.figures.get("rise_time_s"), part.figures.get("fall_time_s")
    if rise is None or fall is None:
        return (*GENERIC_SWITCHING, True)
    if rise.load_ohm != fall.load_ohm:
        raise InputError(f"{part.name}: rise_time_s and fall_time_s at different loads")
    assumed = "assumed" in (rise.kind, fall.kind)
    return rise.value, fall.value, rise.load_ohm, assumed


def sensor_model(name):
    """The sensor model of a part name: a preset, else a part of the shipped catalogue.

    Parameters
    ----------
    name : str
        One of :data:`~reflector_opt.model._sensors.PRESETS` (``"NJL5901R-2"``,
        ``"QRE1113"``) or a part of the shipped catalogue (e.g. ``"VCNT2020"``).

    Returns
    -------
    SensorModel
        Raises :class:`~reflector_opt.util._errors.InputError` naming the presets and the
        catalogue's parts when ``name`` is neither. The catalogue is read only for a name
        that is not a preset.
    """
    if name in PRESETS:
        return PRESETS[name]
    parts = {part.name: part.model for part in shipped_catalogue()}
    if name not in parts:
        raise InputError(
            f"unknown sensor preset {name!r}; known presets: {', '.join(sorted(PRESETS))}; "
            f"the sensor catalogue's parts: {', '.join(parts)}"
        )
    return parts[name]


def resolve_parts(spec):
    """The parts ``--sensor SPEC`` names: ``auto``, part names and catalogue files, by commas.

    Parameters
    ----------
    spec : str
        Comma-separated items: ``auto`` (every part of the shipped catalogue), a part's name,
        or a catalogue file (an item ending in ``.toml``, or naming an existing file: all its
        parts).

    Returns
    -------
    list of CataloguePart
        In the order given, each part once. Raises
        :class:`~reflector_opt.util._errors.InputError` for an unknown name, a bad file, two
        different parts of one name, or an empty list.
    """
    items = [item.strip() for item in str(spec).split(",")]
    if not any(items) or not all(items):
        raise InputError(f"--sensor: expected auto, part names or PARTS.toml files, got {spec!r}")
    chosen = {}
    for item in items:
        if item == "auto":
            found = shipped_catalogue()
        elif item.endswith(".toml") or Path(item).is_file():
            found = load_catalogue(item)
        else:
            found = (get_part(item),)
        for part in found:
            known = chosen.get(part.name)
            if known is not None and known.model != part.model:
                raise InputError(
                    f"--sensor: two different parts named {part.name!r} ({known.origin}, "
                    f"{part.origin})"
                )
            chosen.setdefault(part.name, part)
    return list(chosen.values())


def measured_part(model, base, curve, distance_mm, volts, target, rms_residual_v):
    """A catalogue part for a sensor model fitted to a measured flat-target curve.

    The part keeps the base part's package, spacing, wavelength, usable range (as the model
    does) and temperature figures (a curve at one temperature says nothing of them); its peak
    distance is the measured one, the distance of the curve's lowest voltage (most light),
    with a tolerance of the readings' spacing there (at least 0.05 mm); ω0, θ and G are
    marked fitted to the curve.

    Parameters
    ----------
    model : reflector_opt.model._sensors.SensorModel
        The fitted model (:func:`reflector_opt.model._measured.fit_sensor_model`).
    base : CataloguePart
        The catalogue part the fit started from.
    curve : str
        The curve's file, for the sources.
    distance_mm, volts : array_like
        The curve: distances (mm, increasing) and output voltages (V).
    target : str
        The flat target of the measurement, a key of ``catalogue_fit.TARGETS``.
    rms_residual_v : float
        RMS residual of the fit, V.

    Returns
    -------
    CataloguePart
        Checked (:func:`check_part`): an InputError if the model misses the measured peak.
    """
    measured = f"{curve}: fitted by reflector-opt fit-sensor ({len(distance_mm)} readings, RMS "
    measured += f"residual {1e3 * rms_residual_v:.2f} mV)"
    figures = {k: v for k, v in base.figures.items() if k in ("package_mm", "emitter_detector_mm")}
    figures["wavelength_nm"] = base.figures["wavelength_nm"]
    figures["peak_distance_mm"] = _measured_peak(curve, distance_mm, volts)
    figures["usable_range_mm"] = RangeFigure(
        value=list(model.range_mm), kind="assumed", source=f"the usable range of {base.name}"
    )
    figures["test_target"] = TargetFigure(value=target, kind="measured", source=curve)
    figures.update({k: base.figures[k] for k in THERMAL_FIGURES if k in base.figures})
    basis = dict(base.basis)
    for key in ("source_radius_mm", "divergence_deg", "current_gain"):
        basis[key] = Basis(kind="fitted", source=measured)
    part = CataloguePart(
        name=model.name,
        maker=base.maker,
        datasheet=f"measured: {curve}; otherwise {base.datasheet}",
        figures=figures,
        model=model.with_(package_mm=base.package_mm),
        basis=basis,
        origin=curve,
        notes=f"Fitted to a measured curve from the {base.name} catalogue part.",
    )
    _check_relations(part, f"part {part.name!r}")
    check_part(part, f"part {part.name!r}")
    return part


def _measured_peak(curve, distance_mm, volts):
    """The peak distance of a measured curve: the distance of its lowest voltage (the most
    light), with the readings' spacing there as its tolerance (at least 0.05 mm)."""
    import numpy as np

    d, v = np.asarray(distance_mm, dtype=float), np.asarray(volts, dtype=float)
    i = int(np.argmin(v))
    spacing = max(np.diff(d[max(i - 1, 0) : i + 2]), default=0.0)
    return LengthFigure(
        value=float(d[i]),
        kind="measured",
        source=f"{curve}: the distance of the lowest voltage (the most light)",
        tolerance=round(max(0.05, float(spacing)), 6),
    )


def part_to_toml(part):
    """A catalogue file holding one part, as TOML text (:func:`load_catalogue` reads it).

    Parameters
    ----------
    part : CataloguePart

    Returns
    -------
    str
    """
    lines = [f"format = {_toml(FORMAT)}", "", "[[part]]"]
    for key in ("name", "maker", "datasheet", "notes"):
        if getattr(part, key):
            lines.append(f"{key} = {_toml(getattr(part, key))}")
    lines += ["", "[part.figures]"]
    for key, figure in part.figures.items():
        fields = {k: v for k, v in msgspec.structs.asdict(figure).items() if v is not None}
        lines.append(f"{key} = {_toml(fields)}")
    lines += ["", "[part.model]"]
    lines += [f"{k} = {_toml(v)}" for k, v in part.model.to_dict().items()]
    lines += ["", "[part.basis]"]
    lines += [f"{k} = {_toml(msgspec.structs.asdict(v))}" for k, v in part.basis.items()]
    return "\n".join(lines) + "\n"


def _toml(value):
    """A TOML value: strings as JSON (their escapes are TOML's), numbers, lists, inline tables."""
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{k} = {_toml(v)}" for k, v in value.items()) + " }"
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    return repr(float(value)) if isinstance(value, float) else str(value)


#: Datasheet figures a display lists; the rest are counted.
SHOWN_FIGURES = 12
