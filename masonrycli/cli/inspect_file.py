"""``masonry inspect FILE``: a recording (.rrd), a run history (.npz) or a study table summarised, each as
its own reader sees it; a file that is none of them named in one line. Registered on the app by
:mod:`masonrycli.cli.app`."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from masonrycli.cli.messages import console, warn
from masonrycli.cli.option_values import path_value
from masonrycli.errors import InputError


def inspect_command(
    recording: Annotated[
        Path,
        typer.Argument(
            help="Recording (.rrd), run history (.npz) or study table.",
            metavar="REC.rrd|H.npz|S.csv",
            parser=path_value,  # "" was read as "." (the working folder's recordings listed), "~" not expanded
        ),
    ],
) -> None:
    """Summarise a recording (scenario, frames, time span, entities), a run history (its parameters,
    status, frames and each array's unit) or a study's table (its rows and each column's unit)."""
    from masonrycli.outputs.inspect_history import inspect_history, is_history
    from masonrycli.study.inspect_table import is_study_table, study_summary

    if recording.is_file() and recording.stat().st_size == 0:  # rerun's "file too small to be an RRD", a zip error
        raise InputError(f"{recording}: an empty file (0 bytes), not a recording or a history")
    if is_study_table(recording):
        from masonrycli.outputs.report import columns_lines

        table, lines = columns_lines(
            f"{recording} — study table", *study_summary(recording), "column", "unit / meaning"
        )
        console.print(table)
        _print_levels(recording)
        for line in lines:
            console.print(line, soft_wrap=True)
        return
    if is_history(recording):
        from masonrycli.outputs.report import history_tables

        table, lines = history_tables(str(recording), inspect_history(recording))
        console.print(table)
        for line in lines:
            console.print(line, soft_wrap=True)
        return
    from masonrycli.outputs.report import recording_table
    from masonrycli.recording import inspect_recording, recording_path_problem

    problem = recording_path_problem(recording)
    if problem:
        raise InputError(problem)
    try:
        info = inspect_recording(recording)
    except ValueError as exc:  # the reader's own words: the file holds no complete recording
        raise InputError(f"{recording}: not a readable Rerun recording: {exc}") from None
    except Exception as exc:  # a corrupt or foreign file: say so in one line
        raise InputError(f"{recording}: not a readable Rerun recording ({type(exc).__name__}: {exc})") from None
    console.print(recording_table(str(recording), info))
    if info.get("metadata"):
        console.print(info["metadata"])
    if info["truncated"]:
        from masonrycli.outputs.files import part_writer

        pid = part_writer(recording)
        why = (
            f"a run still going (pid {pid}) writes it"
            if pid
            else "its writer did not finish: killed, or the disk was full"
        )
        warn(f"{recording}: truncated ({why}) — {info['frames']} frames up to its last complete chunk")


def _print_levels(path: Path) -> None:
    """A record study's collapsed fraction per level (``pga_g`` or ``scale``), under its table: the counts the
    sweep printed at its end, from the table (masonrycli/study/levels.py)."""
    from rich import box
    from rich.table import Table

    from masonrycli.study.inspect_table import level_table

    found = level_table(path)
    if found is None:
        return
    title, heads, cells, note = found
    table = Table(title=title, title_justify="left", box=box.SIMPLE_HEAD)
    for i, head in enumerate(heads):
        table.add_column(head, justify="left" if i == 0 else "right", no_wrap=True)
    for line in cells:
        table.add_row(*line)
    console.print(table)
    if note:
        console.print(note, soft_wrap=True)
