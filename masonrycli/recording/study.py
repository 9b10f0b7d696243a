"""Rerun recording of a study (``masonry sweep --recording study.rrd``).

Everything is static (a study has no timeline): the state map as coloured points over the two swept
parameters (``study/state_map``), the fragility curve with its runs (``study/fragility``) or the
threshold curve (``study/thresholds``), the PNG the command also wrote (``study/plot``), and the rows
as a markdown table (``study/rows``). Axes are in the parameters' own units, so a 2-D view shows them
as they are; the PNG is the annotated picture.

Rerun's 2-D views draw y downward: each picture entity gets a static y-flip transform and its view looks
at it from ``study`` (an origin's own transform is not applied in its view), so larger values are up, as
in the PNG — before, the state map showed freq = 1 Hz above 2 Hz and the fragility curve upside down.
The state map's labels ("amp=0.25 freq=1: intact") are shown on hover only: drawn, a 6 × 2 grid's
overlapped into an unreadable line.
"""

from __future__ import annotations

import math
import uuid
from pathlib import Path

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from masonrycli.recording.document import viewer_safe_text
from masonrycli.recording.recorder import APPLICATION_ID

STATE_RGBA = {
    "intact": (46, 158, 91, 255),
    "damaged": (240, 160, 48, 255),
    "collapsed": (208, 48, 48, 255),
    "": (160, 160, 160, 255),
}


def record_study(path: Path, name: str, rows: list[dict], request, fit, im: str, plot: Path) -> Path:
    """Write the study's ``.rrd`` at ``path`` (closed, with its blueprint); the caller writes it under
    a temporary name and renames it (``masonrycli.outputs.written_whole``)."""
    path = Path(path)
    rec = rr.RecordingStream(APPLICATION_ID, recording_id=str(uuid.uuid4()))
    views = [rrb.TextDocumentView(origin="study/rows", name="rows")]
    if plot and Path(plot).exists():
        rec.log("study/plot", rr.EncodedImage(path=plot), static=True)
        views.insert(0, rrb.Spatial2DView(origin="study/plot", name="plot"))
    names = [a.name for a in request.axes if a.name != request.find and len(a.values) > 1]
    if request.find:
        _log_thresholds(rec, rows, request.find, names)
        entity, title = "study/thresholds", "thresholds"
    elif fit is not None or "record" in [a.name for a in request.axes]:
        _log_fragility(rec, rows, fit, im)
        entity, title = "study/fragility", "fragility"
    else:
        _log_state_map(rec, rows, names)
        entity, title = "study/state_map", "state map"
    rec.log(entity, rr.Transform3D(scale=[1.0, -1.0, 1.0]), static=True)  # y up (module doc)
    views.insert(0, rrb.Spatial2DView(origin="study", contents=[f"+ /{entity}/**"], name=title))
    rec.log("study/rows", rr.TextDocument(_markdown(name, rows), media_type=rr.MediaType.MARKDOWN), static=True)
    rec.save(path, default_blueprint=rrb.Blueprint(rrb.Grid(*views)))
    rec.disconnect()
    return path


def _number(value) -> float:
    return float(value) if isinstance(value, (int, float)) else math.nan


def _log_state_map(rec, rows: list[dict], names: list[str]) -> None:
    # a string axis (record names) is drawn by index
    def coord(r, n):
        if not n:
            return 0.0
        values = sorted({row[n] for row in rows}, key=str)
        return _number(r[n]) if not isinstance(r[n], str) else float(values.index(r[n]))

    x, y = (names + [None, None])[:2]
    pos = np.array([[coord(r, x), coord(r, y)] for r in rows], dtype=np.float32).reshape(-1, 2)
    colours = np.array([STATE_RGBA.get(r.get("state") or "", STATE_RGBA[""]) for r in rows], dtype=np.uint8)
    labels = [
        viewer_safe_text(" ".join(f"{n}={r[n]}" for n in names) + f": {r.get('state') or 'failed'}") for r in rows
    ]
    span = np.ptp(pos, axis=0) if len(pos) else np.ones(2)
    radius = 0.02 * float(max(span.max(), 1e-9))
    points = rr.Points2D(pos, colors=colours, labels=labels, radii=radius, show_labels=False)
    rec.log("study/state_map", points, static=True)


def _log_fragility(rec, rows: list[dict], fit, im: str) -> None:
    good = [r for r in rows if r.get("status") != "error"]
    x = np.array([_number(r.get(im)) for r in good])
    c = np.array([1.0 if r.get("state") == "collapsed" else 0.0 for r in good])
    colours = [STATE_RGBA.get(r.get("state") or "", STATE_RGBA[""]) for r in good]
    rec.log("study/fragility/runs", rr.Points2D(np.stack([x, c], axis=1), colors=colours), static=True)
    if fit is not None and np.isfinite(x).any():
        grid = np.linspace(0, np.nanmax(x) * 1.2, 200)[1:]
        curve = np.stack([grid, fit.probability(grid)], axis=1)
        text = f"median {fit.median:.3g}, dispersion {fit.dispersion:.2f}"
        label = viewer_safe_text("lognormal: " + ("not resolved (runs separated)" if fit.separated else text))
        rec.log("study/fragility/fit", rr.LineStrips2D([curve], labels=[label]), static=True)


def _log_thresholds(rec, rows: list[dict], find: str, names: list[str]) -> None:
    key = f"{find}_threshold"
    x = names[0] if names else None
    pts = np.array([[_number(r[x]) if x else float(i), _number(r[key])] for i, r in enumerate(rows)])
    pts = pts[np.isfinite(pts).all(axis=1)] if len(pts) else pts.reshape(0, 2)
    rec.log("study/thresholds", rr.LineStrips2D([pts]) if len(pts) > 1 else rr.Points2D(pts), static=True)


def _markdown(name: str, rows: list[dict]) -> str:
    if not rows:
        return f"# {name}\n\nno rows"
    columns = [c for c in rows[0] if c != "study"]
    lines = [f"# study: {name}", "", "| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    for r in rows[:500]:
        cells = [f"{r[c]:.4g}" if isinstance(r[c], float) else str(r[c]) for c in columns]
        lines.append("| " + " | ".join(cells) + " |")
    return viewer_safe_text("\n".join(lines))
