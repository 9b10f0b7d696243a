"""The ``masonry`` command line. Thin: options → Scenario → execute; errors → one line, exit code 2."""

from __future__ import annotations

import dataclasses
import functools
import os
import sys
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.table import Table

from geometry_library.blocks import GeometryError
from masonrycli import __version__
from masonrycli.errors import InputError

app = typer.Typer(
    rich_markup_mode="rich",
    no_args_is_help=True,
    add_completion=False,
    help="Dynamic analysis of dry-stone masonry: rigid blocks, Coulomb friction, NSCD, "
    "the cell stress and strain tensors of Chetouane et al. (2003), Rerun recordings.",
)
simulate_app = typer.Typer(no_args_is_help=True, help="Build a structure, load it and record the run.")
build_app = typer.Typer(no_args_is_help=True, help="Build a structure and write it as GeoJSON.")
app.add_typer(simulate_app, name="simulate")
app.add_typer(build_app, name="build")

console = Console()
err_console = Console(stderr=True)

EXIT_BAD_INPUT = 2
EXIT_INTERRUPTED = 130
EXIT_DIVERGED = 3
EXIT_INTERNAL = 1


def _fail(message: str) -> None:
    err_console.print(f"[bold red]error:[/bold red] {message}", highlight=False, soft_wrap=True)
    raise typer.Exit(EXIT_BAD_INPUT)


def user_errors(func):
    """Turn bad input into one line on stderr and exit code 2 — never a traceback."""

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        try:
            return func(*args, **kwargs)
        except (InputError, GeometryError) as exc:
            _fail(str(exc).splitlines()[0] if str(exc) else type(exc).__name__)
        except OSError as exc:
            _fail(f"{exc.filename or ''}: {exc.strerror or exc}".lstrip(": "))

    return wrapper


def _version(value: bool) -> None:
    if value:
        console.print(f"masonry {__version__}")
        raise typer.Exit()


@app.callback()
def main_callback(
    version: Annotated[
        bool, typer.Option("--version", callback=_version, is_eager=True, help="Print the version and exit.")
    ] = False,
) -> None:
    """masonry: rigid-block dynamics of dry-stone masonry."""


# -- shared options -------------------------------------------------------------------------------

Duration = Annotated[float | None, typer.Option(help="Simulated time, s.", rich_help_panel="Run")]
Dt = Annotated[float | None, typer.Option("--dt", help="Time step, s (default 1e-3).", rich_help_panel="Run")]
Theta = Annotated[float | None, typer.Option(help="Moreau–Jean θ in [0.5, 1] (default 0.5).", rich_help_panel="Run")]
Friction = Annotated[
    float | None, typer.Option(help="Coulomb coefficient of every contact (default 0.6).", rich_help_panel="Material")
]
Density = Annotated[float | None, typer.Option(help="Block density, kg/m³ (default 2500).", rich_help_panel="Material")]
Thickness = Annotated[
    float | None, typer.Option(help="Out-of-plane thickness, m (default 1).", rich_help_panel="Material")
]
RecordEvery = Annotated[
    int | None, typer.Option(help="Steps between recorded frames (default 10).", rich_help_panel="Run")
]
Tolerance = Annotated[
    float | None,
    typer.Option(help="NLGS tolerance, relative quadratic norm (default 1.666e-4).", rich_help_panel="Run"),
]
MaxIterations = Annotated[
    int | None, typer.Option(help="NLGS sweep cap per step (default 1000).", rich_help_panel="Run")
]
Out = Annotated[
    Path | None,
    typer.Option(
        "--out",
        "-o",
        help="Recording (.rrd). Default: recordings/<scenario>-<timestamp>.rrd.",
        rich_help_panel="Output",
    ),
]
NoRecording = Annotated[bool, typer.Option("--no-recording", help="Write no .rrd recording.", rich_help_panel="Output")]
HistoryOpt = Annotated[
    Path | None,
    typer.Option("--history", help="History file (.npz), one row per recorded frame.", rich_help_panel="Output"),
]
Freq = Annotated[float | None, typer.Option("--freq", help="Ground velocity frequency, Hz.", rich_help_panel="Loading")]
Amp = Annotated[
    float | None, typer.Option("--amp", help="Horizontal ground velocity amplitude, m/s.", rich_help_panel="Loading")
]
Settlement = Annotated[
    float | None, typer.Option(help="Downward velocity of the right foundation, m/s.", rich_help_panel="Loading")
]
RecordFile = Annotated[
    Path | None,
    typer.Option(
        "--record",
        help="Ground motion record shaking the ground/foundations instead of the sine: PEER .AT2 (g) or CSV "
        "(time, velocity). Baseline-corrected; window and vertical component in a scenario file.",
        rich_help_panel="Loading",
    ),
]
Scale = Annotated[float | None, typer.Option("--scale", help="Multiplies the --record.", rich_help_panel="Loading")]


def _run_overrides(**values) -> dict:
    return {k: v for k, v in values.items() if v is not None}


def _replace(obj, where: str, **changes):
    """dataclasses.replace with the option name in the error message."""
    try:
        return dataclasses.replace(obj, **changes)
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None


def _apply_options(scenario, *, duration, dt, theta, friction, record_every, tolerance, max_iterations):
    from masonrycli.scenario import RunConfig  # noqa: F401  (validation lives in the dataclass)

    run_changes = _run_overrides(
        duration=duration,
        dt=dt,
        theta=theta,
        record_every=record_every,
        tolerance=tolerance,
        max_iterations=max_iterations,
    )
    for key, value in run_changes.items():
        _replace(scenario.run, f"--{key.replace('_', '-')}", **{key: value})
    run = _replace(scenario.run, "options", **run_changes) if run_changes else scenario.run
    material = scenario.material
    if friction is not None:
        material = _replace(material, "--friction", friction=friction)
    return dataclasses.replace(scenario, run=run, material=material)


def _outputs(name: str, out: Path | None, no_recording: bool) -> Path | None:
    from masonrycli.execute import default_recording_path

    if no_recording:
        return None
    if out is None:
        return default_recording_path(name)
    if out.suffix != ".rrd":
        raise InputError(f"--out {out}: a recording file must end in .rrd")
    return out


PAPER_INSTANT = {"wall": ("III.2–III.5", 0.1), "arch": ("III.7–III.10", 5.0)}
"""The instant of the paper's figures for each built-in structure."""


def _execute(scenario, out: Path | None, history: Path | None, hint: str = "") -> None:
    from masonrycli.execute import execute, print_summary

    for warning in scenario.warnings:
        err_console.print(f"[yellow]warning:[/yellow] {warning}", highlight=False)
    try:
        result = execute(scenario, out=out, history=history, console=console)
    except KeyboardInterrupt:
        err_console.print(
            "interrupted: the recording and history hold every frame computed so far" + (f" ({out})" if out else "")
        )
        raise typer.Exit(EXIT_INTERRUPTED) from None
    except (InputError, GeometryError):
        raise
    except Exception as exc:  # an engine bug: say so in one line, keep what was computed
        if os.environ.get("MASONRY_DEBUG"):
            raise
        err_console.print(
            f"[bold red]internal error:[/bold red] {type(exc).__name__}: {exc} — the recording"
            " and history hold every frame computed before it (MASONRY_DEBUG=1 shows the"
            " traceback)",
            highlight=False,
            soft_wrap=True,
        )
        raise typer.Exit(EXIT_INTERNAL) from None
    print_summary(console, result, scenario, out, history)
    if hint and out is not None:
        console.print(hint, soft_wrap=True)
    if result.status == "diverged":
        raise typer.Exit(EXIT_DIVERGED)
    if result.status == "interrupted":
        raise typer.Exit(EXIT_INTERRUPTED) from None


# -- builder options ------------------------------------------------------------------------------


def _wall_options(blocks, courses, length, block_length, block_height) -> dict:
    opts = {
        "blocks": blocks,
        "courses": courses,
        "length": length,
        "block_length": block_length,
        "block_height": block_height,
    }
    if courses is not None or length is not None:
        opts["blocks"] = blocks  # None unless given: the builder solves for the rest
    return {k: v for k, v in opts.items() if v is not None}


def _arch_options(voussoirs, pier_courses, span, ring_thickness, pier_width) -> dict:
    opts = {
        "voussoirs": voussoirs,
        "pier_courses": pier_courses,
        "span": span,
        "ring_thickness": ring_thickness,
        "pier_width": pier_width,
    }
    return {k: v for k, v in opts.items() if v is not None}


Blocks = Annotated[
    int | None,
    typer.Option(help="Number of blocks (default 51; 248 for the paper's large wall).", rich_help_panel="Structure"),
]
Courses = Annotated[int | None, typer.Option(help="Number of courses.", rich_help_panel="Structure")]
Length = Annotated[float | None, typer.Option(help="Wall length, m.", rich_help_panel="Structure")]
BlockLength = Annotated[float | None, typer.Option(help="Block length, m (default 0.30).", rich_help_panel="Structure")]
BlockHeight = Annotated[float | None, typer.Option(help="Block height, m (default 0.20).", rich_help_panel="Structure")]
Voussoirs = Annotated[int | None, typer.Option(help="Voussoirs in the arch (default 30).", rich_help_panel="Structure")]
PierCourses = Annotated[
    int | None, typer.Option(help="Courses per pier, 2 blocks each (default 17).", rich_help_panel="Structure")
]
Span = Annotated[
    float | None, typer.Option(help="Clear span of the arch, m (default 3.6).", rich_help_panel="Structure")
]
RingThickness = Annotated[
    float | None, typer.Option(help="Arch ring thickness, m (default 0.35).", rich_help_panel="Structure")
]
PierWidth = Annotated[float | None, typer.Option(help="Pier width, m (default 0.90).", rich_help_panel="Structure")]
WallCourses = Annotated[
    int | None, typer.Option(help="Courses of the spandrel walls (default 18).", rich_help_panel="Structure")
]

DEFAULT_DURATION = {"wall": 1.0, "arch": 5.0, "aqueduct": 5.0}


def _simulate(
    builder: str,
    options: dict,
    *,
    freq,
    amp,
    settlement,
    record,
    scale,
    duration,
    dt,
    theta,
    friction,
    density,
    thickness,
    record_every,
    tolerance,
    max_iterations,
    out,
    no_recording,
    history,
) -> None:
    from masonrycli.motion import Constant
    from masonrycli.scenario import Material, RunConfig, scenario_from_builder

    material = Material()
    for key, value in _run_overrides(density=density, thickness=thickness, friction=friction).items():
        material = _replace(material, f"--{key}", **{key: value})
    run = RunConfig(duration=DEFAULT_DURATION[builder])
    if record is not None:
        if amp is not None or freq is not None or settlement:
            given = "--amp" if amp is not None else "--freq" if freq is not None else "--settlement"
            raise InputError(f"--record with {given}: choose one loading (the record replaces the sine)")
        shaken = ("ground",) if builder == "wall" else ("left-foundation", "right-foundation")
        motion = _record(record, scale)
        motions = {name: motion for name in shaken}
    elif scale is not None:
        raise InputError("--scale: goes with --record (it multiplies the record)")
    elif builder == "wall":
        if settlement:
            raise InputError("--settlement: the wall stands on one ground; settlement applies to arch and aqueduct")
        amp = 1.0 if amp is None else amp
        freq = 2.0 if freq is None else freq
        motions = {"ground": _sine(amp, freq)} if amp else {}
    else:
        settlement = 0.01 if settlement is None else settlement
        amp = 0.0 if amp is None else amp
        freq = 2.0 if freq is None else freq
        if settlement < 0:
            raise InputError(f"--settlement {settlement}: must be >= 0 (a downward velocity, m/s)")
        motions = {}
        if amp:
            motions = {"left-foundation": _sine(amp, freq), "right-foundation": _sine(amp, freq)}
        if settlement:
            if amp:
                raise InputError("--settlement with --amp: choose one loading (settle or shake)")
            motions["right-foundation"] = Constant(velocity=(0.0, -settlement))
    scenario = scenario_from_builder(builder, options, run, material, motions)
    scenario = _apply_options(
        scenario,
        duration=duration,
        dt=dt,
        theta=theta,
        friction=None,
        record_every=record_every,
        tolerance=tolerance,
        max_iterations=max_iterations,
    )
    hint = ""
    if builder in PAPER_INSTANT:
        figs, t = PAPER_INSTANT[builder]
        step = round(t / scenario.run.dt)
        if step <= scenario.run.n_steps:
            hint = f"The paper's Figs. {figs} are at t = {t:g} s: step {step} on the viewer's timeline."
    _execute(scenario, _outputs(builder, out, no_recording), history, hint)


def _record(path: Path, scale: float | None):
    from masonrycli.records import record_motion

    try:
        return record_motion(path, scale=1.0 if scale is None else scale, display=str(path))
    except InputError as exc:
        msg = str(exc)
        raise InputError(msg if msg.startswith(str(path)) else f"--record {path}: {msg}") from None


def _with_record(scenario, record: Path | None, scale: float | None):
    """``scenario`` with every shaking support (sine or record motion) driven by the ``--record`` file."""
    if record is None:
        if scale is not None:
            raise InputError("--scale: goes with --record (it multiplies the record)")
        return scenario
    shaking = [m.kind in ("sine", "record") for m in scenario.motions]
    if not any(shaking):
        raise InputError(f"--record: {scenario.name} has no shaking support (give one a sine or record motion)")
    motion = _record(record, scale)
    motions = tuple(motion if shake else m for shake, m in zip(shaking, scenario.motions))
    return dataclasses.replace(scenario, motions=motions)


def _sine(amp: float, freq: float):
    from masonrycli.motion import Sine

    try:
        return Sine(direction=(1.0, 0.0), amplitude=amp, frequency=freq)
    except InputError as exc:
        raise InputError(f"--amp/--freq: {exc}") from None


@simulate_app.command("wall")
@user_errors
def simulate_wall(
    blocks: Blocks = None,
    courses: Courses = None,
    length: Length = None,
    block_length: BlockLength = None,
    block_height: BlockHeight = None,
    freq: Freq = None,
    amp: Amp = None,
    settlement: Settlement = None,
    record: RecordFile = None,
    scale: Scale = None,
    duration: Duration = None,
    dt: Dt = None,
    theta: Theta = None,
    friction: Friction = None,
    density: Density = None,
    thickness: Thickness = None,
    record_every: RecordEvery = None,
    tolerance: Tolerance = None,
    max_iterations: MaxIterations = None,
    out: Out = None,
    no_recording: NoRecording = False,
    history: HistoryOpt = None,
) -> None:
    """The paper's running-bond wall on a shaken ground (default 51 blocks, 1 m/s at 2 Hz for 1 s)."""
    if blocks is None and courses is None and length is None:
        blocks = 51
    _simulate(
        "wall",
        _wall_options(blocks, courses, length, block_length, block_height),
        freq=freq,
        amp=amp,
        settlement=settlement,
        record=record,
        scale=scale,
        duration=duration,
        dt=dt,
        theta=theta,
        friction=friction,
        density=density,
        thickness=thickness,
        record_every=record_every,
        tolerance=tolerance,
        max_iterations=max_iterations,
        out=out,
        no_recording=no_recording,
        history=history,
    )


@simulate_app.command("arch")
@user_errors
def simulate_arch(
    voussoirs: Voussoirs = None,
    pier_courses: PierCourses = None,
    span: Span = None,
    ring_thickness: RingThickness = None,
    pier_width: PierWidth = None,
    freq: Freq = None,
    amp: Amp = None,
    settlement: Settlement = None,
    record: RecordFile = None,
    scale: Scale = None,
    duration: Duration = None,
    dt: Dt = None,
    theta: Theta = None,
    friction: Friction = None,
    density: Density = None,
    thickness: Thickness = None,
    record_every: RecordEvery = None,
    tolerance: Tolerance = None,
    max_iterations: MaxIterations = None,
    out: Out = None,
    no_recording: NoRecording = False,
    history: HistoryOpt = None,
) -> None:
    """The paper's 98-block arch on two piers; default: right foundation settles at 1 cm/s for 5 s."""
    _simulate(
        "arch",
        _arch_options(voussoirs, pier_courses, span, ring_thickness, pier_width),
        freq=freq,
        amp=amp,
        settlement=settlement,
        record=record,
        scale=scale,
        duration=duration,
        dt=dt,
        theta=theta,
        friction=friction,
        density=density,
        thickness=thickness,
        record_every=record_every,
        tolerance=tolerance,
        max_iterations=max_iterations,
        out=out,
        no_recording=no_recording,
        history=history,
    )


@simulate_app.command("aqueduct")
@user_errors
def simulate_aqueduct(
    voussoirs: Voussoirs = None,
    pier_courses: PierCourses = None,
    span: Span = None,
    ring_thickness: RingThickness = None,
    pier_width: PierWidth = None,
    wall_courses: WallCourses = None,
    freq: Freq = None,
    amp: Amp = None,
    settlement: Settlement = None,
    record: RecordFile = None,
    scale: Scale = None,
    duration: Duration = None,
    dt: Dt = None,
    theta: Theta = None,
    friction: Friction = None,
    density: Density = None,
    thickness: Thickness = None,
    record_every: RecordEvery = None,
    tolerance: Tolerance = None,
    max_iterations: MaxIterations = None,
    out: Out = None,
    no_recording: NoRecording = False,
    history: HistoryOpt = None,
) -> None:
    """A segment of the Arles aqueduct (98 arch + 248 wall blocks); default: settlement 1 cm/s for 5 s.

    Shake it instead with [bold]--settlement 0 --amp 1 --freq 2[/bold].
    """
    options = _arch_options(voussoirs, pier_courses, span, ring_thickness, pier_width)
    if wall_courses is not None:
        options["wall_courses"] = wall_courses
    _simulate(
        "aqueduct",
        options,
        freq=freq,
        amp=amp,
        settlement=settlement,
        record=record,
        scale=scale,
        duration=duration,
        dt=dt,
        theta=theta,
        friction=friction,
        density=density,
        thickness=thickness,
        record_every=record_every,
        tolerance=tolerance,
        max_iterations=max_iterations,
        out=out,
        no_recording=no_recording,
        history=history,
    )


@app.command("run")
@user_errors
def run_command(
    scenario_file: Annotated[
        Path, typer.Argument(help="Scenario file (TOML), or a GeoJSON / WKT geometry.", metavar="SCENARIO.toml")
    ],
    duration: Duration = None,
    dt: Dt = None,
    theta: Theta = None,
    friction: Friction = None,
    record_every: RecordEvery = None,
    tolerance: Tolerance = None,
    max_iterations: MaxIterations = None,
    out: Out = None,
    no_recording: NoRecording = False,
    history: HistoryOpt = None,
    record: RecordFile = None,
    scale: Scale = None,
) -> None:
    """Run any scenario file (or a GeoJSON / WKT geometry file, supports fixed); options given here
    override the file's values."""
    from masonrycli.scenario import scenario_from_geometry_file
    from masonrycli.scenario_toml import load_scenario
    from masonrycli.structure import GEOMETRY_SUFFIXES

    if scenario_file.suffix.lower() in GEOMETRY_SUFFIXES:
        scenario = scenario_from_geometry_file(scenario_file)
    else:
        scenario = load_scenario(scenario_file)
    scenario = _with_record(scenario, record, scale)
    scenario = _apply_options(
        scenario,
        duration=duration,
        dt=dt,
        theta=theta,
        friction=friction,
        record_every=record_every,
        tolerance=tolerance,
        max_iterations=max_iterations,
    )
    _execute(scenario, _outputs(scenario.name, out, no_recording), history)


@app.command("limit")
@user_errors
def limit_command(
    structure: Annotated[
        str,
        typer.Argument(
            help="wall, arch or aqueduct (built-in defaults), a scenario file (TOML) or a GeoJSON / WKT geometry.",
            metavar="SCENARIO|wall|arch|aqueduct",
        ),
    ],
    load: Annotated[
        str, typer.Option(help="horizontal (λ × weight), tilt (tilting table, tan ψ = λ) or point (on --block).")
    ] = "horizontal",
    block: Annotated[str | None, typer.Option(help="Block carrying the point load (λ × its weight).")] = None,
    direction: Annotated[str, typer.Option(help="+x or -x (a point load also +y or -y).")] = "+x",
    friction: Friction = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object on stdout, nothing else.")] = False,
    verify: Annotated[
        bool, typer.Option("--verify", help="Run the NSCD engine at 0.95 λ and 1.05 λ (tilted gravity) and compare.")
    ] = False,
    out: Annotated[
        Path | None, typer.Option("--out", "-o", help="Write the mechanism recording (.rrd).", metavar="REC.rrd")
    ] = None,
) -> None:
    """The collapse load factor λ and mechanism of a block assembly (rigid-block limit analysis, one LP)."""
    from masonrycli.limit.command import run_limit

    run_limit(
        structure,
        load=load,
        direction=direction,
        block=block,
        friction=friction,
        as_json=as_json,
        verify=verify,
        out=out,
        console=console,
        err_console=err_console,
    )


@app.command("check")
@user_errors
def check_command(
    scenario_file: Annotated[Path, typer.Argument(help="Scenario file (TOML).", metavar="SCENARIO.toml")],
) -> None:
    """Validate a scenario file and print a summary (blocks, supports, mass, bounding box)."""
    from masonrycli.scenario import scenario_summary
    from masonrycli.scenario_toml import load_scenario

    scenario = load_scenario(scenario_file)
    info = scenario_summary(scenario)
    table = Table(title=f"{scenario_file} — valid", show_header=False, title_justify="left")
    table.add_column("", style="bold")
    table.add_column("")
    xmin, ymin, xmax, ymax = info["bounding_box"]
    table.add_row("scenario", str(info["name"]))
    table.add_row("blocks", str(info["blocks"]))
    table.add_row(
        "supports",
        ", ".join(f"{k} ({v})" for k, v in info["support_motions"].items())
        if isinstance(info.get("support_motions"), dict)
        else str(info["supports"]),
    )
    table.add_row("total mass", f"{info['total_mass']:.6g} kg")
    table.add_row("bounding box", f"x {xmin:.4g} … {xmax:.4g} m, y {ymin:.4g} … {ymax:.4g} m")
    table.add_row("friction", f"{info['friction']:g}")
    table.add_row(
        "time", f"{info['duration']:g} s in {info['n_steps']} steps of {info['dt']:g} s, θ = {info['theta']:g}"
    )
    console.print(table)
    for warning in scenario.warnings:
        err_console.print(f"[yellow]warning:[/yellow] {warning}", highlight=False)


def _write_assembly(builder: str, options: dict, density, thickness, out: Path) -> None:
    from geometry_library.builders import BUILDERS
    from geometry_library.checks import validate_assembly
    from geometry_library.io import write_geojson

    if density is not None:
        options["density"] = density
    if thickness is not None:
        options["thickness"] = thickness
    try:
        assembly = BUILDERS[builder](**options).build()
    except (ValueError, GeometryError) as exc:
        raise InputError(f"{builder}: {exc}") from None
    for warning in validate_assembly(assembly):
        err_console.print(f"[yellow]warning:[/yellow] {warning}", highlight=False)
    write_geojson(assembly, out)
    console.print(
        f"{builder}: {assembly.block_count} blocks and {assembly.support_count} "
        f"support{'s' if assembly.support_count != 1 else ''} → {out}"
    )


GeoOut = Annotated[Path, typer.Option("--out", "-o", help="GeoJSON file to write.")]


@build_app.command("wall")
@user_errors
def build_wall_command(
    out: GeoOut,
    blocks: Blocks = None,
    courses: Courses = None,
    length: Length = None,
    block_length: BlockLength = None,
    block_height: BlockHeight = None,
    density: Density = None,
    thickness: Thickness = None,
) -> None:
    """A running-bond wall on its ground."""
    if blocks is None and courses is None and length is None:
        blocks = 51
    _write_assembly("wall", _wall_options(blocks, courses, length, block_length, block_height), density, thickness, out)


@build_app.command("arch")
@user_errors
def build_arch_command(
    out: GeoOut,
    voussoirs: Voussoirs = None,
    pier_courses: PierCourses = None,
    span: Span = None,
    ring_thickness: RingThickness = None,
    pier_width: PierWidth = None,
    density: Density = None,
    thickness: Thickness = None,
) -> None:
    """A semicircular arch on two piers, each on its foundation."""
    _write_assembly(
        "arch", _arch_options(voussoirs, pier_courses, span, ring_thickness, pier_width), density, thickness, out
    )


@build_app.command("aqueduct")
@user_errors
def build_aqueduct_command(
    out: GeoOut,
    voussoirs: Voussoirs = None,
    pier_courses: PierCourses = None,
    span: Span = None,
    ring_thickness: RingThickness = None,
    pier_width: PierWidth = None,
    wall_courses: WallCourses = None,
    density: Density = None,
    thickness: Thickness = None,
) -> None:
    """The arch plus spandrel walls in running bond up to a level top."""
    options = _arch_options(voussoirs, pier_courses, span, ring_thickness, pier_width)
    if wall_courses is not None:
        options["wall_courses"] = wall_courses
    _write_assembly("aqueduct", options, density, thickness, out)


@app.command("inspect")
@user_errors
def inspect_command(
    recording: Annotated[Path, typer.Argument(help="Recording (.rrd).", metavar="REC.rrd")],
) -> None:
    """Summarise a recording: scenario, frames, time span, entities."""
    from masonrycli.recording import inspect_recording

    if not recording.is_file():
        raise InputError(f"{recording}: no such recording")
    try:
        info = inspect_recording(recording)
    except Exception as exc:  # a corrupt or foreign file: say so in one line
        raise InputError(f"{recording}: not a readable Rerun recording ({type(exc).__name__}: {exc})") from None
    table = Table(title=str(recording), show_header=False, title_justify="left")
    table.add_column("", style="bold")
    table.add_column("")
    for key, value in info.items():
        if key == "metadata":
            continue
        if key in ("steps", "time_span") and isinstance(value, (list, tuple)) and len(value) == 2:
            value = f"{value[0]} … {value[1]}" + (" s" if key == "time_span" else "")
        elif isinstance(value, (list, tuple)):
            value = "\n".join(map(str, value))
        table.add_row(key, str(value))
    console.print(table)
    if info.get("metadata"):
        console.print(info["metadata"])


def main() -> None:
    app()


if __name__ == "__main__":
    sys.exit(main())
