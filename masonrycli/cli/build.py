"""``masonry build NAME``: a built-in structure built, checked and written as GeoJSON, whole or not at all.
Added to the app as its ``build`` group by :mod:`masonrycli.cli.app`."""

from __future__ import annotations

import typer

from masonrycli.cli.messages import console, say, user_errors, warn
from masonrycli.cli.options import AQUEDUCT, ARCH, BLOCK_MATERIAL, FORCE, GEO_OUT, WALL, with_options

build_app = typer.Typer(no_args_is_help=True, help="Build a structure and write it as GeoJSON.")


def _write_assembly(builder: str, opts: dict) -> None:
    """Build, check and write the GeoJSON under a temporary name, renamed onto ``--out`` when complete."""
    from geometry_library.assembly_checks import validate_assembly
    from geometry_library.blocks import GeometryError
    from geometry_library.io import write_geojson
    from masonrycli.outputs.files import check_output, written_whole
    from masonrycli.scenario.builtin import build_assembly

    # .json too: `masonry run` reads a .json file as GeoJSON (GEOMETRY_SUFFIXES), build refused to write one
    target = check_output(opts.pop("out"), "--out", (".geojson", ".json"), opts.pop("force"))
    assembly = build_assembly(builder, **opts)
    for warning in validate_assembly(assembly):
        warn(warning)
    from masonrycli.interrupt import StopSignals, exit_code, signal_name

    out = target.path
    # A signal waits until the file is whole and said: a Ctrl-C just after the rename said "Ctrl-C: stopped
    # before any output was written" of the file written, a SIGTERM there killed the command (-15).
    with StopSignals() as signals:
        signals.closing()
        with written_whole(target) as part:
            try:
                write_geojson(assembly, part)
            except GeometryError as exc:  # a full disk said ".b.geojson.123.part: cannot write file", exit 2
                raise exc.__cause__ if isinstance(exc.__cause__, OSError) else exc from None
        console.print(
            f"{builder}: {assembly.block_count} block{'s' if assembly.block_count != 1 else ''} and "
            f"{assembly.support_count} support{'s' if assembly.support_count != 1 else ''} → {out}",
            soft_wrap=True,  # the path whole on its line (at 80 columns off a terminal it was cut in two)
            markup=False,
        )
    if signals.signum is not None:
        say("note", "yellow", f"{signal_name(signals.signum)} while {out} was written: it is whole")
        raise typer.Exit(exit_code(signals.signum))


@build_app.command("wall")
@user_errors
@with_options(GEO_OUT, WALL, BLOCK_MATERIAL, FORCE)
def build_wall_command(**opts) -> None:
    """A running-bond wall on its ground."""
    _write_assembly("wall", opts)


@build_app.command("arch")
@user_errors
@with_options(GEO_OUT, ARCH, BLOCK_MATERIAL, FORCE)
def build_arch_command(**opts) -> None:
    """A semicircular arch on two piers, each on its foundation; segmental with --rise below span / 2."""
    _write_assembly("arch", opts)


@build_app.command("aqueduct")
@user_errors
@with_options(GEO_OUT, AQUEDUCT, BLOCK_MATERIAL, FORCE)
def build_aqueduct_command(**opts) -> None:
    """The arch plus spandrel walls in running bond up to a level top."""
    _write_assembly("aqueduct", opts)
