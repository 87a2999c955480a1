"""The ``reflector-opt`` command line: parse, call the library, print.

Each subcommand has an ``add_<name>(subparsers)`` in :mod:`reflector_opt.cli._commands`,
which adds its parser and sets ``handler`` to a function taking the parsed arguments and
returning an exit code. That module imports only light modules at its top, so that
``--help`` starts at once, and the library in each handler. Every subcommand also takes
``-q/--quiet`` and ``-v/--verbose`` (:mod:`reflector_opt.cli._output`). Exit codes: 0 success,
2 bad input (one line on stderr, no traceback), 1 an internal error (one line pointing to a
log file with the traceback), 130 interrupted (Ctrl-C), 143 terminated (SIGTERM)
(docs/conventions.md). ``args.argv`` holds the command line (the manifests of output
folders record it).
"""

import argparse
import os
import signal
import sys
import time

from reflector_opt import __version__
from reflector_opt.cli._commands import SUBCOMMANDS
from reflector_opt.cli._output import add_console_arguments, console_logging
from reflector_opt.util._crashlog import write_crash_log
from reflector_opt.util._errors import InputError
from reflector_opt.util._interrupts import Terminated, interrupts_after_imports

__all__ = ["main"]


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose usage errors are one line and exit code 2, and that takes no
    abbreviation of an option (``--cond`` is not ``--conditions``)."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("allow_abbrev", False)
        super().__init__(*args, **kwargs)

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message}\n")

    def parse_args(self, args=None, namespace=None):
        """As argparse's, but unknown arguments are reported by the subcommand's parser
        (``reflector-opt CMD: error: unrecognized arguments: …``), as every other usage
        error is."""
        args, extras = self.parse_known_args(args, namespace)
        if extras:
            commands = getattr(self, "commands", {})
            parser = commands.get(getattr(args, "command", None), self)
            parser.error(f"unrecognized arguments: {' '.join(extras)}")
        return args


def build_parser():
    """The top-level argument parser with every subcommand registered."""
    parser = _Parser(
        prog="reflector-opt",
        description="Design the convex spherical reflector of an optoelectronic shape sensor.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    subparsers = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    for add in SUBCOMMANDS:
        add(subparsers)
    for subparser in subparsers.choices.values():
        add_console_arguments(subparser)
    parser.commands = subparsers.choices
    return parser


def main(argv=None):
    """The command line (the ``reflector-opt`` console script runs it); returns the exit code."""
    started = time.perf_counter()
    argv = sys.argv[1:] if argv is None else list(argv)
    args = build_parser().parse_args(argv)
    args.started = started  # the wall time printed is the whole command's
    args.argv = ["reflector-opt", *argv]
    try:
        with (
            interrupts_after_imports(),
            console_logging(f"reflector-opt {args.command}", args.quiet, args.verbose),
        ):
            code = args.handler(args)
            sys.stdout.flush()  # a reader that left shows here, not at the interpreter's exit
            return code
    except InputError as exc:
        print(f"reflector-opt {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except Terminated:
        print("reflector-opt: terminated", file=sys.stderr)
        return 143
    except KeyboardInterrupt:
        print("reflector-opt: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return _stdout_closed()
    except Exception as exc:
        log = write_crash_log(exc, args.argv)
        reason = str(exc).splitlines()[0] if str(exc) else ""
        print(
            f"reflector-opt {args.command}: internal error ({type(exc).__name__}: {reason}); "
            f"please report it with the traceback in {log}",
            file=sys.stderr,
        )
        return 1


def _stdout_closed():
    """The reader of stdout left (``… --json | head``): end quietly, as a piped tool does.

    A command prints its summary after its files are written, each whole: nothing is lost.
    stdout is pointed at the null device so that the interpreter's own flush at exit does
    not fail again; the exit code is the shell's for a pipe closed under a writer (128 +
    SIGPIPE).
    """
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())
    os.close(devnull)
    return 128 + signal.SIGPIPE


if __name__ == "__main__":
    sys.exit(main())
