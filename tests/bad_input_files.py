"""Bad-input catalogue rows about input files: scenario TOML and motion CSV records (GeoJSON and WKT:
bad_input_geometry.py).

Each row is (id, files, argv, exit code, fragment of the one line); tests/test_bad_input_catalogue.py runs them.
"""

from __future__ import annotations

BLOCK = 'name = "b1"\npolygon = [[0, 0], [1, 0], [1, 1], [0, 1]]\n'
GROUND = '[[support]]\nname = "ground"\npolygon = [[-2, -1], [3, -1], [3, 0], [-2, 0]]\n'
SCENE = f"[[block]]\n{BLOCK}{GROUND}"


def scen(run: str = "", block: str = BLOCK, extra: str = "") -> dict:
    """A valid one-block scenario s.toml with ``run`` in [run], the block table and ``extra`` appended."""
    head = f"[run]\n{run}\n" if run else ""
    return {"s.toml": f"{head}[[block]]\n{block}{GROUND}{extra}"}


def sine(motion: str) -> dict:
    return {"s.toml": f"[[block]]\n{BLOCK}{GROUND}motion = {{ {motion} }}\n"}


def record(csv: str) -> dict:
    return {"q.csv": csv, "s.toml": f'[[block]]\n{BLOCK}{GROUND}motion = {{ kind = "record", file = "q.csv" }}\n'}


# (id, files, argv, exit code, fragment of the one line)
FILE_ROWS = [
    # paths that exist but are no file: /dev/zero was read for ever (the command hung), and the commands
    # that ask is_file() called it missing ("no such scenario or geometry file", "no such recording")
    ("scenario-dev-zero", {}, ("run", "/dev/zero"), 2, "/dev/zero: not a regular file (a device, a pipe or a socket)"),
    ("limit-dev-zero", {}, ("limit", "/dev/zero"), 2, "/dev/zero: not a regular file (a device, a pipe or a socket)"),
    ("inspect-dev-zero", {}, ("inspect", "/dev/zero"), 2, "/dev/zero: not a regular file"),
    (
        "sweep-records-dev-zero",
        {},
        ("sweep", "wall", "--records", "/dev/zero"),
        2,
        "--records /dev/zero: not a regular",
    ),
    (
        "scenario-record-dev-zero",
        scen(extra='motion = { kind = "record", file = "/dev/zero" }\n'),
        ("check", "s.toml"),
        2,
        'motion.file = "/dev/zero": not a regular file (a device, a pipe or a socket)',
    ),
    # -- scenario TOML: [run] and [material]
    (
        "run-duration-string",
        scen('duration = "1.0"'),
        ("check", "s.toml"),
        2,
        's.toml:2: [run] duration = "1.0": must be a number',
    ),
    ("run-dt-negative", scen("dt = -0.001"), ("check", "s.toml"), 2, "s.toml:2: [run] dt = -0.001: must be > 0"),
    (
        "run-dt-not-dividing",
        scen("duration = 1.0\ndt = 0.3"),
        ("check", "s.toml"),
        2,
        "[run] duration = 1.0 is not a whole number of steps of dt = 0.3",
    ),
    (
        "run-too-many-steps",
        scen("duration = 1e5\ndt = 1e-4"),
        ("check", "s.toml"),
        2,
        "[run] duration = 100000.0 at dt = 0.0001 is 1,000,000,000 steps",
    ),
    ("run-theta", scen("theta = 0.2"), ("check", "s.toml"), 2, "[run] theta = 0.2: must be >= 0.5"),
    ("run-record-every-0", scen("record_every = 0"), ("check", "s.toml"), 2, "[run] record_every = 0: must be >= 1"),
    (
        "run-max-iterations-float",
        scen("max_iterations = 1.5"),
        ("check", "s.toml"),
        2,
        "[run] max_iterations = 1.5: must be an integer",
    ),
    ("run-gravity-short", scen("gravity = [0]"), ("check", "s.toml"), 2, "[run] gravity = [0]: must be 2 numbers"),
    (  # it ran (a block on the ground at 1e8 g, "intact")
        "run-gravity-absurd",
        scen("gravity = [0, -1e9]"),
        ("check", "s.toml"),
        2,
        "[run] gravity = [0.0, -1000000000.0]: |g| = 1e+09 m/s² is more than 10000 (about 1000 g; a likely typo)",
    ),
    (  # the integers below overflowed float(): a traceback
        "run-dt-huge-integer",
        scen(f"dt = {10**400}"),
        ("check", "s.toml"),
        2,
        "s.toml:2: [run] dt = 100000000000000000000000000000000000000000000000000000000...: must be a finite number",
    ),
    (
        "block-vertex-huge-integer",
        scen(block=f'name = "b1"\npolygon = [[0, 0], [{10**400}, 0], [1, 1]]\n'),
        ("check", "s.toml"),
        2,
        '[[block]] #1 ("b1"): polygon[1] = [1000000000000000000000000000000000000000000000000000000',
    ),
    ("run-tolerance", scen("tolerance = 2"), ("check", "s.toml"), 2, "[run] tolerance = 2: must be < 1"),
    (
        "run-unknown-key",
        scen("durration = 1.0"),
        ("check", "s.toml"),
        2,
        's.toml:2: [run] unknown key "durration" (did you mean "duration"?)',
    ),
    (
        "material-friction",
        {"s.toml": f"[material]\nfriction = -1\n{SCENE}"},
        ("check", "s.toml"),
        2,
        "[material] friction = -1: must be >= 0",
    ),
    ("toml-syntax", {"s.toml": "[run\nduration = 1"}, ("check", "s.toml"), 2, "s.toml: TOML syntax error"),
    (
        "toml-not-utf8",
        {"s.toml": b"[run]\nname = '\xff'\n"},
        ("check", "s.toml"),
        2,
        "s.toml:2: not a UTF-8 text file (byte 14, 0xff",
    ),
    (  # nested arrays made tomllib and json recurse: RecursionError, a traceback
        "toml-nested-too-deeply",
        {"s.toml": "a = " + "[" * 5000 + "]" * 5000 + "\n"},
        ("check", "s.toml"),
        2,
        "s.toml: TOML nested too deeply",
    ),
    (
        "geojson-nested-too-deeply",
        {"g.geojson": "[" * 100000 + "]" * 100000},
        ("check", "g.geojson"),
        2,
        "g.geojson: invalid GeoJSON (JSON nested too deeply)",
    ),
    ("top-level-unknown", {"s.toml": f"blok = 1\n{SCENE}"}, ("check", "s.toml"), 2, 's.toml:1: unknown key "blok"'),
    # -- scenario TOML: blocks and supports
    (
        "no-blocks",
        {"s.toml": "[run]\nduration = 1.0\n"},
        ("check", "s.toml"),
        2,
        "s.toml: no blocks: add [[block]] tables or a [structure] builder",
    ),
    (
        "duplicate-name",
        {
            "s.toml": f"[[block]]\n{BLOCK}[[block]]\n{BLOCK.replace('0, 0], [1, 0', '0, 2], [1, 2').replace('[1, 1], [0, 1]', '[1, 3], [0, 3]')}"
        },
        ("check", "s.toml"),
        2,
        '[[block]] #2 ("b1"): name = "b1": already used by [[block]] #1 ("b1")',
    ),
    (
        "block-velocity-inf",
        scen(block=BLOCK + "velocity = [inf, 0, 0]\n"),
        ("check", "s.toml"),
        2,
        '[[block]] #1 ("b1"): velocity = [inf, 0, 0]: must be finite numbers',
    ),
    (
        "block-velocity-short",
        scen(block=BLOCK + "velocity = [1, 0]\n"),
        ("check", "s.toml"),
        2,
        '[[block]] #1 ("b1"): velocity = [1, 0]: must be 3 numbers',
    ),
    (
        "block-two-vertices",
        scen(block='name = "b1"\npolygon = [[0, 0], [1, 0]]\n'),
        ("check", "s.toml"),
        2,
        '[[block]] #1 ("b1"): polygon = [[0, 0], [1, 0]]: needs at least 3 vertices',
    ),
    (
        "block-vertex-nan",
        scen(block='name = "b1"\npolygon = [[0, 0], [nan, 0], [1, 1]]\n'),
        ("check", "s.toml"),
        2,
        '[[block]] #1 ("b1"): polygon[1] = [nan, 0]: must be finite numbers',
    ),
    (
        "block-non-convex",
        scen(block='name = "dart"\npolygon = [[0, 0], [2, 0], [1, 0.5], [1, 2]]\n'),
        ("check", "s.toml"),
        2,
        '[[block]] #1 ("dart"): ',
    ),
    ("block-no-polygon", scen(block='name = "b1"\n'), ("check", "s.toml"), 2, '[[block]] #1 ("b1"): polygon: missing'),
    (
        "block-density-zero",
        scen(block=BLOCK + "density = 0\n"),
        ("check", "s.toml"),
        2,
        '[[block]] #1 ("b1"): density = 0: must be > 0',
    ),
    (
        "block-unknown-key",
        scen(block=BLOCK + 'colour = "red"\n'),
        ("check", "s.toml"),
        2,
        '[[block]] #1 ("b1"): unknown key "colour"',
    ),
    (
        "block-empty-name",
        scen(block='name = ""\npolygon = [[0, 0], [1, 0], [1, 1]]\n'),
        ("check", "s.toml"),
        2,
        '[[block]] #1: name = "": must not be empty',
    ),
    (
        "blocks-overlap",
        {
            "s.toml": '[[block]]\nname = "a"\npolygon = [[0, 0], [1, 0], [1, 1], [0, 1]]\n[[block]]\nname = "b"\npolygon = [[0.5, 0], [1.5, 0], [1.5, 1], [0.5, 1]]\n'
        },
        ("check", "s.toml"),
        2,
        '"b"',
    ),
    (
        "motion-kind",
        sine('kind = "wobble"'),
        ("check", "s.toml"),
        2,
        '[[support]] #1 ("ground"): motion.kind = "wobble": unknown motion kind',
    ),
    (
        "motion-missing-amplitude",
        sine('kind = "sine", frequency = 2.0'),
        ("check", "s.toml"),
        2,
        '[[support]] #1 ("ground"): motion.amplitude: missing',
    ),
    (
        "motion-frequency-nan",
        sine('kind = "sine", amplitude = 1.0, frequency = nan'),
        ("check", "s.toml"),
        2,
        '[[support]] #1 ("ground"): motion.frequency = nan',
    ),
    (  # sin(1e300 + 2π·f·t) is sin(1e300) at every step: a constant velocity that ran without a word
        "motion-phase-absurd",
        sine('kind = "sine", amplitude = 1.0, frequency = 2, phase = 1e300'),
        ("check", "s.toml"),
        2,
        "motion.phase = 1e+300: must be within ±10000 rad (the sine repeats every 2π; a likely typo)",
    ),
    (
        "motion-unused-key",
        sine('kind = "fixed", amplitude = 1.0'),
        ("check", "s.toml"),
        2,
        '[[support]] #1 ("ground"): motion.amplitude: not used by kind "fixed"',
    ),
    (
        "motion-record-missing-file",
        sine('kind = "record", file = "nope.csv"'),
        ("check", "s.toml"),
        2,
        '[[support]] #1 ("ground"): motion.file = "nope.csv": no such file',
    ),
    (
        "structure-unknown-builder",
        {"s.toml": '[structure]\nbuilder = "tower"\n'},
        ("check", "s.toml"),
        2,
        's.toml:2: [structure] builder = "tower"',
    ),
    (
        # a builder's check names the key and its line (the option, given on the command line: bad_input_options)
        "structure-builder-check",
        {"s.toml": '# an arch\n[structure]\nbuilder = "arch"\nring_thickness = 0.0001\n'},
        ("check", "s.toml"),
        2,
        's.toml:4: [structure] builder "arch": ring_thickness 0.0001 m is absurd (a likely typo: 0.001 to 1000 m)',
    ),
    (
        "structure-file-format",
        {"s.toml": '[structure]\nfile = "w.txt"\n', "w.txt": ""},
        ("check", "s.toml"),
        2,
        "s.toml:2: [structure] file = ",
    ),
    (
        "structure-file-missing",
        {"s.toml": '[structure]\nfile = "missing.geojson"\n'},
        ("check", "s.toml"),
        2,
        "missing.geojson",
    ),
    (  # it said "not a regular file (a device, a pipe or a socket)"
        "structure-file-is-folder",
        {"s.toml": '[structure]\nfile = "d.geojson"\n', "d.geojson/x": ""},
        ("check", "s.toml"),
        2,
        'd.geojson": is a directory',
    ),
    ("scenario-missing", {}, ("check", "no-such.toml"), 2, "no-such.toml: no such scenario or geometry file"),
    (
        "scenario-is-folder",
        {"sub.toml/x": ""},
        ("check", "sub.toml"),
        2,
        "sub.toml: is a directory, not a scenario or geometry file",
    ),
    # -- motion CSV records
    (
        "csv-not-a-number",
        record("t,v\n0,0\n1,abc\n"),
        ("check", "s.toml"),
        2,
        ('[[support]] #1 ("ground"): motion.file: q.csv:3: not a number: "abc"'),
    ),
    (
        "csv-four-columns",
        record("0,0,0,0\n"),
        ("check", "s.toml"),
        2,
        "q.csv:1: expected 2 columns (time, value) or 3 (time, x, y), got 4",
    ),
    (
        "csv-column-mismatch",
        record("0,0\n1,0,0\n"),
        ("check", "s.toml"),
        2,
        "q.csv:2: expected 2 columns like the first sample, got 3",
    ),
    ("csv-decreasing", record("0,0\n1,0\n0.5,0\n"), ("check", "s.toml"), 2, "q.csv:3:"),
    ("csv-infinite", record("0,0\n1,inf\n"), ("check", "s.toml"), 2, "q.csv:2:"),
    ("csv-one-sample", record("0,0\n"), ("check", "s.toml"), 2, "q.csv"),
    # -- report: the history read as export reads it, --out checked first (export's rule: never overwritten)
    ("report-missing", {}, ("report", "missing.npz"), 2, "missing.npz: no such history"),
    (
        "report-recording",
        {"w.rrd": b"RRF2" + bytes(60)},
        ("report", "w.rrd"),
        2,
        "w.rrd: a Rerun recording (.rrd), not",
    ),
    ("report-study-table", {"s.csv": "amp,state\n0.1,intact\n"}, ("report", "s.csv"), 2, "s.csv: a CSV table, not a"),
    ("report-text", {"h.npz": "time,a\n"}, ("report", "h.npz"), 2, "h.npz: not a readable history (.npz)"),
    ("report-folder", {"d/x": ""}, ("report", "d"), 2, "d: a folder, not a history"),
    ("report-out-exists", {"r.md": "mine"}, ("report", "h.npz", "--out", "r.md"), 2, "--out r.md: the file exists"),
    (
        "report-figure-exists",
        {"r.png": "mine"},
        ("report", "h.npz", "--out", "r.md"),
        2,
        "--out r.md's figure r.png: the file exists (add --force",
    ),
    ("report-out-suffix", {}, ("report", "h.npz", "--out", "r.txt"), 2, "--out r.txt: the file name must end in .md"),
    # an accelerogram's time step over 0.1 s: DT = 10 ran, read as a record of 70 s (a warning on its length only)
    (
        "at2-dt-absurd",
        {"q.AT2": "PEER\nx\nACCELERATION TIME SERIES IN UNITS OF G\nNPTS= 3, DT= 10 SEC\n0.0 0.1 0.0\n"},
        ("check", "wall", "--record", "q.AT2"),
        2,
        "q.AT2:4: DT = 10: must be within 1e-06–1 s",
    ),
    (
        "at2-dt-coarse",
        {"q.AT2": "PEER\nx\nACCELERATION TIME SERIES IN UNITS OF G\nNPTS= 3, DT= 0.5 SEC\n0.0 0.1 0.0\n"},
        ("sweep", "wall", "--records", "q.AT2", "--scale", "1,2", "--workers", "0"),
        2,
        "q.AT2:4: DT = 0.5: an acceleration record sampled every 0.5 s holds nothing above 1 Hz",
    ),
    (
        "one-column-acceleration-coarse",
        {"q.csv": "acc (g)\n0\n0.1\n0\n"},
        ("check", "wall", "--record", "q.csv", "--record-dt", "0.5"),
        2,
        "q.csv: acceleration samples 0.5 s apart (the time step given) hold nothing above 1 Hz",
    ),
]
