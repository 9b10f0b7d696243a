"""A run's output files planned before step 1 (:mod:`masonrycli.execute` writes them): the recording and the
history checked (their paths, that they are distinct, that they fit on the disk: upper estimates of their sizes)
and ``--magnify`` with them; what ``masonry check`` stops after."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from masonrycli.errors import InputError
from masonrycli.outputs.files import OutputFile, check_distinct, check_output, check_space, default_recording_path
from masonrycli.scenario.values import option_text

HISTORY_BYTES_PER_BLOCK = 500
"""Upper estimate of one block's share of a history row (measured: 326 B for the walls, 420 B for an arch of
60 voussoirs, whose blocks have more joints)."""
HISTORY_STATIC_BYTES = 60_000
"""... and of what a history holds however short (names, joints, intensity measures, the run's result; its
``units`` table alone is 43 kB: 61 rows of two 89-character UTF-32 cells, measured 2026-11-29)."""
RECORDING_BYTES_PER_BLOCK = 500
"""Upper estimate of one block's share of a recorded frame (measured: 405 B for the walls)."""
FRAME_OVERHEAD_BYTES = 2000
RECORDING_STATIC_BYTES = 750_000
"""Upper estimate of what a recording holds however short: blueprint, legends, document, static geometry
(measured: 452 kB for the 51-block wall's 10 steps, 548 kB for the aqueduct's 2; without it a 0.1 s run
was let start on a disk it then filled, exit 4). Re-measured 2026-11-29 (c5b6ab5): 678 kB for the wall's 2
steps, 763 kB for the aqueduct's; the wall's 0.3 s at --record-every 100 wrote 815–835 kB against the 600 kB
constant's estimate of 813 kB (test_execute's size test failed in CI)."""
RECORDING_STATIC_BYTES_PER_BLOCK = 300
"""... and its share per block (measured: 703 kB for 1004 blocks and 2 steps, one frame of ~400 kB in it)."""
RECORDING_BYTES_PER_STEP = 200
"""Upper estimate of the per-step series (solver sweeps, residual, contacts: measured ~150 B a step for
the wall at --record-every 1000, 603 kB for 1000 steps)."""


@dataclass
class Outputs:
    """The run's output files, checked (see :func:`plan_outputs`); None where not written."""

    recording: OutputFile | None = None
    history: OutputFile | None = None

    def files(self) -> list[OutputFile]:
        return [o for o in (self.recording, self.history) if o is not None]


MAX_MAGNIFY = 1e6
"""Largest --magnify: beyond it a millimetre is drawn a kilometre long (1e300 overflowed the recording's
float32 coordinates to inf, with a RuntimeWarning)."""


def check_run(
    scenario, out: Path | None, history: Path | None, *, no_recording: bool, force: bool, magnify: float | None
) -> Outputs:
    """Everything checked before a run (what ``masonry check`` stops after): the time step against the
    supports' motions, ``--magnify``, then the outputs (:func:`plan_outputs`). Raises InputError."""
    from masonrycli.scenario.sampling import check_sampling

    check_sampling(scenario)
    check_magnify(magnify, no_recording)
    return plan_outputs(scenario, out, history, no_recording=no_recording, force=force)


def check_magnify(magnify: float | None, no_recording: bool) -> None:
    if magnify is not None and not 1.0 <= magnify <= MAX_MAGNIFY:
        raise InputError(f"--magnify {option_text(magnify)}: must be between 1 and {MAX_MAGNIFY:g}")
    if magnify is not None and no_recording:  # it was ignored, as --out was: nothing draws the shape
        raise InputError(
            f"--magnify {option_text(magnify)} with --no-recording: choose one (it draws in the recording)"
        )


def plan_outputs(scenario, out: Path | None, history: Path | None, *, no_recording: bool, force: bool) -> Outputs:
    """Check the output paths and the free space before anything is computed (raises InputError)."""
    if no_recording and out is not None:  # it was ignored: the recording asked for was silently not written
        raise InputError(f"--out {out} with --no-recording: choose one")
    rec = None
    if not no_recording:
        if out is None:
            # checked as --out is: a file named "recordings" here gave "internal error: NotADirectoryError"
            path = default_recording_path(scenario.name)
            try:
                rec = check_output(path, "--out", ".rrd", False, default_name=True)
            except InputError as exc:
                problem = str(exc).removeprefix(f"--out {path}: ")
                raise InputError(
                    f"the default recording {path}: {problem} (give --out R.rrd, or --no-recording)"
                ) from None
        else:
            rec = check_output(out, "--out", ".rrd", force)
    hist = check_output(history, "--history", ".npz", force) if history is not None else None
    check_distinct(rec, hist)
    check_space([(o, size) for o, size in zip((rec, hist), output_sizes(scenario)) if o is not None])
    return Outputs(rec, hist)


def output_sizes(scenario) -> tuple[int, int]:
    """Upper estimates of the recording's and the history's sizes, bytes (what check_space compares)."""
    steps, n = scenario.run.n_steps, scenario.assembly.block_count
    frames = steps // scenario.run.record_every + 2
    recording = (
        RECORDING_STATIC_BYTES
        + RECORDING_STATIC_BYTES_PER_BLOCK * n
        + RECORDING_BYTES_PER_STEP * steps
        + frames * (RECORDING_BYTES_PER_BLOCK * n + FRAME_OVERHEAD_BYTES)
    )
    return recording, HISTORY_STATIC_BYTES + frames * (HISTORY_BYTES_PER_BLOCK * n + FRAME_OVERHEAD_BYTES)
