"""The arguments every command shares: its output (``-o/--out``, a folder or a file, refused
before any work if it cannot be one or would overwrite an input) and the deprecated spellings
of renamed options. A run's own options are declared with the run
(:mod:`reflector_opt.util._declared`).
"""

import argparse
import os
import sys
from pathlib import Path

from reflector_opt.util._atomic import check_output_folder
from reflector_opt.util._errors import InputError

#: Where every command writes by default: one git-ignored folder in the working folder.
DEFAULT_OUT = "cad_out"


def output_file(text):
    """A file to write: not an existing folder."""
    if Path(text).is_dir():
        raise argparse.ArgumentTypeError(f"{text} is a folder; give the name of a file to write")
    return text


def output_folder(path):
    """The ``-o/--out`` folder, refused before any work if it cannot be one.

    Raises
    ------
    InputError
        ``--out PATH: …`` (:func:`~reflector_opt.util._atomic.check_output_folder`).
    """
    try:
        return check_output_folder(path)
    except InputError as exc:
        raise InputError(f"--out {exc}") from None


def refuse_output_over_inputs(output, inputs, option="--out"):
    """Refuse an output file that is one of the command's input files.

    ``calibrate data.csv -o data.csv`` would replace the measurements with the results.

    Parameters
    ----------
    output : str
        The ``-o/--out`` file.
    inputs : mapping of str to str or None
        Each input's name on the command line (``"data"``, ``"--design"``) and its path;
        None where not given.
    option : str, optional
        The option that named ``output``, for the message.

    Raises
    ------
    InputError
        Naming the output and the input it would overwrite (the same file, however named:
        a symbolic or hard link included).
    """
    for name, path in inputs.items():
        if path is not None and _same_file(output, path):
            raise InputError(
                f"{option} {output}: is the input {name} ({path}); writing it would replace "
                "the input, give the output a file of its own"
            )


def _same_file(a, b):
    try:
        return os.path.samefile(a, b)
    except OSError:  # one of them does not exist (yet), or cannot be read
        return False


class _Deprecated(argparse.Action):
    """Store like the option it stands for, with a warning naming the new spelling."""

    def __init__(self, option_strings, dest, replacement, **kwargs):
        self.replacement = replacement
        super().__init__(option_strings, dest, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        print(
            f"{parser.prog}: warning: {option_string} is deprecated; use {self.replacement}",
            file=sys.stderr,
        )
        setattr(namespace, self.dest, values)


def deprecated_alias(parser, old, new):
    """Accept ``old`` as a hidden, deprecated spelling of the option ``new`` of ``parser``.

    The alias takes the same value type, is left out of ``--help`` and prints a one-line
    warning naming ``new`` when used.
    """
    action = parser._option_string_actions[new]
    parser.add_argument(
        old,
        dest=action.dest,
        type=action.type,
        nargs=action.nargs,
        metavar=action.metavar,
        action=_Deprecated,
        replacement="/".join(action.option_strings),
        default=action.default,
        help=argparse.SUPPRESS,
    )


def add_output_folder(parser, default, what):
    """Add ``-o/--out DIR``, the folder a subcommand writes ``what`` into (under cad_out/)."""
    parser.add_argument(
        "-o",
        "--out",
        metavar="DIR",
        default=default,
        help=f"folder for {what} (default {default}/)",
    )


def add_output_file(parser, what, required=True):
    """Add ``-o/--out FILE``, the file a subcommand writes ``what`` into (``args.output``).

    Output files and output folders share the spelling ``-o/--out``; the metavar and the help
    say which one a subcommand takes. The former spelling ``--output`` stays accepted, hidden
    from ``--help``, with a warning.
    """
    parser.add_argument(
        "-o",
        "--out",
        dest="output",
        metavar="FILE",
        type=output_file,
        required=required,
        help=f"file to write: {what}",
    )
    deprecated_alias(parser, "--output", "--out")
