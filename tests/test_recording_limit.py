"""The mechanism recording of a limit analysis: complete file, both copies, the mechanism moved rigidly."""

from __future__ import annotations

import numpy as np
import pytest
import rerun as rr

from masonrycli.limit import LiveLoad, analyse
from masonrycli.limit.drawing import write_recording
from masonrycli.recording import inspect_recording
from masonrycli.recording.colormap import VIRIDIS
from masonrycli.recording.limit import (
    FILL,
    HINGES,
    LIMIT_PATHS,
    MAGNIFIED_SHARE,
    OUTLINES,
    SPEED_BAR,
    SPEED_LABELS,
    SPEED_TITLE,
    STEPS,
    THRUST,
)

from limit_helpers import column


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    result = analyse(column(2, 0.4, 0.8, 0.9), LiveLoad("horizontal"))  # both blocks tip as one about (0.4, 0)
    path = tmp_path_factory.mktemp("limit") / "mechanism.rrd"
    write_recording(result, path)
    return path, result


def rows(path, entity: str, column_name: str) -> dict[int, list]:
    out = {}
    for chunk in rr.chunk.RrdReader(path).stream():
        if chunk.entity_path == f"/{entity}" and not chunk.is_static:
            batch = chunk.to_record_batch()
            if column_name in batch.schema.names:
                for step, value in zip(batch.column("step").to_pylist(), batch.column(column_name).to_pylist()):
                    out[step] = value
    return out


def test_file_is_complete_with_a_blueprint_and_every_entity(written):
    path, _ = written
    info = inspect_recording(path)
    assert info["complete"] and info["has_blueprint"] and info["application_id"] == "masonry"
    assert info["steps"] == (0, STEPS)
    assert {f"/{p}" for p in LIMIT_PATHS} <= set(info["entity_paths"])


def test_undeformed_copy_stays_and_the_mechanism_copy_rotates_about_the_hinge(written):
    path, result = written
    strips = rows(path, OUTLINES, "LineStrips2D:strips")
    first, last = (np.array(strips[k], dtype=float) for k in (0, STEPS))
    # Four closed outlines: the two blocks as built, then the two blocks of the mechanism copy.
    assert len(first) == 4
    np.testing.assert_allclose(first[:2], last[:2], atol=1e-6)  # the undeformed copy never moves
    shift = first[2][0] - first[0][0]
    assert shift[0] > 0.4 and abs(shift[1]) < 1e-6  # beside it, on the right
    # Full amplitude: the fastest point (the top corner r = √(0.4² + 1.6²) from the toe) turned by
    # θ = MAGNIFIED_SHARE × size / r about the toe, so it moved 2 r sin(θ/2).
    r = np.hypot(0.4, 1.6)
    theta = MAGNIFIED_SHARE * 1.6 / r
    moved = np.hypot(*(last[2:] - first[2:]).reshape(-1, 2).T).max()
    assert moved == pytest.approx(2 * r * np.sin(theta / 2), rel=1e-5)
    # Rigid rotation about the hinge (0.4, 0) (shifted): the toe corner does not move.
    toe = np.array([0.4, 0.0]) + shift
    d0 = np.linalg.norm(first[2] - toe, axis=1)
    d1 = np.linalg.norm(last[2] - toe, axis=1)
    np.testing.assert_allclose(d0, d1, atol=1e-5)


def test_hinge_drawn_on_both_copies_and_thrust_points_static(written):
    path, result = written
    hinges = rows(path, HINGES, "Points2D:positions")
    assert len(hinges[STEPS]) == 2 * len(result.hinges) == 2
    np.testing.assert_allclose(hinges[STEPS][0], [0.4, 0.0], atol=1e-6)
    assert FILL in {c.entity_path.lstrip("/") for c in rr.chunk.RrdReader(path).stream()}
    thrust = [c for c in rr.chunk.RrdReader(path).stream() if c.entity_path == f"/{THRUST}" and c.is_static]
    assert thrust


def static_column(path, entity: str, column_name: str) -> list:
    for chunk in rr.chunk.RrdReader(path).stream():
        if chunk.entity_path == f"/{entity}" and chunk.is_static:
            batch = chunk.to_record_batch()
            if column_name in batch.schema.names:
                return batch.column(column_name).to_pylist()[-1]
    raise AssertionError(f"no static {column_name} on {entity}")


def test_the_speed_colours_have_a_bar_right_of_the_mechanism(written):
    """The mechanism copy was filled by speed (viridis) with no scale: `masonry limit arch --out` showed
    coloured blocks and an empty band right of them. A bar now stands there, 0 to 1 of the fastest speed."""
    path, _ = written
    colours = np.array(static_column(path, SPEED_BAR, "Mesh3D:vertex_colors"), dtype=np.uint32)
    bar = np.array(static_column(path, SPEED_BAR, "Mesh3D:vertex_positions"))[:, :2]
    assert colours[0] == VIRIDIS[0] and colours[-1] == VIRIDIS[-1]  # slow at the bottom, fastest at the top
    assert bar[np.argmax(bar[:, 1]), 1] > bar[0, 1]
    labels = static_column(path, SPEED_LABELS, "Points2D:labels")
    assert labels[0] == "0" and labels[-2] == "1" and labels[-1] == SPEED_TITLE
    blocks = np.array(rows(path, OUTLINES, "LineStrips2D:strips")[STEPS], dtype=object)
    right = max(float(np.max(np.array(strip)[:, 0])) for strip in blocks)
    assert bar[:, 0].min() > right  # beside the mechanism copy, not over it


def test_a_limit_recording_that_cannot_be_written_whole_is_exit_4_and_no_file(tmp_path):
    # With every file limited below the recording's size (RLIMIT_FSIZE, writes failing as on a full disk)
    # `masonry limit arch --out` said nothing and exited 0 with a truncated l.rrd (limits of 40, 150 and 165
    # of 171 kB), or hung in rerun's disconnect for good (80, 120 kB). Now: exit 4, one line naming --out,
    # no file (the temporary one removed).
    import os
    import subprocess
    import sys

    from test_recording_outputs import _LIMITED

    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    env = dict(os.environ, PYTHONPATH=root)
    args = ["limit", "arch", "--out", "l.rrd"]
    done = subprocess.run([sys.executable, "-m", "masonrycli", *args], cwd=tmp_path, env=env, capture_output=True,
                          text=True, timeout=120)  # fmt: skip
    assert done.returncode == 0, done.stderr
    size = (tmp_path / "l.rrd").stat().st_size
    for k, share in enumerate((0.25, 0.7, 0.96)):
        run = tmp_path / f"limit{k}"
        run.mkdir()
        done = subprocess.run([sys.executable, "-c", _LIMITED, str(int(share * size)), *args], cwd=run, env=env,
                              capture_output=True, text=True, timeout=30)  # fmt: skip
        lines = [ln for ln in done.stderr.splitlines() if ln.strip()]
        assert done.returncode == 4 and len(lines) == 1, (share, done.stdout[-1000:], done.stderr[-1000:])
        assert lines[0].startswith("error: cannot write --out l.rrd: ") and "incomplete" in lines[0], lines[0]
        assert list(run.iterdir()) == []


def test_many_hinges_are_smaller_dots(written, tmp_path, monkeypatch):
    """'masonry limit aqueduct --out': 315 hinges and 380 sliding joints drawn as dots of 4 ui points covered
    its upper wall, the blocks' speed colours hidden. Past MANY_MARKERS the dots are half the size."""
    import dataclasses

    from masonrycli.recording import limit as limit_rec

    _, result = written
    drawings = []
    real = limit_rec.write_limit_recording
    monkeypatch.setattr(limit_rec, "write_limit_recording", lambda path, d: drawings.append(d))
    write_recording(result, tmp_path / "unused.rrd")
    few = drawings[0]
    many = dataclasses.replace(
        few,
        hinge_point=np.repeat(few.hinge_point, limit_rec.MANY_MARKERS + 1, axis=0),
        hinge_block=np.repeat(few.hinge_block, limit_rec.MANY_MARKERS + 1),
    )
    radii = {}
    for name, d in (("few", few), ("many", many)):
        real(tmp_path / f"{name}.rrd", d)
        for chunk in rr.chunk.RrdReader(tmp_path / f"{name}.rrd").stream():
            if chunk.entity_path == f"/{HINGES}" and chunk.is_static:
                radii[name] = chunk.to_record_batch().column("Points2D:radii").to_pylist()[-1]
    assert radii == {"few": [-4.0], "many": [-2.0]}


def test_the_live_load_is_drawn_where_it_acts(written, tmp_path):
    """The point load of 'masonry limit aqueduct --load point --block v15 --direction -y' was nowhere on
    screen (the document alone named its block). An arrow whose tip is on the load's point, along it: the
    loaded block's centroid for a point load; the blocks' centre of mass for body forces (their resultant)."""
    from masonrycli.recording.limit import LOAD, LOAD_LENGTH

    import recording_fixtures as fx

    path, _ = written  # two 0.4 x 0.8 blocks stacked, a horizontal body force +x: the centre of mass (0.2, 0.8)
    size = 1.6
    for rrd, tip, direction in (
        (path, (0.2, 0.8), (1.0, 0.0)),
        (tmp_path / "point.rrd", (0.2, 1.2), (-1.0, 0.0)),  # block b1: centroid (0.2, 1.2)
    ):
        if rrd != path:
            write_recording(analyse(column(2, 0.4, 0.8, 0.9), LiveLoad("point", "-x", "b1")), rrd)
        origin = np.array(fx.static_value(rrd, f"/{LOAD}", "Arrows2D:origins"))
        vector = np.array(fx.static_value(rrd, f"/{LOAD}", "Arrows2D:vectors"))
        np.testing.assert_allclose(origin[0] + vector[0], tip, atol=1e-6)
        np.testing.assert_allclose(vector[0], LOAD_LENGTH * size * np.array(direction), atol=1e-6)


def test_the_document_lists_a_dozen_joints_and_says_how_many_more():
    """The aqueduct's point load listed 40 of its 363 hinges and 40 of its 500 sliding joints beside the
    view, a 30-line wall of names with no word that there were more."""
    from masonrycli.limit.drawing import DOCUMENT_NAMES, _document_names

    names = [f"j{k}" for k in range(363)]
    text = _document_names(names)
    assert text.startswith(", ".join(names[:DOCUMENT_NAMES])) and f"j{DOCUMENT_NAMES}," not in text
    assert text.endswith(f"and {363 - DOCUMENT_NAMES} more (all in --json)")
    assert _document_names(names[:3]) == "j0, j1, j2"


def test_a_surveyed_walls_recording_says_how_its_file_was_read(tmp_path):
    """limit --out of a traced wall said nothing of its reading (map shift, units, settling), where a run's
    Parameters table does (39a60e9): the side panel has the same rows."""
    import json

    import surveyed_wall

    from masonrycli.recording.limit import DOCUMENT

    import recording_fixtures as fx
    from cli_helpers import invoke

    surveyed_wall.write(tmp_path / "l93.geojson", offset=surveyed_wall.LAMBERT93, scale=1000.0, slip=0.0, ndigits=6)
    rrd = tmp_path / "l.rrd"
    result = invoke("limit", tmp_path / "l93.geojson", "--units", "mm", "--settle", "0.02", "--out", rrd, "--json")
    assert result.exit_code == 0, result.output
    panel = fx.static_value(rrd, f"/{DOCUMENT}", "TextDocument:text")[0]
    table = panel.split("## Parameters")[1]
    assert "| reading.map_origin_m | [651000.0, 6861000.0] |" in table
    assert "| reading.units | mm |" in table and "| reading.metres_per_unit | 0.001 |" in table
    assert "| reading.settle_s | 0.02 |" in table
    assert json.loads(result.stdout)["load_factor"] > 0.0
    write_recording(analyse(column(2, 0.4, 0.8, 0.9), LiveLoad("horizontal")), tmp_path / "bare.rrd")
    assert "## Parameters" not in fx.static_value(tmp_path / "bare.rrd", f"/{DOCUMENT}", "TextDocument:text")[0]


def _parameters(text: str) -> dict[str, str]:
    """The rows of a document's Parameters table, key -> value."""
    table = text.split("## Parameters")[1].split("\n## ")[0]
    return dict(line.strip("| ").split(" | ", 1) for line in table.splitlines() if line.startswith("| "))


def test_the_parameters_table_is_simulates(tmp_path):
    """limit --out's panel had no Parameters table (the bridge's span, cover, fill mass nowhere; a traced wall's
    'reading' rows alone since e7f9366): it is built as simulate's, from execute.run_metadata, the same rows,
    but every support fixed (the analysis holds them so; the built-in's loading was a settling foundation)."""
    from masonrycli.recording.layout import METADATA
    from masonrycli.recording.limit import DOCUMENT

    import recording_fixtures as fx
    from cli_helpers import invoke

    bridge = ["arch", "--span", 8, "--rise", 2, "--ring-thickness", 0.5, "--pier-width", 3, "--pier-courses", 5]
    bridge += ["--fill-cover", 0.3]
    limit, run = tmp_path / "limit.rrd", tmp_path / "run.rrd"
    assert invoke("limit", *bridge, "--out", limit).exit_code == 0
    assert invoke("simulate", *bridge, "--duration", 0.001, "--dt", 0.001, "--out", run).exit_code == 0
    shown = _parameters(fx.static_value(limit, f"/{DOCUMENT}", "TextDocument:text")[0])
    ran = _parameters(fx.static_value(run, f"/{METADATA}", "TextDocument:text")[0])
    # the same rows, in order, but the run's result (result.state, result.peak drift, …: 8592083), which a
    # limit analysis has not run, and the time loop's (dt, duration, θ, solver, tolerance, frames: one LP has none)
    time_loop = ("duration_s", "dt_s", "theta", "nlgs_tolerance", "nlgs_max_iterations", "solver", "record_every")
    assert any(k.startswith("result.") for k in ran) and not any(k.startswith("result.") for k in shown)
    assert all(k in ran for k in time_loop) and not any(k in shown for k in time_loop)
    assert list(shown) == [k for k in ran if not k.startswith("result.") and k not in time_loop]
    for key in ("structure.span", "structure.fill_cover", "fill_mass_kg", "blocks", "friction", "source"):
        assert shown[key] == ran[key], key
    assert float(shown["fill_mass_kg"]) > 4e4  # 421.6 kN / 9.81
    assert ran["supports.right-foundation"] != "fixed" and shown["supports.right-foundation"] == "fixed"


def test_the_mechanism_says_by_how_much_it_is_magnified(written):
    """'masonry limit arch --out l.rrd' drew the mechanism "magnified" and never said by how much. The view's
    name and the side panel give the distance its fastest block point travels at the last step, which the test
    measures on the drawn outlines (the column's top corner turning about the toe: a chord 0.06 % under it)."""
    from masonrycli.recording.limit import DOCUMENT
    from masonrycli.recording.readback import blueprint_views

    path, _ = written
    strips = rows(path, OUTLINES, "LineStrips2D:strips")
    first, last = (np.array(strips[k], dtype=float) for k in (0, STEPS))
    moved = np.hypot(*(last[2:] - first[2:]).reshape(-1, 2).T).max()  # the mechanism copy's vertices
    stated = f"{MAGNIFIED_SHARE * 1.6:.3g} m"  # the column is 1.6 m high, 0.4 m wide
    assert float(stated.split()[0]) == pytest.approx(moved, rel=1e-3), (stated, moved)
    (document,) = static_column(path, DOCUMENT, "TextDocument:text")
    assert f"fastest block point travels {stated} ({MAGNIFIED_SHARE:.0%} of the structure's 1.6 m)" in document
    (name,) = [v for v in blueprint_views(path) if v.startswith("Collapse mechanism")]
    assert f"fastest point moved {stated}" in name, name
