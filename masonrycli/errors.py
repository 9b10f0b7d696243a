"""The one error type the command line turns into a one-line message and exit code 2, where it happened,
and the exit codes.

Exit codes (README, "Troubleshooting"): 0 the run completed (or the command succeeded) · 1 internal error
(an engine bug; ``MASONRY_DEBUG=1`` shows the traceback) · 2 bad input, including an output path that
cannot be written, checked before step 1 · 3 the run diverged · 4 an output could not be written during
the run (disk full, folder removed) · 5 a study (``masonry sweep``) finished with failed runs (rows with
``status = error``: an engine error or an output that could not be written; the table is whole) · 128 + signal number when stopped by a signal (130 Ctrl-C, 143 SIGTERM, 129 SIGHUP: the terminal closed).
"""

import os
import stat

EXIT_OK = 0
EXIT_INTERNAL = 1
EXIT_BAD_INPUT = 2
EXIT_DIVERGED = 3
EXIT_OUTPUT_FAILED = 4
EXIT_ROWS_FAILED = 5


class RecordWarning(UserWarning):
    """An input read with a remark (an .AT2 file with samples beyond its NPTS); the command line prints it
    as one ``warning: …`` line (:func:`masonrycli.cli.messages.user_errors`)."""


class InputError(ValueError):
    """Bad user input (scenario file, option, geometry). ``str(err)`` is one line saying what and where."""


NOT_A_FILE = "not a regular file (a device, a pipe or a socket)"
"""What input readers say of a path that exists but is no file: reading ``/dev/zero`` or a named pipe never
ended (the run hung before its first line), and the commands that test ``is_file()`` called it missing."""


def input_path(base_dir: str, given: str) -> str:
    """The absolute path of a file a scenario names (a record, a geometry): relative to the scenario's folder,
    ``~`` expanded ("~/records/q.AT2" was looked for as <folder>/~/records/q.AT2: no shell expands a TOML
    string)."""
    return os.path.abspath(os.path.join(base_dir, os.path.expanduser(given)))


ESCAPED_PATH = (
    "a \\ between double quotes starts an escape (\\t, \\n, \\U…): write the path with / "
    "(\"C:/Users/ana/quake.AT2\") or between single quotes ('C:\\Users\\ana\\quake.AT2')"
)
"""What to do about a Windows path written between a TOML file's double quotes."""


def not_a_file(path) -> str:
    """Why ``path`` is no regular file to read: "is a directory" (a folder was called a device, a pipe or a
    socket), NOT_A_FILE, or "no such file"."""
    if os.path.isdir(path):
        return "is a directory"
    if os.path.exists(path):
        return NOT_A_FILE
    if any(c in os.fspath(path) for c in "\t\n\r\f\b\v"):  # "C:\temp\new.csv" in a TOML "…" string
        return f"no such file: its name holds a tab or a line break, {ESCAPED_PATH}"
    return "no such file"


def special_file(path) -> bool:
    """True for a path that exists and is neither a regular file nor a folder (checked without opening it:
    opening a named pipe waits for a writer)."""
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return False
    return not (stat.S_ISREG(mode) or stat.S_ISDIR(mode))


FILE_KINDS = {  # suffix: (what a file of it is, what to do with it), for an input read as another kind
    ".rrd": ("a Rerun recording (.rrd)", "masonry inspect summarises it"),
    ".npz": ("a run history (.npz)", ""),
    ".parquet": ("a sweep table (.parquet)", ""),
    ".png": ("an image (.png)", ""),
    ".xlsx": ("a spreadsheet (.xlsx)", "save the sheet as CSV"),
    ".xls": ("a spreadsheet (.xls)", "save the sheet as CSV"),
    ".ods": ("a spreadsheet (.ods)", "save the sheet as CSV"),
    ".toml": ("a scenario file (TOML)", "masonry run runs it"),
    ".geojson": ("a geometry file (GeoJSON)", "masonry run runs it"),
    ".json": ("a geometry file (GeoJSON)", "masonry run runs it"),
    ".wkt": ("a geometry file (WKT)", "masonry run runs it"),
    ".csv": ("a CSV table", "a record goes in --record or a scenario's record motion"),
    ".at2": ("an earthquake record (.AT2)", "a record goes in --record or a scenario's record motion"),
    ".asc": ("an earthquake record (ESM .ASC)", "a record goes in --record or a scenario's record motion"),
}
"""Reading a recording as a scenario said "not a UTF-8 text file (byte 31)", a GeoJSON as a record
"wall.geojson:2: not a number": the input's name says what it is."""


TEXT_SUFFIXES = frozenset({".toml", ".geojson", ".json", ".wkt", ".csv", ".at2", ".asc"})
"""Suffixes of text files: a binary file under one was named "a scenario file (TOML)" by inspect and --record."""
BINARY_FILE = "not a text file (it holds NUL bytes: a binary file)"
"""What a binary file read as text is called (no encoding makes it text: saving it "as UTF-8" is no advice)."""


def binary_under_text_suffix(path) -> bool:
    """Whether ``path`` has a text file's suffix (TEXT_SUFFIXES) but NUL bytes in its first 4 kB: a binary
    file that its name would have described as a scenario, a geometry or a record. False for a missing or
    unreadable file (its reader says why)."""
    if os.path.splitext(os.fspath(path))[1].lower() not in TEXT_SUFFIXES:
        return False
    try:
        with open(path, "rb") as fh:
            return b"\x00" in fh.read(4096)
    except OSError:
        return False


def file_kind(path, expected: str, skip: tuple[str, ...] = (), name: str | None = None) -> InputError | None:
    """The error for an input whose suffix names another kind of file than the one ``expected`` (said in
    the message: "a scenario"), or None (an unknown suffix, or one in ``skip``: the reader decides).
    ``name``: the input as the messages name it (default: ``path``)."""
    suffix = os.path.splitext(os.fspath(path))[1].lower()
    if suffix not in FILE_KINDS or suffix in skip:
        return None
    kind, hint = FILE_KINDS[suffix]
    if binary_under_text_suffix(path):  # a binary file so named is none of these
        kind, hint = BINARY_FILE, ""
    return InputError(
        f"{os.fspath(path) if name is None else name}: {kind}, not {expected}{'; ' if hint else ''}{hint}"
    )


def _utf16_without_mark(head: bytes) -> bool:
    """Latin text in UTF-16 with no byte-order mark: a 0 at (nearly) every even or every odd byte, the others
    not 0 (a binary file has zeros at both)."""
    half = len(head) // 2
    even, odd = head[0::2].count(0), head[1::2].count(0)
    return half >= 4 and max(even, odd) >= 0.9 * half and min(even, odd) <= 0.1 * half


def not_utf8(name: str, raw: bytes, exc: UnicodeDecodeError | None = None) -> InputError:
    """The error for a text input that is not UTF-8: a UTF-16 file (Excel's "Unicode Text", Notepad's
    "Unicode") is named as such, where "not a UTF-8 text file (byte 0)" left the user to guess."""
    if raw[:2] in (b"\xff\xfe", b"\xfe\xff"):
        return InputError(f"{name}: a UTF-16 text file (it starts with UTF-16's byte-order mark); save it as UTF-8")
    if _utf16_without_mark(raw[:400]):
        return InputError(f"{name}: a UTF-16 text file (a 0 byte beside every character); save it as UTF-8")
    if b"\x00" in raw or exc is None:  # no text in any encoding: saving it "as UTF-8" is no advice
        return InputError(f"{name}: {BINARY_FILE}")
    # the line, and what to do: "not a UTF-8 text file (byte 18)" left a user to count bytes for a "è" typed
    # in a comment by an editor saving in the Windows code page
    line = raw.count(b"\n", 0, exc.start) + 1
    return InputError(
        f"{name}:{line}: not a UTF-8 text file (byte {exc.start}, 0x{raw[exc.start]:02x}: a character saved in "
        "another encoding, such as Windows-1252); save it as UTF-8"
    )


def one_line(text: str) -> str:
    """``text`` on one line: every run of whitespace (newlines included) becomes one space."""
    return " ".join(str(text).split())


class InputContext:
    """Where we are in an input file, for error messages: ``error(where, message)`` gives
    ``InputError("fname: where message")`` on one line; ``base_dir`` resolves the file's relative paths."""

    def __init__(self, fname: str, base_dir: str):
        self.fname = fname
        self.base_dir = base_dir

    def error(self, where: str, message: str) -> InputError:
        where = f"{where} " if where else ""
        return InputError(one_line(f"{self.fname}: {where}{message}"))
