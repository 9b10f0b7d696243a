"""``masonry export``: a run history as CSV. Thin: options -> :func:`masonrycli.outputs.export.export_table`
-> the CSV written whole (:func:`masonrycli.outputs.files.written_whole`); registered on the app by :mod:`masonrycli.cli.app`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from masonrycli.cli.options import file_path_value, path_value, whole_value
from masonrycli.errors import InputError


def _names(values: list[str] | None) -> list[str]:
    """``--blocks a,b --blocks c`` → [a, b, c]."""
    return [name.strip() for value in values or () for name in value.split(",") if name.strip()]


def _course_numbers(values: list[str] | None) -> list[int]:
    out = []
    for text in _names(values):
        try:
            out.append(int(text))
        except ValueError:
            raise InputError(f"--course {text}: not a course number (1 = the lowest course)") from None
    return out


def _inputs(paths: list[Path]) -> list[Path]:
    """The histories named: files as given, a folder's ``*.npz`` (a study's ``--histories``), sorted."""
    out = []
    for path in paths:
        if path.is_dir():
            found = sorted(p for p in path.glob("*.npz") if not p.name.startswith("."))
            if not found:
                raise InputError(f"{path}: a folder without histories (*.npz)")
            out += found
        else:
            out.append(path)
    return out


def _targets(histories: list[Path], out: Path | None, force: bool, several: bool):
    """The checked output of each history (:func:`masonrycli.outputs.files.check_output`): ``out`` for one history,
    ``out``/NAME.csv (a folder) or NAME.csv beside each for several."""
    from masonrycli.outputs.files import check_distinct, check_output

    if several and out is not None and not out.is_dir():
        raise InputError(f"--out {out}: several histories, one CSV each: --out names an existing folder for them")
    targets = []
    for history in histories:
        path = history.with_suffix(".csv")
        if out is not None:
            path = out / path.name if several else out
        targets.append(check_output(path, "--out", ".csv", force))
    check_distinct(*targets)
    return targets


def export_command(
    histories: Annotated[
        list[Path],
        typer.Argument(
            help="Run histories (--history H.npz), or a folder of them (a study's --histories).",
            metavar="H.npz...|FOLDER",
            parser=path_value,
        ),
    ],
    out: Annotated[
        Path | None,
        typer.Option(
            "--out",
            "-o",
            parser=file_path_value,
            help="The CSV to write (default: H.csv beside H.npz); for several histories, a folder.",
            metavar="S.csv|FOLDER",
        ),
    ] = None,
    blocks: Annotated[
        list[str] | None,
        typer.Option(
            "--blocks", help="Blocks by name, comma-separated or repeated: their columns each.", metavar="NAME,..."
        ),
    ] = None,
    course: Annotated[
        list[str] | None,
        typer.Option("--course", help="A course's mean (1 = the lowest), comma-separated or repeated.", metavar="N"),
    ] = None,
    top: Annotated[bool, typer.Option("--top", help="The top course's mean (the default without a target).")] = False,
    ground: Annotated[
        str | None,
        typer.Option(
            help="The support the targets' motion is measured from (default: the only one, or the first moving sideways).",
            metavar="NAME",
        ),
    ] = None,
    absolute: Annotated[
        bool,
        typer.Option(
            "--absolute", help="The targets' motion in the fixed frame (default: relative to the ground, ' rel')."
        ),
    ] = False,
    every: Annotated[
        int,
        typer.Option(parser=whole_value, help="Keep every K-th recorded frame (after differentiating).", metavar="K"),
    ] = 1,
    force: Annotated[bool, typer.Option("--force", help="Replace the --out file if it exists.")] = False,
) -> None:
    """Write a run history as CSV (one row per frame, units in the header): the ground's motion, blocks' or
    courses' displacement, velocity, acceleration (relative to the ground), drift ratio, base shear,
    overturning moment, hinges, energies."""
    from masonrycli.cli.messages import console, say
    from masonrycli.outputs.export import export_table, write_csv
    from masonrycli.outputs.files import written_whole

    if every < 1:
        raise InputError(f"--every {every}: keep every K-th frame, K ≥ 1")
    inputs = _inputs(histories)
    several = len(inputs) > 1 or any(path.is_dir() for path in histories)
    targets = _targets(inputs, out, force, several)
    options = dict(
        blocks=_names(blocks),
        course_numbers=_course_numbers(course),
        top=top,
        ground=ground,
        relative=not absolute,
        every=every,
    )
    # every table made before the first CSV is written: a folder whose second history lacked a --blocks name or
    # held no frame wrote the first CSV, then stopped (exit 2), and the same command again met "the file exists"
    tables = [export_table(history, **options) for history in inputs]
    for history, target, table in zip(inputs, targets, tables):
        with written_whole(target) as part:
            write_csv(table, part)
        for note in table.notes:
            say("note", "yellow", note)
        rows = len(table.values[0])
        line = f"{history}: {rows} row{'s' if rows != 1 else ''} × {len(table.names)} columns → {target.path}"
        console.print(line, soft_wrap=True, markup=False)
