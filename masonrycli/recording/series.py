"""The recording's time series: energies, displacements and support motion per frame, solver health per step.

What the time-series views plot (entity paths ``layout.SERIES``), each a set of scalars against the
timelines: per frame, the kinetic energy; the supports' work, the dissipated energy and the potential
energy (from the as-built state's); the energy balance error (log10 of its share of the largest term), the largest block displacement (relative to a
shaken ground: :func:`_common_travel`) and the supports'
velocity and displacement (from the as-built state); per step (``Recorder.log_step``), the NLGS sweeps,
log10 of the residual beside log10 of the tolerance, and the contact count.
"""

from __future__ import annotations

from typing import Final

import numpy as np
import rerun as rr

from masonrycli.recording.arrays import FrameBatch, partition_lengths, time_indexes
from masonrycli.recording.layout import SERIES


def send_series(
    rec: rr.RecordingStream,
    idx: list,
    b: FrameBatch,
    q: np.ndarray,
    ref: tuple[np.ndarray, np.ndarray, float],
    n_blocks: int,
) -> dict[str, tuple[float, float]]:
    """The per-frame series of a batch ``b`` (``q`` (F, N, 3) its block poses); ``ref``: the as-built block
    and support poses and potential energy. Returns the lowest and highest finite value of each
    :data:`RANGED` plot in the batch (0 included)."""
    n_frames = len(q)
    ref_q, ref_sq, ref_pot = ref
    kinetic, potential, dissipated, work = np.array(b["scalars"]).T  # SCALARS order
    sq, sv = b.stack("support_q"), b.stack("support_v")
    moved = q[..., :2] - ref_q[None, :, :2] - _common_travel(sq, ref_sq)[:, None, :]
    series = {
        "energy_kinetic": kinetic,
        "energy_large": np.stack([work, dissipated, potential - ref_pot], axis=1),
        "energy_balance": balance_log10(kinetic, potential - ref_pot, dissipated, work),
        "max_displacement": np.sqrt((moved**2).sum(-1)).max(axis=1) if n_blocks else np.zeros(n_frames),
        "support_velocity": sv,
        "support_displacement": sq[..., :2] - ref_sq[None, :, :2],
    }
    _send_scalars(rec, idx, series)
    return {key: _span(series[key]) for key in RANGED}


def _span(values: np.ndarray) -> tuple[float, float]:
    """(lowest, highest) finite value of ``values`` with 0: a plot's lines and its 0."""
    v = np.asarray(values, dtype=np.float64)
    v = v[np.isfinite(v)]
    return float(v.min(initial=0.0)), float(v.max(initial=0.0))


BALANCE_FLOOR = 1e-16
"""The relative balance error plotted for an exact balance (0): about float64's round-off."""


def balance_log10(kinetic, potential_change, dissipated, work) -> np.ndarray:
    """log10 of |kinetic + potential change + dissipated − support work| ÷ the largest of the four terms'
    magnitudes, per frame (all J; floored at :data:`BALANCE_FLOOR`, and that floor where all four are 0).

    Why relative and log10: the error is at round-off (3e-11 J on the quick start's wall, whose terms are
    kJ), and plotted in joules its ticks read "0.000 000 000 03 J"; as a share it reads −13 beside terms of
    1, and a real imbalance (a solver off its tolerance) stands out as a rise of decades."""
    terms = np.stack([kinetic, potential_change, dissipated, work])
    scale = np.abs(terms).max(axis=0)
    error = np.abs(kinetic + potential_change + dissipated - work)
    with np.errstate(divide="ignore", invalid="ignore"):
        share = np.where(scale > 0.0, error / scale, 0.0)
    return np.log10(np.maximum(share, BALANCE_FLOOR))


RANGED: Final = ("energy_large", "support_velocity", "support_displacement")
"""The plots of several series, with a legend, whose y range the recording sets (``plot_range``). Support
v alone was: Support u's lines ran along its top and bottom edges and under its legend (a record's ground ux
dipped behind it), and in Energies the legend hid the start of the support work and the two lines at 0."""


SUPPORT_PALETTE: Final = (
    0xFF9F40FF,  # orange
    0x5FA8FFFF,  # blue
    0x59C36AFF,  # green
    0xE15759FF,  # red
    0xB07AE0FF,  # purple
    0xEDC948FF,  # yellow
    0x76D7D1FF,  # cyan
    0xFF8FC8FF,  # pink
)
"""The support plots' series colours, RGBA, in order (support 0 x, support 0 y, support 1 x, ...): left to the
viewer, a settling arch's left-foundation vy and right-foundation vy were both pink (which foundation settles
could not be read), and the same component had another colour in Support v and in Support u."""


def support_series_colours(supports: int) -> np.ndarray:
    """(2 S,) uint32 RGBA of each series of the Support v and Support u plots (x, y a support), the same in both
    (uint32: rerun reads 4 plain ints as one colour's R, G, B, A)."""
    return np.array([SUPPORT_PALETTE[k % len(SUPPORT_PALETTE)] for k in range(2 * supports)], dtype=np.uint32)


def _common_travel(sq: np.ndarray, ref_sq: np.ndarray) -> np.ndarray:
    """(F, 2) m: the supports' translation from as built at each frame when they all moved alike (a shaken
    ground, both foundations shaken as one), else 0 (a foundation settling beside a fixed one): the
    reference of the summary's largest displacement and of the magnified view. The plot drew the shaken
    wall's travel with its ground, 0.16 m under 'masonry simulate wall --freq 2 --amp 1', as the blocks'."""
    out = np.zeros((len(sq), 2))
    if sq.shape[1] == 0:
        return out
    d = sq[..., :2] - ref_sq[None, :, :2]  # (F, S, 2)
    atol = 1e-9 * max(1.0, float(np.abs(ref_sq[:, :2]).max()))
    alike = np.all(np.abs(d - d[:, :1]) <= atol, axis=(1, 2))
    out[alike] = d[alike, 0]
    return out


def send_steps(rec: rr.RecordingStream, s: FrameBatch, log10_tolerance: float) -> None:
    """The solver health of the steps buffered in ``s`` (``values``: sweeps, residual, contacts per step)."""
    iterations, residual, contacts = np.array(s["values"]).T
    with np.errstate(divide="ignore"):
        log_residual = np.log10(residual)
    tolerance = np.full(len(residual), log10_tolerance)
    _send_scalars(
        rec,
        time_indexes(s),
        {"iterations": iterations, "residual": np.stack([log_residual, tolerance], 1), "contacts": contacts},
    )


def _send_scalars(rec: rr.RecordingStream, idx: list, series: dict[str, np.ndarray]) -> None:
    for key, values in series.items():
        n_rows = len(values)
        values = np.asarray(values, dtype=np.float64).reshape(n_rows, -1)
        if values.shape[1]:
            rec.send_columns(
                SERIES[key],
                indexes=idx,
                columns=rr.Scalars.columns(scalars=values.reshape(-1)).partition(
                    partition_lengths(n_rows, values.shape[1])
                ),
            )
