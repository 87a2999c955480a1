"""``python -m reflector_opt`` and the ``reflector-opt`` console script: the command line."""

import os
import signal
import sys


def _interrupted_while_starting(signum, frame):
    """Ctrl-C before the command line has started: nothing is written yet, so one line and
    exit 130 at once (not a traceback of the imports)."""
    sys.stderr.write("reflector-opt: interrupted\n")
    sys.stderr.flush()
    os._exit(130)


def run():
    """Entry point of ``reflector-opt``; returns the exit code of
    :func:`reflector_opt.cli.main`, which handles Ctrl-C from then on."""
    signal.signal(signal.SIGINT, _interrupted_while_starting)
    from reflector_opt.cli import main

    return main()


if __name__ == "__main__":
    sys.exit(run())
