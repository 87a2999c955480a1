"""The sensor catalogue: it loads, every part reproduces its datasheet figures, user files.

The figures a part's model must reproduce are computed here independently of
``reflector_opt.model._catalogue_fit``: the peak of the flat-target coupling on a dense grid
refined by a parabola through its three highest points, and the test current G · I_F · η from
``optics.flat_target_coupling`` on the test target.
"""

import dataclasses
import math
import re
import tomllib

import numpy as np
import pytest

from reflector_opt.design._layout import plan_layout, window_wall_mm
from reflector_opt.design._parts import CadParameters, package_parameters
from reflector_opt.model._catalogue import (
    FORMAT,
    THERMAL_FIGURES,
    assumed_temperature_figures,
    load_catalogue,
    measured_part,
    resolve_parts,
    shipped_catalogue,
    thermal_coefficients,
)
from reflector_opt.model._optics import flat_target_coupling
from reflector_opt.model._sensors import NJL5901R_2, PRESETS
from reflector_opt.model._temperature import self_heating_k
from reflector_opt.optimiser import Problem
from reflector_opt.util._errors import InputError

#: The datasheet test targets as (reflectance, specular fraction), stated here on their own.
TARGETS = {"white-card": (0.9, 0.0), "aluminium": (0.9, 1.0), "mirror": (1.0, 1.0)}
PARTS = {p.name: p for p in shipped_catalogue()}


def _peak(model, target):
    """Peak distance of the flat-target coupling: a 2000-point grid and a parabola, mm."""
    rho, f = TARGETS[target]
    d = np.linspace(0.01, max(5.0, 20 * model.emitter_detector_mm), 2000)
    eta = flat_target_coupling(d, model, rho, f)
    i = int(np.argmax(eta))
    y0, y1, y2 = eta[i - 1 : i + 2]
    return d[i] + 0.5 * (d[1] - d[0]) * (y0 - y2) / (y0 - 2 * y1 + y2)


def test_the_catalogue_loads_and_every_entry_validates():
    parts = load_catalogue()  # checks the schema, the relations and the figures
    assert len(parts) >= 8
    assert len({p.name for p in parts}) == len(parts)
    for part in parts:
        for name, figure in part.figures.items():
            assert figure.kind in {"published", "measured", "derived", "assumed", "fitted"}, name
            assert figure.source.strip(), name
        assert part.model.name == part.name
        assert tuple(part.model.range_mm) == tuple(part.figures["usable_range_mm"].value)
        assert part.package_mm == tuple(part.figures["package_mm"].value)
        assert all(b.source.strip() for b in part.basis.values())


def test_the_njl5901r_2_entry_is_the_preset_unchanged():
    part = PARTS["NJL5901R-2"]
    assert part.model.with_(package_mm=None) == NJL5901R_2 == PRESETS["NJL5901R-2"]
    assert (
        part.package_mm
        == (1.0, 1.4, 0.6)
        == (
            CadParameters().sensor_width_mm,
            CadParameters().sensor_length_mm,
            CadParameters().sensor_depth_mm,
        )
    )


@pytest.mark.parametrize("name", sorted(PARTS))
def test_each_model_reproduces_its_peak_and_output_current(name):
    part = PARTS[name]
    figures, model = part.figures, part.model
    target = figures["test_target"].value
    peak = figures["peak_distance_mm"]
    assert abs(_peak(model, target) - peak.value) <= peak.tolerance
    if "output_current_a" in figures:
        rho, f = TARGETS[target]
        distance = figures["test_distance_mm"].value
        eta = flat_target_coupling(np.array([distance]), model, rho, f)[0]
        current = model.current_gain * figures["test_led_current_a"].value * eta
        wanted = figures["output_current_a"]
        assert abs(current - wanted.value) <= wanted.tolerance


def test_every_part_spans_the_reference_swing():
    """Each part's flat-mirror peak drops the output as far as the NJL5901R-2 preset's."""
    drops = []
    for part in PARTS.values():
        m = part.model
        eta = flat_target_coupling(np.array([_peak(m, "mirror")]), m, 1.0, 1.0)[0]
        drops.append(m.current_gain * m.led_current_a * eta * m.load_resistor_ohm)
    np.testing.assert_allclose(drops, drops[0], rtol=2e-3)


def _section(name):
    """The TOML text of one shipped part, from its ``[[part]]`` line to the next."""
    from importlib import resources

    text = resources.files("reflector_opt").joinpath("data/sensor_catalogue.toml").read_text()
    sections = re.split(r"(?m)^(?=\[\[part\]\])", text)
    return next(s for s in sections if f'name = "{name}"' in s.split("\n", 2)[1])


def _user_file(tmp_path, section, old="VCNT2020", new="MY-PART"):
    path = tmp_path / "parts.toml"
    path.write_text(f'format = "{FORMAT}"\n\n' + section.replace(old, new), encoding="utf-8")
    return path


def test_a_user_file_of_the_same_format_is_accepted(tmp_path):
    path = _user_file(tmp_path, _section("VCNT2020"))
    (part,) = load_catalogue(path)
    assert part.name == "MY-PART" and part.origin == str(path)
    assert part.model.with_(name="VCNT2020") == PARTS["VCNT2020"].model
    chosen = resolve_parts(f"NJL5901R-2,{path}")
    assert [p.name for p in chosen] == ["NJL5901R-2", "MY-PART"]
    assert part.record()["figures"]["peak_distance_mm"]["value"] == 0.5


@pytest.mark.parametrize(
    ("old", "new", "fragment"),
    [
        ('maker = "Vishay"\n', "", "part[0].maker: missing"),
        ("value = [2.0, 2.5, 0.8]", "value = [2.0, 0.0, 0.8]", "figures.package_mm.value[1]"),
        ("value = 940.0", "value = 5.0", "wavelength_nm.value: expected a number from 200"),
        ('kind = "published", tolerance = 0.05', 'kind = "guessed", tolerance = 0.05', "kind"),
        ("value = 0.5, kind", "value = 3.0, kind", "peak_distance_mm: the model gives 0.5"),
        ("value = 1.6e-3", "value = 50.0", "output_current_a.value"),
        ("package_mm = [2.0, 2.5, 0.8]\n", "package_mm = [2.0, 2.5, 0.9]\n", "must equal"),
        ("load_resistor_ohm = ", "colour = 1\nload_resistor_ohm = ", "unknown key"),
    ],
)
def test_a_bad_part_file_is_refused_with_one_line(tmp_path, old, new, fragment):
    section = _section("VCNT2020")
    assert old in section
    path = _user_file(tmp_path, section.replace(old, new, 1))
    with pytest.raises(InputError) as exc:
        load_catalogue(path)
    message = str(exc.value)
    assert "\n" not in message and message.startswith(str(path))
    assert fragment in message


def test_unknown_names_and_clashes_are_refused(tmp_path):
    with pytest.raises(InputError, match="unknown sensor part 'XYZ'; the catalogue has: NJL"):
        resolve_parts("auto,XYZ")
    with pytest.raises(InputError, match="expected auto"):
        resolve_parts("VCNT2020,,")
    path = _user_file(tmp_path, _section("VCNT2020"), new="VCNT2020")
    assert [p.name for p in resolve_parts(f"VCNT2020,{path}")] == ["VCNT2020"]  # the same part
    other = _section("VCNT2020").replace("saturation_v = 0.2", "saturation_v = 0.21")
    other_path = tmp_path / "other.toml"
    other_path.write_text(f'format = "{FORMAT}"\n\n' + other, encoding="utf-8")
    with pytest.raises(InputError, match="two different parts named 'VCNT2020'"):
        resolve_parts(f"VCNT2020,{other_path}")


def test_the_package_of_a_part_sets_the_window_and_the_strip():
    part = PARTS["VCNT2020"]
    params = package_parameters(CadParameters(), [part.model])
    assert (params.sensor_width_mm, params.sensor_length_mm, params.sensor_depth_mm) == (
        2.0,
        2.5,
        0.8,
    )
    assert params.strip_width_mm == pytest.approx(2.2)  # widened to the window
    assert package_parameters(CadParameters(), [NJL5901R_2]) == CadParameters()
    design = Problem(sensor=part.model).baseline_design()
    layout = plan_layout(design)
    assert layout.params.sensor_length_mm == 2.5
    njl = Problem().baseline_design()
    # 1.1 mm more of window above the sensor height: the wall above it is thinner by
    # (2.5 − 1.4)/2 mm at the axis' horizontal
    assert window_wall_mm(njl) - window_wall_mm(design) == pytest.approx(
        [0.55 * math.hypot(*njl.axes[0][:2])] * 2
    )


def test_fit_sensor_writes_a_part_file_from_a_measured_curve(tmp_path, capsys):
    from reflector_opt.cli import main

    truth = PARTS["VCNT2020"].model.with_(divergence_deg=33.0)  # the part as measured
    d = np.round(np.arange(0.2, 2.55, 0.1), 3)
    volts = truth.output_voltage(truth.flat_coupling(d, 0.9, 1.0))  # on aluminium
    curve = tmp_path / "curve.csv"
    curve.write_text(
        "distance_mm,volts\n" + "".join(f"{a},{b:.5f}\n" for a, b in zip(d, volts, strict=True))
    )
    parts, design = tmp_path / "parts.toml", tmp_path / "design.json"
    args = ["fit-sensor", str(curve), "--base", "VCNT2020", "-o", str(design)]
    assert main([*args, "--part-file", str(parts)]) == 0
    (part,) = resolve_parts(str(parts))  # loads, checks the measured peak
    assert part.name == "VCNT2020-measured" and part.package_mm == (2.0, 2.5, 0.8)
    assert part.model.divergence_deg == pytest.approx(33.0, abs=0.1)
    peak = part.figures["peak_distance_mm"]
    assert (peak.kind, peak.value, peak.tolerance) == ("measured", 0.5, 0.1)
    assert part.figures["test_target"].value == "aluminium"
    assert part.basis["divergence_deg"].source.startswith(f"{curve}: fitted by")
    assert "parts.toml" in capsys.readouterr().out
    other = ["--reflectance", "0.5", "--part-file", str(tmp_path / "x.toml")]
    assert main([*args, *other]) == 2
    assert "--part-file: the target must be one of" in capsys.readouterr().err
    assert not (tmp_path / "x.toml").exists()


@pytest.mark.parametrize(
    ("part", "old", "new", "fragment"),
    [
        ("VCNT2020", 'maker = "Vishay"\n', "", "part[0].maker: missing"),
        ("VCNT2020", "value = 940.0", "value = nan", "wavelength_nm.value: got nan"),
        ("VCNT2020", "value = [2.0, 2.5, 0.8]", "value = [2.0, inf, 0.8]", "got inf"),
        ("VCNT2020", "value = 1.6e-3", "value = -1.6e-3", "output_current_a.value: expected"),
        ("CNY70", "", "", "MY-PART (7 × 7 × 6 mm): wall: "),  # larger than the envelope
    ],
)
def test_optimise_refuses_a_bad_or_oversized_part_file(tmp_path, capsys, part, old, new, fragment):
    """A part file with missing, absurd or non-finite figures, or a part the unit cannot
    hold: one line naming it, exit 2, nothing written."""
    from reflector_opt.cli import main

    section = _section(part)
    assert old in section
    path = _user_file(tmp_path, section.replace(old, new, 1), old=part)
    out = tmp_path / "out"
    assert main(["optimise", "--sensor", str(path), "-o", str(out), "-q", "--no-report"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("reflector-opt optimise: error: ") and "\n" not in err
    assert fragment in err
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["parts.toml"]


# --- temperature figures ------------------------------------------------------------------------

#: The temperature figures, named here on their own (the fields of ThermalCoefficients).
TEMPERATURE_KEYS = (
    "led_output_per_k",
    "detector_gain_per_k",
    "forward_voltage_v_per_k",
    "dark_current_a",
    "dark_doubling_k",
    "thermal_resistance_k_per_w",
    "output_per_k",
    "output_per_k2",
)
#: The six every shipped part states: its output against temperature at a constant I_F (the
#: datasheets' curve, LED and detector together), V_F's, the dark current's and R_thJA.
SHIPPED_KEYS = (
    "output_per_k",
    "output_per_k2",
    "forward_voltage_v_per_k",
    "dark_current_a",
    "dark_doubling_k",
    "thermal_resistance_k_per_w",
)


def test_every_shipped_part_states_its_six_temperature_figures():
    assert THERMAL_FIGURES == TEMPERATURE_KEYS
    assert len(PARTS) == 9
    for part in PARTS.values():
        for key in SHIPPED_KEYS:
            figure = part.figures[key]
            assert figure.kind in {"published", "derived", "assumed"}, (part.name, key)
            assert figure.source.strip(), (part.name, key)
            assert math.isfinite(figure.value), (part.name, key)
            if figure.kind == "assumed":  # the unfavourable end of a stated range
                assert figure.value in figure.range, (part.name, key)
        assert not {"led_output_per_k", "detector_gain_per_k"} & set(part.figures)


def test_the_vcnt2020_carries_its_published_temperature_figures():
    """Vishay doc 84285 rev. 1.3: Fig. 8 +0.40 %/K (read off, the fit's slope), TK_VF
    −1.0 mV/K, I_CEO 1 nA typ, its doubling 6-6.5 K (Fig. 6), R_thJA 380 K/W."""
    t = thermal_coefficients("VCNT2020")
    assert (t.output_per_k, t.forward_voltage_v_per_k, t.dark_current_a) == (0.004, -0.001, 1e-9)
    assert (t.dark_doubling_k, t.thermal_resistance_k_per_w) == (6.25, 380.0)
    assert assumed_temperature_figures("VCNT2020") == {}
    njl = assumed_temperature_figures("NJL5901R-2")  # nothing read: all six assumed
    assert set(njl) == set(SHIPPED_KEYS)
    assert njl["output_per_k"]["value"] == 0.004 and njl["output_per_k"]["range"][1] == 0.004


def test_an_assumed_figure_without_its_range_is_refused(tmp_path):
    section = _section("NJL5901R-2")
    line = _temperature_line(section, "dark_doubling_k")
    bare = re.sub(r"range = \[[^]]*\], ", "", line)
    path = _user_file(tmp_path, section.replace(line, bare), old="NJL5901R-2")
    with pytest.raises(InputError, match=r"dark_doubling_k: an assumed figure states its"):
        load_catalogue(path)


def _shipped_toml_figures(name):
    """The temperature figures of a shipped part, read from the TOML file with tomllib."""
    from importlib import resources

    text = resources.files("reflector_opt").joinpath("data/sensor_catalogue.toml").read_text()
    (entry,) = [p for p in tomllib.loads(text)["part"] if p["name"] == name]
    return {key: entry["figures"][key]["value"] for key in SHIPPED_KEYS}


@pytest.mark.parametrize("name", ["NJL5901R-2", "SFH 9206", "QRE1113"])
def test_thermal_coefficients_are_the_files_numbers(name):
    coefficients = thermal_coefficients(name)
    stated = {k: v for k, v in dataclasses.asdict(coefficients).items() if k in SHIPPED_KEYS}
    assert stated == _shipped_toml_figures(name)
    assert thermal_coefficients(PARTS[name]) == coefficients


def test_the_published_temperature_figures_and_the_self_heating_they_give():
    """SFH 9206: R_thJA 495 K/W and I_CE0 1 nA typ. (datasheet v1.5); QRE1113: 75 mW derated
    by 1.00 mW/K, so 1000 K/W. In the paper's circuit I_F = (3.3 − 1.2) V / 680 Ω = 3.088 mA
    and the LED dissipates 1.2 V × 3.088 mA = 3.706 mW: 1.834 K of self-heating at 495 K/W."""
    sfh, qre = thermal_coefficients("SFH 9206"), thermal_coefficients("QRE1113")
    assert (sfh.thermal_resistance_k_per_w, sfh.dark_current_a) == (495.0, 1e-9)
    assert qre.thermal_resistance_k_per_w == 1 / 1.00e-3
    model = PARTS["SFH 9206"].model
    assert self_heating_k(model, sfh) == pytest.approx(495.0 * 1.2 * 2.1 / 680.0, rel=1e-12)
    assert self_heating_k(model, sfh) == pytest.approx(1.834, abs=5e-4)


def _temperature_line(section, key):
    return next(line for line in section.splitlines() if line.startswith(f"{key} = "))


@pytest.mark.parametrize(
    ("key", "value", "fragment"),
    [
        ("output_per_k", "0.5", "within ±0.05 (±5 %/K), got 0.5"),
        ("forward_voltage_v_per_k", "nan", "got nan"),  # refused by the schema
        ("dark_doubling_k", "0.0", "must be positive, got 0.0"),
        ("thermal_resistance_k_per_w", "-500.0", "expected 0–10000 K/W, got -500.0"),
        ("dark_current_a", "1.0", "expected 0–1e-4 A, got 1.0"),
    ],
)
def test_an_absurd_temperature_figure_is_refused_with_one_line(tmp_path, key, value, fragment):
    section = _section("VCNT2020")
    line = _temperature_line(section, key)
    bad = re.sub(r"value = [^,]+,", f"value = {value},", line, count=1)
    path = _user_file(tmp_path, section.replace(line, bad))
    with pytest.raises(InputError) as exc:
        load_catalogue(path)
    message = str(exc.value)
    assert "\n" not in message and message.startswith(f"{path}: part[0]")
    assert f".figures.{key}" in message and fragment in message


def test_a_part_file_without_temperature_figures_loads_with_the_defaults(tmp_path):
    section = _section("SFH 9206")
    lines = [_temperature_line(section, key) for key in SHIPPED_KEYS]
    bare = section
    for line in lines:
        bare = bare.replace(line + "\n", "")
    (part,) = load_catalogue(_user_file(tmp_path, bare, old="SFH 9206"))
    assert not set(TEMPERATURE_KEYS) & set(part.figures)
    assert part.model.with_(name="SFH 9206") == PARTS["SFH 9206"].model
    defaults = thermal_coefficients(part)
    assert (defaults.led_output_per_k, defaults.forward_voltage_v_per_k) == (-0.005, -0.0018)
    assert (defaults.dark_current_a, defaults.thermal_resistance_k_per_w) == (1e-8, 500.0)
    # one figure left out: that one takes its default, the others are the file's
    partial = section.replace(_temperature_line(section, "dark_current_a") + "\n", "")
    (part,) = load_catalogue(_user_file(tmp_path, partial, old="SFH 9206"))
    coefficients = thermal_coefficients(part)
    assert (coefficients.dark_current_a, coefficients.thermal_resistance_k_per_w) == (1e-8, 495.0)


def test_a_measured_part_keeps_its_base_parts_temperature_figures():
    base = PARTS["SFH 9206"]
    model = base.model.with_(name="SFH 9206-measured")
    d = np.round(np.arange(0.3, 5.0, 0.1), 3)
    volts = model.output_voltage(model.flat_coupling(d, 0.9, 0.0))  # on the white card
    part = measured_part(model, base, "curve.csv", d, volts, "white-card", 0.0)
    assert thermal_coefficients(part) == thermal_coefficients(base)
    assert all(part.figures[k] == base.figures[k] for k in SHIPPED_KEYS)
