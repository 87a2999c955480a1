"""Declared schemas: one-line messages, published JSON Schemas, defaults, and fuzzed documents.

Every input format's schema is checked the same way: the JSON Schema published in ``docs/``
is the generated one; the schema's defaults are those of the objects it builds; random and
mutated documents give a valid object or an :class:`~reflector_opt.util.errors.InputError`,
never another exception.
"""

import copy
import json
import math
import tomllib
from pathlib import Path
from typing import Annotated

import msgspec
import pytest
from hypothesis import HealthCheck, given, settings
from msgspec import Meta

from reflector_opt.calibration import Eq6
from reflector_opt.calibration import schema as calibration_schema
from reflector_opt.calibration.coefficients import model_from_dict, model_to_dict
from reflector_opt.design import parts
from reflector_opt.design import schema as design_schema
from reflector_opt.design.parts import CadParameters, CadTable
from reflector_opt.model import catalogue, sensor_file
from reflector_opt.model.sensors import NJL5901R_2, SensorModel
from reflector_opt.optimise import schema as optimise_schema
from reflector_opt.optimise.config import OptimiseConfig, parse_config
from reflector_opt.tolerance import Settings, Targets, Tolerances
from reflector_opt.tolerance import schema as tolerance_schema
from reflector_opt.tolerance.config import RunOptions, ToleranceConfig, parse_tolerance_config
from reflector_opt.util import schema
from reflector_opt.util.errors import InputError
from tests.mutation import JUNK, mutated

DOCS = Path(__file__).resolve().parents[2] / "docs"
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

PUBLISHED = {
    "design.schema.json": design_schema,
    "cad-parameters.schema.json": parts,
    "optimise.schema.json": optimise_schema,
    "tolerance.schema.json": tolerance_schema,
    "calibration-model.schema.json": calibration_schema,
    "sensor-model.schema.json": sensor_file,
    "sensor-catalogue.schema.json": catalogue,
}


@pytest.mark.parametrize("name", sorted(PUBLISHED))
def test_the_published_json_schemas_are_the_generated_ones(name):
    """Regenerate with ``python -c "import json; from reflector_opt.optimise import schema;
    print(json.dumps(schema.json_schema(), indent=2, ensure_ascii=False))"
    > docs/optimise.schema.json`` (and likewise for each module of ``PUBLISHED``)."""
    published = json.loads((DOCS / name).read_text(encoding="utf-8"))
    assert published == PUBLISHED[name].json_schema()
    assert published["$schema"] == "https://json-schema.org/draft/2020-12/schema"


def test_the_schema_defaults_are_the_objects_defaults():
    assert CadParameters.from_table(CadTable()) == CadParameters()
    document = tolerance_schema.ToleranceDocument()
    assert RunOptions(**msgspec.structs.asdict(document.run)) == RunOptions()
    assert Settings(**msgspec.structs.asdict(document.settings)) == Settings()
    assert Targets(**msgspec.structs.asdict(document.targets)) == Targets()
    assert Tolerances.from_table(document.tolerances) == Tolerances()
    assert parse_tolerance_config({}) == ToleranceConfig()
    assert parse_config({}) == OptimiseConfig()


# --- the messages ---------------------------------------------------------------------------


class Inner(schema.Table):
    gap_mm: Annotated[float, Meta(gt=0, le=3)] = 1.0
    count: Annotated[int, Meta(ge=1, le=1000)] = 1
    angle_deg: Annotated[
        list[Annotated[float, Meta(ge=-90, le=90)]], Meta(min_length=2, max_length=2)
    ] = msgspec.field(default_factory=lambda: [0.0, 1.0])


class Outer(schema.Table):
    search: Inner = msgspec.field(default_factory=Inner)
    named: dict[str, Inner] = msgspec.field(default_factory=dict)
    label: str | None = None


@pytest.mark.parametrize(
    ("data", "toml", "message"),
    [
        (
            {"search": {"count": 0}},
            True,
            "search.count: expected a whole number from 1 to 1000, got 0",
        ),
        (
            {"search": {"count": 2.5}},
            True,
            "search.count: expected a whole number from 1 to 1000, got 2.5",
        ),
        ({"search": {"gap_mm": 5}}, True, "search.gap_mm: expected a number > 0 and ≤ 3 mm, got 5"),
        (
            {"search": {"gap_mm": math.nan}},
            True,
            "search.gap_mm: expected a number > 0 and ≤ 3 mm, got nan",
        ),
        (
            {"search": {"angle_deg": [0, 95]}},
            True,
            "search.angle_deg[1]: expected a number from -90 to 90°, got 95",
        ),
        (
            {"search": {"angle_deg": [0]}},
            True,
            "search.angle_deg: expected a list of 2 numbers from -90 to 90°, got [0]",
        ),
        (
            {"search": {"speed": 1}},
            True,
            "[search]: unknown key(s) speed; allowed: gap_mm, count, angle_deg",
        ),
        ({"search": {"speed": 1}}, False, "search: unknown key(s) speed; allowed: gap_mm"),
        ({"serch": {}}, True, "unknown key(s) serch; allowed: search, named, label"),
        ({"search": 3}, True, "search: expected a table, got 3"),
        ({"label": 3}, True, "label: expected text, got 3"),
        ({"label": 3}, False, "label: expected text or null, got 3"),
        ({"named": {"a": {}, "b": {"count": -1}}}, True, "named.b.count: expected a whole number"),
        ({"named": {"b": {"x": 1}}}, False, "named.b: unknown key(s) x"),
        ([], False, "document: expected a table, got []"),
    ],
)
def test_messages_name_the_key_path_the_range_and_the_unit(data, toml, message):
    with pytest.raises(InputError) as info:
        schema.convert(data, Outer, toml=toml)
    assert str(info.value).startswith(message)


def test_a_missing_key_and_a_place_in_a_larger_document_are_named():
    class Needs(schema.Table):
        radius_mm: float

    with pytest.raises(InputError, match=r"^cad\.radius_mm: missing key$"):
        schema.convert({}, Needs, where="cad")
    with pytest.raises(InputError, match=r"^cad\.radius_mm: expected a number, got 'x'$"):
        schema.convert({"radius_mm": "x"}, Needs, where="cad")


def test_long_values_are_cut_short():
    with pytest.raises(InputError) as info:
        schema.convert({"search": {"angle_deg": list(range(500))}}, Outer)
    assert str(info.value).endswith("got 500 items")


def test_tolerance_file_messages():
    text = "[tolerances]\ngain = { scale = 0.01, kind = 'lognormal' }\n"
    with pytest.raises(InputError) as info:
        parse_tolerance_config(tomllib.loads(text))
    assert str(info.value) == (
        "tolerances.gain.kind: expected one of 'normal', 'uniform', got 'lognormal'"
    )
    with pytest.raises(InputError, match=r"^run\.sobol_samples: must be 0 \(off\) or a power"):
        parse_tolerance_config({"run": {"sobol_samples": 3}})  # what the schema cannot state


def test_coefficient_file_messages():
    good = model_to_dict(Eq6().fit(*_synthetic()))
    for change, message in (
        (
            lambda d: d["coefficients"].update(pitch_deg=[math.inf] * 8),
            "coefficients.pitch_deg[0]: expected a number",
        ),
        (
            lambda d: d.update(n_samples=-1),
            "n_samples: expected a whole number from 0 to 1000000000000, got -1",
        ),
        (lambda d: d.update(colour=1), "calibration: unknown key(s) colour; allowed: model,"),
        (
            lambda d: d["training"].update(rms_deg={"pitch_deg": 1}),
            "calibration.training.rms_deg.roll_deg: missing key",
        ),
    ):
        document = copy.deepcopy(good)
        change(document)
        with pytest.raises(InputError) as info:
            model_from_dict(document)
        assert message in str(info.value)


def _synthetic(n=60):
    import numpy as np

    rng = np.random.default_rng(0)
    volts = rng.uniform(0.5, 2.5, (n, 2))
    angles = np.column_stack([3 * volts[:, 0] - volts[:, 1], volts[:, 1] ** 2])
    return volts, angles


# --- fuzzed documents -------------------------------------------------------------------------


def _outcome(parse, document, kind):
    try:
        result = parse(document)
    except InputError as exc:
        assert "\n" not in str(exc)
        return
    assert isinstance(result, kind)


FUZZ = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
OPTIMISE = tomllib.loads((EXAMPLES / "optimise.toml").read_text(encoding="utf-8"))
TOLERANCE = {
    "tolerances": {"gain": {"scale": 0.01, "kind": "uniform"}, "centre_offset_mm": 0.05},
    "settings": {"model": "eq6", "fit": "lsq", "calibrate": True},
    "targets": {"rms_deg": 1.0},
    "run": {"samples": 10, "sobol_samples": 0},
}


@FUZZ
@given(mutated(OPTIMISE))
def test_any_optimiser_config_parses_or_is_an_input_error(document):
    _outcome(parse_config, document, OptimiseConfig)


@FUZZ
@given(mutated(TOLERANCE))
def test_any_tolerance_config_parses_or_is_an_input_error(document):
    _outcome(parse_tolerance_config, document, ToleranceConfig)


@FUZZ
@given(mutated({"clearance_mm": 0.3, "tendon_azimuth_deg": 40.0}))
def test_any_cad_table_parses_or_is_an_input_error(document):
    _outcome(CadParameters.from_dict, document, CadParameters)
    _outcome(SensorModel.from_dict, document, SensorModel)


@FUZZ
@given(mutated(model_to_dict(Eq6().fit(*_synthetic()))))
def test_any_coefficient_document_parses_or_is_an_input_error(document):
    _outcome(model_from_dict, document, Eq6)


@FUZZ
@given(mutated(NJL5901R_2.to_dict()))
def test_any_sensor_model_parses_or_is_an_input_error(document):
    _outcome(SensorModel.from_dict, document, SensorModel)


@settings(max_examples=100, deadline=None)
@given(JUNK)
def test_junk_is_an_input_error_or_a_default(document):
    _outcome(parse_config, document, OptimiseConfig)
    _outcome(parse_tolerance_config, document, ToleranceConfig)
    _outcome(model_from_dict, document, Eq6)
    _outcome(CadParameters.from_dict, document, CadParameters)
    _outcome(SensorModel.from_dict, document, SensorModel)


def test_a_key_that_cannot_be_named_is_shown_as_any_key():
    """msgspec leaves out dict keys; a table at the root has no field to retry its entries by."""
    with pytest.raises(InputError) as info:
        schema.convert({"a": {"count": "q"}}, dict[str, Inner])
    assert str(info.value) == "[...].count: expected a whole number from 1 to 1000"


def test_numpy_numbers_from_library_callers_are_read_as_numbers():
    import numpy as np

    document = schema.convert({"search": {"gap_mm": np.float64(0.5), "count": np.int64(3)}}, Outer)
    assert document.search.gap_mm == 0.5 and type(document.search.count) is int
    with pytest.raises(InputError, match=r"^search\.count: expected a whole number"):
        schema.convert({"search": {"count": np.float64(0.5)}}, Outer)
