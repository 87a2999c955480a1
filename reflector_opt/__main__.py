"""``python -m reflector_opt`` and the ``reflector-opt`` console script: the command line."""

import os
import signal
import sys


def _interrupted_while_starting(signum, frame):
    """Ctrl-C (or SIGTERM) before the command line has started: nothing is written yet, so
    one line and exit 130 (143) at once, not a traceback of the imports."""
    terminated = signum == signal.SIGTERM
    sys.stderr.write(f"reflector-opt: {'terminated' if terminated else 'interrupted'}\n")
    sys.stderr.flush()
    os._exit(143 if terminated else 130)


def run():
    """Entry point of ``reflector-opt``; returns the exit code of
    :func:`reflector_opt.cli.main`, which handles Ctrl-C and SIGTERM from then on."""
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, _interrupted_while_starting)
    from reflector_opt.cli import main

    return main()


if __name__ == "__main__":
    sys.exit(run())
