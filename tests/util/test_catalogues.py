"""Catalogues of named entries: order, a name twice, the file named in every message."""

import re
from typing import Literal

import pytest

from reflector_opt.util import _schema as schema
from reflector_opt.util._catalogues import find_named, read_catalogue
from reflector_opt.util._errors import InputError


class _Entry(schema.Table):
    name: str
    size_mm: float


class _Document(schema.Table):
    format: Literal["test@1"]
    item: list[_Entry]


def _build(entry, origin, where):
    if entry.size_mm <= 0:
        raise InputError(f"{where}.size_mm: must be positive")
    return (entry.name, entry.size_mm, origin, where)


def _file(tmp_path, *entries):
    lines = ['format = "test@1"']
    for name, size in entries:
        lines += ["[[item]]", f'name = "{name}"', f"size_mm = {size}"]
    path = tmp_path / "CAT.toml"
    path.write_text("\n".join(lines) + "\n")
    return path


def test_items_in_the_files_order_with_origin_and_place(tmp_path):
    path = _file(tmp_path, ("B", 2.0), ("A", 1.0))
    items = read_catalogue(path, "unused", _Document, "item", _build)
    assert items == (
        ("B", 2.0, str(path), "item[0] (B)"),
        ("A", 1.0, str(path), "item[1] (A)"),
    )


@pytest.mark.parametrize(
    ("entries", "message"),
    [
        ((("A", 1.0), ("A", 2.0)), "CAT.toml: item[1] (A).name: 'A' appears twice"),
        ((("A", 1.0), ("B", -1.0)), "CAT.toml: item[1] (B).size_mm: must be positive"),
    ],
)
def test_one_line_naming_the_file_and_the_entry(tmp_path, entries, message):
    with pytest.raises(InputError, match=re.escape(message)) as err:
        read_catalogue(_file(tmp_path, *entries), "unused", _Document, "item", _build)
    assert "\n" not in str(err.value)


def test_the_shipped_file_is_read_from_the_package():
    def name_only(entry, origin, where):
        return entry.name, origin

    from reflector_opt.design._bearings import SHIPPED, CatalogueDocument

    items = read_catalogue(None, SHIPPED, CatalogueDocument, "bearing", name_only)
    assert items and all(origin == "shipped" for _, origin in items)
    assert len({name for name, _ in items}) == len(items)


class _Item:
    def __init__(self, name):
        self.name = name


def test_find_named_returns_the_item_or_names_the_known_ones():
    items = [_Item("A"), _Item("B")]
    assert find_named(items, "B", "widget") is items[1]
    with pytest.raises(InputError) as err:
        find_named(items, "C", "widget", key="spec.widget", hint="or give a file")
    assert str(err.value) == (
        "spec.widget: unknown widget 'C'; the catalogue has: A, B (or give a file)"
    )
    with pytest.raises(InputError) as err:
        find_named(items, "C", "widget")
    assert str(err.value) == "unknown widget 'C'; the catalogue has: A, B"
