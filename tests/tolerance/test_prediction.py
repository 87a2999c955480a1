"""A design's predicted calibration errors, against built units."""

import dataclasses

import pytest

from reflector_opt.tolerance._prediction import predicted_performance


@pytest.fixture(scope="module")
def predicted(design):
    return predicted_performance(design, seed=0)


def test_recommended_form_reaches_the_floor_and_beats_eq6(predicted):
    c = predicted.calibration
    assert c.protocol["n_units"] == 4
    rec, eq6 = c.recommended, c.eq6
    assert rec.n_calibration <= 200
    for axis in ("pitch", "roll"):
        assert 1.0 <= rec.floor_ratio[axis] <= 1.2
        assert rec.rms_deg[axis] < eq6.rms_deg[axis] / 3
        assert c.floor_rms_deg[axis] < rec.rms_deg[axis]
    assert all(name.startswith("poly") for name in rec.models)
    blocks = predicted.to_dict()["calibration"]  # the JSON: the same figures under the names
    assert blocks["recommended"]["rms_deg"] == {
        "pitch": rec.rms_deg.pitch,
        "roll": rec.rms_deg.roll,
    }
    assert list(blocks) == ["protocol", "floor_rms_deg", "eq5", "eq6", "recommended"]


def test_segment_is_re_predicted_with_the_recommended_form(predicted):
    paper, ours = predicted.segment, predicted.segment_recommended
    assert paper["model"] == "eq6" and ours["model"] == "recommended"
    for axis in ("pitch", "roll"):
        assert ours[axis]["predicted"]["rms_deg"] < paper[axis]["predicted"]["rms_deg"]
        assert ours[axis]["paper"] == paper[axis]["paper"]


def test_designs_without_two_sensors_are_not_predicted(design):
    extra = dataclasses.replace(design.sensors[0], name="S3")
    three = design.replace(sensors=(*design.sensors, extra))
    out = predicted_performance(three)
    assert out.to_dict() == {"calibration": None, "segment": None, "segment_recommended": None}


def test_a_raster_too_coarse_for_the_papers_models_names_the_step(design):
    """A 30° step over ±15° (a 2 × 2 raster) ended in 'eq6 lsq fit: 4 samples are fewer
    than the 8 coefficients per angle', naming neither the design nor the key."""
    from reflector_opt.design._components import Workspace
    from reflector_opt.util._errors import InputError

    coarse = design.replace(workspace=Workspace((-15.0, 15.0), (-15.0, 15.0), 30.0))
    with pytest.raises(
        InputError,
        match=r"^workspace\.step_deg: 30° makes a calibration raster of 4 poses, fewer than "
        r"the 8 coefficients",
    ):
        predicted_performance(coarse)
