"""Argument types of the command line: each refuses a bad value as a one-line usage error.

A type is a callable argparse applies to the option's text; an
:class:`argparse.ArgumentTypeError` becomes ``reflector-opt CMD: error: argument --x: …``
and exit code 2, before any work starts.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from reflector_opt.util.limits import MAX_ANGLE_DEG

__all__ = ["angle_deg", "count", "number", "output_file", "seed"]


def count(low, high):
    """Type of a whole number within ``[low, high]``."""

    def parse(text):
        try:
            value = int(text)
        except ValueError:
            value = None
        if value is None or not low <= value <= high:
            raise argparse.ArgumentTypeError(
                f"expected a whole number from {low:,} to {high:,}, got {text!r}"
            )
        return value

    return parse


def seed(text):
    """A random seed: a whole number ≥ 0."""
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a whole number ≥ 0, got {text!r}")
    return value


def number(low, high, unit="", *, low_open=False):
    """Type of a finite number within ``[low, high]`` (``(low, high]`` with ``low_open``)."""
    shown = f"{'(' if low_open else '['}{low:g}, {high:g}]{' ' + unit if unit else ''}"

    def parse(text):
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        inside = low < value <= high if low_open else low <= value <= high
        if not inside:
            raise argparse.ArgumentTypeError(f"expected a number in {shown}, got {text!r}")
        return value

    return parse


def angle_deg(text):
    """A pose angle: a number strictly within ±90 degrees."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not abs(value) < MAX_ANGLE_DEG:
        raise argparse.ArgumentTypeError(
            f"expected an angle within (-{MAX_ANGLE_DEG:g}, {MAX_ANGLE_DEG:g}) degrees, "
            f"got {text!r}"
        )
    return value


def output_file(text):
    """A file to write: not an existing folder."""
    if Path(text).is_dir():
        raise argparse.ArgumentTypeError(f"{text} is a folder; give the name of a file to write")
    return text
