"""``masonry export``: a run history as CSV. Thin: options -> :func:`masonrycli.outputs.export.export_table`
-> the CSV written whole (:func:`masonrycli.outputs.files.written_whole`); registered on the app by :mod:`masonrycli.cli.app`.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Annotated

import typer

from masonrycli.cli.option_values import file_path_value, path_value, whole_value
from masonrycli.errors import InputError


def _names(values: list[str] | None, option: str = "--blocks", what: str = "block names") -> list[str]:
    """``--blocks a,b --blocks c`` → [a, b, c]. An empty value (an unset "$BLOCKS") is refused: it exported the
    default target (the top course) without a word."""
    for value in values or ():
        if not value.replace(",", "").strip():
            raise InputError(f"{option} {value!r}: an empty list ({what}, comma-separated)")
    return [name.strip() for value in values or () for name in value.split(",") if name.strip()]


def _course_numbers(values: list[str] | None) -> list[int]:
    out = []
    for text in _names(values, "--course", "course numbers"):
        try:
            out.append(int(text))
        except ValueError:
            raise InputError(f"--course {text}: not a course number (1 = the lowest course)") from None
    return out


def _check_cut_lists(lists: dict, histories: list[Path]) -> None:
    """``--blocks c01-b01, c01-b02``: the shell cut the list at its space and the rest became a history,
    which said only "c01-b02: no such history"."""
    for option, values in lists.items():
        cut = [value for value in values or () if value.endswith(",")]
        rest = [path for path in histories if not path.exists()]
        if cut and rest:
            raise InputError(
                f"{option} {cut[-1]} {rest[0]}: a list goes without spaces after its commas: "
                f"{option} {cut[-1]}{rest[0]}"
            )


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
    _named_once(out)
    return out


def _named_once(histories: list[Path]) -> None:
    """``export w.npz w.npz`` (or ``w.npz .``) said "--out and --out name the same file w.csv", of an --out not
    given; with --combined the run was in the table twice."""
    seen: dict[str, Path] = {}
    for path in histories:
        first = seen.setdefault(os.path.realpath(path), path)
        if first is not path:
            same = "named twice" if str(first) == str(path) else f"the same history as {first}"
            raise InputError(f"{path}: {same} (each history is exported once)")


def _targets(histories: list[Path], out: Path | None, force: bool, several: bool):
    """The checked output of each history (:func:`masonrycli.outputs.files.check_output`): ``out`` for one history,
    ``out``/NAME.csv (a folder) or NAME.csv beside each for several."""
    from masonrycli.outputs.files import check_distinct, check_output

    if several and out is not None and (out.suffix.lower() == ".csv" or (out.exists() and not out.is_dir())):
        raise InputError(f"--out {out}: several histories, one CSV each: --out names a folder for them")
    targets = []
    for history in histories:
        path = history.with_suffix(".csv")
        if out is not None:
            path = out / path.name if several else out
        for earlier, target in zip(histories, targets):  # a/w.npz and b/w.npz --out runs/: both runs/w.csv
            if os.path.realpath(target.path) == os.path.realpath(path):
                raise InputError(
                    f"{earlier} and {history}: both would be written to {path} (one CSV each: export them to "
                    "two folders)"
                )
        targets.append(check_output(path, "--out", ".csv", force))
    check_distinct(*targets)
    return targets


def _combined_target(histories: list[Path], out: Path | None, force: bool):
    """The checked output of ``--combined``: ``--out``, else FOLDER.csv beside the one folder given."""
    from masonrycli.outputs.files import check_output

    if out is None:
        if len(histories) != 1 or not histories[0].is_dir():
            raise InputError("--combined: name the table with --out S.csv (FOLDER.csv by default, for one folder)")
        folder = histories[0].resolve()  # "." is the working folder: its table goes beside it, not in it
        out = folder.parent / f"{folder.name}.csv"
    elif out.is_dir():
        raise InputError(f"--out {out}: --combined writes one table: name a file (--out {out / 'study.csv'})")
    return check_output(out, "--out", ".csv", force)


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
    times: Annotated[
        Path | None,
        typer.Option(
            "--times",
            parser=path_value,
            help="A lab's CSV (header row, a time column): every column at its sample times, beside its own columns.",
            metavar="LAB.csv",
        ),
    ] = None,
    time_column: Annotated[
        str | None,
        typer.Option(help="The --times file's time column (default: the one named time or t).", metavar="NAME"),
    ] = None,
    compare: Annotated[
        list[str] | None,
        typer.Option(
            "--compare",
            help="A --times column against the first target's ux (or =MASONRY COLUMN): peak, RMS error, "
            "correlation, Sprague–Geers.",
            metavar="LAB COLUMN[=COLUMN]",
        ),
    ] = None,
    combined: Annotated[
        bool,
        typer.Option(
            "--combined",
            help="Several histories as one long CSV: a row per run × frame, with the history's name and its study "
            "point's values (default --out: FOLDER.csv beside the folder).",
        ),
    ] = False,
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
    if times is None and (compare or time_column is not None):
        raise InputError(
            f"{'--compare' if compare else '--time-column'}: a column of the --times file: give --times LAB.csv"
        )
    if times is not None and every > 1:
        raise InputError(f"--every {every} and --times: the rows are the lab's samples, give one or the other")
    _check_cut_lists({"--blocks": blocks, "--course": course}, histories)
    inputs = _inputs(histories)
    several = len(inputs) > 1 or any(path.is_dir() for path in histories)
    if combined:
        targets = [_combined_target(histories, out, force)]
    else:
        targets = _targets(inputs, out, force, several)
    for target in targets:  # --force must not replace the lab's own file with the export of it
        if times is not None and times.exists() and target.path.exists() and target.path.samefile(times):
            raise InputError(f"{target.option} {target.path}: is the --times file (name another CSV to write)")
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
    lab = None
    if times is not None:  # before the histories: a lab file's error is said however they are
        from masonrycli.outputs.lab_file import read_lab_file

        lab = read_lab_file(times, time_column)
    tables = [export_table(history, **options) for history in inputs]
    measures = [[] for _ in tables]
    if lab is not None:
        from masonrycli.outputs.agreement import compare as measure
        from masonrycli.outputs.resample import resample

        tables = [resample(table, lab, str(history)) for history, table in zip(inputs, tables)]
        for history, table, lines in zip(inputs, tables, measures):
            for spec in compare or ():
                found = measure(table, spec, lab.path, lab.lines, lab.time)
                lines += [f"{history}: {found[0]}", *found[1:]] if combined else found  # one table: say whose
    shown = [str(history) for history in inputs]
    if combined:
        from masonrycli.outputs.export import long_table

        tables = [long_table(tables, [history.stem for history in inputs], shown)]
        shown, measures = [", ".join(shown) if len(shown) < 4 else f"{len(shown)} histories"], [sum(measures, [])]
    for history, target, table, lines in zip(shown, targets, tables, measures):
        with written_whole(target) as part:
            write_csv(table, part)
        for note in table.notes:
            say("note", "yellow", note)
        rows = len(table.values[0])
        line = f"{history}: {rows} row{'s' if rows != 1 else ''} × {len(table.names)} columns → {target.path}"
        console.print(line, soft_wrap=True, markup=False)
        for text in lines:
            console.print(text, soft_wrap=True, markup=False)
