"""When the recorder sends what it buffered (batches), and a failed send as the ``OSError`` it is.

Frames: ``batch_frames`` (100) a batch until the scales are fixed (they come from the first batch with
data), then ``long_batch_frames``: fewer batches, a smaller index (~2 kB a frame at 100 frames a batch),
but a batch costs about 1.5 kB per block and frame while it is sent, hence ``LONG_BATCH_BLOCK_FRAMES`` over
the block count (the 51-block wall: 392 frames; 248 blocks: 100, as before; benchmarks/README.md,
"Memory"). Once the scales are fixed a batch is also sent when ``FLUSH_SECONDS`` have passed, so a killed
run loses at most about a second of frames and a slow run's file stays current. The initial frame (step 0)
does not count towards a batch. The rows do not depend on where the batches end
(``readback.recording_rows``).

Steps' solver health: sent with the frames, or on their own every ``STEP_BATCH`` steps (many steps a frame,
``--record-every 10⁶``: bounded all the same). Whatever is buffered when the recorder closes is sent then.
"""

from __future__ import annotations

import contextlib
import errno
import os
import re
import shutil
import time
from typing import Final

from masonrycli.recording.arrays import FrameBatch

STEP_BATCH: Final = 10_000  # steps' solver health buffered at most between sends (~2 MB)
FLUSH_SECONDS: Final = 1.0  # s of wall-clock time between writes to the file, once the scales are fixed
LONG_BATCH_BLOCK_FRAMES: Final = 20_000  # blocks x frames a batch once the scales are fixed (module doc)


class Batching:
    """The batch sizes of one recording and the time of its last send.

    ``batch_frames``: frames a batch until the scales are fixed; ``long_batch_frames`` after (None:
    ``LONG_BATCH_BLOCK_FRAMES`` over ``block_count``; at least ``batch_frames``).
    """

    def __init__(self, batch_frames: int, block_count: int, long_batch_frames: int | None = None) -> None:
        self.batch_frames = max(1, int(batch_frames))
        long = LONG_BATCH_BLOCK_FRAMES // max(1, block_count) if long_batch_frames is None else long_batch_frames
        self.long_batch_frames = max(self.batch_frames, int(long))
        self._sent = time.perf_counter()

    def size(self, scales_fixed: bool) -> int:
        """Frames a batch: ``batch_frames`` until the scales are fixed, then ``long_batch_frames``."""
        return self.long_batch_frames if scales_fixed else self.batch_frames

    def frames_due(self, batch: FrameBatch, scales_fixed: bool) -> bool:
        """Whether ``batch`` is to be sent now: it holds a batch's frames, or ``FLUSH_SECONDS`` have passed
        and every scale is fixed (the scales come from whole batches, so the recording's content does not
        depend on the machine's speed)."""
        due = time.perf_counter() - self._sent >= FLUSH_SECONDS and scales_fixed
        return len(batch["step"]) - initial_frames(batch) >= self.size(scales_fixed) or due

    def sent(self) -> None:
        """The buffered frames reached the file now."""
        self._sent = time.perf_counter()


def steps_due(steps: FrameBatch) -> bool:
    """Whether the steps' solver health buffered is to be sent on its own (``STEP_BATCH`` steps)."""
    return len(steps["step"]) >= STEP_BATCH


def initial_frames(b: FrameBatch) -> int:
    """1 if the batch opens with the initial frame (step 0: the structure as built), else 0."""
    steps = b.get("step")
    return 1 if steps and steps[0] == 0 else 0


@contextlib.contextmanager
def io_errors(path: str):
    """Rerun reports a failed write (disk full) as ``RuntimeError('… (os error 28)')``: make it the
    ``OSError`` it is, so the run stops as an output failure rather than an engine error."""
    try:
        yield
    except RuntimeError as exc:  # only rerun's writes run in these blocks
        code = re.search(r"\(os error (\d+)\)", str(exc))
        if code is not None:
            raise OSError(int(code.group(1)), os.strerror(int(code.group(1)))) from None
        folder = os.path.dirname(os.path.abspath(path))
        if shutil.disk_usage(folder).free < 1 << 20:  # the cause rerun's message lost
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC)) from None
        raise OSError(errno.EIO, f"rerun could not write the recording ({str(exc).splitlines()[0]})") from None
