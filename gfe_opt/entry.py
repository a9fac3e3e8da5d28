"""The installed ``gfe-opt`` command: imports the command line behind Ctrl-C handling, so
an interrupt while numpy and scipy load is one line too (exit 130)."""

import sys


def main() -> int:
    try:
        from .cli import EXIT_INTERRUPTED
        from .cli import main as run
    except KeyboardInterrupt:
        print("gfe-opt: interrupted", file=sys.stderr)
        return 130
    try:
        return run()
    except KeyboardInterrupt:  # between main()'s own handling and the exit
        print("gfe-opt: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
