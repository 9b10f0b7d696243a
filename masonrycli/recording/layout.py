"""Layout of a recording: entity paths, field specs, colours, scale constants and the default blueprint.

The vocabulary the recorder, the run document and the tests share. Entity paths have no leading "/";
``ENTITY_PATHS`` lists them all.
"""

from __future__ import annotations

from typing import Final, NamedTuple

import rerun as rr
import rerun.blueprint as rrb
from rerun.blueprint.encodings import ComponentSourceKind, VisualizerComponentMapping

from masonrycli.recording.colour_range import Scale, ScaleKind
from masonrycli.scenario.builtin import is_paper_loading, paper_instant_missed

ROBUST_PERCENTILE: Final = 98.0  # the glyph scales come from this percentile of |value|
GLYPH_HALF_LENGTH: Final = 0.45  # longest principal-axis half-length / median block's smaller side
RESULTANT_LENGTH: Final = 1.5  # joint resultant of the first loaded frame's 95th percentile, in block heights
RESULTANT_PERCENTILE: Final = 95.0
RESULTANT_CAP: Final = 0.5  # a joint arrow is drawn at most this × the structure's size long (overlays.send_joints)
INSET: Final = 0.002  # block fills are inset by this × the structure's size: the joints show as dark lines
# but by no more than this × a median block's smaller side: on an 8-course wall 37.5 m long 0.002 × 37.5 m
# inset 0.2 m high blocks by 7.5 cm a side, the fills were 5 cm high (about a pixel at first open) and every
# colour map read as a dark grey strip; the paper's structures stay under it (aqueduct 0.07, arch 0.055)
INSET_BLOCK_CAP: Final = 0.075


class FieldSpec(NamedTuple):
    key: str  # name in Frame.tensors
    title: str
    unit: str
    kind: ScaleKind  # "signed" (diverging about 0), "negative" or "positive" (one-sided)
    floor: float  # the colour range never shrinks below this (field unit): smaller values are noise
    colors: str  # the fill mesh's colour component for this field ("<Name>:colors")
    bar: str  # entity paths: the colour bar and its labels
    labels: str
    scale: Scale = "linear"  # "sqrt": the signed square-root scale (colour_range.sqrt_scale), SQRT_FIELDS

    @property
    def name(self) -> str:
        """The view's field: ``key``, with "@sqrt" on the square-root scale (field_frames' ranges)."""
        return self.key if self.scale == "linear" else f"{self.key}@{self.scale}"


def _field(key: str, title: str, unit: str, kind: ScaleKind, floor: float, scale: Scale = "linear") -> FieldSpec:
    short = key.removeprefix("cell_").removeprefix("block_") + ("" if scale == "linear" else f"_{scale}")
    archetype = "".join(w.capitalize() for w in short.split("_"))
    return FieldSpec(
        key,
        title,
        unit,
        kind,
        floor,
        f"{archetype}:colors",
        f"structure/legend/{short}",
        f"structure/plane/xy/legend/{short}",
        scale,
    )


FIELDS: Final = (
    _field("cell_volumetric_strain_rate", "Volumetric strain rate", "1/s", "signed", 1e-4),
    _field("cell_deviatoric_strain", "Deviatoric cumulated strain", "", "positive", 1e-5),
    _field("cell_spherical_stress", "Spherical stress p", "Pa", "negative", 100.0),
    _field("cell_deviatoric_stress", "Deviatoric stress q", "Pa", "positive", 100.0),
    _field("block_sliding_ratio", "Sliding ratio", "", "positive", 1.0),
    _field("block_max_opening", "Largest joint opening", "m", "positive", 1e-4),
)
"""Colour-mapped per-block fields: the paper's four (Figs. III.2–III.5 / III.7–III.10), then the joint
states. The volumetric strain rate of a block without a cell strain but in a one-block chain (a voussoir
of a bare ring) is its ``chain_strain_rate``: the strain rate along the ring."""
PAPER_FIELDS: Final = FIELDS[:4]
FIELD_BY_KEY: Final = {f.key: f for f in FIELDS}
SQRT_FIELDS: Final = (_field("cell_spherical_stress", "Spherical stress p, √ scale", "Pa", "negative", 100.0, "sqrt"),)
"""Fields shown again on the signed square-root scale, in a tab of their own (not the paper's): a tall wall
after an impact has a few joints at MN and the bulk of its cells at tens of kPa, pale on the linear map
whatever its range. Each takes the range of its linear twin (one tracker: the same ends, refits and counts
beyond them); the colour bar is the same gradient, its ticks at the values of evenly spaced colours."""
COLOURED: Final = FIELDS + SQRT_FIELDS
"""Every colour component of the fill, with its colour bar and labels: the fields, then the square-root views."""
CHAIN_KEY: Final = "chain_strain_rate"
HOVER_VALUES: Final = {  # per-block value shown when hovering a block -> Frame.tensors key
    "p": "cell_spherical_stress",
    "q": "cell_deviatoric_stress",
    "volumetric_strain_rate": "cell_volumetric_strain_rate",
    "chain_strain_rate": CHAIN_KEY,
    "deviatoric_strain": "cell_deviatoric_strain",
    "sliding_ratio": "block_sliding_ratio",
    "max_opening": "block_max_opening",
}
AXES: Final = {  # glyph set -> (principal values (N, 2) key, angle of the major one (N,) key)
    # (stress only: strain-rate glyphs doubled the file of a large structure; the volumetric strain rate
    # and the cells' triangles show where the masonry opens)
    "stress_axes": ("cell_principal_stress", "cell_principal_angle"),
}
TENSOR_KEYS: Final = tuple(
    dict.fromkeys([*(f.key for f in FIELDS), *(k for pair in AXES.values() for k in pair), *HOVER_VALUES.values()])
)
SCALARS: Final = ("energy_kinetic", "energy_potential", "energy_dissipated", "support_work")
PAPER_FIGURES: Final = {  # scenario -> (the paper's instant, s; figure numbers of the four fields)
    "wall": (0.1, ("III.2", "III.3", "III.4", "III.5")),
    "arch": (5.0, ("III.7", "III.8", "III.9", "III.10")),
    "aqueduct": (5.0, ("III.7", "III.8", "III.9", "III.10")),
}

PLANE: Final = "structure/plane"
XY: Final = "structure/plane/xy"
FILL: Final = "structure/fill"  # the blocks, filled: one mesh, one colour component per field
BLOCKS: Final = f"{XY}/blocks"  # a point per block under its fill: names and values on hover
SUPPORT_OUTLINES: Final = f"{XY}/supports"
TRIANGULATION: Final = f"{XY}/triangulation"
FORCES: Final = f"{XY}/forces"
HINGES: Final = f"{XY}/hinges"
STRESS_AXES: Final = f"{XY}/stress_axes"
MAGNIFIED: Final = f"{XY}/magnified"
UNDEFORMED: Final = f"{XY}/undeformed"
SUPPORT_FILL: Final = "structure/supports"
CARRIED_FILL: Final = ("structure/carried_fill", f"{XY}/carried_fill")  # a bridge's fill: mesh, outlines
MAGNIFIED_FILL: Final = f"{XY}/magnified_fill"  # its columns' outlines on the magnified shape
LEGEND_BARS: Final = "structure/legend"  # parent of the colour bars: moved right of where the blocks went
LEGEND_LABELS: Final = f"{XY}/legend"  # parent of their labels, moved with them
METADATA: Final = "run/metadata"
LEGEND: Final = "run/legend"
SERIES: Final = {
    "energy_kinetic": "series/energy/kinetic",
    "energy_large": "series/energy/work_dissipated_potential",
    "energy_balance": "series/energy/balance_error",
    "max_displacement": "series/blocks/max_displacement",
    "support_velocity": "series/supports/velocity",
    "support_displacement": "series/supports/displacement",
    "iterations": "series/solver/iterations",
    "residual": "series/solver/log10_residual",
    "contacts": "series/contacts/count",
}
PER_STEP_SERIES: Final = ("iterations", "residual", "contacts")
SINGLE_SERIES: Final = (
    "energy_kinetic",
    "energy_balance",
    "max_displacement",
    "iterations",
    "contacts",
)  # plotted without legend  # logged after every step, not per frame


ENTITY_PATHS: Final = (
    PLANE,
    XY,
    FILL,
    BLOCKS,
    SUPPORT_OUTLINES,
    TRIANGULATION,
    FORCES,
    HINGES,
    STRESS_AXES,
    MAGNIFIED,
    UNDEFORMED,
    SUPPORT_FILL,
    LEGEND_BARS,
    LEGEND_LABELS,
    *(p for f in COLOURED for p in (f.bar, f.labels)),
    *SERIES.values(),
    METADATA,
    LEGEND,
)
"""Every entity of a recording (without the leading "/")."""

# Colours, packed 0xRRGGBBAA.
OUTLINE_RGBA: Final = 0x282828FF
SUPPORT_FILL_RGBA: Final = 0x8C8273FF
SUPPORT_LINE_RGBA: Final = 0x4A443CFF
TRIANGULATION_RGBA: Final = 0x5A5A5AFF
LEGEND_TEXT_RGBA: Final = 0xDCDCDCFF
STICK_RGBA: Final = 0x00963CFF  # force arrow of a sticking contact (green)
SLIP_RGBA: Final = 0xFF8C00FF  # force arrow of a sliding contact (orange)
OPEN_RGBA: Final = 0xE03C31FF  # joint open at one end, turning about the other (red)
MAGNIFIED_RGBA: Final = 0xE8E8E8FF
UNDEFORMED_RGBA: Final = 0x6E6E6EFF
HINGE_RGBA: Final = 0xFFD700FF
HINGE_RADIUS: Final = -4.0  # ui points; a share of the blocks on a large structure (static_content.hinge_radius)
COMPRESSION_RGBA: Final = 0x141414FF  # principal axis with a negative value (near black)
TENSION_RGBA: Final = 0xDC00DCFF  # principal axis with a positive value (magenta)
CENTROID_RGBA: Final = 0x282828FF  # the dot at each block's centroid, the hover target of its values
CENTROID_RADIUS: Final = -2.5  # ui points: a dot of the same size at every zoom


LIVE_TAB: Final = "Live"
FIELD_TABS: Final = {
    "cell_volumetric_strain_rate": "Strain rate",
    "cell_deviatoric_strain": "Dev. strain",
    "cell_spherical_stress": "Stress p",
    "cell_deviatoric_stress": "Stress q",
    "block_sliding_ratio": "Sliding",
    "block_max_opening": "Opening",
}
SQRT_TABS: Final = {"cell_spherical_stress@sqrt": "p √"}
"""The square-root views' tabs (``FieldSpec.name`` -> tab), each right after its linear twin's."""
MAGNIFIED_TAB: Final = "Magnified"
"""Tab names, short: the quick start's recording has 12 tabs in the structure panel (~1150 px of a 1920 px
window), where names of up to 56 characters ("Live: joint forces, principal stress, Spherical stress p")
left four tabs readable and cut the first. Each colour bar carries its field's full title, and the Legend
panel says what each tab shows (:func:`tabs_legend`)."""
PLOT_NAMES: Final = {
    "energy_kinetic": "Kinetic (J)",
    "energy_balance": "Balance (log10 rel.)",
    "energy_large": "Energies (J)",
    "max_displacement": "Max displ. (m)",
    "support_velocity": "Support v (m/s)",
    "support_displacement": "Support u (m)",
    "residual": "Residual (log10 m/s)",
    "iterations": "Sweeps per step",
    "contacts": "Contacts",
}
"""Plot tab names, short for the same reason: the right column (~770 px) showed 3 of its 6 energy and
support tabs ("Support work, dissipated energy, potential change (J)" cut). Each plot's series names say the
rest: in its legend, or on hover for the plots of one series (SINGLE_SERIES), whose legend is hidden."""


def paper_tab(figure: str) -> str:
    """The tab of the paper's ``figure`` ("III.2"); its instant is in the Legend (:func:`tabs_legend`)."""
    return f"Fig. {figure}"


def tabs_legend(main_field: str = "cell_spherical_stress", paper_t: float | None = None) -> str:
    """The Legend panel's line on the tabs: what each short name shows (``paper_t``: the paper's figures'
    instant, s, when the recording has their tabs)."""
    main = FIELD_BY_KEY[main_field].title
    names = []
    for f in FIELDS:
        names.append(f"{FIELD_TABS[f.key]} = {f.title.lower()}")
        names += [f"{SQRT_TABS[s.name]} = the same on a square-root scale" for s in SQRT_FIELDS if s.key == f.key]
    fields = ", ".join(names)
    # one bullet of two lines at 1920 px: the Legend panel holds seven, and the principal stress axes' line
    # (legend_markdown) pushed the Magnified one out. Left to the other bullets: the Magnified tab (its own
    # line) and which tabs draw the joint forces (theirs)
    pinned = "" if paper_t is None else f"Fig. = the paper's figures, pinned at t = {paper_t:g} s; "
    return f"- **Tabs**: {LIVE_TAB} = joint forces, principal stress axes and {main.lower()}; " + pinned + f"{fields}."


def _fill_colours(f: FieldSpec) -> dict:
    """Blueprint override: the fill mesh takes its vertex colours from field ``f``'s component."""

    def source(target: str, component: str) -> VisualizerComponentMapping:
        return VisualizerComponentMapping(
            target=target, source_kind=ComponentSourceKind.SourceComponent, source_component=component
        )

    return {
        f"/{FILL}": [rr.Mesh3D.from_fields().visualizer(mappings=[source("Mesh3D:vertex_colors", f.colors)])],
    }


def _structure_view(name: str, f: FieldSpec, extra: tuple[str, ...] = (), at: float | None = None) -> rrb.Spatial2DView:
    """A tab of the structure coloured by field ``f``; ``at``: pinned to that sim_time (s), else live.
    Hover points (block values) in the tabs of the paper's fields."""
    paths = (SUPPORT_FILL, FILL, *CARRIED_FILL, f.bar, BLOCKS, SUPPORT_OUTLINES, f.labels, *extra)
    pinned = None
    if at is not None:
        moment = rrb.TimeRangeBoundary.absolute(seconds=at)
        pinned = rrb.VisibleTimeRanges(timeline="sim_time", start=moment, end=moment)
    return rrb.Spatial2DView(
        origin=f"/{PLANE}",
        contents=[f"+ /{p}" for p in paths],
        name=name,
        overrides=_fill_colours(f),
        time_ranges=pinned,
    )


LEGEND_PX: Final = (24.0, 20.0, 1000.0)
"""The Legend panel at 1920 x 1080: its title bar and one line of text, px, and the structure column's height
(tab bar to time panel) that the tabs and the Legend share 5 : 1 (seven lines at 1)."""


def legend_share(lines: int) -> float:
    """The Legend panel's row share (the structure tabs' 5) for ``lines`` of legend at 1920 x 1080
    (``document.legend_lines``): at least 1; more when the lines need it. A bridge's Fill line was the eighth,
    below the panel's fold (seven show at 1)."""
    title, line, column = LEGEND_PX
    need = title + line * lines
    return max(1.0, 5.0 * need / (column - need)) if need < 0.5 * column else 5.0


def build_blueprint(
    main_field: str = "cell_spherical_stress",
    paper: tuple[float, tuple[str, ...]] | None = None,
    residual_range: tuple[float, float] | None = None,
    structure_view: tuple[tuple[float, float], tuple[float, float]] | None = None,
    supports_move: bool = False,
    plot_ranges: dict[str, tuple[float, float] | None] | None = None,
    legend_lines: int = 7,
) -> rrb.Blueprint:
    """Structure tabs and the on-screen legend (left); time series and the run document (right).
    ``residual_range``: the residual plot's y range (log10 of m/s; None: the viewer's fit to the data).
    ``structure_view``: the part of the view that holds the structure and its magnified shape, image ranges
    (u0, u1), (v0, v1) (``static_content.log_plane``): the magnified shape's tab, which has no bar nor
    arrows, shows that part. ``supports_move``: a support moved during the run (a shaken ground, a settling
    foundation): the second row of plots opens on its velocity, else on the solver's residual.
    ``plot_ranges``: the y range of plots (``PLOT_NAMES`` keys: Energies, Support v, Support u, Sweeps), in their
    units, each with its legend bottom left if it has one (``plot_range``); a plot not given or None: the
    viewer's fit.
    ``legend_lines``: the Legend's lines at 1920 x 1080 (:func:`legend_share`).

    Tabs: the live main view (forces, principal stress, ``main_field``), with ``paper`` = (t, figure
    numbers) the paper's four figures pinned to t, the four fields live (p also on the square-root scale,
    ``SQRT_FIELDS``), the magnified deformed shape,
    the joint states (names: :data:`LIVE_TAB`, :func:`paper_tab`, :data:`FIELD_TABS`, :data:`MAGNIFIED_TAB`).
    Opens on ``sim_time`` following the end of the data: at the last frame of a finished run, and on the
    newest frame of a run still being written.
    """
    main = FIELD_BY_KEY[main_field]
    by_key = {f.key: f for f in FIELDS}
    vsr, dev, p, q, sliding, opening = (by_key[k] for k in FIELD_BY_KEY)
    strain_rate_extra = (TRIANGULATION,)
    extras = {vsr.key: strain_rate_extra, p.key: (STRESS_AXES,)}
    joints = (FORCES, HINGES)
    tabs = [_structure_view(LIVE_TAB, main, (FORCES, STRESS_AXES, HINGES))]
    if paper is not None:
        t, figures = paper
        tabs += [
            _structure_view(paper_tab(fig), f, extras.get(f.key, ()), at=t) for fig, f in zip(figures, PAPER_FIELDS)
        ]
    for f in PAPER_FIELDS:  # each square-root view right after its linear twin
        tabs += [_structure_view(FIELD_TABS[f.key], f, extras.get(f.key, ()))]
        tabs += [_structure_view(SQRT_TABS[s.name], s, extras.get(s.key, ())) for s in SQRT_FIELDS if s.key == f.key]
    tabs += [
        rrb.Spatial2DView(
            origin=f"/{PLANE}",
            contents=[f"+ /{x}" for x in (UNDEFORMED, MAGNIFIED, MAGNIFIED_FILL)],
            name=MAGNIFIED_TAB,  # its factor: the Legend (the tab's name had it, and was cut)
            # framed on the structure: it stood in the left two thirds of the tab, the right third kept empty
            # for the colour bar the other tabs have
            visual_bounds=None
            if structure_view is None
            else rrb.VisualBounds2D(x_range=list(structure_view[0]), y_range=list(structure_view[1])),
        ),
        _structure_view(FIELD_TABS[sliding.key], sliding, joints),
        _structure_view(FIELD_TABS[opening.key], opening, joints),
    ]
    structure = rrb.Vertical(
        rrb.Tabs(*tabs, active_tab=1 if paper is not None else 0),
        rrb.TextDocumentView(origin=f"/{LEGEND}", name="Legend"),
        row_shares=[5, legend_share(legend_lines)],
    )
    whole_run = rrb.TimeAxis(
        view_range=rrb.TimeRange(rrb.TimeRangeBoundary.infinite(), rrb.TimeRangeBoundary.infinite())
    )

    ranges = {**(plot_ranges or {}), "residual": residual_range}

    def plot(key: str, axis_y: rrb.ScalarAxis | None = None) -> rrb.TimeSeriesView:
        # a plot of one series whose name says it has no legend: the legend box (bottom left) hid the
        # start of the curve and repeated the name ("kinetic" under "Kinetic energy (J)"); a ranged plot
        # leaves the bottom left to its legend (series.plot_range)
        legend = rrb.PlotLegend(visible=False) if key in SINGLE_SERIES else None
        if ranges.get(key) is not None:
            axis_y, legend = rrb.ScalarAxis(range=ranges[key]), legend or rrb.PlotLegend(corner="LeftBottom")
        return rrb.TimeSeriesView(
            origin=f"/{SERIES[key]}", name=PLOT_NAMES[key], axis_x=whole_run, axis_y=axis_y, plot_legend=legend
        )

    right = rrb.Vertical(
        rrb.Tabs(
            # kinetic alone: beside the dissipated energy, which only grows, it read as a flat line at 0
            # (the aqueduct's 0.5 J under 250 J dissipated); the dissipated energy goes with the support
            # work that feeds it and the potential change, the balance's other large terms
            plot("energy_kinetic"),
            plot("energy_balance"),
            plot("energy_large"),
            plot("max_displacement"),
        ),
        rrb.Tabs(
            # the supports (what moves the structure) beside the solver's health: six tabs in one row did
            # not fit the column
            plot("support_velocity"),
            plot("support_displacement"),
            # the residual's unit (the RMS contact-law violation of a sweep, m/s, as --tolerance): the plot's
            # ticks read -5 .. -5.3 with no unit anywhere on screen
            plot("residual"),
            plot("iterations"),
            plot("contacts"),
            # what moved the structure, at first open: the shaking ground, the settling foundation (an arch
            # shaken by a .AT2 record opened on the solver's log10 residual, which a newcomer cannot read,
            # its ground motion one click away); the residual when no support moves
            active_tab=0 if supports_move else 2,
        ),
        rrb.TextDocumentView(origin=f"/{METADATA}", name="Run"),
        row_shares=[2, 2, 3],
    )
    return rrb.Blueprint(
        rrb.Horizontal(structure, right, column_shares=[3, 2]),
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
        # Following, not paused: a file opens with the cursor at the start of its time line, where the solver
        # health of step 1 lies but no frame yet (the first is at step record_every): every live tab was
        # empty at first open (the colour bar alone). Following puts the cursor on the last frame.
        rrb.TimePanel(state="collapsed", timeline="sim_time", play_state="following"),
    )


def paper_figures(metadata: dict) -> tuple[float, tuple[str, ...]] | None:
    """(instant s, figure numbers) of the paper's figures for a run described by ``metadata``, or None.

    Only under the paper's loading (``metadata["supports"]``, support name -> ``Motion.describe()``): the
    wall shaken by an earthquake record, or at 5 Hz, opened on tabs named "Fig. III.2" pinned to 0.1 s,
    where a record has barely started (strain rates at the 1e-4 1/s floor of the colour range). And only for
    the paper's structure (``metadata["structure"]``: its builder): a user's own blocks in ``wall.toml`` (the
    scenario named "wall" after its file) shaken the paper's way opened on "Fig. III.2 … at t = 0.1 s".
    """
    name = str(metadata.get("scenario"))
    paper = PAPER_FIGURES.get(name)
    duration = metadata.get("duration_s")
    if paper is None or duration is None or float(duration) < paper[0]:
        return None
    if "structure" in metadata and (metadata["structure"] or {}).get("builder") != name:
        return None
    dt, every = metadata.get("dt_s"), metadata.get("record_every")
    if dt is not None and every is not None:  # no frame at the instant: its tabs showed the frame before it
        if paper_instant_missed(paper[0], float(dt), int(every), round(float(duration) / float(dt))):
            return None
    return paper if is_paper_loading(name, metadata.get("supports") or {}) else None
