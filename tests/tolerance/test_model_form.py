"""Built units with model-form error: options, limits, and what each effect does to the volts."""

import dataclasses

import numpy as np
import pytest

from reflector_opt.tolerance._builtunit import build_unit
from reflector_opt.tolerance._model_form import ModelForm
from reflector_opt.util._errors import InputError

GRID = np.linspace(-15.0, 15.0, 9)
PITCH, ROLL = (a.ravel() for a in np.meshgrid(GRID, GRID, indexing="ij"))
#: G · I_F · R2 of the NJL5901R-2 preset: volts per unit coupling, 2.4 · (2.1 V/680 Ω) · 10 kΩ.
VOLTS_PER_COUPLING = 2.4 * (2.1 / 680.0) * 1e4


@pytest.fixture(scope="module")
def base(design):
    return build_unit(design, 0, seed=0)


@pytest.fixture(scope="module")
def units(design):
    """Unit 0 with each effect alone at its default, and with all of them."""
    out = {
        name: build_unit(design, 0, seed=0, model_form=ModelForm().only(name))
        for name in ("specular_roughness_deg", "subsurface_mm", "emitter_pattern")
    }
    out["all"] = build_unit(design, 0, seed=0, model_form=ModelForm())
    return out


def _mean_change_mv(unit, base):
    return 1e3 * np.mean(unit.volts(PITCH, ROLL) - base.volts(PITCH, ROLL), axis=0)


def test_defaults_none_and_only():
    default = ModelForm()
    assert default.to_dict() == {
        "specular_roughness_deg": 3.0,
        "subsurface_mm": 0.1,
        "emitter_pattern": "cosine_power",
        "crosstalk_coupling": 1.5e-4,
        "ambient_current_ua": 0.5,
    }
    none = ModelForm.none()
    assert not none.has_optics and none.crosstalk_coupling == none.ambient_current_ua == 0.0
    only = default.only("subsurface_mm")
    assert only == dataclasses.replace(none, subsurface_mm=0.1) and only.has_optics
    assert not default.only("crosstalk_coupling", "ambient_current_ua").has_optics
    with pytest.raises(InputError, match="unknown form error"):
        default.only("gloss")


@pytest.mark.parametrize(
    "bad",
    [
        {"specular_roughness_deg": -1.0},
        {"specular_roughness_deg": 45.0},
        {"subsurface_mm": float("nan")},
        {"emitter_pattern": "lambertian"},
        {"crosstalk_coupling": -1e-4},
        {"ambient_current_ua": float("inf")},
        {"ambient_current_ua": "0.5"},
    ],
)
def test_bad_options_are_refused(bad):
    with pytest.raises(InputError):
        ModelForm(**bad)


def test_extra_coupling_by_hand(design):
    model = design.models[0]
    # I_F = 2.1 V / 680 Ω = 3.0882 mA; G I_F = 7.4118 mA; 0.5 µA / 7.4118 mA = 6.7460e-5
    assert ModelForm.none().only().extra_coupling(model) == 0.0
    assert ModelForm().only("ambient_current_ua").extra_coupling(model) == pytest.approx(
        6.7460e-5, rel=1e-4
    )
    assert ModelForm().extra_coupling(model) == pytest.approx(1.5e-4 + 6.7460e-5, rel=1e-4)


def test_no_form_error_is_todays_unit(design, base):
    same = build_unit(design, 0, seed=0, model_form=ModelForm.none())
    assert np.array_equal(same.coefficients, base.coefficients)
    assert same.design == base.design
    assert base.model_form == ModelForm.none()
    assert np.array_equal(same.volts(PITCH, ROLL), base.volts(PITCH, ROLL))


def test_crosstalk_and_ambient_shift_every_voltage_by_the_hand_value(design, base):
    """More light, lower voltage: −G I_F R2 · Δη · gain, independent of the pose.

    Crosstalk 1.5e-4: 11.118 mV; ambient 0.5 µA: 5.000 mV (0.5 µA × 10 kΩ); before the gain.
    """
    gain = np.asarray(base.mismatch.gain)
    for name, shift_mv in [("crosstalk_coupling", 11.118), ("ambient_current_ua", 5.000)]:
        unit = build_unit(design, 0, seed=0, model_form=ModelForm().only(name))
        assert np.array_equal(unit.coefficients, base.coefficients)  # the optics are untouched
        change = 1e3 * (unit.volts(PITCH, ROLL) - base.volts(PITCH, ROLL))
        assert change == pytest.approx(np.broadcast_to(-shift_mv * gain, change.shape), abs=2e-3)
    assert 1.5e-4 * VOLTS_PER_COUPLING == pytest.approx(11.118e-3, rel=1e-4)


def test_each_optical_effect_alone(units, base):
    """Measured on unit 0 of the default design (docs/model.md, §9, has the table):

    * rough lobe (3°): the specular share's coupling drops by about 0.5 % and f = 0.05, so the
      voltages rise by a fraction of a millivolt;
    * sub-surface spread (0.1 mm): the diffuse light moves away from where the detector sees
      best: 3–5 % less light, the voltages rise by tens of millivolts;
    * cosine-power emitter: a sharper peak of the same width puts more light on the detector:
      the voltages fall by tens of millivolts.
    """
    rough = _mean_change_mv(units["specular_roughness_deg"], base)
    assert np.all((rough > 0.02) & (rough < 1.0))
    spread = _mean_change_mv(units["subsurface_mm"], base)
    assert np.all((spread > 10.0) & (spread < 60.0))
    pattern = _mean_change_mv(units["emitter_pattern"], base)
    assert np.all((pattern < -15.0) & (pattern > -80.0))
    for unit in units.values():
        assert unit.design == base.design  # the geometry and surface draws are the same


def test_all_effects_leave_an_error_no_gain_and_offset_absorb(units, base):
    """A per-sensor gain and offset fitted to the exact-physics unit's voltages leaves more
    than the noise of the form-error unit's voltages unexplained (3–4 mV RMS here, σ_V 2 mV):
    a model-form error, not a calibration constant."""
    v0, v1 = base.volts(PITCH, ROLL), units["all"].volts(PITCH, ROLL)
    sigma = base.design.noise.total_sigma_v
    for k in range(v0.shape[1]):
        a = np.stack([v0[:, k], np.ones_like(v0[:, k])], 1)
        fit, *_ = np.linalg.lstsq(a, v1[:, k], rcond=None)
        residual = np.sqrt(np.mean((v1[:, k] - a @ fit) ** 2))
        assert 0.5 * sigma < residual < 10 * sigma
    assert units["all"].model_form == ModelForm()


def test_shared_surface(design, base):
    """A given (reflectance, specular fraction) replaces the per-unit draw; halving the
    reflectance halves every optical coupling exactly."""
    one = build_unit(design, 0, seed=0, surface=(0.9, 0.2))
    half = build_unit(design, 0, seed=0, surface=(0.45, 0.2))
    other = build_unit(design, 1, seed=0, surface=(0.9, 0.2))
    assert (one.design.reflector.reflectance, one.design.reflector.specular_fraction) == (0.9, 0.2)
    assert other.design.reflector.specular_fraction == 0.2
    assert one.design.reflector.centre_mm == base.design.reflector.centre_mm
    assert one.design.sensors == base.design.sensors
    assert np.allclose(half.coefficients, 0.5 * one.coefficients, rtol=1e-12, atol=1e-18)
    for bad in [(0.9,), (1.2, 0.1), (0.9, -0.1), "matte"]:
        with pytest.raises(InputError, match="surface"):
            build_unit(design, 0, seed=0, surface=bad)
    with pytest.raises(InputError, match="model_form"):
        build_unit(design, 0, seed=0, model_form={"subsurface_mm": 0.1})
