"""The ``masonry`` command line's option groups: each a dict name → annotated Typer option.

A command takes the groups it needs through :func:`with_options` and receives them as ``**opts``, so one
option (its flag, help text and panel) is written once for every command that has it.
"""

from __future__ import annotations

import copy
import functools
import inspect
import re
import typing
from pathlib import Path
from typing import Annotated

import typer

from masonrycli.cli.option_values import choice_value, file_path_value, number_value, path_value, pga_value, whole_value


def _opt(kind: type, panel: str, help: str, *decls: str, parser=None):
    """An optional ``kind`` value (None when not given), listed under ``panel`` in --help."""
    parser = parser or {Path: path_value, float: number_value, int: whole_value}.get(kind)
    parser = {"parser": parser} if parser else {}
    return Annotated[kind | None, typer.Option(*decls, help=help, rich_help_panel=panel, **parser)]


WALL = {
    "blocks": _opt(int, "Structure", "Number of blocks (default 51; 248 for the paper's large wall)."),
    "courses": _opt(int, "Structure", "Number of courses (with --length and no --blocks: the count follows)."),
    "length": _opt(float, "Structure", "Wall length, m, a whole number of blocks."),
    "block_length": _opt(float, "Structure", "Block length, m (default 0.30)."),
    "block_height": _opt(float, "Structure", "Block height, m (default 0.20)."),
}
ARCH = {
    "voussoirs": _opt(int, "Structure", "Voussoirs in the arch (default 30)."),
    "pier_courses": _opt(int, "Structure", "Courses per pier, 2 blocks each (default 17)."),
    "span": _opt(float, "Structure", "Clear span of the arch, m (default 3.6)."),
    "ring_thickness": _opt(float, "Structure", "Arch ring thickness, m (default 0.35)."),
    "pier_width": _opt(float, "Structure", "Pier width, m (default 0.90)."),
}
# the aqueduct's spandrel is cut to a semicircle: --rise is the bare arch's
AQUEDUCT = {**ARCH, "wall_courses": _opt(int, "Structure", "Courses of the spandrel walls (default 18).")}
ARCH = {
    **ARCH,
    "rise": _opt(
        float,
        "Structure",
        "Rise of the intrados crown above the springings, m (default: span / 2, the semicircle; less: a "
        "segmental arch, with a skewback stone on each pier).",
    ),
    # a bridge's fill: dead load on the blocks under it (geometry_library/fill.py)
    "fill_to": _opt(
        float,
        "Structure",
        "Fill over the arch up to this height above the springings, m, between the piers' outer faces: its "
        "weight rides on the blocks under it (dead load only: no strength, no side pressure).",
    ),
    "fill_cover": _opt(float, "Structure", "The same fill, its level given as the depth over the ring's top, m."),
    "fill_density": _opt(float, "Structure", "Density of the fill, kg/m³ (default 2000)."),
    "abutments": _opt(
        str,
        "Structure",
        "courses (default: piers of two blocks a course), solid (each pier and its skewback one block) or "
        "fixed (that block the rigid foundation).",
        parser=choice_value,
    ),
}
STRUCTURE_OPTIONS = {"wall": WALL, "arch": ARCH, "aqueduct": AQUEDUCT}
"""The structure options of each built-in: ``masonry limit NAME`` takes their union and refuses the others'."""
ANY_STRUCTURE = {k: v for group in STRUCTURE_OPTIONS.values() for k, v in group.items()}
# The wall stands on one ground, shaken by default; the arch and the aqueduct settle their right
# foundation by default and are shaken with --settlement 0 --amp A. One group for both listed --settlement
# under `simulate wall --help` (always refused there) and no loading default anywhere.
WALL_LOADING = {
    "freq": _opt(float, "Loading", "Ground velocity frequency, Hz (default 2).", "--freq"),
    "amp": _opt(float, "Loading", "Horizontal ground velocity amplitude, m/s (default 1; 0: no shaking).", "--amp"),
    # not listed, but taken: refused with why ("the wall stands on one ground …"), not "No such option"
    "settlement": Annotated[float | None, typer.Option(hidden=True, parser=number_value)],
}
SETTLED_LOADING = {
    "freq": _opt(float, "Loading", "Foundations' velocity frequency, Hz (default 2; with --amp).", "--freq"),
    "amp": _opt(
        float,
        "Loading",
        "Horizontal velocity amplitude of both foundations, m/s, with --settlement 0 (default: no shaking).",
        "--amp",
    ),
    "settlement": _opt(
        float, "Loading", "Downward velocity of the right foundation, m/s (default 0.01; 0 with --amp: shaking)."
    ),
}
BUILT_IN_LOADING = {
    "freq": _opt(
        float, "Loading", "A built-in's sine: velocity frequency, Hz (default 2), as simulate's --freq.", "--freq"
    ),
    "amp": _opt(
        float,
        "Loading",
        "A built-in's sine: horizontal velocity amplitude, m/s, as simulate's --amp (the wall's default 1; the "
        "arch and the aqueduct with --settlement 0).",
        "--amp",
    ),
    "settlement": _opt(
        float, "Loading", "The arch's or the aqueduct's: downward velocity of the right foundation, m/s (default 0.01)."
    ),
}
"""``masonry check NAME``'s loading options: those of ``simulate wall`` and ``simulate arch`` together."""
RECORD = {
    "record": _opt(
        Path,
        "Loading",
        "Ground motion record shaking the ground/foundations instead of the sine: PEER .AT2 (g), ESM .ASC (its header's units), K-NET .NS/.EW/.UD or CSV "
        "(time, velocity). Baseline-corrected (--baseline); window and vertical component in a scenario file.",
        "--record",
    ),
    "scale": _opt(float, "Loading", "Multiplies the --record (default 1).", "--scale"),
    "pga": _opt(
        float,
        "Loading",
        "Scale the --record so that the ground motion as applied peaks at this acceleration, in g (0.25), or "
        "with its unit (2.45m/s2, 245gal); instead of --scale.",
        "--pga",
        parser=pga_value,
    ),
    "baseline": _opt(
        str,
        "Loading",
        "Drift correction of an acceleration --record, as a scenario file's baseline: quadratic (default; the "
        "ground ends at rest where it started) or none (the samples as given: a shake table's own input).",
        "--baseline",
        parser=choice_value,
    ),
    "record_dt": _opt(
        float,
        "Loading",
        "Seconds between the samples of a --record CSV of one value per line (no time column); samples at "
        "t = 0, dt, 2 dt, ...",
        "--record-dt",
    ),
}
RUN = {
    "duration": _opt(
        float, "Run", "Simulated time, s (default: the built-in's or the file's; simulate --record: the whole record)."
    ),
    "dt": _opt(float, "Run", "Time step, s (default 1e-3).", "--dt"),
    "theta": _opt(float, "Run", "Moreau–Jean θ in [0.5, 1] (default 0.5)."),
    "record_every": _opt(int, "Run", "Steps between recorded frames (default 10)."),
    "tolerance": _opt(
        float, "Run", "NLGS stopping test: RMS contact-law violation of a sweep, m/s (default 1e-5; 1e-8 is tight)."
    ),
    "max_iterations": _opt(
        int,
        "Run",
        "Sweep cap per step, in Gauss–Seidel sweep units (default 100000). A stalled step stops earlier: with "
        "the default solver when every method of its round-robin gives up, with nlgs after 10000 sweeps without "
        "a new lowest residual.",
    ),
    "solver": _opt(
        str,
        "Run",
        "Contact solver: nlgs-accel32 (default; Gauss–Seidel with momentum, 2-4x fewer sweeps, its first "
        "sweeps in float32, each step judged in float64), nlgs-accel (the same all in float64) or nlgs (plain "
        "Gauss–Seidel, the reference).",
        parser=choice_value,
    ),
}
Friction = _opt(float, "Material", "Coulomb coefficient of every contact (default 0.6).")
# masonry limit's load options
AtOption = Annotated[
    float | None,
    typer.Option(
        "--at",
        parser=number_value,
        metavar="X",
        help="Point load on the top block over x = X m instead of --block (a deck load at that abscissa).",
    ),
]
WorstOption = Annotated[
    bool,
    typer.Option(
        "--worst",
        help="With --load point: try the load at every place on the structure's top (both ends of each "
        "straight stretch, where λ is least) and report the worst.",
    ),
]
PointForceOption = Annotated[
    str | None,
    typer.Option(
        "--point-force",
        metavar="F",
        help="The point load's size with its unit, e.g. 100kN (N, kN, MN), for the blocks' out-of-plane "
        "thickness: λ multiplies it (default: the loaded block's own weight).",
    ),
]
VerifyOption = Annotated[
    bool,
    typer.Option(
        "--verify",
        help="Run the NSCD engine at 0.95 λ and 1.05 λ (tilted gravity; a point load as a weight) and compare.",
    ),
]
MechanismOutOption = Annotated[
    Path | None,
    typer.Option(
        "--out", "-o", parser=file_path_value, help="Write the mechanism recording (.rrd).", metavar="REC.rrd"
    ),
]
SpreadOption = Annotated[
    float | None,
    typer.Option(
        "--spread",
        parser=number_value,
        metavar="DEG",
        help="A point load on the fill's surface spreads down through the fill at DEG from the vertical onto "
        "the blocks' top (e.g. 26.6: 2 down for 1 across each side); needs --fill-to or --fill-cover.",
    ),
]
MinThicknessOption = Annotated[
    bool,
    typer.Option(
        "--min-thickness",
        help="The arch only: the least ring thickness that carries its own weight on the same piers, and "
        "Heyman's geometric factor of safety (the ring's thickness over it).",
    ),
]
SettleOption = Annotated[
    float | None,
    typer.Option(
        "--settle",
        parser=number_value,
        help="First let the structure come to rest under its own weight for this many seconds (the engine, supports "
        "fixed), and analyse it there: a traced wall's gaps closed (0.5).",
    ),
]
SETTLE = {  # run, check, sweep: the structure let come to rest before it is shaken (masonrycli/settle.py)
    "settle": _opt(
        float,
        "Geometry file",
        "First let the structure come to rest under its own weight for this many seconds (the engine, supports "
        "fixed) and shake it from there: a traced wall's gaps closed (0.5).",
        "--settle",
    )
}
SIMULATE_SETTLE = {  # simulate: a built-in let come to rest before it is loaded, as run --settle (settle.py)
    "settle": _opt(
        float,
        "Run",
        "First let the structure come to rest under its own weight for this many seconds (the engine, supports "
        "fixed), then load it from there; the run's parameters say so (reading.settle_s).",
        "--settle",
    )
}
ThrustOption = Annotated[
    bool,
    typer.Option(
        "--thrust",
        help="Also the least and greatest horizontal thrust on each support under the dead load alone (an "
        "arch's abutments spreading / pushed together).",
    ),
]
DirectionOption = Annotated[
    str | None,
    typer.Option(
        parser=choice_value,
        help="+x or -x (default +x); a point load also +y or -y (default -y: down, as a load on a deck).",
    ),
]
FRICTION = {"friction": Friction}
SURVEY = {  # how a GeoJSON / WKT file is read (geometry_library/survey.py): a surveyed wall's
    "units": _opt(
        str,
        "Geometry file",
        "Unit of a GeoJSON / WKT file's coordinates: m (default), cm, mm, or metres per unit (0.002: pixels of 2 mm).",
        "--units",
        parser=choice_value,
    ),
    "flip_y": Annotated[
        bool,
        typer.Option(
            "--flip-y",
            help="The file's y axis points down (image rows): read it pointing up.",
            rich_help_panel="Geometry file",
        ),
    ],
    "convex_hull": Annotated[
        bool,
        typer.Option(
            "--convex-hull",
            help="Read a slightly non-convex stone as its convex hull (at most 5 % more area; the area added is said).",
            rich_help_panel="Geometry file",
        ),
    ],
    "trim_overlaps": _opt(
        float,
        "Geometry file",
        "Cut neighbours overlapping by a tracing slip up to this deep, m (0.003), along the chord where their outlines cross.",
        "--trim-overlaps",
    ),
}

_BUILT_IN_DEFAULT = re.compile(r"\(default ([^;)]*)")
"""The "(default 1e-3" of a help text: the built-in value, which a scenario file's replaces."""


def file_defaults(group: dict, value: str = "the scenario file's value") -> dict:
    """``group`` with each "(default …)" of its help texts saying the scenario file's value is the default:
    ``run --help`` said "(default 1e-3)" for --dt although a file's [run] dt = 2e-4 is what runs. ``value``:
    how that default is named (``check``, which takes a built-in too: the file's or the built-in's)."""
    out = {}
    for name, annotation in group.items():
        kind, info = typing.get_args(annotation)
        info = copy.copy(info)
        info.help = _BUILT_IN_DEFAULT.sub(rf"(default: {value}, else \1", info.help, count=1)
        info.help = info.help.replace("the built-in's or the file's; simulate --record: the whole record", value)
        out[name] = Annotated[kind, info]
    return out


BLOCK_MATERIAL = {
    "density": _opt(float, "Material", "Block density, kg/m³ (default 2500)."),
    "thickness": _opt(float, "Material", "Out-of-plane thickness, m (default 1)."),
}
OUTPUT = {
    "out": _opt(
        Path,
        "Output",
        "Recording (.rrd). Default: recordings/<scenario>-<timestamp>.rrd.",
        "--out",
        "-o",
        parser=file_path_value,
    ),
    "no_recording": Annotated[
        bool, typer.Option("--no-recording", help="Write no .rrd recording.", rich_help_panel="Output")
    ],
    "history": _opt(
        Path, "Output", "History file (.npz), one row per recorded frame.", "--history", parser=file_path_value
    ),
    "magnify": _opt(
        float,
        "Output",
        "Displacement factor of the recording's magnified deformed shape (default: the largest displacement "
        "drawn as 5 % of the structure's size).",
        "--magnify",
    ),
}
STOP = {
    "stop_at_collapse": Annotated[
        bool,
        typer.Option(
            "--stop-at-collapse",
            help="End the run once the structure has collapsed (masonry docs collapse).",
            rich_help_panel="Run",
        ),
    ]
}
FORCE = {
    "force": Annotated[
        bool,
        typer.Option(
            "--force", help="Replace output files that exist (default: refuse, exit 2).", rich_help_panel="Output"
        ),
    ]
}


GEO_OUT = {
    "out": Annotated[
        Path, typer.Option("--out", "-o", parser=file_path_value, help="GeoJSON file to write (.geojson or .json).")
    ]
}


def with_options(*groups: dict):
    """Add the options of ``groups`` (after the command's own parameters) to a Typer command.

    The command takes them as keyword arguments (``**opts``). Options default to None (flags to False,
    an option without a default stays required).
    """

    def decorate(func):
        own = [p for p in inspect.signature(func, eval_str=True).parameters.values() if p.kind != p.VAR_KEYWORD]
        added = [
            inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, annotation=ann, default=_default(ann))
            for group in groups
            for name, ann in group.items()
        ]

        @functools.wraps(func)
        def command(**kwargs):
            return func(**kwargs)

        command.__signature__ = inspect.Signature([*own, *added])
        return command

    return decorate


def _default(annotation):
    """None for an optional value, False for a flag, required (no default) otherwise."""
    kind = typing.get_args(annotation)[0]
    if kind is bool:
        return False
    return None if type(None) in typing.get_args(kind) else inspect.Parameter.empty
