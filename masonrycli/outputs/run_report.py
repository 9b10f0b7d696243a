"""``masonry report H.npz``: a run's one-page summary in Markdown, to hand to a colleague.

Every number on the page is one the tool already gives, by the same code, so the page cannot disagree with
what the user saw:

=========================  ==============================================================================
on the page                from
=========================  ==============================================================================
what was run               ``masonry inspect H.npz``'s rows (:func:`inspect_history.run_rows`): scenario,
                           structure and its size, material, a bridge's fill, loading, run settings, masonry's version,
                           commit and source digest
ground motion as applied   the history's ``intensity_*`` (measured by the run with
                           :func:`masonrycli.records.intensity.intensity_measures`, as ``check``'s
                           'intensity' row) in the words of :func:`~masonrycli.records.intensity.describe`
state, peak drift          the history's ``result_*`` (the run's :func:`masonrycli.run.run_outcome`, watched
                           every step) in the summary's words (``describe_outcome``, ``describe_peak_drift``)
residual drift             ``result_residual_drift``, as the state's line gives it (``masonry export``'s
                           last ``drift ratio (-)``)
hinged joints (end)        the last frame's ``joint_hinged``, as the summary lists them (``describe_hinges``)
unconverged steps          the last frame's ``nlgs_unconverged`` over its ``step``, as the summary's row
figure (``--out`` only)    ``masonry export``'s ``drift ratio (-)`` and the ground's ``ax`` columns
=========================  ==============================================================================

A history written before the run's verdict was stored (``result_*``, 2026-11-29) has no state: the page
says so, and gives the largest drift over its recorded frames (export's column), marked as such: the
run's peak was watched every step, the frames are every ``record_every``-th.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np

from masonrycli.errors import InputError

ACCELERATION_NOTE = (
    "the ground's acceleration at the recorded frames (masonry export's column: the mean over the two intervals "
    "around each frame), so its peak may be below the PGA, which is taken step by step"
)


_MEASURE = re.compile(r"^(PGA|PGV|Arias|D5–95|Sa\([^)]*\)) (.*)$")
"""A measure of :func:`masonrycli.records.intensity.describe`'s line: its name, its value(s)."""


def _run(arrays) -> dict:
    try:
        run = json.loads(str(arrays["run"])) if "run" in arrays else None
    except ValueError:
        run = None
    return run if isinstance(run, dict) else {}


def _info(arrays) -> dict:
    """What :func:`masonrycli.outputs.inspect_history.run_rows` reads (``inspect_history``'s keys), from the
    arrays themselves: the Python API's run in memory has no file to inspect."""
    time, step = np.asarray(arrays["time"]), arrays.get("step")
    run = _run(arrays)

    def count(name):
        return len(arrays[name]) if name in arrays else None

    return {
        "run": run or None,
        "status": str(arrays["status"]) if "status" in arrays else None,
        "note": str(arrays["note"]) if "note" in arrays else None,
        "frames": len(time),
        "steps": (int(step[0]), int(step[-1])) if step is not None and len(step) else None,
        "time_span": (float(time[0]), float(time[-1])) if len(time) else None,
        "blocks": count("block_name"),
        "supports": count("support_name"),
        "joints": count("joint_body"),
        "units_recorded": "units" in arrays,
    }


RUN_ROWS = (
    "command",
    "scenario",
    "structure",
    "reading",
    "study point",
    "material",
    "fill",
    "loading",
    "dt",
    "solver",
    "tolerance",
)
"""The rows of ``masonry inspect`` the page's 'what was run' gives, in this order (then masonry's own)."""


def _what_was_run(arrays, shown: str) -> list[tuple[str, str]]:
    from masonrycli.outputs.inspect_history import run_rows

    rows = dict(run_rows(_info(arrays)))
    out = [(label, rows[label]) for label in RUN_ROWS if label in rows]
    run = _run(arrays)
    out += [("masonry", rows["masonry"]), ("history", shown)]
    if run.get("started"):
        out.append(("started", str(run["started"])))
    return out


def intensity(arrays) -> dict[str, float] | None:
    """The ground motion as the run applied it (the history's ``intensity_*``), or None: no support shook."""
    from masonrycli.records.intensity import INTENSITY_MEASURES

    if not all(f"intensity_{k}" in arrays for k in INTENSITY_MEASURES):
        return None
    return {k: float(arrays[f"intensity_{k}"]) for k in INTENSITY_MEASURES}


def _ground_rows(ims: dict[str, float]) -> list[tuple[str, str]]:
    """The summary's 'ground motion' line (``describe``), one measure a row: 'PGA' | '12.6 m/s² (1.28 g)'."""
    from masonrycli.records.intensity import describe

    return [_MEASURE.match(part).groups() for part in describe(ims).split(", ")]


def outcome(arrays) -> tuple[dict, float] | None:
    """The run's outcome (:func:`masonrycli.run.run_outcome`'s keys) and the structure's height (m) the drifts
    are ratios of, as the history keeps them (``result_*``), or None for a history without them."""
    from masonrycli.outputs.verdict import RESULT_KEYS

    if not all(f"result_{k}" in arrays for k in (*RESULT_KEYS, "height")):
        return None
    values = {k: arrays[f"result_{k}"].item() for k in RESULT_KEYS}
    return values, float(arrays["result_height"])


def hinged_joints(arrays) -> list[str]:
    """The joints hinged at the last frame, ``"a|b"`` as the summary names them."""
    from masonrycli.model import JOINT_SEPARATOR

    if "joint_hinged" not in arrays or not len(arrays["time"]):
        return []
    names = [str(n) for n in arrays["block_name"]] + [str(n) for n in arrays["support_name"]]
    body = np.asarray(arrays["joint_body"])[np.asarray(arrays["joint_hinged"][-1], dtype=bool)]
    return [f"{names[a]}{JOINT_SEPARATOR}{names[b]}" for a, b in body]


def most_open(arrays) -> tuple[str, float, tuple[float, float]] | None:
    """The block whose joints open most at the last frame (``block_max_opening``), that opening (m) and where its
    centroid is then (m, in the coordinates the run read: near the origin for a map grid's file), or None when
    nothing opens or it is not recorded. The state's line gives the largest opening; a researcher asks where."""
    if "block_max_opening" not in arrays or not len(arrays["time"]) or not len(arrays["block_name"]):
        return None
    last = np.asarray(arrays["block_max_opening"][-1], dtype=np.float64)
    k = int(np.argmax(last))
    if not last[k] > 0.0:
        return None
    x, y = (float(v) for v in np.asarray(arrays["block_q"][-1])[k, :2])
    return str(arrays["block_name"][k]), float(last[k]), (x, y)


def unconverged(arrays) -> tuple[int, int] | None:
    """(steps that ended unconverged, steps run), from the last frame, or None: not recorded."""
    if "nlgs_unconverged" not in arrays or "step" not in arrays or not len(arrays["step"]):
        return None
    return int(arrays["nlgs_unconverged"][-1]), int(arrays["step"][-1])


def _result_rows(arrays, table) -> list[tuple[str, str]]:
    from masonrycli.outputs.inspect_history import run_rows
    from masonrycli.outputs.verdict import (
        describe_hinges,
        describe_most_open,
        describe_outcome,
        describe_peak_drift,
        describe_residual_drift,
        shown,
    )

    rows = [("status", dict(run_rows(_info(arrays)))["status"])]
    found = outcome(arrays)
    if found is not None:
        out, height = found
        rows.append(("state", describe_outcome(out)))
        rows.append(("peak drift", describe_peak_drift(out["peak_drift"], height)))
        rows.append(("residual drift", describe_residual_drift(out["residual_drift"], height)))
    else:
        drift = column(table, "drift ratio (-)")
        peak = float(np.nanmax(np.abs(drift))) if len(drift) else math.nan
        rows.append(("state", "not recorded: a history written before masonry kept the run's verdict (run it again)"))
        rows.append(("peak drift", f"{shown(100 * peak)} % of the height over the recorded frames (not every step)"))
        rows.append(("residual drift", f"{shown(100 * float(drift[-1]))} % of the height (the last frame)"))
    if "joint_hinged" in arrays:
        rows.append(("hinged joints (end)", describe_hinges(hinged_joints(arrays))))
    if (found := most_open(arrays)) is not None:
        rows.append(
            ("most open (end)", describe_most_open(*found, _run(arrays).get("reading", {}).get("map_origin_m")))
        )
    counts = unconverged(arrays)
    if counts is not None:
        bad, steps = counts
        rows.append(("unconverged steps", f"{bad} ({100.0 * bad / max(steps, 1):.1f} %)"))
    return rows


def _cell(text: str) -> str:
    """Text in a Markdown table's cell: its '|' (joint names) escaped, lines joined."""
    return " ".join(str(text).split("\n")).replace("|", "\\|")


def _table(rows: list[tuple[str, str]]) -> list[str]:
    return ["| | |", "|---|---|", *(f"| {_cell(a)} | {_cell(b)} |" for a, b in rows)]


def column(table, name: str) -> np.ndarray:
    """A column of ``masonry export``'s table, by its name (with its unit)."""
    return table.values[table.names.index(name)]


def ground_name(arrays) -> str:
    """The support ``masonry export`` measures from (the only one, or the first moving sideways)."""
    from masonrycli.outputs.export import ground_support

    return str(arrays["support_name"][ground_support(arrays, None, "the run")])


def report_table(arrays: dict):
    """``masonry export --top``'s table of the run: the figure's columns, and the drift of a history without
    the run's verdict."""
    from masonrycli.outputs.export import export_table

    if "time" not in arrays or not len(arrays["time"]):
        raise InputError("a history of no frame: nothing to report")
    return export_table(arrays, top=True)


def report_markdown(arrays: dict, shown: str, figure: str | None = None, table=None) -> str:
    """The page: ``arrays`` the history's, ``shown`` its name on the page, ``figure`` the PNG's name beside the
    page (None: no figure); ``table``: :func:`report_table`'s, when the caller has it already."""
    table = report_table(arrays) if table is None else table
    run = _run(arrays)
    name = run.get("scenario") or Path(shown).stem
    lines = [f"# {name}: run report", "", "## What was run", "", *_table(_what_was_run(arrays, shown)), ""]
    ims = intensity(arrays)
    if ims is not None:
        ground = ground_name(arrays)
        lines += [f"## Ground motion as applied ({ground})", "", *_table(_ground_rows(ims)), ""]
    else:
        lines += ["## Ground motion as applied", "", "No support shook (a settlement or a structure at rest).", ""]
    lines += ["## Result", "", *_table(_result_rows(arrays, table)), ""]
    if figure is not None:
        lines += [f"![The top's drift and the ground's acceleration against time]({figure})", ""]
        lines += [f"*Top: the top's drift relative to the ground (% of the height). Bottom: {ACCELERATION_NOTE}.*", ""]
    lines.append("*Definitions of the states: `masonry docs collapse`. Every array: `masonry inspect " + shown + "`.*")
    return "\n".join(lines) + "\n"


def write_figure(arrays: dict, shown: str, path: Path, table=None) -> None:
    """PNG at ``path``: the top's drift ratio (%) and the ground's horizontal acceleration (m/s²) against time,
    ``masonry export``'s columns (``table``: :func:`report_table`'s)."""
    from masonrycli.study.plots import _pyplot  # pyplot on Agg, quiet about its folders (one place says how)

    table = report_table(arrays) if table is None else table
    time = column(table, "time (s)")
    ground = ground_name(arrays)
    plt = _pyplot()
    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(7, 4.5))
    try:
        top.plot(time, 100 * column(table, "drift ratio (-)"), color="tab:red", lw=1)
        top.set_ylabel("top drift (% of height)")
        top.axhline(0, color="0.6", lw=0.5)
        bottom.plot(time, column(table, f"{ground} ax (m/s2)"), color="tab:blue", lw=1)
        bottom.set_ylabel(f"{ground} ax (m/s²)")
        bottom.set_xlabel("time (s)")
        top.set_title(f"{_run(arrays).get('scenario') or Path(shown).stem}: {shown}", fontsize=9)
        fig.savefig(path, format="png", dpi=110, bbox_inches="tight")
    finally:
        plt.close(fig)


def read(path) -> dict:
    """The arrays of the history at ``path``, checked as ``masonry export`` checks it (one line for a missing,
    damaged or foreign file: a recording, a study's table)."""
    from masonrycli.outputs.export import read_history

    return read_history(path)


def check_outputs(out: Path, force: bool):
    """The page (``out``, ``.md``) and its figure beside it (the same name, ``.png``), checked before the history
    is read (:func:`masonrycli.outputs.files.check_output`): an existing file is refused unless ``force``, as
    ``masonry export --out``."""
    from masonrycli.outputs.files import check_distinct, check_output

    page = check_output(out, "--out", ".md", force)
    picture = check_output(out.with_suffix(".png"), f"--out {out}'s figure", ".png", force)
    check_distinct(page, picture)
    return page, picture


def write_report(arrays: dict, shown: str, page, picture) -> tuple[Path, Path]:
    """Write the page and its figure (:func:`check_outputs`'s), each whole
    (:func:`masonrycli.outputs.files.written_whole`): the figure first, so a page never names a missing one.
    Returns where they went."""
    from masonrycli.outputs.files import written_whole

    table = report_table(arrays)
    text = report_markdown(arrays, shown, figure=picture.path.name, table=table)
    with written_whole(picture) as part:
        write_figure(arrays, shown, part, table)
    with written_whole(page) as part:
        part.write_text(text, encoding="utf-8")
    return page.path, picture.path
