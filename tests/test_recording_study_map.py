"""A study's state map (masonrycli.recording.study) read back: its labels stand clear of the dots and of each
other whatever the grid's spacing, the rows under the table are the terminals with units, the key reads as
a key (split from test_recording_study.py, which keeps the plots and the whole-study runs)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sweep_helpers import invoke, static_fields


def two_by_two(tmp_path, states=("intact", "damaged", "damaged", "collapsed")):
    from types import SimpleNamespace

    from masonrycli.recording.study import record_study

    points = [(1, 0.5), (1, 1.0), (2, 0.5), (2, 1.0)]
    rows = [
        {"freq": f, "amp": a, "state": st, "status": "completed", "collapse_time": 0.4 if st == "collapsed" else np.nan,
         "residual_drift": 0.0123, "pga": 3.14159, "max_opening": 0.0007, "hinges": 2, "wall_time": 1.25,
         "peak_drift": 0.02, "sweeps_mean": 12.0, "energy_dissipated": 280.2, "study": "x"}
        for (f, a), st in zip(points, states)
    ]  # fmt: skip
    axes = [SimpleNamespace(name="freq", values=(1, 2)), SimpleNamespace(name="amp", values=(0.5, 1.0))]
    return record_study(tmp_path / "map.rrd", "wall", rows, SimpleNamespace(axes=axes, find=None), None, "pga", None)


def test_the_state_map_labels_stand_clear_of_the_dots(tmp_path):
    """`masonry sweep wall --param freq=1,2 --param amp=0.5,1`: the x labels ("freq=1.0") sat over the
    lower dots, 0.06 below their centres with dots of radius 0.1, and the key's names were drawn by the key's
    dots, on them, in their colour ("intact" green on green). Every name now stands a radius and a tenth of
    the map's size from every dot's centre, in grey."""
    import rerun as rr

    chunks = list(rr.chunk.RrdReader(str(two_by_two(tmp_path))).stream())
    dots = [static_fields(chunks, e) for e in ("/study/state_map", "/study/state_map/key")]
    centres = np.concatenate([np.array(d["Points2D:positions"]) for d in dots])
    radius = np.concatenate(  # each dot's (the key's are smaller)
        [np.broadcast_to(np.array(d["Points2D:radii"], np.float64).ravel(), len(d["Points2D:positions"])) for d in dots]
    )
    assert all(not any(d.get("Points2D:show_labels") or [False]) for d in dots)  # the dots draw no text
    labels = [static_fields(chunks, e) for e in ("/study/state_map/axes", "/study/state_map/key/names")]
    anchors = np.concatenate([np.array(t["Points2D:positions"]) for t in labels])
    assert sum(len(t["Points2D:labels"]) for t in labels) == 4 + 4  # two values per axis, four states
    gap = np.linalg.norm(anchors[:, None, :] - centres[None, :, :], axis=-1) - radius[None, :]
    assert gap.min() >= 0.1 * 1.0 - 1e-6  # the map is 1 (freq) by 0.5 (amp)


def test_the_rows_are_the_terminals_with_units_under_the_table(tmp_path):
    """The rows were the table file's every column: 14 here, 26 from a sweep, run off the view's right
    edge, SI values with no unit anywhere, "nan" for a run that did not collapse. They are the terminal's
    columns now, values in the units the legend under the table names, blank where there is none."""
    import rerun as rr

    chunks = list(rr.chunk.RrdReader(str(two_by_two(tmp_path))).stream())
    text = static_fields(chunks, "/study/rows")["TextDocument:text"][0]
    lines = text.splitlines()
    header = [h.strip() for h in lines[2].strip("|").split("|")]
    assert header == ["freq", "amp", "state", "collapse", "drift", "pga", "open", "hinges", "took", "peak", "sweeps"]
    first, last = ([c.strip() for c in ln.strip("|").split("|")] for ln in (lines[4], lines[7]))
    assert first[3] == "" and last[3] == "0.40"  # no collapse: blank; collapse at 0.4 s
    assert first[4] == "1.23" and first[6] == "0.7"  # drift in % of height, opening in mm
    assert "nan" not in text
    assert "freq Hz · amp m/s · collapse: time of collapse, s · drift: residual, % of height · pga m/s²" in text
    from masonrycli.recording.readback import blueprint_views

    assert "runs of wall (units under the table)" in blueprint_views(tmp_path / "map.rrd")


def label_boxes(rrd: Path) -> tuple[dict, np.ndarray, np.ndarray]:
    """The state map's drawn labels as boxes on screen, by entity: {entity: [(centre x, y, half width,
    half height)]} in map units, and the dots (centre x, y, radius). A label is drawn centred on its anchor
    at a fixed size on screen, whatever the zoom: about 8 px a character plus 10 px wide, 24 px high
    (measured on a headless screenshot: "freq=2.0" 62 px, "collapsed" 72 px). The view (600 x 1000 px at
    least, beside the picture and the rows in a 1920 x 1080 window) fits the dots and the anchors, filling
    55 % of it at the most (0.6 to 0.8 measured): the pixels a map unit are underestimated, the labels
    overestimated."""
    import rerun as rr

    chunks = list(rr.chunk.RrdReader(str(rrd)).stream())
    dots = []
    for entity in ("/study/state_map", "/study/state_map/key"):
        fields = static_fields(chunks, entity)
        at = np.array(fields["Points2D:positions"], dtype=np.float64)
        dots.append(np.column_stack([at, np.broadcast_to(np.array(fields["Points2D:radii"], np.float64), len(at))]))
    dots = np.concatenate(dots)
    texts = {}
    for entity in ("/study/state_map/axes", "/study/state_map/axes/names", "/study/state_map/key/names"):
        fields = static_fields(chunks, entity)
        if fields:
            texts[entity] = (
                np.array(fields["Points2D:positions"], np.float64).reshape(-1, 2),
                fields["Points2D:labels"],
            )
    anchors = np.concatenate([at for at, _ in texts.values()])
    points = np.concatenate([dots[:, :2] - dots[:, 2:], dots[:, :2] + dots[:, 2:], anchors])
    span = np.maximum(np.ptp(points, axis=0), 1e-9)
    px = 0.55 * min(600.0 / span[0], 1000.0 / span[1])
    boxes = {
        entity: [(x, y, (8.0 * len(t) + 10.0) / 2.0 / px, 12.0 / px) for (x, y), t in zip(at, labels)]
        for entity, (at, labels) in texts.items()
    }
    return boxes, dots


def overlapping(boxes: dict, dots: np.ndarray) -> list:
    """Pairs of labels whose boxes meet, and labels whose box meets a dot."""
    every = [(entity, i, b) for entity, bs in boxes.items() for i, b in enumerate(bs)]
    found = []
    for k, (ea, ia, (xa, ya, wa, ha)) in enumerate(every):
        for eb, ib, (xb, yb, wb, hb) in every[k + 1 :]:
            if abs(xa - xb) < wa + wb and abs(ya - yb) < ha + hb:
                found.append(((ea, ia), (eb, ib)))
        # the box's nearest point to each dot's centre, inside the dot: the label covers it
        near = np.column_stack([np.clip(dots[:, 0], xa - wa, xa + wa), np.clip(dots[:, 1], ya - ha, ya + ha)])
        for d in np.nonzero(np.hypot(*(near - dots[:, :2]).T) < dots[:, 2])[0]:
            found.append(((ea, ia), ("dot", int(d))))
    return found


def test_the_state_map_labels_of_close_values_do_not_overlap(tmp_path):
    """`masonry sweep wall -p amp=0.1,0.2 -p freq=1,2`: the labels were spaced from the map's largest span
    (freq, 1 Hz), so the amp values 0.1 apart drew over each other: "amp=0.amp=0.2" on a headless
    screenshot. Read back, no two labels' boxes (their anchors, an estimated size on screen: label_boxes)
    meet, nor a label and a dot."""
    args = ["-p", "amp=0.1,0.2", "-p", "freq=1,2", "--duration", 0.05, "--workers", 0, "-o", tmp_path / "s.parquet"]
    result = invoke("sweep", "wall", *args, "--recording", tmp_path / "s.rrd")
    assert result.exit_code == 0, result.output
    boxes, dots = label_boxes(tmp_path / "s.rrd")
    assert len(boxes["/study/state_map/axes"]) == 4 and len(dots) == 4 + 4
    assert overlapping(boxes, dots) == []


GRIDS = {
    "readme": ([round(0.1 * k, 6) for k in range(1, 11)], [0.5 * k for k in range(1, 9)]),  # README's 10 x 8
    "uneven": ([0.1, 0.105, 0.11, 1.0], [1, 1.01, 2, 20]),  # close values beside far ones
    "fine": ([round(0.01 * k, 6) for k in range(1, 31)], [round(0.1 * k, 6) for k in range(1, 31)]),  # 30 x 30
    "one axis": ([round(0.123456 * k, 6) for k in range(1, 26)], None),
}


@pytest.mark.parametrize("name", GRIDS)
def test_the_state_map_labels_do_not_overlap_whatever_the_spacing(tmp_path, name):
    """Many values, uneven ones, one axis alone: the values' labels take turns in two rows under the map and
    two columns left of it where a cell is narrower than they are, and label every 2nd, 5th … value where
    two lanes cannot hold them all, so that none meets another or a dot."""
    from types import SimpleNamespace

    from masonrycli.recording.study import record_study

    xs, ys = GRIDS[name]
    rows = [
        {"amp": a, **({"freq": f} if ys else {}), "state": "intact", "status": "completed"}
        for a in xs
        for f in ys or [None]
    ]
    axes = [SimpleNamespace(name="amp", values=tuple(xs))] + (
        [SimpleNamespace(name="freq", values=tuple(ys))] if ys else []
    )
    rrd = record_study(tmp_path / "map.rrd", "wall", rows, SimpleNamespace(axes=axes, find=None), None, "pga", None)
    boxes, dots = label_boxes(rrd)
    assert overlapping(boxes, dots) == []
    # every value's label where a lane or two hold them, else every 2nd, 5th, 10th …, from the first
    import rerun as rr

    drawn = static_fields(list(rr.chunk.RrdReader(str(rrd)).stream()), "/study/state_map/axes")["Points2D:labels"]
    shown = []
    for values in (xs, ys) if ys else (xs,):
        ticks = [f"{v:g}" for v in values]
        every = ticks.index(drawn[len(shown) + 1]) if len(drawn) > len(shown) + 1 else len(ticks)
        shown += ticks[::every]
        assert every in (1, 2, 5, 10), (name, drawn)
    assert drawn == shown
    if name in ("readme", "uneven"):
        assert len(drawn) == len(xs) + len(ys)


def test_the_key_does_not_read_as_a_row_of_runs(tmp_path):
    """'masonry sweep wall --param amp=0.2:1:3': the map is one row of three runs, and the key under it was
    four dots of the same size, as far apart (intact, damaged, collapsed, failed): a second row of runs to
    the eye. The key's dots are less than half the runs' size."""
    import rerun as rr

    chunks = list(rr.chunk.RrdReader(str(two_by_two(tmp_path))).stream())
    runs = float(np.min(static_fields(chunks, "/study/state_map")["Points2D:radii"]))
    key = float(np.max(static_fields(chunks, "/study/state_map/key")["Points2D:radii"]))
    assert key < 0.5 * runs, (key, runs)
