"""Catalogues of named entries: the shipped TOML file or the user's, read and checked one way.

The sensor parts (:mod:`reflector_opt.model._catalogue`) and the spherical bearings
(:mod:`reflector_opt.design._bearings`) are both lists of entries with a unique ``name``, in a
TOML file shipped with the package or given by the user. :func:`read_catalogue` reads either
file, converts it to its document type, refuses a name given twice and turns each entry into
its checked item, every message one line that names the file and the entry at fault;
:func:`find_named` looks an item up by name, naming the known ones when it is not there.
"""

import tomllib
from importlib import resources

from reflector_opt.util import _schema as schema
from reflector_opt.util._errors import InputError
from reflector_opt.util._fileio import read_toml


def read_catalogue(path, shipped, document_type, section, build):
    """Read a catalogue file and build its items, in the file's order.

    Parameters
    ----------
    path : str, pathlib.Path or None
        A catalogue file (TOML); None for the shipped one.
    shipped : str
        The shipped catalogue's path inside the ``reflector_opt`` package.
    document_type : type
        The msgspec ``Struct`` the file converts to (:func:`reflector_opt.util._schema.convert`).
    section : str
        The document's attribute holding the entries (``"part"``, ``"bearing"``); each entry
        has a ``name``.
    build : callable
        ``build(entry, origin, where)``: the checked item of one entry, where ``origin`` is
        ``"shipped"`` or the path and ``where`` the entry's place for a message, e.g.
        ``part[0] (NJL5901R-2)``; raises :class:`~reflector_opt.util._errors.InputError`.

    Returns
    -------
    tuple
        The items. Raises :class:`~reflector_opt.util._errors.InputError` with one line: the file
        (or the shipped file's name), then the key at fault; a name given twice is refused.
    """
    if path is None:
        text = resources.files("reflector_opt").joinpath(shipped).read_text(encoding="utf-8")
        data, origin, label = tomllib.loads(text), "shipped", shipped
    else:
        data, origin, label = read_toml(path), str(path), str(path)
    try:
        document = schema.convert(data, document_type, toml=True)
        items, seen = [], set()
        for i, entry in enumerate(getattr(document, section)):
            where = f"{section}[{i}] ({entry.name})"
            if entry.name in seen:
                raise InputError(f"{where}.name: {entry.name!r} appears twice")
            seen.add(entry.name)
            items.append(build(entry, origin, where))
    except InputError as exc:
        raise InputError(f"{label}: {exc}") from None
    return tuple(items)


def find_named(items, name, what, *, key=None, hint=None):
    """The item of a catalogue with the given name.

    Parameters
    ----------
    items : iterable
        Items with a ``name`` attribute.
    name : str
    what : str
        What an item is, for the message (``"sensor part"``, ``"bearing"``).
    key : str, optional
        The input key the name came from, put before the message (``mechanics.bearing``).
    hint : str, optional
        What else the user can do, in brackets after the known names.

    Returns
    -------
    object
        The item. Raises :class:`~reflector_opt.util._errors.InputError` naming the known items
        when none has that name.
    """
    known = {item.name: item for item in items}
    if name not in known:
        head = f"{key}: " if key else ""
        tail = f" ({hint})" if hint else ""
        raise InputError(
            f"{head}unknown {what} {name!r}; the catalogue has: {', '.join(known)}{tail}"
        )
    return known[name]
