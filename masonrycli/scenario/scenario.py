"""Scenarios: what to simulate (structure, material, support motions) and how (time stepping, solver).

The data classes and the constructors that do not read TOML: from a builder of ``geometry_library.builders``
(:func:`scenario_from_builder`: ``masonry simulate wall ...``) or a geometry file (:func:`scenario_from_geometry_file`).
:mod:`masonrycli.scenario.toml_file` reads and writes scenario files; :func:`scenario_summary` gives what
``masonry check`` prints. A problem with the input raises :class:`masonrycli.errors.InputError`, one line naming
the file and the key: ``wall.toml: [run] dt = -0.001: must be > 0``.
"""

from __future__ import annotations

import dataclasses
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

from geometry_library.blocks import Assembly, Block, GeometryError
from geometry_library.values import MATERIAL_RANGE
from masonrycli.errors import InputContext, InputError
from masonrycli.scenario.motion import Fixed, Motion
from masonrycli.scenario.structure import (
    BuilderError,
    build_structure,
    check_finite_tree,
    read_geometry,
    structure_warnings,
)
from masonrycli.scenario.values import check_int, check_real, check_vector, field_error, quote_string, shorten

MAX_DURATION = 1e5
"""s — longer runs are refused as a likely typo."""
MAX_STEPS = 10**8
"""Steps per run: more is refused up front as a likely typo (10⁸ steps of the 51-block wall take ~1 day)."""
MIN_DT = 1e-9
"""s — a shorter step is refused as a likely typo: --duration 1e-310 --dt 1e-310 ran its one step, then the
summary overflowed (t / dt = inf: an OverflowError traceback)."""
MIN_TOLERANCE = 1e-15
"""m/s — a tighter NLGS tolerance is refused as a likely typo: float64 resolves a velocity of 1 m/s (the default
shaking) to 2.2e-16 m/s, so a residual below a few of those is not a goal a solve can aim at (a 51-block wall
ends every step at the sweep cap from 1e-12 on: benchmarks/bench_solver.py uses that as "no solve meets it";
``--tolerance 1e-300`` ran each step to the 100 000-sweep cap)."""
MAX_COUNT = 10**9
MAX_FRICTION = 1e3
"""Largest Coulomb μ: masonry joints have 0.4–1 and μ = 1000 already forbids sliding; beyond ~1e7 the limit
analysis LP lost the weight against the friction cone's size and called the wall unable to stand."""
MAX_GRAVITY = 1e4
"""m/s² — a larger gravity vector is refused as a likely typo (≈ 1000 g; ``gravity = [0, -1e9]`` ran)."""
MAX_SUPPORT_SPEED = 1e3
"""m/s — a support moving faster is refused as a likely typo: run.py calls a block that fast diverged
(``--amp 1e30`` ran and reported the wall "collapsed at t = 0.001 s", exit 0; a record of 1e300 m/s too,
with numpy's overflow warnings)."""
MAX_BLOCK_SPEED = 1e3
"""m/s — an initial block velocity moving a point of the block faster (|v| + |ω|·r, r the farthest vertex
from the centroid) is refused as a likely typo: run.py calls a block that fast diverged (a block given
``velocity = [1e9, 0, 0]`` ended as exit 3, "diverged at step 1")."""
SOLVERS = ("nlgs-accel32", "nlgs-accel", "nlgs")
"""Contact solvers a run can select (RunConfig.solver); the first is the default."""

# configuration dataclasses ----------------------------------------------------------------------


@dataclass(frozen=True)
class RunConfig:
    """Time stepping and solver settings.

    duration : s, simulated time (0 < duration <= 1e5).
    dt : s, time step (0 < dt <= duration); duration must be a whole number of steps (within 1e-6 of
        one), else the run would silently stop short of it. At most ``MAX_STEPS`` steps.
    theta : Moreau–Jean θ, in [0.5, 1].
    gravity : (gx, gy) m/s², a vector (tilt it for tilting tests).
    tolerance : m/s, NLGS stopping test: RMS contact-law violation of a sweep (engine.nlgs), in [MIN_TOLERANCE, 1).
    max_iterations : NLGS sweep cap per step, >= 1.
    solver : the contact solver, one of ``SOLVERS``: "nlgs-accel32" (default) Gauss–Seidel with Nesterov
        momentum, its first sweeps in single precision and the step judged by the float64 test (0.69–0.88×
        the CPU of "nlgs-accel" over 1 s of shaken walls of 16–64 courses: README, Performance);
        "nlgs-accel" the same all in double precision; "nlgs" plain Gauss–Seidel, the reference to compare
        them with (engine.nlgs).
    record_every : record one frame every this many steps, >= 1.
    alert_distance : m, contacts with a gap below this are kept, > 0 (and at most the structure's extent:
        :class:`Scenario` checks that, knowing the blocks).
    """

    duration: float = 1.0
    dt: float = 1e-3
    theta: float = 0.5
    gravity: tuple[float, float] = (0.0, -9.81)
    tolerance: float = 1e-5
    max_iterations: int = 100000
    record_every: int = 10
    alert_distance: float = 1e-3
    solver: str = "nlgs-accel32"

    def __post_init__(self):
        put = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731
        # as given (an option's TypedNumber keeps its text) for the messages below: "--dt 2" said "dt = 2.0"
        dt, duration = self.dt, shorten(self.duration)
        put("duration", check_real("duration", self.duration, gt=0.0, le=MAX_DURATION))
        put("dt", check_real("dt", self.dt, gt=0.0))
        if self.dt > self.duration:
            raise field_error("dt", dt, f"must be <= duration ({duration})")
        # of both: a sentence naming both (the API respells each); a dt of 1e-310 is not 'inf steps': below
        if MAX_STEPS < self.duration / self.dt < math.inf:
            raise InputError(
                f"duration = {duration} at dt = {shorten(dt)} is {self.duration / self.dt:,.0f} steps (at most "
                f"{MAX_STEPS:,})"
            )
        if self.dt < MIN_DT:  # after the steps' check, which says more of a dt too small for its duration
            raise field_error("dt", dt, f"must be >= {MIN_DT:g} s (a likely typo)")
        steps = self.duration / self.dt
        if abs(steps - round(steps)) > 1e-6 * max(1.0, steps):
            n = max(1, round(steps))
            raise InputError(
                f"duration = {duration} is not a whole number of steps of dt = {shorten(dt)} ({steps:.6g} steps); "
                f"use dt = {self.duration / n:.6g} ({n} steps) or change the duration"
            )
        put("theta", check_real("theta", self.theta, ge=0.5, le=1.0))
        put("gravity", check_vector("gravity", self.gravity))
        if math.hypot(*self.gravity) > MAX_GRAVITY:
            raise field_error(
                "gravity",
                self.gravity,
                f"|g| = {math.hypot(*self.gravity):.3g} m/s² is more than {MAX_GRAVITY:g} (about 1000 g; a likely typo)",
            )
        tolerance = self.tolerance  # as given, for the message
        put("tolerance", check_real("tolerance", self.tolerance, gt=0.0, lt=1.0))
        if self.tolerance < MIN_TOLERANCE:
            raise field_error(
                "tolerance",
                tolerance,
                f"must be >= {MIN_TOLERANCE:g} m/s (float64 resolves a 1 m/s velocity to 2.2e-16 m/s; a likely typo)",
            )
        put("max_iterations", check_int("max_iterations", self.max_iterations, ge=1, le=MAX_COUNT))
        if self.solver not in SOLVERS:
            raise field_error("solver", self.solver, f"must be one of {', '.join(SOLVERS)}")
        put("record_every", check_int("record_every", self.record_every, ge=1, le=MAX_COUNT))
        put("alert_distance", check_real("alert_distance", self.alert_distance, gt=0.0))

    @property
    def n_steps(self) -> int:
        """Number of time steps, round(duration / dt)."""
        return max(1, round(self.duration / self.dt))


@dataclass(frozen=True)
class Material:
    """Defaults for every block, and the friction of every contact.

    density : kg/m³, thickness : m, out of plane, both within MATERIAL_RANGE.  friction : Coulomb μ, in
    [0, MAX_FRICTION].
    """

    density: float = 2500.0
    thickness: float = 1.0
    friction: float = 0.6

    def __post_init__(self):
        for key, (lo, hi, unit) in MATERIAL_RANGE.items():
            given = getattr(self, key)  # as given (an option's TypedNumber: its text) for the message
            value = check_real(key, given, gt=0.0)
            if not lo <= value <= hi:
                raise field_error(key, given, f"must be between {lo:g} and {hi:g} {unit} (a likely typo)")
            object.__setattr__(self, key, value)
        given = self.friction
        object.__setattr__(self, "friction", check_real("friction", given, ge=0.0))
        if self.friction > MAX_FRICTION:
            raise field_error(
                "friction",
                given,
                f"must be <= {MAX_FRICTION:g} (a likely typo: {MAX_FRICTION:g} already forbids sliding)",
            )


@dataclass(frozen=True, eq=False)
class Scenario:
    """Everything one run needs.

    name : label of the run (recording names, summaries).
    run : :class:`RunConfig`.  material : :class:`Material`.
    assembly : blocks and supports (``geometry_library.blocks.Assembly``).
    motions : one :class:`~masonrycli.scenario.motion.Motion` per support, in ``assembly.supports`` order.
    source : scenario file path, or ``"builder:<name>"``.
    structure : ``{"builder": name, **options}`` for builder scenarios, else ``{}``.
    warnings : non-fatal remarks from ``geometry_library.assembly_checks.validate_assembly``.
    marked_driven : names of the supports a geometry file run as it is marks ``"driven"`` (``support_role``): a
        record given on the command line shakes them (:func:`masonrycli.scenario.record_option.shaken_supports`).
    reading : how its file was read and settled (map shift, units, hulls, trims, ``settle_s``): run parameters.

    Each support's ``role`` is made consistent with its motion (``"driven"`` unless the motion is fixed).
    """

    name: str
    run: RunConfig
    material: Material
    assembly: Assembly
    motions: tuple[Motion, ...]
    source: str = ""
    structure: dict = field(default_factory=dict)
    warnings: tuple[str, ...] = ()
    marked_driven: tuple[str, ...] = ()
    reading: dict = field(default_factory=dict)

    def __post_init__(self):
        motions = tuple(self.motions)
        object.__setattr__(self, "motions", motions)
        object.__setattr__(self, "warnings", tuple(self.warnings))
        if len(motions) != self.assembly.support_count:
            raise InputError(
                f"scenario {self.name!r}: {len(motions)} motions for {self.assembly.support_count} supports "
                "(one motion per support, same order)"
            )
        if not all(isinstance(m, Motion) for m in motions):
            raise InputError(f"scenario {self.name!r}: motions must be Motion objects")
        if any(s.role != m.role for s, m in zip(self.assembly.supports, motions)):
            supports = tuple(
                s if s.role == m.role else dataclasses.replace(s, role=m.role)
                for s, m in zip(self.assembly.supports, motions)
            )
            object.__setattr__(self, "assembly", dataclasses.replace(self.assembly, supports=supports))  # fills kept
        where = "" if self.source.startswith("builder:") or not self.source else f"{self.source}: "
        object.__setattr__(self, "assembly", _cleaned_assembly(self.assembly, where))
        _check_initial_velocities(self.assembly, where)
        _check_alert_distance(self.run.alert_distance, self.assembly, where)

    @property
    def block_count(self) -> int:
        return self.assembly.block_count

    @property
    def support_count(self) -> int:
        return self.assembly.support_count

    @property
    def friction(self) -> float:
        return self.material.friction


def block_speed_problem(block: Block) -> str | None:
    """``velocity = [...]: ...`` when the block's initial velocity moves one of its points faster than
    ``MAX_BLOCK_SPEED``, else None."""
    from geometry_library.mass import mass_properties

    vx, vy, omega = block.velocity
    if vx == 0.0 and vy == 0.0 and omega == 0.0:
        return None
    xy = block.vertices
    centroid = mass_properties(xy).centroid
    speed = math.hypot(vx, vy) + abs(omega) * max(math.hypot(*(p - centroid)) for p in xy)
    if speed <= MAX_BLOCK_SPEED:
        return None
    why = f"a point of the block would move at {speed:.3g} m/s, more than {MAX_BLOCK_SPEED:g} m/s (a likely typo"
    return str(field_error("velocity", list(block.velocity), why + ": a block that fast is a diverged run)"))


def _cleaned_assembly(assembly: Assembly, where: str) -> Assembly:
    """``assembly`` with every polygon as ``geometry_library.checks`` cleans it (what ``validate_assembly``
    checks is what the engine gets), or a refusal naming the body (not a polygon, non-convex, …).

    A ``Block`` made by hand in Python with a vertex 0.2 mm inside an edge passed ``validate_assembly``,
    which checks the cleaned copy, and the engine was given the non-convex polygon. Builders and readers
    hand over polygons already clean (found by identity, no cost); a hand-made one is cleaned (~0.2 ms)
    and replaced only if the cleaning removed a vertex, so its vertex order is kept otherwise."""
    from geometry_library.checks import normalise_polygon

    def cleaned(body, index: int, kind: str):
        try:
            polygon = normalise_polygon(body.polygon, index, body.name, kind)
        except GeometryError as exc:
            raise InputError(f"{where}{exc}") from None
        if polygon is body.polygon or len(polygon.exterior.coords) == len(body.vertices) + 1:
            return body
        return dataclasses.replace(body, polygon=polygon)

    blocks = tuple(cleaned(b, i, "block") for i, b in enumerate(assembly.blocks))
    supports = tuple(cleaned(s, j, "support") for j, s in enumerate(assembly.supports))
    if all(a is b for a, b in zip(blocks + supports, (*assembly.blocks, *assembly.supports))):
        return assembly
    return dataclasses.replace(assembly, blocks=blocks, supports=supports)  # traced fills kept (traced_fills checks)


def _check_initial_velocities(assembly: Assembly, where: str) -> None:
    """:func:`block_speed_problem` for every block (the TOML reader checks its own with its locator first),
    the block numbered from 1 in file order as geometry_library's messages number it."""
    from geometry_library.checks import body_label

    for i, block in enumerate(assembly.blocks):
        problem = block_speed_problem(block)
        if problem:
            raise InputError(f"{where}{body_label(i, block.name)}: {problem}")


def _check_alert_distance(alert_distance: float, assembly: Assembly, where: str) -> None:
    """Refuse an alert distance longer than the structure (the larger side of the blocks' bounding box):
    a gap that large is no contact (``alert_distance = 1e9`` was accepted)."""
    if not assembly.blocks:
        return
    xmin, ymin, xmax, ymax = assembly.bounds(blocks_only=True)
    extent = max(xmax - xmin, ymax - ymin)
    if alert_distance > extent:
        raise field_error(
            f"{where}[run] alert_distance",
            alert_distance,
            f"longer than the structure ({extent:.3g} m, the larger side of its blocks' bounding box); a "
            "likely typo: contacts closer than this are kept (default 0.001 m)",
        )


# constructors -----------------------------------------------------------------------------------


def scenario_from_builder(
    builder: str, options: dict, run: RunConfig, material: Material, motions_by_support: dict[str, Motion]
) -> Scenario:
    """A scenario from ``geometry_library.builders.BUILDERS[builder](**options).build()``.

    ``material.density`` / ``material.thickness`` are passed to the builder unless ``options`` sets
    them. ``motions_by_support`` maps support names to motions; supports not named are fixed; a name the
    builder does not make is an error. Raises :class:`InputError` (``builder "wall": ...``).
    """
    where = f'builder "{builder}":'
    options = dict(options)
    for key, value in options.items():
        try:
            check_finite_tree(key, value)
        except InputError as exc:
            raise BuilderError(builder, str(exc), (key,)) from None
    try:
        assembly = build_structure(builder, options, material.density, material.thickness)
    except InputError as exc:  # 'builder "wall": …', a BuilderError's keys kept (an unknown option has none)
        raise BuilderError(builder, getattr(exc, "problem", str(exc)), getattr(exc, "keys", ())) from None
    known = [s.name for s in assembly.supports]
    for name, motion in motions_by_support.items():
        if name not in known:
            raise InputError(
                f"{where} no support named {quote_string(str(name))} (supports: {', '.join(known) or 'none'})"
            )
        if not isinstance(motion, Motion):
            raise InputError(f"{where} motion of support {quote_string(name)} must be a Motion")
    motions = tuple(motions_by_support.get(s.name, Fixed()) for s in assembly.supports)
    warnings = structure_warnings(assembly, InputContext(f'builder "{builder}"', "."))
    # the builder's density, thickness (--param density) are the blocks': said by the run's document, not 2500
    material = dataclasses.replace(material, **{k: options[k] for k in ("density", "thickness") if options.get(k)})
    return Scenario(
        name=builder,
        run=run,
        material=material,
        assembly=assembly,
        motions=motions,
        source=f"builder:{builder}",
        structure={"builder": builder, **options},
        warnings=warnings,
    )


def scenario_from_geometry_file(path, survey=None) -> Scenario:
    """A scenario with default run and material settings for a GeoJSON / WKT file, every support fixed (``masonry
    run my-wall.geojson``; for motions or settings: a scenario file, ``[structure] file = "my-wall.geojson"``)."""
    path = os.fspath(path)
    ctx = InputContext(path, os.path.dirname(os.path.abspath(path)))
    material = Material()
    notes: list[str] = []
    reading: dict = {}
    assembly = read_geometry(path, material.density, material.thickness, ctx, "", notes, survey, reading)
    from masonrycli.scenario.caveats import idle_driven_supports

    motions = tuple(Fixed() for _ in assembly.supports)
    warnings = (*notes, *idle_driven_supports(assembly, motions), *structure_warnings(assembly, ctx, as_run=True))
    return Scenario(
        name=Path(path).stem,
        run=RunConfig(),
        material=material,
        assembly=assembly,
        motions=motions,
        source=path,
        structure={"file": os.path.abspath(path)},
        warnings=warnings,
        marked_driven=tuple(s.name for s in assembly.supports if s.role == "driven"),  # before roles follow motions
        reading=reading,
    )


# summary ----------------------------------------------------------------------------------------


def _block_mass(block: Block) -> float:
    from geometry_library.mass import mass_properties

    return float(mass_properties(block.vertices, block.density, block.thickness).mass)


def scenario_summary(scenario: Scenario) -> dict:
    """Numbers for ``masonry check``: counts, total mass (kg), bounding box (m), run settings, warnings."""
    asm = scenario.assembly
    masses = [_block_mass(b) for b in asm.blocks]
    return {
        "name": scenario.name,
        "source": scenario.source,
        "structure": dict(scenario.structure),
        "blocks": asm.block_count,
        "supports": asm.support_count,
        "support_motions": [
            {"name": s.name, "role": s.role, "motion": m.describe()} for s, m in zip(asm.supports, scenario.motions)
        ],
        "total_mass": float(sum(masses)),
        "fill_mass": float(sum(b.carried_mass for b in asm.blocks)),  # a bridge's fill riding on the blocks, kg
        "total_area": float(sum(float(b.polygon.area) for b in asm.blocks)),
        "bounding_box": tuple(float(x) for x in asm.bounds()),
        "friction": scenario.material.friction,
        "duration": scenario.run.duration,
        "dt": scenario.run.dt,
        "n_steps": scenario.run.n_steps,
        "theta": scenario.run.theta,
        "record_every": scenario.run.record_every,
        "warnings": list(scenario.warnings),
    }
