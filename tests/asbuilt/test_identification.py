"""Identification against built units whose physics the fit model lacks.

The units are drawn by the tolerance model and built with the exact reference extended by a
rough specular lobe, sub-surface spread, a cosine-power emitter, in-package crosstalk and
ambient light (:class:`reflector_opt.tolerance._model_form.ModelForm`): the fast model the
identification fits has none of these, so what it finds is checked against a truth it did
not make. Their angle reference is exact (its noise aside) and the identification is told
so (``reference_std=None``, ``--reference-zero fixed``); tests/asbuilt/test_reference.py
identifies units recorded by a reference that is not.

The claims are about the distribution of built units, not about one batch: each is checked
on two batches of three units (seeds 11 and 12), and its bound was set from the same claim
measured on eight batches (seeds 11–18, 24 units, the present draws), with the rate at which
a pair of batches would fail it given in the test. A bound that held on batch 11 alone
(every distance error halved, every geometric error within 3 std) failed on other batches.
"""

import numpy as np
import pytest

from reflector_opt.asbuilt._identification import identify
from reflector_opt.asbuilt._parameters import SUBSURFACE_NOMINAL_MM, true_deviations
from reflector_opt.calibration._plans import make_plan
from reflector_opt.design import default_design
from reflector_opt.model._geometry import sensor_distance
from reflector_opt.tolerance._builtunit import build_unit, built_unit_protocol, crlb_floor_deg
from reflector_opt.tolerance._model_form import ModelForm
from reflector_opt.util._errors import FitError, InputError

SURFACE = (0.9, 0.05)
SEEDS = (11, 12)  # two batches
N_UNITS = 3  # units per batch

#: The reference anchored: its readings are the true poses.
ANCHORED = {"reference_std": None}


@pytest.fixture(scope="module")
def batch():
    """Two batches of three built units with model-form error, their calibration on 200
    Sobol poses."""
    design = default_design()
    plan = make_plan(design.workspace, "sobol", 200, seed=0)
    units, protocols = [], []
    for seed in SEEDS:
        for index in range(N_UNITS):
            unit = build_unit(design, index, seed=seed, model_form=ModelForm(), surface=SURFACE)
            units.append(unit)
            protocols.append(built_unit_protocol(unit, plan, n_validation=1500, seed=index))
    return design, units, protocols


@pytest.fixture(scope="module")
def identified(batch):
    """Each unit identified on its own."""
    design, _, protocols = batch
    return [
        identify(
            design,
            {"u": (p.calibration.volts, p.calibration.angles_deg)},
            profiles=True,
            **ANCHORED,
        )
        for p in protocols
    ]


def _truth(design, unit, layout):
    """The unit's true parameter vector in ``layout``'s order; the model-form amplitudes,
    which have no literal truth, NaN."""
    spread = ModelForm().subsurface_mm - SUBSURFACE_NOMINAL_MM
    return np.r_[
        SURFACE[0] - design.reflector.reflectance,
        SURFACE[1] - design.reflector.specular_fraction,
        [spread] * (len(layout.shared_names) - 2),
        true_deviations(design, unit.design, unit.mismatch),
        [np.nan] * len(layout.model_form_names),
    ]


#: Parameters whose "truth" the model-form error redefines: the gains, offsets and beam
#: width take up the emitter pattern, the crosstalk and the ambient light, and the
#: reflectance the overall level; they have no literal value to compare with.
_EFFECTIVE = ("gain", "offset_v", "divergence_deg", "reflectance")


@pytest.mark.slow
def test_what_is_called_determined_holds_the_truth(batch, identified):
    """The 90 % intervals of determined geometry cover the truth: 76 of 86 (88 %) on eight
    batches, none off by 3.5 std; a pair of batches covers under 70 % with probability
    0.8 % (binomial, 21 parameters at 88 %)."""
    design, units, _ = batch
    hits, count = 0, 0
    for unit, result in zip(units, identified, strict=True):
        truth = _truth(design, unit, result.layout)
        names = result.layout.names()
        for j, name in enumerate(names):
            row = result.std[j] / result.layout.prior_std()[j] if result.std[j] else 1.0
            if row > 0.5 or name.endswith(_EFFECTIVE) or not np.isfinite(truth[j]):
                continue
            z = (result.x[j] - truth[j]) / result.std[j]
            assert abs(z) < 3.5, f"{name}: error {z:.1f} std"
            hits += abs(z) <= 1.645
            count += 1
    assert count >= 2 * len(units)  # some geometry is determined in every unit
    assert hits / count >= 0.7


@pytest.mark.slow
def test_the_as_built_distance_is_closer_than_the_design_and_honest(batch, identified):
    """The identified distances are off by about half the design's: the RMS over units and
    both sensors of the identified distance's error is 0.52 of the design's on eight batches
    (seeds 11–18, 24 units); a pair of batches gives more than 0.8 with probability under
    10⁻³ (resampling those units). Unit by unit it is not always halved: where the design
    was 0.05 mm or more off, halved in 13 of 19 cases ("halved on every unit" held on batch
    11 and failed on four of eight), and a pair of batches can hold one such case or none.
    The error over its reported std: mean square 0.90 on 48 cases, largest 2.4."""
    design, units, _ = batch
    pitch, roll = np.meshgrid(np.linspace(-15, 15, 16), np.linspace(-15, 15, 16))
    nominal = sensor_distance(
        design.positions_mm, design.reflector.centre_mm, design.reflector.radius_mm, pitch, roll
    )
    errors, befores, honest = [], [], []
    for unit, result in zip(units, identified, strict=True):
        built = unit.design
        true = sensor_distance(
            built.positions_mm, built.reflector.centre_mm, built.reflector.radius_mm, pitch, roll
        )
        found, std = result.distance_mm(0, pitch, roll)
        for k in range(2):
            errors.append(np.sqrt(np.mean((found - true)[..., k] ** 2)))
            befores.append(np.sqrt(np.mean((nominal - true)[..., k] ** 2)))
            honest.append(errors[-1] / np.sqrt(np.mean(std[..., k] ** 2)))
    assert np.max(honest) < 4 and np.mean(np.square(honest)) < 2.5
    assert np.sqrt(np.sum(np.square(errors)) / np.sum(np.square(befores))) < 0.8


@pytest.mark.slow
def test_the_specular_fraction_is_bracketed_or_called_undetermined(identified):
    for result in identified:
        row = result.shared_parameters()["specular_fraction"]
        interval = row["interval_90"]
        assert not row["identifiable"] or interval["low"] <= SURFACE[1] <= interval["high"]
        assert interval["low"] <= SURFACE[1] <= interval["high"]


@pytest.mark.slow
def test_angles_through_the_identified_unit_reach_the_cramer_rao_floor(batch, identified):
    _, units, protocols = batch
    for unit, protocol, result in zip(units, protocols, identified, strict=True):
        model = result.estimator(0)  # the unit as built, its spread and model-form terms
        validation = protocol.validation
        error = model.predict(validation.volts) - validation.angles_deg
        rms = np.sqrt(np.mean(error**2, axis=0))
        assert np.all(rms <= 1.2 * crlb_floor_deg(unit, validation.angles_deg))


@pytest.mark.slow
def test_a_pooled_batch_shares_its_surface_and_agrees_with_single_fits(batch, identified):
    design, _, protocols = batch  # the first batch (seed 11)
    samples = {
        str(i): (p.calibration.volts, p.calibration.angles_deg)
        for i, p in enumerate(protocols[:N_UNITS])
    }
    pooled = identify(design, samples, profiles=False, **ANCHORED)
    assert pooled.labels == ("0", "1", "2")
    # the surface and its spread shared; per unit its block and its model-form amplitudes
    per_unit = pooled.layout.block_size + len(pooled.layout.model_form_names)
    assert pooled.layout.size == 3 + N_UNITS * per_unit
    # three units' gains tell the shared reflectance better than one unit's do
    assert pooled.std[0] < min(result.std[0] for result in identified[:N_UNITS])
    pitch, roll = np.meshgrid(np.linspace(-15, 15, 7), np.linspace(-15, 15, 7))
    for u, single in enumerate(identified[:N_UNITS]):
        mine, std = pooled.distance_mm(u, pitch, roll)
        theirs, _ = single.distance_mm(0, pitch, roll)
        assert np.sqrt(np.mean((mine - theirs) ** 2)) < 2 * np.sqrt(np.mean(std**2))


# --- bad input ------------------------------------------------------------------------------


def test_fewer_samples_than_parameters_are_refused(batch):
    design, _, protocols = batch
    c = protocols[0].calibration
    with pytest.raises(InputError, match="fewer than the 25 as-built parameters"):
        identify(design, {"7": (c.volts[:9], c.angles_deg[:9])}, **ANCHORED)
    with pytest.raises(InputError, match="fewer than the 28 as-built parameters"):
        identify(design, {"7": (c.volts[:9], c.angles_deg[:9])})  # and the reference's three


def test_poses_outside_the_workspace_are_refused(batch):
    design, _, protocols = batch
    c = protocols[0].calibration
    angles = c.angles_deg.copy()
    angles[3] = [40.0, 0.0]
    with pytest.raises(InputError, match="outside the design's workspace"):
        identify(design, {"a": (c.volts, angles)})


def test_data_from_another_design_are_refused(batch):
    design, _, protocols = batch
    c = protocols[0].calibration
    with pytest.raises(FitError, match="do not fit this design"):
        identify(design, {"a": (c.volts[:, ::-1] * 0.6, c.angles_deg)}, profiles=False)


@pytest.mark.parametrize(
    "samples, message",
    [
        ({}, "hold no unit"),
        ({"a": (np.full((30, 2), np.nan), np.zeros((30, 2)))}, "must be finite"),
        ({"a": (np.zeros((30, 3)), np.zeros((30, 2)))}, "3 voltages per sample"),
        ({"a": (np.zeros((30, 2)), np.zeros((29, 2)))}, r"\(n, 2\) angles"),
    ],
)
def test_malformed_samples_are_refused(design, samples, message):
    with pytest.raises(InputError, match=message):
        identify(design, samples)


_GEOMETRY = ("_mm", "_deg")
_NUISANCE = ("divergence_deg", "source_radius_mm")


@pytest.mark.slow
def test_every_geometric_interval_is_honest_under_model_form_error(batch, identified):
    """Determined or not, the geometric parameters' 90 % intervals cover their truth: 331 of
    360 (92 %) on eight batches, the largest error 3.8 std (batch 14; "every error within 3
    std" held on batch 11 and failed there). A pair of batches (90 parameters) covers under
    80 % with probability 10⁻⁴."""
    design, units, _ = batch
    z = []
    for unit, result in zip(units, identified, strict=True):
        truth = _truth(design, unit, result.layout)
        for j, name in enumerate(result.layout.names()):
            if name.endswith(_GEOMETRY) and not name.endswith(_NUISANCE) and "form_" not in name:
                z.append(abs(result.x[j] - truth[j]) / result.std[j])
    assert np.max(z) < 4.5
    assert np.mean(np.array(z) <= 1.645) >= 0.8


@pytest.mark.slow
def test_the_statistical_covariance_alone_is_overconfident_about_the_centre_height(batch):
    """What the model-form term is for: without it, the reflector centre's height is pulled
    upwards by the physics the model lacks by more than its statistical std allows. On eight
    batches (seeds 11–18, 24 units) its error averages +19 ± 5 µm, 0.89 std (sd 1.12; mean
    square 2.0 std², 79 % of the 90 % intervals cover the truth); with the term +8 ± 5 µm
    (0.35 std, 92 % covered). "The worst of three units is off by more than 1.645 std" held
    on batch 11 and failed on batches 12, 13, 16 and 18. Six units average a signed error of
    0 std or less with probability about 3 %."""
    design, units, protocols = batch
    z = []
    for unit, protocol in zip(units, protocols, strict=True):
        c = protocol.calibration
        result = identify(
            design, {"u": (c.volts, c.angles_deg)}, profiles=False, model_form=None, **ANCHORED
        )
        j = result.layout.names().index("unit 1: reflector_centre_z_mm")
        z.append((result.x[j] - _truth(design, unit, result.layout)[j]) / result.std[j])
    assert np.mean(z) > 0, z
