"""Declared schemas: one-line messages, published JSON Schemas, defaults, and fuzzed documents.

Every input format's schema is checked the same way: the JSON Schema published in ``docs/``
is the generated one; the schema's defaults are those of the objects it builds; random and
mutated documents give a valid object or an :class:`~reflector_opt.util._errors.InputError`,
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
from hypothesis import strategies as st
from msgspec import Meta

from reflector_opt.asbuilt import _asbuiltfile as asbuiltfile
from reflector_opt.calibration import Eq6
from reflector_opt.calibration import _schema as calibration_schema
from reflector_opt.calibration._coefficients import model_from_dict, model_to_dict
from reflector_opt.design import _conditions as conditions
from reflector_opt.design import _parts as parts
from reflector_opt.design import _schema as design_schema
from reflector_opt.design._parts import CadParameters, CadTable
from reflector_opt.model import _catalogue as catalogue
from reflector_opt.model import _sensor_file as sensor_file
from reflector_opt.model._sensors import NJL5901R_2, SensorModel
from reflector_opt.optimiser import _schema as optimise_schema
from reflector_opt.optimiser._config import OptimiseConfig, parse_config
from reflector_opt.tolerance import Settings, Targets, Tolerances
from reflector_opt.tolerance import _schema as tolerance_schema
from reflector_opt.tolerance._config import RunOptions, ToleranceConfig, parse_tolerance_config
from reflector_opt.util import _schema as schema
from reflector_opt.util._errors import InputError
from tests.mutation import JUNK, check_contract, mutation, single_edits

DOCS = Path(__file__).resolve().parents[2] / "docs"
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

PUBLISHED = {
    "as-built.schema.json": asbuiltfile,
    "design.schema.json": design_schema,
    "cad-parameters.schema.json": parts,
    "optimise.schema.json": optimise_schema,
    "tolerance.schema.json": tolerance_schema,
    "calibration-model.schema.json": calibration_schema,
    "sensor-model.schema.json": sensor_file,
    "sensor-catalogue.schema.json": catalogue,
    "conditions.schema.json": conditions,
}


@pytest.mark.parametrize("name", sorted(PUBLISHED))
def test_the_published_json_schemas_are_the_generated_ones(name):
    """Regenerate with ``python -c "import json; from reflector_opt.optimiser import schema;
    print(json.dumps(schema.json_schema(), indent=2, ensure_ascii=False))"
    > docs/optimise.schema.json`` (and likewise for each module of ``PUBLISHED``)."""
    published = json.loads((DOCS / name).read_text(encoding="utf-8"))
    assert published == PUBLISHED[name].json_schema()
    assert published["$schema"] == "https://json-schema.org/draft/2020-12/schema"


def test_a_published_schema_does_not_depend_on_how_msgspec_copies_docstrings(monkeypatch):
    """msgspec 0.18–0.19 copy a docstring's indentation into ``description``, 0.23 cleans it:
    the published schema is the same either way."""

    class Block(schema.Table):
        """One block.

        Attributes
        ----------
        gap_mm : float
            The gap, mm.
        """

        gap_mm: float = 1.0

    cleaned = schema.json_schema(Block, "block")
    generate = msgspec.json.schema

    def indented(kind):
        generated = generate(kind)
        for definition in generated["$defs"].values():
            definition["description"] = Block.__doc__  # as the older releases copy it
        return generated

    monkeypatch.setattr(msgspec.json, "schema", indented)
    assert schema.json_schema(Block, "block") == cleaned
    description = cleaned["$defs"]["Block"]["description"]
    assert description.splitlines()[2:5] == ["Attributes", "----------", "gap_mm : float"]


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


FUZZ = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
OPTIMISE = tomllib.loads((EXAMPLES / "optimise.toml").read_text(encoding="utf-8"))
TOLERANCE = {
    "tolerances": {"gain": {"scale": 0.01, "kind": "uniform"}, "centre_offset_mm": 0.05},
    "settings": {"model": "eq6", "fit": "lsq", "calibrate": True},
    "targets": {"rms_deg": 1.0},
    "run": {"samples": 10, "sobol_samples": 0},
}
CAD = {"clearance_mm": 0.3, "tendon_azimuth_deg": 40.0}
EQ6 = model_to_dict(Eq6().fit(*_synthetic()))


def _cad_round_trip(cad):
    return CadParameters.from_dict(cad.to_dict())


def _sensor_round_trip(model):
    return SensorModel.from_dict(model.to_dict())


def _eq6_round_trip(model):
    again = model_from_dict(model_to_dict(model))
    assert model_to_dict(again) == model_to_dict(model)
    return model


#: The optimiser config's checks of relations between sections, named by what they judge: the
#: printed wall, the distance window, the search bounds that follow from the constraints.
OPTIMISE_RELATIONS = ("wall: ", "distance window: ")
#: The readers, a valid document of each, and how an accepted result is written and read back.
READERS = {
    "optimise": (parse_config, OPTIMISE, None, OptimiseConfig),
    "tolerance": (parse_tolerance_config, TOLERANCE, None, ToleranceConfig),
    "cad": (CadParameters.from_dict, CAD, _cad_round_trip, CadParameters),
    "eq6": (model_from_dict, EQ6, _eq6_round_trip, Eq6),
    "sensor": (SensorModel.from_dict, NJL5901R_2.to_dict(), _sensor_round_trip, SensorModel),
}


@pytest.mark.parametrize("name", READERS)
def test_the_valid_documents_are_accepted(name):
    read, document, round_trip, kind = READERS[name]
    assert isinstance(check_contract(read, copy.deepcopy(document), [], round_trip), kind)


@pytest.mark.parametrize("name", READERS)
@FUZZ
@given(data=st.data())
def test_a_mutated_document_is_refused_naming_its_key_or_read_to_finite_values(name, data):
    read, document, round_trip, kind = READERS[name]
    mutated_document, touched = data.draw(mutation(document))
    relations = OPTIMISE_RELATIONS if name == "optimise" else ()
    result = check_contract(read, mutated_document, touched, round_trip, relations)
    assert result is None or isinstance(result, kind)


@pytest.mark.parametrize("name", READERS)
def test_every_single_bad_value_is_refused_naming_its_key_or_read_to_finite_values(name):
    read, document, round_trip, kind = READERS[name]
    relations = OPTIMISE_RELATIONS if name == "optimise" else ()
    for edited, touched in single_edits(document):
        result = check_contract(read, edited, touched, round_trip, relations)
        assert result is None or isinstance(result, kind)


@settings(max_examples=100, deadline=None)
@given(JUNK)
def test_junk_is_refused_in_one_line_or_read_to_finite_values(document):
    for read, _, round_trip, kind in READERS.values():
        result = check_contract(read, document, [], round_trip)
        assert result is None or isinstance(result, kind)


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
