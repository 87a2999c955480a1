"""Exceptions raised by reflector_opt.

Every error caused by what a user supplied (a design file, a config, a CSV, a command-line
argument) is an :class:`InputError`; the command-line interface turns it into one line on
stderr and exit code 2.
"""


class InputError(ValueError):
    """Bad user input: the message names the offending field and what is wrong with it."""


class CollisionError(InputError):
    """A sensor lies on or inside the reflector sphere at one or more poses."""


class FitError(InputError):
    """A calibration fit cannot be trusted.

    The data do not determine the coefficients (too few samples, a rank-deficient design
    matrix), or the convex solver did not report an optimal solution.
    """
