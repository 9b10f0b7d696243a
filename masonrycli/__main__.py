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
    except KeyboardInterrupt:
        sys.stderr.write("error: Ctrl-C while masonry was starting: nothing was run\n")
        raise SystemExit(130) from None
    try:
        cli_main()
    except SystemExit as stop:  # stopped by a signal: the rest of the way out ignores a second one
        from masonrycli.interrupt import ignore_signals_while_exiting

        ignore_signals_while_exiting(stop.code)
        raise


if __name__ == "__main__":
    main()
