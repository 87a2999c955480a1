"""Exceptions raised by reflector_opt.

Every error caused by what a user supplied (a design file, a config, a CSV, a command-line
argument) is an :class:`InputError`; the command-line interface turns it into one line on
stderr and exit code 2.
"""

from contextlib import contextmanager

#: Control characters, written as escapes in a message so that it stays one line.
_CONTROL = {c: repr(chr(c))[1:-1] for c in (*range(0x20), 0x7F)}


class InputError(ValueError):
    """Bad user input: the message names the offending field and what is wrong with it.

    The message is one line: a control character in it (a newline in a key of the user's
    file, say) is written as its escape (``\\n``).
    """

    def __init__(self, message=""):
        super().__init__(str(message).translate(_CONTROL))


class CollisionError(InputError):
    """A sensor lies on or inside the reflector sphere at one or more poses."""


class NoDesignError(InputError):
    """No design meets the constraints: settings no point within the bounds can meet, a
    search that finds no feasible point, or a design that fails its last check and cannot be
    repaired. The message names the constraint; ``reflector-opt optimise`` adds the smallest
    change of the settings it found that gives a design (:mod:`reflector_opt.workflow._remedy`).
    """


class FitError(InputError):
    """A calibration fit cannot be trusted.

    The data do not determine the coefficients (too few samples, a rank-deficient design
    matrix), or the convex solver did not report an optimal solution.
    """


@contextmanager
def in_section(name):
    """Name a config file's section in the InputError raised inside: ``name.key: …``.

    A message that already begins with ``name.`` is kept as it is.

    Parameters
    ----------
    name : str
        The TOML section (``robust``, ``run``).

    Raises
    ------
    InputError
        The one raised inside, its message prefixed with the section.
    """
    try:
        yield
    except InputError as exc:
        message = str(exc)
        if message.startswith(f"{name}."):
            raise
        raise InputError(f"{name}.{message}") from None
