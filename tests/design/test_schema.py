"""The declared schema of design.json: published, truthful about the defaults, clear messages."""

import json
from pathlib import Path

import msgspec
import pytest

from reflector_opt.design import default_design, load_design
from reflector_opt.design._components import Mechanics, Noise, Reflector, Workspace
from reflector_opt.design._schema import (
    DesignDocument,
    MechanicsBlock,
    NoiseBlock,
    WorkspaceBlock,
    check_document,
    json_schema,
)
from reflector_opt.util._errors import InputError

PUBLISHED = Path(__file__).resolve().parents[2] / "docs" / "design.schema.json"


def test_the_published_json_schema_is_the_generated_one():
    """Regenerate with ``python -c "import json; from reflector_opt.design._schema import
    json_schema; print(json.dumps(json_schema(), indent=2, ensure_ascii=False))"
    > docs/design.schema.json``."""
    assert json.loads(PUBLISHED.read_text(encoding="utf-8")) == json_schema()


def test_the_schema_defaults_are_the_designs():
    assert msgspec.to_builtins(MechanicsBlock()) == Mechanics().to_dict()
    assert msgspec.to_builtins(NoiseBlock()) == Noise().to_dict()
    workspace = msgspec.to_builtins(WorkspaceBlock(pitch_deg=[-15.0, 15.0], roll_deg=[-15, 15]))
    assert workspace == Workspace().to_dict()
    document = check_document(
        {
            "reflector": {"radius_mm": 9, "centre_mm": [0, 0, -1.5]},
            "sensors": [],
            "workspace": Workspace().to_dict(),
        }
    )
    assert document.reflector.inner_radius_mm == Reflector().inner_radius_mm
    assert document.reflector.reflectance == Reflector().reflectance


def test_a_saved_design_conforms_to_the_schema(tmp_path):
    design = default_design()
    design.save(tmp_path / "design.json")
    data = json.loads((tmp_path / "design.json").read_text())
    document = check_document(data)
    assert isinstance(document, DesignDocument)
    assert msgspec.to_builtins(document)["reflector"] == data["reflector"]
    assert load_design(tmp_path / "design.json").reflector == design.reflector


def _mutated(change):
    data = default_design().to_dict()
    change(data)
    return data


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (
            lambda d: d["reflector"].update(radius_mm=2000),
            "reflector.radius_mm: expected a number > 0 and ≤ 1000 mm, got 2000",
        ),
        (
            lambda d: d["workspace"].update(pitch_deg=[-95, 3]),
            "workspace.pitch_deg[0]: expected a number > -90 and < 90°, got -95",
        ),
        (
            lambda d: d["noise"].update(sigma_v=-1),
            "noise.sigma_v: expected a number from 0 to 1000 V, got -1",
        ),
        (
            lambda d: d["mechanics"].update(n_units=2.5),
            "mechanics.n_units: expected a whole number from 1 to 1000, got 2.5",
        ),
        (lambda d: d["reflector"].pop("radius_mm"), "reflector.radius_mm: missing key"),
        (
            lambda d: d["sensors"][0].update(colour=1),
            "sensors[0]: unknown key(s) colour; allowed: model, position_mm, axis, name, "
            "detector_direction",
        ),
        (
            lambda d: d["sensors"][0].update(name=3),
            "sensors[0].name: expected text or null, got 3",
        ),
        (
            lambda d: d.update(format="x"),
            "format: expected one of 'reflector-opt/design@1', got 'x'",
        ),
        (
            lambda d: d.update(sensor_models={"a": 1}),
            "sensor_models.a: expected a table, got 1",
        ),
    ],
)
def test_schema_messages_name_the_key_the_range_and_the_unit(change, message):
    with pytest.raises(InputError) as info:
        check_document(_mutated(change))
    assert str(info.value) == message


def test_what_only_the_schema_catches_is_refused_on_loading(tmp_path):
    path = tmp_path / "design.json"
    path.write_text(json.dumps(_mutated(lambda d: d["sensors"][0].update(name=3))))
    with pytest.raises(InputError, match=r"sensors\[0\]\.name: expected text"):
        load_design(path)
