"""Layout of a recording: entity paths, field specs, colours, scale constants and the default blueprint.

The vocabulary the recorder, the run document and the tests share. Entity paths have no leading "/";
``ENTITY_PATHS`` lists them all.
"""

from __future__ import annotations

from typing import Final, NamedTuple

import rerun.blueprint as rrb

ROBUST_PERCENTILE: Final = 98.0  # scales and colour ranges come from this percentile of |value|
ARROW_CAP: Final = 2.0  # longest force arrow, in median block heights (hover an arrow for its force)
GLYPH_HALF_LENGTH: Final = 0.45  # longest principal-axis half-length / median block's smaller side


class FieldSpec(NamedTuple):
    key: str  # name in Frame.tensors
    title: str
    unit: str
    signed: bool  # diverging colour map on [−M, M] if True, sequential on [0, M] otherwise
    fill: str  # entity paths: the blocks filled with the field's colours, the colour bar, its labels
    bar: str
    labels: str


def _field(key: str, title: str, unit: str, signed: bool) -> FieldSpec:
    short = key.removeprefix("cell_")
    return FieldSpec(
        key,
        title,
        unit,
        signed,
        f"structure/fields/{short}",
        f"structure/legend/{short}",
        f"structure/plane/xy/legend/{short}",
    )


FIELDS: Final = (
    _field("cell_volumetric_strain_rate", "Volumetric strain rate", "1/s", True),
    _field("cell_deviatoric_strain", "Deviatoric cumulated strain", "", False),
    _field("cell_spherical_stress", "Spherical stress p", "Pa", True),
    _field("cell_deviatoric_stress", "Deviatoric stress q", "Pa", False),
)
FIELD_BY_KEY: Final = {f.key: f for f in FIELDS}
HOVER_VALUES: Final = {  # per-block value shown when hovering a block outline -> Frame.tensors key
    "p": "cell_spherical_stress",
    "q": "cell_deviatoric_stress",
    "volumetric_strain_rate": "cell_volumetric_strain_rate",
    "deviatoric_strain": "cell_deviatoric_strain",
    "sliding_ratio": "block_sliding_ratio",
    "max_opening": "block_max_opening",
}
AXES: Final = {  # glyph set -> (principal values (N, 2) key, angle of the major one (N,) key)
    "stress_axes": ("cell_principal_stress", "cell_principal_angle"),
    "strain_rate_axes": ("cell_principal_strain_rate", "cell_principal_strain_rate_angle"),
}
TENSOR_KEYS: Final = tuple(
    dict.fromkeys([*(f.key for f in FIELDS), *(k for pair in AXES.values() for k in pair), *HOVER_VALUES.values()])
)
SCALARS: Final = (
    "energy_kinetic",
    "energy_potential",
    "energy_dissipated",
    "support_work",
    "nlgs_iterations",
    "nlgs_residual",
    "contact_count",
)

PLANE: Final = "structure/plane"
XY: Final = "structure/plane/xy"
BLOCKS: Final = f"{XY}/blocks"
SUPPORT_OUTLINES: Final = f"{XY}/supports"
TRIANGULATION: Final = f"{XY}/triangulation"
FORCES: Final = f"{XY}/forces"
HINGES: Final = f"{XY}/hinges"
STRESS_AXES: Final = f"{XY}/stress_axes"
STRAIN_RATE_AXES: Final = f"{XY}/strain_rate_axes"
SUPPORT_FILL: Final = "structure/supports"
METADATA: Final = "run/metadata"
SERIES: Final = {
    "energy": "series/energy",
    "max_displacement": "series/blocks/max_displacement",
    "support_velocity": "series/supports/velocity",
    "support_displacement": "series/supports/displacement",
    "iterations": "series/solver/iterations",
    "residual": "series/solver/residual",
    "contacts": "series/contacts/count",
}


ENTITY_PATHS: Final = (
    PLANE,
    XY,
    BLOCKS,
    SUPPORT_OUTLINES,
    TRIANGULATION,
    FORCES,
    HINGES,
    STRESS_AXES,
    STRAIN_RATE_AXES,
    SUPPORT_FILL,
    *(p for f in FIELDS for p in (f.fill, f.bar, f.labels)),
    *SERIES.values(),
    METADATA,
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
OPEN_RGBA: Final = 0x9A9A9AFF  # an open contact with a force (should not happen)
HINGE_RGBA: Final = 0xFFD700FF
COMPRESSION_RGBA: Final = 0x141414FF  # principal axis with a negative value (near black)
TENSION_RGBA: Final = 0xDC00DCFF  # principal axis with a positive value (magenta)


def _structure_view(name: str, field: FieldSpec, extra: tuple[str, ...] = ()) -> rrb.Spatial2DView:
    paths = (SUPPORT_FILL, field.fill, field.bar, BLOCKS, SUPPORT_OUTLINES, field.labels, *extra)
    return rrb.Spatial2DView(origin=f"/{PLANE}", contents=[f"+ /{p}" for p in paths], name=name)


def build_blueprint(main_field: str = "cell_spherical_stress") -> rrb.Blueprint:
    """Structure views in tabs (left); time series and the run document (right)."""
    main = FIELD_BY_KEY[main_field]
    strain_rate_extra = (TRIANGULATION, STRAIN_RATE_AXES)
    structure = rrb.Tabs(
        _structure_view(f"Structure: forces, principal stress, {main.title}", main, (FORCES, STRESS_AXES, HINGES)),
        *(_structure_view(f.title, f, strain_rate_extra if f is FIELDS[0] else ()) for f in FIELDS),
        active_tab=0,
    )

    whole_run = rrb.TimeAxis(
        view_range=rrb.TimeRange(rrb.TimeRangeBoundary.infinite(), rrb.TimeRangeBoundary.infinite())
    )

    def plot(key: str, name: str) -> rrb.TimeSeriesView:
        return rrb.TimeSeriesView(origin=f"/{SERIES[key]}", name=name, axis_x=whole_run)

    right = rrb.Vertical(
        rrb.Tabs(
            plot("energy", "Energy (J)"),
            plot("max_displacement", "Max block displacement (m)"),
            plot("support_velocity", "Support velocity (m/s)"),
            plot("support_displacement", "Support displacement (m)"),
        ),
        rrb.Tabs(
            plot("iterations", "NLGS iterations"), plot("residual", "NLGS residual"), plot("contacts", "Contacts")
        ),
        rrb.TextDocumentView(origin=f"/{METADATA}", name="Run"),
        row_shares=[2, 2, 3],
    )
    return rrb.Blueprint(
        rrb.Horizontal(structure, right, column_shares=[3, 2]),
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
        rrb.TimePanel(state="collapsed"),
    )
