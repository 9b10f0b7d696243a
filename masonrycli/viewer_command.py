"""The line that opens a recording in the Rerun viewer, quoted for this system's shell, and how to start the viewer
from here (a run's summary ends with it; ``api.view`` starts it; ``masonry sweep`` names it)."""

from __future__ import annotations

import ntpath
import os
import re
import shlex
import shutil
import sys
from pathlib import Path


def open_command(recording, *, windows: bool = os.name == "nt", environ=os.environ) -> str:
    """The line that opens ``recording`` in the viewer, quoted for this system's shell ("rerun my runs/w.rrd"
    opened "my" and "runs/w.rrd"). On Windows with double quotes, which cmd.exe and PowerShell both read
    (shlex's '…', taken for a backslash, so every default path 'recordings\\wall-….rrd', are no quotes to
    cmd.exe); a quoted viewer ("C:\\Users\\Ana Silva\\…\\rerun.exe") is a string to PowerShell, run only
    after its call operator &, which cmd.exe refuses: in PowerShell (:func:`in_powershell`) the line starts
    with "& ". An unquoted viewer needs no operator, so that line runs in either."""
    if not windows:
        return shlex.join([rerun_command(windows=windows), os.fspath(recording)])
    viewer, path = (_windows_word(text) for text in (rerun_command(windows=windows), os.fspath(recording)))
    call = "& " if viewer.startswith('"') and in_powershell(environ) else ""
    return f"{call}{viewer} {path}"


_PLAIN_WORD = re.compile(r"[\w.:\\/+=~-]+")
"""What cmd.exe and PowerShell both read as one literal word; anything else goes between double quotes
(a space, and the characters either shell gives a meaning outside quotes: ' & ( ) ; , @ { } ^ < > |)."""


def _windows_word(text: str) -> str:
    return text if _PLAIN_WORD.fullmatch(text) else f'"{text}"'


def in_powershell(environ=os.environ) -> bool:
    """Whether this process most likely runs in a PowerShell window: PowerShell (5.1 and 7) adds the user's
    own module folder (under %USERPROFILE%, Documents\\WindowsPowerShell\\Modules or
    Documents\\PowerShell\\Modules) to PSModulePath at start, which the machine's value, the one cmd.exe
    started from the Start menu gets, does not hold. A cmd.exe started from PowerShell inherits it: the
    line is then PowerShell's."""
    home = environ.get("USERPROFILE", "").rstrip("\\/")
    if not home:
        return False
    home = ntpath.normcase(home) + "\\"
    return any(ntpath.normcase(p).startswith(home) for p in environ.get("PSModulePath", "").split(";") if p)


def rerun_command(*, windows: bool = os.name == "nt") -> str:
    """How to start the viewer from here: ``rerun`` if it is on PATH, else the one beside this Python (on
    Windows ``Scripts\\rerun.exe``: a ``rerun`` there does not exist, and "rerun" alone is not found in a
    venv not activated), relative to the working folder when it is below it (``.venv/bin/rerun``)."""
    if shutil.which("rerun"):
        return "rerun"
    beside = Path(sys.executable).parent / ("rerun.exe" if windows else "rerun")
    if not beside.exists():
        return "rerun"
    try:
        below = os.path.relpath(beside)
    except ValueError:  # on another drive
        return str(beside)
    if below.startswith(os.pardir):
        return str(beside)
    return os.path.join(os.curdir, below) if windows or os.sep not in below else below  # PowerShell: .\x.exe
