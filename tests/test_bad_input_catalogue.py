"""The bad-input catalogue: every row is an input a user may give, the exit code and a fragment of the one
line the tool must print — a fragment that says *where* (file, table, key, option, line).

Files of a row are written to a fresh folder that is also the working directory; ``{d}`` in an argument
is that folder. Every row runs in-process (CliRunner) and stops before step 1, so the table is cheap.
"""

from __future__ import annotations

import os

import pytest
from typer.testing import CliRunner

from masonrycli.cli import app

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


def feature(coords, role: str = "block", name: str = "a", gtype: str = "Polygon") -> str:
    import json

    geometry = {"type": gtype, "coordinates": coords}
    return json.dumps(
        {
            "type": "FeatureCollection",
            "features": [{"type": "Feature", "properties": {"role": role, "name": name}, "geometry": geometry}],
        }
    )


SQUARE = [[[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]]]
WALL = ("simulate", "wall", "--duration", "0.01")
ARCH = ("simulate", "arch", "--duration", "0.01")
RUN = ("run", "s.toml")

# (id, files, argv, exit code, fragment of the one line)
CATALOGUE = [
    # -- scenario TOML: [run] and [material]
    (
        "run-duration-string",
        scen('duration = "1.0"'),
        ("check", "s.toml"),
        2,
        's.toml: [run] duration = "1.0": must be a number',
    ),
    ("run-dt-negative", scen("dt = -0.001"), ("check", "s.toml"), 2, "s.toml: [run] dt = -0.001: must be > 0"),
    (
        "run-dt-not-dividing",
        scen("duration = 1.0\ndt = 0.3"),
        ("check", "s.toml"),
        2,
        "[run] dt = 0.3: does not divide duration = 1.0",
    ),
    (
        "run-too-many-steps",
        scen("duration = 1e5\ndt = 1e-4"),
        ("check", "s.toml"),
        2,
        "[run] dt = 0.0001: gives 1e+09 steps",
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
    ("run-tolerance", scen("tolerance = 2"), ("check", "s.toml"), 2, "[run] tolerance = 2: must be < 1"),
    (
        "run-unknown-key",
        scen("durration = 1.0"),
        ("check", "s.toml"),
        2,
        's.toml: [run] unknown key "durration" (did you mean "duration"?)',
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
        "s.toml: not a UTF-8 text file (byte",
    ),
    ("top-level-unknown", {"s.toml": f"blok = 1\n{SCENE}"}, ("check", "s.toml"), 2, 's.toml: unknown key "blok"'),
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
        's.toml: [structure] builder = "tower"',
    ),
    (
        "structure-file-format",
        {"s.toml": '[structure]\nfile = "w.txt"\n', "w.txt": ""},
        ("check", "s.toml"),
        2,
        "s.toml: [structure] file = ",
    ),
    (
        "structure-file-missing",
        {"s.toml": '[structure]\nfile = "missing.geojson"\n'},
        ("check", "s.toml"),
        2,
        "missing.geojson",
    ),
    ("scenario-missing", {}, ("check", "no-such.toml"), 2, "no-such.toml: cannot read scenario"),
    (
        "scenario-is-folder",
        {"sub.toml/x": ""},
        ("check", "sub.toml"),
        2,
        "sub.toml: cannot read scenario: is a directory",
    ),
    # -- GeoJSON (run and check read it alike)
    ("geojson-not-json", {"g.geojson": "{ not json"}, ("check", "g.geojson"), 2, "g.geojson: "),
    (
        "geojson-string-coordinate",
        {"g.geojson": feature([[[0, 0], [1, 0], [1, "x"], [0, 0]]])},
        ("check", "g.geojson"),
        2,
        'g.geojson: feature 0 (block 0 "a"): coordinates must be [x, y] number pairs',
    ),
    (
        "geojson-nan",
        {"g.geojson": feature([[[0, 0], [1, 0], [1, float("nan")], [0, 0]]])},
        ("run", "g.geojson", "--no-recording"),
        2,
        'g.geojson: feature 0: block 0 ("a"): vertex 2 has a NaN',
    ),
    ("geojson-role", {"g.geojson": feature(SQUARE, role="roof")}, ("check", "g.geojson"), 2, "g.geojson: feature 0"),
    ("geojson-point", {"g.geojson": feature([0, 0], gtype="Point")}, ("check", "g.geojson"), 2, "g.geojson: feature 0"),
    (
        "geojson-non-convex",
        {"g.geojson": feature([[[0, 0], [2, 0], [1, 0.5], [1, 2], [0, 0]]])},
        ("check", "g.geojson"),
        2,
        'g.geojson: feature 0: block 0 ("a"): polygon is not convex',
    ),
    (
        "geojson-no-features",
        {"g.geojson": '{"type": "FeatureCollection", "features": []}'},
        ("check", "g.geojson"),
        2,
        "g.geojson: ",
    ),
    ("geojson-missing", {}, ("run", "nope.geojson"), 2, "nope.geojson: no such file"),
    # -- WKT
    (
        "wkt-nan",
        {"n.wkt": "POLYGON ((0 0, nan 0, 1 1, 0 1, 0 0))\n"},
        ("run", "n.wkt", "--no-recording"),
        2,
        'n.wkt: line 1: block 0 ("block-0"): vertex 1 has a NaN or infinite coordinate',
    ),
    ("wkt-garbage", {"n.wkt": "POLYGON ((0 0, 1 0\n"}, ("check", "n.wkt"), 2, "n.wkt: line 1"),
    ("wkt-linestring", {"n.wkt": "LINESTRING (0 0, 1 1)\n"}, ("check", "n.wkt"), 2, "n.wkt: line 1"),
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
    # -- every option of run / check / simulate / build
    ("opt-dt", {**scen()}, (*RUN, "--dt", "-1", "--no-recording"), 2, "--dt: dt = -1.0: must be > 0"),
    ("opt-dt-text", {**scen()}, (*RUN, "--dt", "abc"), 2, "Invalid value for '--dt'"),
    ("opt-duration", {**scen()}, (*RUN, "--duration", "0", "--no-recording"), 2, "--duration: duration = 0"),
    (
        "opt-duration-dt-steps",
        {**scen()},
        (*RUN, "--duration", "1e5", "--dt", "1e-4", "--no-recording"),
        2,
        "--duration and --dt: dt = 0.0001: gives 1e+09 steps",
    ),
    (
        "opt-dt-not-dividing",
        {**scen()},
        (*RUN, "--dt", "0.3", "--no-recording"),
        2,
        "--dt: dt = 0.3: does not divide duration",
    ),
    ("opt-theta", {**scen()}, (*RUN, "--theta", "0.2", "--no-recording"), 2, "--theta: theta = 0.2"),
    ("opt-friction", {**scen()}, (*RUN, "--friction", "nan", "--no-recording"), 2, "--friction: friction = nan"),
    (
        "opt-record-every",
        {**scen()},
        (*RUN, "--record-every", "0", "--no-recording"),
        2,
        "--record-every: record_every = 0",
    ),
    ("opt-tolerance", {**scen()}, (*RUN, "--tolerance", "1", "--no-recording"), 2, "--tolerance: tolerance = 1"),
    (
        "opt-max-iterations",
        {**scen()},
        (*RUN, "--max-iterations", "0", "--no-recording"),
        2,
        "--max-iterations: max_iterations = 0",
    ),
    ("opt-unknown", {**scen()}, (*RUN, "--bogus"), 2, "No such option: --bogus"),
    ("check-opt-dt", {**scen()}, ("check", "s.toml", "--dt", "-1"), 2, "--dt: dt = -1"),
    ("sim-density", {}, (*WALL, "--density", "-5", "--no-recording"), 2, "--density: density = -5"),
    ("sim-thickness", {}, (*WALL, "--thickness", "0", "--no-recording"), 2, "--thickness: thickness = 0"),
    ("sim-blocks", {}, (*WALL, "--blocks", "0", "--no-recording"), 2, "block count"),
    (
        "sim-blocks-impossible",
        {},
        (*WALL, "--blocks", "51", "--courses", "5", "--no-recording"),
        2,
        'builder "wall": wall: 51 blocks cannot be laid in running bond with 5 courses',
    ),
    (
        "sim-length",
        {},
        (*WALL, "--courses", "8", "--length", "10", "--no-recording"),
        2,
        "length 10 m is not a whole number of 0.3 m blocks",
    ),
    ("sim-courses", {}, (*WALL, "--courses", "0", "--no-recording"), 2, "courses"),
    ("sim-block-length", {}, (*WALL, "--block-length", "-0.3", "--no-recording"), 2, "block_length"),
    (
        "sim-settlement-wall",
        {},
        (*WALL, "--settlement", "0.01", "--no-recording"),
        2,
        "--settlement: the wall stands on one ground",
    ),
    (
        "sim-settlement-negative",
        {},
        (*ARCH, "--settlement", "-1", "--no-recording"),
        2,
        "--settlement -1.0: must be >= 0",
    ),
    ("sim-settlement-and-amp", {}, (*ARCH, "--amp", "1", "--no-recording"), 2, "--settlement with --amp"),
    ("sim-amp-nan", {}, (*WALL, "--amp", "nan", "--no-recording"), 2, "--amp/--freq:"),
    ("sim-freq-negative", {}, (*WALL, "--freq", "-1", "--no-recording"), 2, "--amp/--freq:"),
    ("sim-voussoirs", {}, (*ARCH, "--voussoirs", "1", "--no-recording"), 2, 'builder "arch"'),
    ("sim-span", {}, (*ARCH, "--span", "-1", "--no-recording"), 2, 'builder "arch"'),
    ("build-blocks", {}, ("build", "wall", "--blocks", "0", "--out", "w.geojson"), 2, "wall: wall: block count"),
    (
        "sim-block-height",
        {},
        (*WALL, "--block-height", "0", "--no-recording"),
        2,
        "wall: block_height must be a positive",
    ),
    (
        "sim-pier-courses",
        {},
        (*ARCH, "--pier-courses", "0", "--no-recording"),
        2,
        "arch: pier_courses must be an integer",
    ),
    ("sim-ring-thickness", {}, (*ARCH, "--ring-thickness", "-1", "--no-recording"), 2, "arch: ring_thickness must be"),
    ("sim-pier-width", {}, (*ARCH, "--pier-width", "0", "--no-recording"), 2, "arch: pier_width must be a positive"),
    ("sim-wall-courses", {}, ("simulate", "aqueduct", "--wall-courses", "0", "--no-recording"), 2, "wall_courses must"),
    ("sim-record-missing", {}, (*WALL, "--record", "nope.at2", "--no-recording"), 2, "nope.at2: cannot read record"),
    ("sim-scale-alone", {}, (*WALL, "--scale", "2", "--no-recording"), 2, "--scale: goes with --record"),
    (
        "limit-load",
        {},
        ("limit", "arch", "--load", "bogus"),
        2,
        "--load bogus: expected one of horizontal, tilt, point",
    ),
    ("limit-direction", {}, ("limit", "arch", "--direction", "up"), 2, "--direction up: expected one of +x, -x"),
    ("limit-point-no-block", {}, ("limit", "arch", "--load", "point"), 2, "--load point: name the loaded block"),
    ("limit-friction", {}, ("limit", "arch", "--friction", "-1"), 2, "--friction: friction = -1.0: must be >= 0"),
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
    # -- inspect
    ("inspect-missing", {}, ("inspect", "missing.rrd"), 2, "missing.rrd: no such recording"),
    (
        "inspect-not-rrd",
        {"bad.rrd": "not a recording"},
        ("inspect", "bad.rrd"),
        2,
        "bad.rrd: not a readable Rerun recording",
    ),
    ("inspect-folder", {"d.rrd/x": ""}, ("inspect", "d.rrd"), 2, "d.rrd: no such recording"),
]


def write_files(folder, files: dict) -> None:
    for name, content in files.items():
        path = folder / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, str) and content.startswith("@"):  # a symbolic link to another file
            os.symlink(folder / content[1:], path)
        elif isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content)


def test_catalogue_is_large_enough():
    assert len(CATALOGUE) >= 60
    assert len({row[0] for row in CATALOGUE}) == len(CATALOGUE)


@pytest.mark.parametrize("name, files, argv, code, fragment", CATALOGUE, ids=[row[0] for row in CATALOGUE])
def test_bad_input(name, files, argv, code, fragment, tmp_path, monkeypatch):
    write_files(tmp_path, files)
    monkeypatch.chdir(tmp_path)
    before = sorted(p.name for p in tmp_path.rglob("*"))
    result = CliRunner().invoke(app, [a.format(d=tmp_path) for a in argv])
    assert result.exit_code == code, result.output
    assert "Traceback" not in result.output
    lines = [ln for ln in result.output.splitlines() if ln.strip()]
    assert len(lines) == 1, result.output
    assert lines[0].startswith("error: "), lines[0]
    assert fragment in lines[0], lines[0]
    assert sorted(p.name for p in tmp_path.rglob("*")) == before  # nothing written, not even a temporary file
