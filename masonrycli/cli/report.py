"""``masonry report``: a run's one-page summary in Markdown. Thin: the history read and checked as ``export``
reads it, the page made by :mod:`masonrycli.outputs.run_report`; registered on the app by
:mod:`masonrycli.cli.app`."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from masonrycli.cli.option_values import file_path_value, path_value


def report_command(
    history: Annotated[
        Path,
        typer.Argument(help="A run's history (--history H.npz).", metavar="H.npz", parser=path_value),
    ],
    out: Annotated[
        Path | None,
        typer.Option(
            "--out",
            "-o",
            parser=file_path_value,
            help="The Markdown page to write (its name ending in .md), its figure beside it (the same name, .png); default: the page on stdout.",
            metavar="PAGE",
        ),
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Replace the --out files if they exist.")] = False,
) -> None:
    """A run's one-page report in Markdown: what was run (structure, material, loading, masonry's version), the
    ground motion as applied (PGA, PGV, Arias, D5–95), the result (state, peak and residual drift, hinged
    joints, unconverged steps) — the numbers of the run's summary — and with --out a figure of the top's drift
    and the ground's acceleration."""
    from masonrycli.cli.messages import console
    from masonrycli.outputs.run_report import check_outputs, read, report_markdown, write_report

    outputs = check_outputs(out, force) if out is not None else None  # first, as export: nothing computed in vain
    arrays = read(history)
    if outputs is None:
        typer.echo(report_markdown(arrays, str(history)), nl=False)
        return
    page, picture = write_report(arrays, str(history), *outputs)
    console.print(f"{history}: report → {page} (figure {picture})", soft_wrap=True, markup=False)
