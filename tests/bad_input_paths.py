"""Bad-input catalogue rows about the paths the command line names: the outputs a run writes (checked before
step 1), the file inspect reads, export's histories and --times file. Each row is (id, files, argv, exit code,
fragment); tests/test_bad_input_catalogue.py runs them.
"""

from __future__ import annotations

from bad_input_files import scen
from bad_input_options import RUN, WALL

# (id, files, argv, exit code, fragment of the one line)
PATH_ROWS = [
    # -- output paths (checked before step 1)
    (
        "out-exists",
        {**scen(), "r.rrd": "old"},
        (*RUN, "--out", "r.rrd"),
        2,
        "--out r.rrd: the file exists (add --force to replace it)",
    ),
    (
        "history-exists",
        {**scen(), "h.npz": "old"},
        (*RUN, "--no-recording", "--history", "h.npz"),
        2,
        "--history h.npz: the file exists (add --force",
    ),
    ("out-suffix", {**scen()}, (*RUN, "--out", "r.txt"), 2, "--out r.txt: the file name must end in .rrd"),
    (
        "history-suffix",
        {**scen()},
        (*RUN, "--no-recording", "--history", "h.txt"),
        2,
        "--history h.txt: the file name must end in .npz",
    ),
    (
        "out-and-history-same",
        {**scen()},
        (*RUN, "--out", "x.rrd", "--history", "x.rrd"),
        2,
        "--history x.rrd: the file name must end in .npz",
    ),
    (
        "out-and-history-same-file",
        {**scen(), "x.rrd": "", "x.npz": "@x.rrd"},
        (*RUN, "--out", "x.rrd", "--history", "x.npz", "--force"),
        2,
        "--out and --history name the same file",
    ),
    (
        "history-parent-is-file",
        {**scen(), "f": ""},
        (*RUN, "--no-recording", "--history", "f/h.npz"),
        2,
        "--history f/h.npz: f is not a folder",
    ),
    ("out-is-folder", {**scen(), "d.rrd/x": ""}, (*RUN, "--out", "d.rrd"), 2, "--out d.rrd: is a folder"),
    # Path("x.rrd/") is x.rrd: each of these wrote the file x.rrd (h.npz, …) without a word
    ("out-trailing-slash", {**scen()}, (*RUN, "--out", "x.rrd/"), 2, 'x.rrd/: a path ending in "/" names a folder'),
    ("out-trailing-dot", {**scen()}, (*RUN, "--out", "x.rrd/."), 2, 'x.rrd/.: a path ending in "/." names a folder'),
    (
        "history-trailing-slash",
        {**scen()},
        (*RUN, "--no-recording", "--history", "h.npz/"),
        2,
        "'--history': h.npz/: a path ending in \"/\" names a folder, not a file",
    ),
    ("check-out-trailing-slash", {**scen()}, ("check", "s.toml", "--out", "x.rrd/"), 2, "x.rrd/: a path ending in"),
    ("build-out-trailing-slash", {}, ("build", "wall", "--out", "w.geojson/"), 2, "w.geojson/: a path ending in"),
    ("limit-out-trailing-slash", {}, ("limit", "arch", "--out", "l.rrd/"), 2, "l.rrd/: a path ending in"),
    ("sweep-out-trailing-slash", {}, ("sweep", "wall", "-p", "amp=0.1", "--out", "s.csv/"), 2, "s.csv/: a path ending"),
    ("sweep-plot-trailing-slash", {}, ("sweep", "wall", "-p", "amp=0.1", "--plot", "p.png/"), 2, "'--plot': p.png/: a"),
    (
        "sweep-recording-trailing-slash",
        {},
        ("sweep", "wall", "-p", "amp=0.1", "--recording", "r.rrd/"),
        2,
        "'--recording': r.rrd/: a path ending in",
    ),
    # an existing folder keeps the message that names a file in it
    (
        "out-folder-with-slash",
        {"d/x": ""},
        (*WALL, "--out", "d/"),
        2,
        "--out d: is a folder (name a file in it: d/NAME",
    ),
    (
        "check-out-exists",
        {**scen(), "r.rrd": "old"},
        ("check", "s.toml", "--out", "r.rrd"),
        2,
        "--out r.rrd: the file exists",
    ),
    (
        "build-out-exists",
        {"w.geojson": "{}"},
        ("build", "wall", "--out", "w.geojson"),
        2,
        "--out w.geojson: the file exists (add --force",
    ),
    ("build-out-suffix", {}, ("build", "arch", "--out", "w.txt"), 2, "--out w.txt: the file name must end in .geojson"),
    (
        "limit-out-exists",
        {"r.rrd": "old"},
        ("limit", "arch", "--out", "r.rrd"),
        2,
        "--out r.rrd: the file exists (add --force to replace it)",
    ),
    # /proc is writable to root, yet no file can be made there; it said "the run would write about
    # 699.8 kB but /proc has 0 B free (shorten --duration …)"
    ("out-in-proc", {}, (*WALL, "--out", "/proc/x.rrd"), 2, "--out /proc/x.rrd: cannot write in /proc ("),
    (
        "history-in-proc",
        {},
        (*WALL, "--no-recording", "--history", "/proc/x.npz"),
        2,
        "--history /proc/x.npz: cannot write in /proc (",
    ),
    ("build-out-in-proc", {}, ("build", "wall", "--out", "/proc/w.geojson"), 2, "--out /proc/w.geojson: cannot write"),
    # it said "error: : no such scenario or geometry file"
    ("limit-empty-name", {}, ("limit", ""), 2, "the structure argument is empty (''): give wall, arch, aqueduct or"),
    # -- inspect
    ("inspect-missing", {}, ("inspect", "missing.rrd"), 2, "missing.rrd: no such recording"),
    # "" was read as "." (the working folder: "a folder, not a recording"), as --out "" once was
    ("inspect-empty-path", {"w.rrd": "x"}, ("inspect", ""), 2, "'REC.rrd|H.npz|S.csv': the path is empty"),
    (
        "inspect-not-rrd",
        {"bad.rrd": "not a recording"},
        ("inspect", "bad.rrd"),
        2,
        "bad.rrd: not a readable Rerun recording",
    ),
    # a damaged history: rerun's raw 'expected FourCC header "RRF2", got "PK\u{3}\u{4}"' at first, then
    # "a run history (.npz), not a recording" (inspect summarises histories since)
    (
        "inspect-damaged-history",
        {"H.npz": b"PK\x03\x04" + bytes(60)},
        ("inspect", "H.npz"),
        2,
        "H.npz: not a readable history (.npz): BadZipFile: File is not a zip file",
    ),
    # rerun's "Failed to decode frame: file too small to be an RRD" and a zip error; a recording cut before its
    # first message said "(ValueError: cut.rrd: no recording in this file)"
    ("inspect-empty-rrd", {"e.rrd": b""}, ("inspect", "e.rrd"), 2, "e.rrd: an empty file (0 bytes), not a recording"),
    ("inspect-empty-npz", {"e.npz": b""}, ("inspect", "e.npz"), 2, "e.npz: an empty file (0 bytes), not a recording"),
    # -- export
    ("export-missing", {}, ("export", "missing.npz"), 2, "missing.npz: no such history"),
    ("export-empty", {"e.npz": b""}, ("export", "e.npz"), 2, "e.npz: not a readable history (.npz): BadZipFile"),
    ("export-text", {"h.npz": "time,a\n"}, ("export", "h.npz"), 2, "h.npz: not a readable history (.npz)"),
    ("export-out-suffix", {}, ("export", "missing.npz", "--out", "s.xlsx"), 2, "--out s.xlsx: the file name must end"),
    ("export-out-exists", {"s.csv": "mine"}, ("export", "h.npz", "--out", "s.csv"), 2, "--out s.csv: the file exists"),
    ("export-every-0", {}, ("export", "h.npz", "--every", "0"), 2, "--every 0: keep every K-th frame, K ≥ 1"),
    # a history named twice said "--out and --out name the same file h.csv" (no --out given); --combined took it twice
    ("export-history-twice", {}, ("export", "h.npz", "h.npz"), 2, "h.npz: named twice (each history is exported once)"),
    (
        "export-combined-twice",
        {},
        ("export", "h.npz", "./h.npz", "--combined", "--out", "c.csv"),
        2,
        "h.npz: named twice",
    ),
    # an empty --blocks / --course (an unset "$BLOCKS") exported the top course without a word
    ("export-blocks-empty", {}, ("export", "h.npz", "--blocks", ""), 2, "--blocks '': an empty list (block names"),
    ("export-course-empty", {}, ("export", "h.npz", "--course", " "), 2, "--course ' ': an empty list (course numbers"),
    ("export-one-csv-two-runs", {}, ("export", "a/h.npz", "b/h.npz", "--out", "o"), 2, "a/h.npz and b/h.npz: both"),
    # -- export --times: the lab's file is read before the histories
    (
        "export-times-no-time",
        {"lab.csv": "a,b (mm)\n0,1\n"},
        ("export", "h.npz", "--times", "lab.csv"),
        2,
        "lab.csv:1: no time column",
    ),
    (
        "export-times-back",
        {"lab.csv": "time (s),x\n0.1,1\n0.05,2\n"},
        ("export", "h.npz", "--times", "lab.csv"),
        2,
        "lab.csv:3: time 0.05 is not after the previous sample's 0.1",
    ),
    (
        "export-times-nan",
        {"lab.csv": "t (ms),x\n0,1\nNaN,2\n"},
        ("export", "h.npz", "--times", "lab.csv"),
        2,
        "lab.csv:3: time NaN is not a finite",
    ),
    (
        "export-times-xlsx",
        {"lab.xlsx": b"PK\x03\x04" + bytes(40)},
        ("export", "h.npz", "--times", "lab.xlsx"),
        2,
        "lab.xlsx: a zip file (an Excel workbook?), not a CSV",
    ),
    (
        "export-combined-no-out",
        {},
        ("export", "a.npz", "b.npz", "--combined"),
        2,
        "--combined: name the table with --out",
    ),
    (
        "inspect-cut-before-a-message",
        {"cut.rrd": bytes.fromhex("52524632002900000102000001000000000000005e000000")},
        ("inspect", "cut.rrd"),
        2,
        "cut.rrd: not a readable Rerun recording: no complete recording in its 24 bytes (cut short, or damaged)",
    ),
    (
        "inspect-scenario",
        {**scen()},
        ("inspect", "s.toml"),
        2,
        "s.toml: a scenario file (TOML; run it with masonry run), not a recording",
    ),
    ("inspect-folder", {"d.rrd/x": ""}, ("inspect", "d.rrd"), 2, "d.rrd: a folder, not a recording (it holds no .rrd"),
    (
        "inspect-folder-of-recordings",
        {"recs/a.rrd": "", "recs/b.rrd": "", "recs/notes.txt": ""},
        ("inspect", "recs"),
        2,
        "recs: a folder, not a recording; it holds 2 recordings (a.rrd, b.rrd): give one, e.g. masonry inspect recs/",
    ),
    # walk-through 2026-11-28: the command suggested for a folder with a space could not be pasted
    # ("masonry inspect my recs/a.rrd"), and an .AT2 record got rerun's 'Not an RRD file: expected FourCC header'
    (
        "inspect-folder-with-a-space",
        {"my recs/a.rrd": ""},
        ("inspect", "my recs"),
        2,
        "my recs: a folder, not a recording; it holds 1 recording (a.rrd): give one, e.g. masonry inspect 'my recs/a.rrd'",
    ),
    (
        "inspect-at2-record",
        {"q.AT2": "PEER NGA STRONG MOTION DATABASE RECORD\n"},
        ("inspect", "q.AT2"),
        2,
        "q.AT2: a ground-motion record (PEER .AT2; simulate and run take it with --record), not a recording; inspect "
        "reads the .rrd recordings that --out writes (its PGA, PGV, Arias and length as a run applies it: masonry "
        "check wall --record q.AT2)",
    ),
    (  # said rerun's 'Not an RRD file: expected FourCC header "RRF2", got "Orig"'
        "inspect-knet-record",
        {"q.EW2": "Origin Time       2011/03/11 14:46:00\n"},
        ("inspect", "q.EW2"),
        2,
        "q.EW2: a ground-motion record (K-NET .EW2; simulate and run take it with --record), not a recording",
    ),
]
