"""Options declared once: a run's options as a frozen :class:`msgspec.Struct`, each field's type,
range, default and help in its annotation.

From one declaration come the command line's arguments and their ``--help``
(:func:`add_options`), the run's keyword arguments, signature and docstring (:func:`takes`),
the one check at the boundary (:func:`checked`, through :func:`reflector_opt.util._schema.convert`
and its one-line messages) and the option tables of docs/cli.md
(:func:`reflector_opt.cli.option_tables`). An option shared with a TOML config (``workers``,
``seed``) is the same annotated type in both (:data:`Workers`, :data:`Seed`).

Example
-------
>>> class FitOptions(Options):
...     folds: option(int, "cross-validation folds; 0 skips", ge=0, le=1000) = 5
"""

import argparse
import functools
import inspect
import typing
from typing import Annotated

import msgspec
import msgspec.inspect as mi
from msgspec import Meta

from reflector_opt.util import _schema as schema
from reflector_opt.util._limits import MAX_ANGLE_DEG, MAX_STARTS, MAX_WORKERS


class Options(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """Base of a run's declared options: keyword-only, frozen, unknown names refused."""


def option(kind, help, *, flag=None, metavar=None, repeated=False, **bounds):
    """An option's declaration, as a field's annotation.

    Parameters
    ----------
    kind : type
        The value's type (``int``, ``float``, ``str``, ``bool``, a ``Literal`` of the choices,
        ``object`` for a file or an object the run loads and checks itself, or a declared
        option such as :data:`Workers`, whose help this one replaces); ``| None`` where the
        option may be left out.
    help : str
        One sentence: what the option does (``--help``, the run's docstring, docs/cli.md).
    flag : str, optional
        The command line's spelling, default ``--name-with-dashes``; ``--no-name`` for an
        option that is on by default.
    metavar : str or tuple of str, optional
        The value's name in ``--help`` (``N``, ``FILE.toml``; one per value of a tuple).
    repeated : bool, optional
        A list given as the option repeated (``--curve A --curve B``); a list is otherwise
        comma-separated text, a tuple of fixed length that many values.
    **bounds
        :class:`msgspec.Meta` bounds (``ge``, ``le``, ``gt``, ``lt``, ``min_length``, …); a
        number's bounds also refuse NaN.

    Returns
    -------
    typing.Annotated
    """
    extra = {"flag": flag, "metavar": metavar, "repeated": repeated}
    extra = {key: value for key, value in extra.items() if value}
    return Annotated[kind, Meta(description=help, extra=extra, **bounds)]


#: Worker processes, as every command and config takes them.
Workers = option(int, "worker processes", metavar="N", ge=1, le=MAX_WORKERS)
#: A random seed.
Seed = option(int, "random seed", metavar="N", ge=0, le=2**32 - 1)
#: A pose angle, degrees.
Angle = option(float, "angle, degrees", gt=-MAX_ANGLE_DEG, lt=MAX_ANGLE_DEG)
#: Operating conditions a run judges in: a ``Conditions`` or its TOML file.
ConditionsFile = option(
    object,
    "operating conditions (Conditions, or a [conditions] TOML file, docs/conditions.md) the "
    "design is judged in; the default conditions if left out",
    metavar="COND.toml",
)
#: Independent searches from derived seeds, the best kept.
Starts = option(
    int,
    "independent searches from seeds derived from --seed, the best kept",
    metavar="N",
    ge=1,
    le=MAX_STARTS,
)


class _Field(typing.NamedTuple):
    """One declared option, read from its struct."""

    name: str
    default: object
    help: str
    flag: str
    metavar: str | None
    choices: tuple | None
    bounds: str
    is_bool: bool
    items: int | None  # a list's: 0 for any length (comma-separated text), else its length
    repeated: bool


def fields(kind):
    """The declared options of ``kind``, in declaration order (a list of ``_Field``)."""
    declared = []
    for field in mi.type_info(kind).fields:
        meta, info = meta_of(field.type)
        default = field.default if field.default is not mi.NODEFAULT else None
        is_bool = isinstance(info, mi.BoolType)
        flag = meta.extra.get("flag") or "--" + (
            f"no-{field.name}" if is_bool and default else field.name
        ).replace("_", "-")
        items = None
        if isinstance(info, mi.TupleType):
            items = len(info.item_types)
        elif isinstance(info, mi.ListType | mi.VarTupleType):
            items = 0
        declared.append(
            _Field(
                field.name,
                default,
                meta.extra_json_schema.get("description", ""),
                flag,
                meta.extra.get("metavar"),
                info.values if isinstance(info, mi.LiteralType) else None,
                _bounds(info),
                is_bool,
                items,
                meta.extra.get("repeated", False),
            )
        )
    return declared


def meta_of(info):
    """The annotation's :class:`msgspec.inspect.Metadata` and the plain type under it (the
    non-None member of an optional one)."""
    meta = mi.Metadata(type=None)
    if isinstance(info, mi.UnionType):
        info = next(t for t in info.types if not isinstance(t, mi.NoneType))
    if isinstance(info, mi.Metadata):
        meta, info = info, info.type
    if isinstance(info, mi.UnionType):  # Annotated[X | None, …]
        info = next(t for t in info.types if not isinstance(t, mi.NoneType))
    return mi.Metadata(info, meta.extra_json_schema or {}, meta.extra or {}), info


def _bounds(info):
    """A number's range as the docs show it: ``1–256``, ``≥ 0``, ``(0, 1)``."""
    if not isinstance(info, mi.IntType | mi.FloatType):
        return ""
    low = info.ge if info.ge is not None else info.gt
    high = info.le if info.le is not None else info.lt
    if high is not None and high >= 2**32 - 1:  # a seed's: any whole number a seed takes
        high = None
    shown = "{:,}" if isinstance(info, mi.IntType) else "{:g}"
    low, high = (None if v is None else shown.format(v) for v in (low, high))
    if low is not None and high is not None:
        if info.gt is None and info.lt is None:
            return f"{low}–{high}"
        opening, closing = "(" if info.gt is not None else "[", ")" if info.lt is not None else "]"
        return f"in {opening}{low}, {high}{closing}"
    if low is not None:
        return f"{'>' if info.gt is not None else '≥'} {low}"
    return f"{'<' if info.lt is not None else '≤'} {high}" if high is not None else ""


def checked(kind, given, *, strict=True):
    """The options ``given``, checked against their declaration: the one check at the boundary.

    Parameters
    ----------
    kind : type
        An :class:`Options` subclass.
    given : mapping or Options
        Option names to values (an option left out takes its default), or an instance of
        ``kind`` (checked again: a struct's constructor does not check).
    strict : bool, optional
        False to take a number or a choice as the command line's text.

    Returns
    -------
    kind

    Raises
    ------
    InputError
        Naming the option as the command line spells it, what it takes and what it got:
        ``--starts: expected a whole number from 1 to 256, got 0``.
    TypeError
        An option ``kind`` does not declare.
    """
    if isinstance(given, kind):
        given = msgspec.structs.asdict(given)
    flags = {f.name: f.flag for f in fields(kind)}
    unknown = sorted(set(given) - set(flags))
    if unknown:
        raise TypeError(f"unknown option(s) {', '.join(unknown)}; allowed: {', '.join(flags)}")
    return schema.convert(dict(given), kind, strict=strict, names=flags)


def add_options(parser, kind):
    """Add ``kind``'s options to a command's ``parser``, each as its declaration says.

    A value is taken as text and checked by :func:`checked` (one message per option,
    exit 2); an option left out is absent from the parsed arguments, so that its declared
    default applies. Read them back with :func:`options_of`.
    """
    for field in fields(kind):
        shown = "" if field.is_bool or field.default is None else f"default {field.default}"
        detail = "; ".join(part for part in (field.bounds, shown) if part)
        negated = field.flag.startswith("--no-")
        action = parser.add_argument(
            field.flag,
            dest=field.name,
            default=argparse.SUPPRESS,
            help=(
                ("do not " if negated else "") + field.help + (f" ({detail})" if detail else "")
            ).replace("%", "%%"),  # argparse formats the help
            **_action(field),
        )
        action.declared_default, action.declared_kind = field.default, kind


def _action(field):
    if field.is_bool:
        return {"action": "store_false" if field.flag.startswith("--no-") else "store_true"}
    if field.choices is not None:  # shown as argparse shows choices, checked by the declaration
        return {"metavar": field.metavar or "{" + ",".join(str(c) for c in field.choices) + "}"}
    metavar = field.metavar or field.name.upper()
    if field.repeated:
        return {"action": "append", "metavar": metavar}
    if field.items:
        return {"nargs": field.items, "metavar": metavar}
    return (
        {"metavar": metavar, "type": _comma_separated} if field.items == 0 else {"metavar": metavar}
    )


def _comma_separated(text):
    """A list option's text, split at its commas (an empty list would stand for the default)."""
    parts = [part.strip() for part in text.split(",") if part.strip()]
    if not parts:
        raise argparse.ArgumentTypeError(f"expected a comma-separated list, got {text!r}")
    return parts


def options_of(args, kind):
    """The options of ``kind`` in parsed command-line arguments, checked."""
    given = {f.name: getattr(args, f.name) for f in fields(kind) if hasattr(args, f.name)}
    return checked(kind, given, strict=False)


def takes(kind):
    """Give a run the declared options of ``kind`` as its keyword arguments.

    The decorated run is written ``run(*inputs, options, progress=None)``; the run users call
    is ``run(*inputs, *, <each option>=<its default>, progress=None)`` (or
    ``run(*inputs, kind(...))``), whose options are checked once by :func:`checked` and whose
    signature and docstring list them.
    """

    def decorate(run):
        parameters = list(inspect.signature(run).parameters.values())
        cut = next(i for i, p in enumerate(parameters) if p.name == "options")
        inputs, after = parameters[:cut], parameters[cut + 1 :]
        declared = [
            inspect.Parameter(f.name, inspect.Parameter.KEYWORD_ONLY, default=f.default)
            for f in fields(kind)
        ]

        @functools.wraps(run)
        def call(*args, **given):
            extra = {p.name: given.pop(p.name) for p in after if p.name in given}
            if args and isinstance(args[-1], kind):
                given = msgspec.structs.asdict(args[-1]) | given
                args = args[:-1]
            return run(*args, options=checked(kind, given), **extra)

        call.__signature__ = inspect.Signature(
            [*inputs, *declared, *(p.replace(kind=p.KEYWORD_ONLY) for p in after)]
        )
        doc = run.__doc__ or ""
        cut = doc.find("\n    Returns\n")
        cut = len(doc) if cut < 0 else cut
        call.__doc__ = doc[:cut] + _options_doc(kind) + doc[cut:]
        call.options = kind
        return call

    return decorate


def _options_doc(kind):
    """The numpydoc ``Other Parameters`` of a run's declared options."""
    lines = ["", "    Other Parameters", "    ----------------"]
    for f in fields(kind):
        lines.append(f"    {f.name} : optional, default {f.default!r}")
        text = f.help.replace("|", "\\|")  # reStructuredText: | starts a substitution
        lines.append(f"        {text} ({f.flag}{'; ' + f.bounds if f.bounds else ''}).")
    return "\n".join(lines)
