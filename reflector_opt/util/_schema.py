"""Declared schemas of the input files, checked with msgspec, with one-line messages.

Every input format (``design.json``, the TOML configs, the coefficient JSON, sensor files)
declares its keys as :class:`msgspec.Struct` classes in the layer of the object it describes:
each key's type, range (as :class:`msgspec.Meta` bounds) and default. :func:`convert` checks a
parsed document against such a schema and turns the first failure into an
:class:`~reflector_opt.util._errors.InputError` that names the key path, the allowed range and
the unit (read from the key's suffix: ``_mm``, ``_mm2``, ``_deg``, ``_v``, ``_a``, ``_ohm``), for
example
``search.popsize: expected a whole number from 1 to 1000, got 0``. :func:`json_schema` gives
the JSON Schema published in ``docs/`` for each format. What a schema cannot state — relations
between keys, names looked up in a catalogue — is checked by the object built from it.
"""

import inspect
import json
import math
import re
import typing

import msgspec
import msgspec.inspect as mi

from reflector_opt.util._errors import InputError


class Table(msgspec.Struct, forbid_unknown_fields=True, omit_defaults=False):
    """Base of a schema block: unknown keys are refused."""


_AT = re.compile(r"^(?P<what>.*?)(?: - at `\$(?P<path>[^`]*)`)?$", re.DOTALL)
_SEGMENT = re.compile(r"\.([^.\[]+)|\[(\d+|\.\.\.)\]")
_INDEX = re.compile(r"\[\d+\]$")
_UNITS = (
    ("_mm", " mm"),
    ("_mm2", " mm²"),
    ("_deg", "°"),
    ("_v", " V"),
    ("_a", " A"),
    ("_ohm", " Ω"),
)
_KINDS = (
    (mi.BoolType, "true or false"),
    (mi.IntType, "a whole number"),
    (mi.FloatType, "a number"),
    (mi.StrType, "text"),
    (mi.ListType | mi.VarTupleType | mi.TupleType, "a list"),
    (mi.DictType, "a table"),
    (mi.StructType, "a table"),
    (mi.NoneType, "null"),
)


def json_schema(kind, title):
    """The JSON Schema (draft 2020-12) of a schema class.

    Parameters
    ----------
    kind : type or tuple of type
        A :class:`Table` subclass, or several: the document is any one of them.
    title : str
        The document's name, e.g. ``"optimise.toml"``.

    Returns
    -------
    dict
    """
    if isinstance(kind, tuple):
        refs, defs = msgspec.json.schema_components(kind)
        schema = {"anyOf": list(refs), "$defs": defs}
    else:
        schema = msgspec.json.schema(kind)
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = title
    return _clean_descriptions(schema)


def _clean_descriptions(node):
    """``node`` as every msgspec release within the bounds writes it: each ``description``
    cleaned as :func:`inspect.cleandoc` cleans a docstring (0.18-0.19 copy the indentation,
    0.23 cleans it) and each ``anyOf`` in one order (the releases order ``null`` differently;
    the order means nothing in JSON Schema)."""
    if isinstance(node, dict):
        cleaned = {
            key: inspect.cleandoc(value)
            if key == "description" and isinstance(value, str)
            else _clean_descriptions(value)
            for key, value in node.items()
        }
        if isinstance(cleaned.get("anyOf"), list):
            cleaned["anyOf"] = sorted(cleaned["anyOf"], key=lambda s: json.dumps(s, sort_keys=True))
        return cleaned
    if isinstance(node, list):
        return [_clean_descriptions(value) for value in node]
    return node


def convert(data, kind, toml=False, where="", strict=True, names=None):
    """Check a parsed document against a schema.

    Parameters
    ----------
    data : object
        The parsed JSON or TOML.
    kind : type
        A :class:`Table` subclass.
    toml : bool, optional
        Name tables as TOML does (``[search]``, ``unknown section(s)``).
    where : str, optional
        The place of the document's root in a larger one (``"cad"``,
        ``"lab.json: units[0].model"``), put before the key paths.
    strict : bool, optional
        False to take a number or a choice as text.
    names : mapping of str to str, optional
        The top-level keys as the caller spells them (a run's options: ``{"starts":
        "--starts"}``). A message about such a key names it so, an item of its list by its
        position (``--sizes: value 1: …``), says ``needed`` where the key is missing and
        offers no null (leaving the key out is how it is left out).

    Returns
    -------
    kind
        With the defaults filled in.

    Raises
    ------
    InputError
        Naming the key path of the first failure, the allowed range and the unit.
    """
    try:
        return msgspec.convert(data, kind, strict=strict)
    except msgspec.ValidationError as exc:
        if "got `numpy." in str(exc):  # numpy scalars from library callers: as Python numbers
            data = msgspec.to_builtins(data, enc_hook=_python_scalar)
            return convert(data, kind, toml, where, strict, names)
        base = (_Written(where),) if where else ()
        message = _message(str(exc), data, mi.type_info(kind), toml, base, names or {})
        raise InputError(message) from None


def _python_scalar(value):
    import numpy as np  # reached only for numpy values, so the parsers' imports stay light

    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"not a number: {type(value).__name__}")


def _plain(info):
    while isinstance(info, mi.Metadata):
        info = info.type
    return info


def _step(info, segment):
    """The type one path segment below ``info``."""
    sequence = mi.ListType | mi.VarTupleType | mi.TupleType
    info = _member(info, sequence if isinstance(segment, int) else mi.StructType | mi.DictType)
    if isinstance(info, mi.StructType):
        return next(f.type for f in info.fields if f.encode_name == segment)
    if isinstance(info, mi.DictType):
        return info.value_type
    if isinstance(info, mi.TupleType):
        return info.item_types[segment]
    return info.item_type


def _member(info, kind):
    """``info``, or the member of that union which is of ``kind``."""
    info = _plain(info)
    if isinstance(info, mi.UnionType):
        return next(_plain(t) for t in info.types if isinstance(_plain(t), kind))
    return info


def _segments(path):
    return [
        name or (index if index == "..." else int(index)) for name, index in _SEGMENT.findall(path)
    ]


def _join(segments, names=()):
    """The key path of ``segments``; its first key spelled as ``names`` says, if named there."""
    named = bool(segments) and segments[0] in names
    text = names[segments[0]] if named else ""
    for position, segment in enumerate(segments[named:], named):
        if named and position == 1 and isinstance(segment, int):
            text += f": value {segment + 1}"
        elif isinstance(segment, int) or segment == "...":
            text += f"[{segment}]"
        else:
            text += f".{_name(segment)}"
    return text.lstrip(".")


class _Written(str):
    """The caller's name of a document's place, shown as given."""


def _name(key):
    """A key as written, or quoted when it is not a plain word (empty, spaces, newlines)."""
    return key if isinstance(key, _Written) or re.fullmatch(r"[\w-]+", key) else repr(key)


def _message(text, data, info, toml, base, names):
    match = _AT.match(text)
    what, segments = match["what"], _segments(match["path"] or "")
    if "..." in segments:
        located = _locate_key(segments, data, info, toml, base, names)
        if located:
            return located
    return _format(what, segments, data, info, toml, base, names)


def _locate_key(segments, data, info, toml, base, names):
    """Retry the entries of the table whose key msgspec leaves out, to name that key."""
    cut = segments.index("...")
    if cut == 0:
        return None
    parent = _at(info, segments[: cut - 1])
    if not isinstance(parent, mi.StructType):
        return None
    hint = typing.get_type_hints(parent.cls, include_extras=True)[segments[cut - 1]]
    while typing.get_origin(hint) is typing.Annotated:
        hint = typing.get_args(hint)[0]
    item = typing.get_args(hint)[1]
    for key, entry in _value(data, segments[:cut]).items():
        try:
            msgspec.convert(entry, item)
        except msgspec.ValidationError as exc:
            return _message(
                str(exc), entry, mi.type_info(item), toml, (*base, *segments[:cut], key), names
            )
    return None


def _format(what, segments, data, info, toml, base, names):
    keys = [*base, *segments]
    path, named = _join(keys), bool(keys) and keys[0] in names
    field = re.search(r"field `(.*)`$", what, re.DOTALL)
    if what.startswith("Object missing required field"):
        missing = [*keys, field[1]]
        return f"{_join(missing, names)}: {'needed' if missing[0] in names else 'missing key'}"
    if what.startswith("Object contains unknown field"):
        table = _member(_at(info, segments), mi.StructType)
        allowed = "allowed: " + ", ".join(f.encode_name for f in table.fields)
        if not path:
            tables = all(
                isinstance(_plain(f.type), mi.StructType | mi.DictType) for f in table.fields
            )
            return (
                f"unknown {'section' if toml and tables else 'key'}(s) {_name(field[1])}; {allowed}"
            )
        where = f"[{path}]" if toml else path
        return f"{where}: unknown key(s) {_name(field[1])}; {allowed}"
    kind = _expected(_at(info, segments), path, toml or named)  # a named key: left out, not null
    expected = f"{_join(keys, names) or 'document'}: expected {kind}"
    if "..." in segments:  # a key msgspec did not name and no retry found
        return expected
    return f"{expected}, got {_shown(_value(data, segments))}"


def _at(info, segments):
    for segment in segments:
        info = _step(info, segment)
    return _plain(info)


def _value(data, segments):
    for segment in segments:
        data = data[segment]
    return data


def _expected(info, path, toml=False):
    if isinstance(info, mi.UnionType):
        kinds = [_plain(t) for t in info.types]
        if toml:  # TOML has no null: an optional key is simply left out
            kinds = [t for t in kinds if not isinstance(t, mi.NoneType)]
        return " or ".join(_expected(t, path, toml) for t in kinds)
    if isinstance(info, mi.LiteralType):
        return "one of " + ", ".join(repr(v) for v in info.values)
    kind = next(name for cls, name in _KINDS if isinstance(info, cls))
    if isinstance(info, mi.ListType) and info.min_length is not None:
        item = _plain(info.item_type)
        items = "items"
        if isinstance(item, mi.IntType | mi.FloatType):
            items = f"numbers {_bounds(item)}{_unit(path)}".rstrip()
        if info.min_length == info.max_length:
            return f"{kind} of {info.min_length} {items}"
        return f"{kind} of {info.min_length} to {info.max_length or 'any number of'} {items}"
    if isinstance(info, mi.IntType | mi.FloatType):
        bounds = _bounds(info)
        if bounds:
            return f"{kind} {bounds}{_unit(_INDEX.sub('', path))}"
    if isinstance(info, mi.StrType) and info.pattern is not None:
        return f"{kind} matching {info.pattern}"
    return kind


def _unit(path):
    return next((unit for suffix, unit in _UNITS if path.endswith(suffix)), "")


def _shown(value):
    """The value given, cut short when long."""
    if isinstance(value, list | dict) and len(value) > 4:
        return f"{len(value)} items"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _bounds(info):
    low = (info.ge, "≥") if info.ge is not None else (info.gt, ">")
    high = (info.le, "≤") if info.le is not None else (info.lt, "<")
    if low[0] is not None and high[0] is not None:
        if low[1] == "≥" and high[1] == "≤":
            return f"from {_number(low[0])} to {_number(high[0])}"
        return f"{low[1]} {_number(low[0])} and {high[1]} {_number(high[0])}"
    one = low if low[0] is not None else high
    return f"{one[1]} {_number(one[0])}" if one[0] is not None else ""


def _number(value):
    if isinstance(value, float) and math.isfinite(value) and value.is_integer():
        value = int(value)
    return f"{value:g}" if isinstance(value, float) else str(value)
