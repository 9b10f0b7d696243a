"""``python -m masonrycli`` and the ``masonry`` command (the entry point in pyproject.toml).

The command line lives in :mod:`masonrycli.cli`; it is imported here, inside ``main``, so that a Ctrl-C
while Python loads it (typer, rich, numpy: the first half second) ends in one line and exit 130 instead
of a KeyboardInterrupt traceback.
"""

from __future__ import annotations

import sys


def main() -> None:
    try:
        from masonrycli.cli import main as cli_main
        from masonrycli.interrupt import ignore_signals_while_exiting
    except KeyboardInterrupt:
        sys.stderr.write("error: Ctrl-C while masonry was starting: nothing was run\n")
        raise SystemExit(130) from None
    try:
        cli_main()
    finally:
        # the command is over, however it ended (its files whole, or removed): a signal from here on could
        # only cut the interpreter's shutdown (exit -2, or a traceback from an atexit callback)
        ignore_signals_while_exiting()


if __name__ == "__main__":
    main()
