"""What ``masonry limit`` does behind its Typer command: resolve the structure, analyse, verify, report.

The structure is a built-in name (``wall``, ``arch``, ``aqueduct``: the builders' defaults), a scenario
file (TOML) or a geometry file (GeoJSON / WKT), resolved as ``masonry run`` resolves them. ``--json``
prints exactly one JSON object on stdout and nothing else (warnings go to stderr).
"""

from __future__ import annotations

import json
import math
import signal
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import typer
from rich.console import Console
from rich.table import Table
from rich.text import Text

from masonrycli import SOURCE_DIGEST, __version__
from masonrycli.errors import EXIT_OUTPUT_FAILED, InputError
from masonrycli.interrupt import StopRun, StopSignals, exit_code, signal_name
from masonrycli.limit.analysis import LimitResult, analyse, parts_text
from masonrycli.limit.problem import LimitError, LiveLoad, NoEquilibrium, force_text, parse_force
from masonrycli.outputs.files import check_output, written_whole
from masonrycli.source_digest import source_commit

SHOWN = 8
"""Joint names listed in the terminal table (all of them are in --json)."""


def resolve_structure(structure: str, friction: float | None, options: dict | None = None):
    """A scenario from a built-in name (the builder's defaults, or ``options``: the structure options of
    ``masonry build NAME`` and --density / --thickness, no motion), a scenario file or a geometry file
    (:func:`~masonrycli.scenario.target.target_scenario`); ``friction`` overrides μ."""
    from masonrycli.cli.check import material_hint
    from masonrycli.cli.options import BLOCK_MATERIAL, STRUCTURE_OPTIONS, SURVEY
    from masonrycli.scenario.builtin import builtin, override_run
    from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder
    from masonrycli.scenario.target import is_built_in, target_scenario

    options = dict(options or {})
    survey = {k: options.pop(k) for k in SURVEY if k in options}  # a geometry file's reading (target_scenario)
    given = {k: v for k, v in options.items() if v is not None}
    flags = ", ".join(f"--{k.replace('_', '-')}" for k in given)
    if given and not is_built_in(structure):
        raise InputError(
            f"{flags}: structure options shape a built-in structure (masonry limit wall|arch|aqueduct …); "
            f"{structure} is a file, which gives its own geometry{material_hint(given)}"
        )
    if given and is_built_in(structure):
        allowed = {*STRUCTURE_OPTIONS[structure], *BLOCK_MATERIAL}
        foreign = [k for k in given if k not in allowed]
        if foreign:
            names = ", ".join(f"--{k.replace('_', '-')}" for k in sorted(allowed))
            raise InputError(
                f"--{foreign[0].replace('_', '-')}: not an option of the {structure} (its options: {names})"
            )

    def built_in(name: str):
        if given:  # the scenario simulate would run, its loading left out: limit's supports are fixed
            return builtin(name, **given)
        return scenario_from_builder(name, {}, RunConfig(), Material(), {})

    scenario = target_scenario(structure, built_in, survey)
    return override_run(scenario, friction=friction)


MAP_ABSCISSA = 1e4
"""m: an --at this far from the origin, on a file read moved from a map grid, is the map's abscissa (the file as
read lies within this of the origin: geometry_library.survey)."""


def _on_the_file(live: LiveLoad, scenario, err_console) -> LiveLoad:
    """``live`` with an --at given in the map's coordinates (a Lambert-93 abscissa, 651233.5) moved as the file was
    read (to 233.5): it said 'no block over x = 651233 m (the blocks span x = 228.8 … 239.2 m)'."""
    origin = (scenario.reading or {}).get("map_origin_m")
    if live.at is None or origin is None or abs(live.at) < MAP_ABSCISSA:
        return live
    x = live.at - origin[0]
    err_console.print(
        Text.assemble(
            ("note:", "cyan"),
            f" --at {live.at:.12g} is the map's abscissa: x = {x:.12g} m in the file as read (moved by {-origin[0]:.0f} m)",
        ),
        soft_wrap=True,
    )
    return replace(live, at=x)


def _names(names: list[str]) -> str:
    """``names`` come fastest first: a long list shows the mechanism's main joints, not the first names
    in body order (the aqueduct's point load listed 8 pier and spandrel joints turning at 0.01–1 % of its
    crown hinge v15|v16, which was not shown)."""
    if len(names) > SHOWN:
        return f"{len(names)}, the {SHOWN} fastest: {', '.join(names[:SHOWN])} … (all in --json)"
    return f"{len(names)}" + (f": {', '.join(names)}" if names else "")


def lambda_reading(result: LimitResult) -> str:
    """λ in an engineer's words: a body force λ × weight is a horizontal acceleration of λ g; the tilt."""
    reading = []
    if result.load.kind == "horizontal":
        g = float(np.hypot(*result.model.gravity))
        reading.append(f"a horizontal acceleration of {result.load_factor:.3g} g = {result.load_factor * g:.3g} m/s²")
    if result.tilt_angle() is not None:
        reading.append(f"tilt ψ = {result.tilt_angle():.2f}°")
    if result.load.force is not None:  # an axle's verdict: carried, or by how much it is not
        size = force_text(result.load.force)
        verdict = "carries it" if result.load_factor >= 1.0 else "does not carry it"
        reading.append(f"{verdict}: collapse at {result.load_factor:.3g} × {size}")
    return "; ".join(reading)


def depth_text(result: LimitResult) -> str:
    """Which out-of-plane thickness the newtons are for."""
    return "" if result.thickness is None else f", for blocks {result.thickness:g} m thick (out of plane)"


def _worst_text(result: LimitResult) -> str:
    """The --worst row: where, among how many places, and the next-worst places elsewhere."""
    found = sorted((p for p in result.places if p.load_factor is not None), key=lambda p: p.load_factor)
    skipped = len(result.places) - len(found)
    on_map = "" if result.map_origin is None else f" ({result.load.at + result.map_origin[0]:.12g} on the map)"
    said = (
        f"x = {result.load.at:.4g} m{on_map} on {result.load.block}, the least λ of {len(result.places)} places tried"
    )
    said += " (both ends of each straight stretch of the blocks' top: λ is least at one of them)"
    others, seen = [], {round(result.load.at, 9)}
    for p in found:  # the next-worst elsewhere: a joint's other side is the same place
        if round(p.at, 9) not in seen and len(others) < 3:
            others.append(p)
            seen.add(round(p.at, 9))
    if others:
        said += "; next: " + ", ".join(f"λ = {p.load_factor:.4g} at x = {p.at:.4g} m on {p.block}" for p in others)
    return said + (f"; {skipped} with no mechanism that follows the load" if skipped else "")


SLIDING_CAVEAT = (
    "may overstate: the LP's joints dilate as they slide (by μ × the slip: associative flow), the stones' and the "
    "engine's do not, so the structure may collapse below λ (the built-in wall at 0.90–0.95 λ); --verify runs "
    "the engine at 0.95 and 1.05 λ"
)
"""The row said under a mechanism with sliding joints (docs/limit.md, *The caveat*)."""


def result_table(result: LimitResult, out: Path | None) -> Table:
    s = result.summary()
    table = Table(title=f"masonry limit — {result.scenario_name}", show_header=False, title_justify="left")
    table.add_column("quantity", style="bold")
    table.add_column("value")
    counts = ", ".join(
        f"{n} {what}{'s' if n != 1 else ''}" for n, what in ((s["blocks"], "block"), (s["supports"], "support"))
    )
    table.add_row("structure", f"{counts}, friction μ = {s['friction']:g}")
    if s["fill_load_N"]:
        table.add_row("fill", f"{s['fill_load_N']:.4g} N{depth_text(result)}, dead load on the blocks under it")
    if result.settled is not None:
        table.add_row("settled", result.settled.describe())
    table.add_row("joints", f"{s['joints']} ({s['contact_points']} contact points, from the engine's detection)")
    fill_too = "; the fill's mass too" if s["fill_load_N"] and result.load.kind != "point" else ""
    table.add_row("live load", result.load.describe() + fill_too)
    if result.places is not None:
        table.add_row("worst place", _worst_text(result))
    lam = Text(f"{result.load_factor:.4f}", style="bold")  # Text: the consoles parse no markup
    reading = lambda_reading(result)
    if reading:
        lam.append(f"  ({reading})")
    table.add_row("load factor λ", lam)
    table.add_row(
        "collapse load", f"{s['collapse_load_N']:.4g} N (λ × {s['reference_load_N']:.4g} N){depth_text(result)}"
    )
    if result.ring is not None:
        table.add_row("least ring thickness", result.ring.describe())
    if result.support_thrust and result.model.support_count == 1:  # "0 … 0 N towards -x" said nothing
        table.add_row(
            f"thrust on {result.support_thrust[0][0]}",
            "none to give: one support carries every block, so the horizontal forces on it balance; an arch's "
            "thrust on its abutments needs each on its own support (a file: each abutment's foundation traced as "
            "a support)",
        )
    for name, direction, least, greatest in (result.support_thrust or ()) if result.model.support_count > 1 else ():
        bound = f"{greatest:.4g} N" if math.isfinite(greatest) else "no bound (blocks jammed between supports)"
        lower = f"{least:.4g}" if math.isfinite(least) else "no bound"
        table.add_row(
            f"thrust on {name}",
            f"{lower} … {bound} towards {direction}, under the dead load alone (least: the supports "
            "spreading; greatest: pushed together)",
        )
    table.add_row("hinges", _names(result.hinges_largest_first()))
    table.add_row("sliding joints", _names(result.sliding_largest_first()))
    if result.sliding_joints:
        table.add_row("λ, as it slides", SLIDING_CAVEAT)
    if result.motion.joint_opening.any():  # parting all along: not hinges (the wall's wedge had "10 hinges")
        table.add_row("joints opening", _names(result.opening_largest_first()))
    table.add_row(
        "blocks in the mechanism",
        f"{len(result.moving_blocks)} of {s['blocks']}{parts_text(result.model.block_name, result.part_indices)}",
    )
    table.add_row(
        "solve time", f"{s['solve_time_s'] * 1e3:.0f} ms HiGHS, {s['analysis_time_s'] * 1e3:.0f} ms analysis in all"
    )
    if out is not None:
        table.add_row("recording", str(out))
    return table


def verify_table(checks) -> Table:
    applied = checks[0].applied if checks else "tilt"
    title = {
        "weight": "the point load as a weight f·λ·F on its block",
        "force": "the point load as a force f·λ·F applied where it acts",
    }.get(applied, "gravity tilted to atan(f·λ)")
    table = Table(title=f"--verify: the NSCD engine under {title}", title_justify="left")
    # Short header words, each column at least as wide as its longest word: at 80 columns rich cut
    # "max displacement" and "mechanism similarity" to "displacem…" and "similari…".
    for col in ("f", "tilt", "engine", "predicted", "largest move", "similarity", "hinges shared"):
        table.add_column(col, min_width=max(len(word) for word in col.split()))
    for c in checks:
        table.add_row(
            f"{c.factor:g}",
            c.applied if c.tilt_deg is None else f"{c.tilt_deg:.2f}°",
            f"collapses at t = {c.time:.3f} s"
            if c.collapsed
            else f"stands for {c.time:.2f} s (end speed {c.max_speed * 1e3:.2g} mm/s)",
            Text("yes") if c.as_predicted else Text("no", style="bold red"),
            f"{c.max_displacement * 1e3:.2f} mm (threshold {c.threshold * 1e3:.1f})",
            "" if c.similarity is None else f"{c.similarity:.3f}",
            f"{len(c.shared_hinges)} of {len(c.hinges)}",
        )
    return table


def run_limit(
    structure: str,
    *,
    load: str,
    direction: str | None,
    block: str | None,
    friction: float | None,
    as_json: bool,
    verify: bool,
    out: Path | None,
    console: Console,
    err_console: Console,
    force: bool = False,
    structure_options: dict | None = None,
    at: float | None = None,
    thrust: bool = False,
    min_thickness: bool = False,
    settle: float | None = None,
    worst: bool = False,
    point_force: str | None = None,
    spread: float | None = None,
) -> None:
    """``masonry limit``: analyse, optionally record and verify, then print a table or one JSON object.
    ``settle``: s the wall is first let come to rest under its own weight (:mod:`masonrycli.settle`).

    Ctrl-C or SIGTERM stops it (:mod:`masonrycli.interrupt`) with one line on stderr and exit 130 / 143, as
    ``simulate`` and ``sweep`` do (SIGTERM killed it before: exit -15, no word); one that arrives while the
    recording is written waits for it to be whole.
    """
    done = _Done()
    with StopSignals() as signals:
        try:
            with signals.setup_work():  # the analysis and --verify compile numba kernels on a first run
                checks = _analyse(
                    structure,
                    LiveLoad(
                        load,
                        direction,
                        block,
                        at,
                        worst=worst,
                        force=None if point_force is None else parse_force(point_force),
                        spread=spread,
                    ),
                    friction,
                    verify,
                    out,
                    force,
                    done,
                    signals,
                    console=None if as_json else console,
                    err_console=err_console,
                    structure_options=structure_options,
                    thrust=thrust,
                    min_thickness=min_thickness,
                    settle=settle,
                )
        except StopRun as stop:
            how = "" if stop.signum == signal.SIGINT else f" ({signal_name(stop.signum)})"  # as `masonry sweep`
            err_console.print(f"interrupted{how}: {done.describe()}", soft_wrap=True)
            raise typer.Exit(exit_code(stop.signum)) from None
        done.verifying = False  # it finished
        # The answer is printed under the handlers, a signal only noted: once they had been put back, a Ctrl-C
        # here said "Ctrl-C: stopped before any output was written" with the recording written, and a SIGTERM
        # killed the command mid-table (exit -15).
        signals.closing()
        _print_answer(done, checks, verify, as_json, console)
    if signals.signum is not None:
        said = f"{signal_name(signals.signum)} after the answer was printed: {done.describe()}"
        err_console.print(f"note: {said}", soft_wrap=True)
        raise typer.Exit(exit_code(signals.signum))


def _print_answer(done, checks, verify: bool, as_json: bool, console) -> None:
    """The result table (and the --verify table), or one JSON object."""
    result, out = done.result, done.out
    if as_json:
        # the code that answered, as a run's history and recording name it (before: no version, no commit)
        made_by = {"masonry": __version__, "commit": source_commit(), "source_digest": SOURCE_DIGEST}
        summary = result.summary() | {"recording": str(out) if out else None} | made_by
        if verify:
            summary["verify"] = [c.summary() for c in checks]
        print(json.dumps(summary, allow_nan=False))
        return
    if not verify:
        console.print(result_table(result, out))
    elif checks:
        console.print(verify_table(checks))


@dataclass
class _Done:
    """How far ``masonry limit`` got: what the line of an interrupted one says."""

    result: LimitResult | None = None
    out: Path | None = None
    """The recording, once it is complete on disk."""
    verifying: bool = False

    def describe(self) -> str:
        if self.result is None:
            return "before λ was found; nothing was written"
        said = f"λ = {self.result.load_factor:.4f}"
        if self.out is not None:
            said += f", the recording {self.out} is complete"
        return said + "; --verify did not finish" if self.verifying else said


def _analyse(structure, live, friction, verify, out, force, done: _Done, signals, *, console, err_console, **options):
    """The work of :func:`run_limit`, filling ``done`` as it goes; returns the --verify checks. ``console``:
    where the result table goes before --verify runs (None with --json)."""
    from masonrycli.scenario.caveats import setting_warnings

    target = None if out is None else check_output(out, "--out", ".rrd", force)
    if options["min_thickness"]:  # before anything runs: --settle would have run the engine for nothing
        from masonrycli.limit.thickness import check_min_thickness

        check_min_thickness(structure, options["settle"])
    scenario = resolve_structure(structure, friction, options["structure_options"])
    settings = setting_warnings(scenario)  # not its records': it has no time
    settling = None
    if options["settle"] is not None:  # the engine first: a traced wall's gaps closed under its own weight
        from masonrycli.settle import settle

        scenario, settling = settle(scenario, options["settle"])
    live = _on_the_file(live, scenario, err_console)
    try:
        origin = (scenario.reading or {}).get("map_origin_m")
        done.result = replace(
            analyse(scenario, live, thrust=options["thrust"]),
            settled=settling,
            map_origin=None if origin is None else (float(origin[0]), float(origin[1])),
        )
        if options["min_thickness"]:
            from masonrycli.limit.thickness import builtin_least_ring, traced_least_ring
            from masonrycli.scenario.target import is_built_in

            ring = (
                builtin_least_ring(structure, friction, options["structure_options"])
                if is_built_in(structure)
                else traced_least_ring(scenario)
            )
            done.result = replace(done.result, ring=ring)
    except LimitError as exc:
        # one line, as any refusal: a block touching nothing was said twice (a warning, then the error in the
        # same words); a setting's warning is the reason ("no equilibrium" under a gravity pointing up)
        said = f"{exc} ({'; '.join(settings)})" if settings else str(exc)
        # a traced wall: stones a tracing's gap apart. Not a built-in's (its stones are laid exact: a thin ring, no
        # friction), nor one a setting's warning explains: --settle would not mend them
        drawn = "builder" not in scenario.structure and not settings
        if isinstance(exc, NoEquilibrium) and settling is None and drawn:
            said += "; stones drawn apart (a traced wall's gaps)? --settle 0.5 lets them come to rest first"
        raise LimitError(said) from None
    for warning in (*scenario.warnings, *settings):
        err_console.print(Text.assemble(("warning:", "yellow"), f" {warning}"))
    if target is not None:
        with signals.held():  # a signal now waits until the recording is whole and in place
            try:
                from masonrycli.limit.drawing import write_recording

                with written_whole(target) as part:  # under a temporary name, renamed when complete
                    write_recording(done.result, part, scenario)
            except OSError as exc:  # a full disk: as simulate's outputs, exit 4 (it said "completed", exit 0)
                from masonrycli.cli.messages import fail

                fail(f"cannot write {target.option} {target.path}: {exc.strerror or exc}", EXIT_OUTPUT_FAILED)
            done.out = target.path
    if not verify:
        return []
    if done.result.load_factor <= 1e-12:
        # 0.95 λ and 1.05 λ are the same unloaded structure: the engine ran it twice and the second row read a
        # red "no" under "predicted" (it stands: there is no load)
        if console is not None:
            console.print(result_table(done.result, done.out))
        err_console.print(
            "--verify: λ = 0, so 0.95 λ and 1.05 λ are both the unloaded structure: nothing to verify "
            "(a joint slides or opens under any live load)",
            soft_wrap=True,
        )
        return []
    from masonrycli.limit.verify import verify as run_verify

    done.verifying = True
    if console is not None:
        console.print(result_table(done.result, done.out))
        console.print("running the engine at 0.95 λ and 1.05 λ …", style="dim")
    return run_verify(scenario, done.result)
