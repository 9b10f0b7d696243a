"""``python -m masonrycli`` and the ``masonry`` command (the entry point in pyproject.toml).

The command line lives in :mod:`masonrycli.cli.app`; it is imported here, inside ``main``, so that a Ctrl-C
while Python loads it (typer, rich, numpy: the first half second) ends in one line and exit 130 instead
of a KeyboardInterrupt traceback.
"""

from __future__ import annotations

import signal
import sys
import threading


class _Terminated(BaseException):
    """SIGTERM while the command line is loaded."""


def _terminated(signum, frame):
    raise _Terminated


def _unencodable_characters_replaced() -> None:
    """Terminals and pipes whose encoding lacks a character masonry writes (—, →, ≤, σ: a Windows console
    in cp1252, ``PYTHONIOENCODING=cp1252``, a redirect under an ASCII locale) get ``?`` for it.

    Without this, the first such character raised UnicodeEncodeError: ``masonry simulate wall`` ended with a
    traceback and exit 1 at its summary ('→' in the energy row), after its files were written.
    """
    for stream in (sys.stdout, sys.stderr):
        reconfigure = getattr(stream, "reconfigure", None)  # a TextIOWrapper; not a replaced stream (tests)
        if reconfigure is not None and stream.errors == "strict":
            reconfigure(errors="replace")


def main() -> None:
    _unencodable_characters_replaced()
    # SIGTERM before a command's own handling (masonrycli.interrupt) takes over — Python loading the command
    # line, the structure being built, the outputs checked — killed it without a word (exit -15), where a
    # Ctrl-C says one line; nothing is written in those phases. The commands' handlers put this one back.
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, _terminated)
    try:
        from masonrycli.cli.app import main as cli_main
        from masonrycli.interrupt import ignore_signals_while_exiting
    except KeyboardInterrupt:
        sys.stderr.write("error: Ctrl-C while masonry was starting: nothing was run\n")
        raise SystemExit(130) from None
    except _Terminated:
        sys.stderr.write("error: SIGTERM while masonry was starting: nothing was run\n")
        raise SystemExit(143) from None
    try:
        cli_main()
    except _Terminated:
        sys.stderr.write("error: SIGTERM: stopped before any output was written\n")
        raise SystemExit(143) from None
    finally:
        # the command is over, however it ended (its files whole, or removed): a signal from here on could
        # only cut the interpreter's shutdown (exit -2, or a traceback from an atexit callback)
        ignore_signals_while_exiting()


if __name__ == "__main__":
    main()
