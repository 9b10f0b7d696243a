"""Where a step's contact impulses start: the previous step's (warm start), or a static guess.

Warm start: a contact keeps a stable key (body pair + features) from one step to the next; a contact
found again starts from the impulse it ended the previous step with, a new one from 0.

Static guess, for a step that nothing warm-starts (the first one): from r = 0 Gauss–Seidel carries
the weight down about one course per sweep (the 248-block wall needed 1785 sweeps). The guess carries
it down at once:

    S_k = contacts that hold block k up: their normal impulse on k points within 60° of "up"
          (s = n_k·up > ½), their gap closes within the step (bias g/dt ≤ |g| dt, the speed gravity
          gives in one step) and the body on the other side is held
    held: supports; a block with a contact of S_k to a held body (blocks from the lowest up)
    load_k = m_k |g| dt for every block (its weight over one step, N·s)
    for each held block k from the highest to the lowest (along −g):
        r_n = load_k / Σ_{S_k} s      (equal normal impulses whose vertical parts carry the load)
        the body o on the other side of each contact of S_k gets load_o += r_n s

Why the gap: with a raised alert distance (``[run] alert_distance = 0.5``) the contacts include pairs
0.2 m apart (a block and the course below the one it sits on). Loaded by the guess, they took 56 of the
51-block wall's 145 N·s; NLGS then had to move that load back, stopped at its tolerance with the blocks
moving at up to 3e-4 m/s, and the wall at rest went on sinking into its joints: 0.039 J "dissipated"
(= the potential energy lost) in 0.2 s, against 5e-14 J with the default 1 mm.

Tangential impulses start at 0. The guess only has to be close: NLGS then solves the exact contact law
from it, so the converged answer is the one of any other start. Contacts that hold nothing up (side
joints, steep arch joints) start at 0, and so does every contact of a block with no load path down to a
support (a stack in free flight: its exact impulses are 0).
"""

from __future__ import annotations

import math

import numpy as np

from masonrycli.engine._jit import kernel_only, njit
from masonrycli.engine.contact_key import first_at_least
from masonrycli.engine.nlgs import P_BIAS, P_NX, P_NY

HOLDS_UP = 0.5
"""A contact holds a body up when its normal on that body is within 60° of up (cos 60° = ½)."""


@njit(inline="always")
def _warm_start(key, count, prev_key, prev_r, r):
    # For each contact: i = the first row of last step's sorted keys with prev_key[i] ≥ key[c] (what a
    # binary search, np.searchsorted, finds); r ← prev_r[i] if prev_key[i] = key[c], else 0.
    #   i = contact_key.first_at_least from lo = the previous contact's i if key[c] ≥ key[c − 1] (every
    #   row before it is < key[c]), else 0 (a gallop from lo, then a bisection)
    # Why: detection emits the keys almost sorted (by body pair, their leading bits), so i is usually
    # within a row or two of the previous one and the search is a merge of two sorted lists: 12.8 → 5.8 µs
    # for wall-248's 1188 contacts (a binary search of each key, np.searchsorted, before). The row found
    # is the same, so are the impulses.
    hits = 0
    n = prev_key.shape[0]
    last = 0
    for c in range(count):
        r[c, 0] = 0.0
        r[c, 1] = 0.0
        if n == 0:
            continue
        k = key[c]
        lo = first_at_least(prev_key, n, k, last if c > 0 and k >= key[c - 1] else 0)
        last = lo
        if lo < n and prev_key[lo] == k:
            r[c, 0] = prev_r[lo, 0]
            r[c, 1] = prev_r[lo, 1]
            hits += 1
    return hits


@njit(inline="always")
def _remember(key, r, count, out_key, out_r):
    # Keys sorted (stable) with their impulses, for the next step's searches (_warm_start).
    # Insertion sort: detection emits the contacts sorted by body pair, the keys' leading bits, so only
    # the one or two contacts of a pair can be out of order: ~linear, and no allocation.
    for i in range(count):
        k = key[i]
        r0 = r[i, 0]
        r1 = r[i, 1]
        j = i - 1
        while j >= 0 and out_key[j] > k:
            out_key[j + 1] = out_key[j]
            out_r[j + 1, 0] = out_r[j, 0]
            out_r[j + 1, 1] = out_r[j, 1]
            j -= 1
        out_key[j + 1] = k
        out_r[j + 1, 0] = r0
        out_r[j + 1, 1] = r1


@njit
def _static_guess(contact_body, pack, count, body_mass, block_count, gravity, dt, order, r):
    # The load-path guess of the module doc (``order``: the blocks from the lowest up, _lowest_first):
    #   r ← 0; up = −g/|g|; CSR lists of each body's contacts
    #   held ← supports; for each block k from the lowest up:
    #       held[k] if a contact holding k up (_holding: s > HOLDS_UP) touches a held body
    #   load_k = m_k |g| dt
    #   for each held block k from the highest down:
    #       r_n = load_k / Σ s over k's holding contacts to held bodies; each such contact gets r_n,
    #       and the body o on its other side load_o += r_n s
    # Why lowest-up then highest-down: a block is held only through held bodies below it, and a body
    # must have received the load of everything above before it passes its own down.
    body_count = body_mass.shape[0]
    g = np.sqrt(gravity[0] * gravity[0] + gravity[1] * gravity[1])
    for c in range(count):
        r[c, 0] = 0.0
        r[c, 1] = 0.0
    if g == 0.0 or count == 0:
        return
    upx = -gravity[0] / g
    upy = -gravity[1] / g
    reach = g * dt  # m/s: a contact whose bias (gap/dt) exceeds this does not close within the step
    # Contacts of each body, compressed rows: contacts of k are index[start[k]:start[k + 1]].
    start = np.empty(body_count + 1, np.int64)
    start[:] = 0
    for c in range(count):
        start[contact_body[c, 0] + 1] += 1
        start[contact_body[c, 1] + 1] += 1
    for k in range(body_count):
        start[k + 1] += start[k]
    fill = start[:-1].copy()
    index = np.empty(2 * count, np.int64)
    for c in range(count):
        for side in range(2):
            k = contact_body[c, side]
            index[fill[k]] = c
            fill[k] += 1
    # Held blocks, from the lowest up: a block is held when a contact that holds it up touches a
    # support or a held block. A load path must end on a support: a falling stack gets no impulse.
    held = np.empty(body_count, np.bool_)
    held[:] = False
    for k in range(block_count, body_count):
        held[k] = True
    for k in order:
        for i in range(start[k], start[k + 1]):
            c = index[i]
            s, other = _holding(contact_body, pack, c, k, upx, upy, reach)
            if s > HOLDS_UP and held[other]:
                held[k] = True
                break
    load = np.empty(body_count, np.float64)
    load[:] = 0.0
    for k in range(block_count):
        load[k] = body_mass[k] * g * dt
    for j in range(block_count - 1, -1, -1):  # from the highest down
        k = order[j]
        if not held[k]:
            continue
        total = 0.0
        for i in range(start[k], start[k + 1]):
            s, other = _holding(contact_body, pack, index[i], k, upx, upy, reach)
            if s > HOLDS_UP and held[other]:
                total += s
        rn = load[k] / total
        for i in range(start[k], start[k + 1]):
            c = index[i]
            s, other = _holding(contact_body, pack, c, k, upx, upy, reach)
            if s > HOLDS_UP and held[other]:
                r[c, 1] = rn
                load[other] += rn * s


@kernel_only
def _holding(contact_body, pack, c, k, upx, upy, reach):
    # (s, other): s = the up-component of the unit normal impulse contact c puts on body k (the normal n
    # points from a to b: r_n n pushes b along n and a along −n); other = the body on the other side.
    # s = 0 for a contact too far open to close within the step (bias above ``reach``): it holds nothing.
    s = pack[c, P_NX] * upx + pack[c, P_NY] * upy
    if pack[c, P_BIAS] > reach:
        s = 0.0
    if contact_body[c, 0] == k:
        return -s, contact_body[c, 1]
    return s, contact_body[c, 0]


def static_guess(contact_body, pack, count, body_q, model, r) -> None:
    """Write the top-down load-path guess of the impulses (C, 2) N·s into ``r`` (see the module doc).
    ``pack`` holds the contacts' normals (nlgs.prepare_contacts); ``body_q`` (B, 3) the configuration."""
    order = _lowest_first(body_q, model.block_count, model.gravity)
    _static_guess(contact_body, pack, count, model.body_mass, model.block_count, model.gravity, model.dt, order, r)


def _lowest_first(body_q, block_count, gravity) -> np.ndarray:
    """(N,) int64: the blocks by height along up = −g/|g|, lowest first, ties in block order (a stable
    sort). numpy's stable argsort, not numba's inside the kernel: its merge sort compiled for 1.2 s of a
    first run's CPU, for one call a run. The same IEEE operations as the kernel's (gx·gx, not pow), so the
    same order; NaN heights last, as in numba's sort."""
    gx, gy = float(gravity[0]), float(gravity[1])
    g = math.sqrt(gx * gx + gy * gy)
    if g == 0.0:
        return np.arange(block_count)
    height = body_q[:block_count, 0] * (-gx / g) + body_q[:block_count, 1] * (-gy / g)
    return np.argsort(height, kind="stable")


class WarmStart:
    """The previous step's contact keys (sorted) and impulses, carried over to the next step."""

    def __init__(self, capacity: int):
        self._key = np.empty(capacity, np.int64)
        """(≥ C_prev,) int64: the previous step's contact keys, sorted (rows [:C_prev])."""
        self._r = np.empty((capacity, 2))
        """(≥ C_prev, 2) N·s: their final impulses (r_t, r_n), in key order."""
        self._count = 0
        """C_prev: contacts of the previous step."""

    @property
    def key(self) -> np.ndarray:
        """(C_prev,) int64 the previous step's contact keys, sorted."""
        return self._key[: self._count]

    @property
    def r(self) -> np.ndarray:
        """(≥ C_prev, 2) N·s their final impulses (rows ``[:C_prev]``)."""
        return self._r

    def start(self, key: np.ndarray, count: int, r: np.ndarray) -> int:
        """Write the starting impulses of this step's ``count`` contacts (keys ``key``) into ``r`` (C, 2);
        return how many were found in the previous step."""
        return _warm_start(key, count, self.key, self._r, r)

    def remember(self, key: np.ndarray, r: np.ndarray, count: int) -> None:
        """Keep this step's final impulses ``r`` for the next step."""
        _remember(key, r, count, *self.reserve(count))

    def reserve(self, count: int) -> tuple[np.ndarray, np.ndarray]:
        """The (key, r) arrays that this step's ``count`` sorted keys and impulses go to (grown if needed);
        the next :meth:`start` reads their first ``count`` rows."""
        if count > self._key.shape[0]:
            self._key = np.empty(count, np.int64)
            self._r = np.empty((count, 2))
        self._count = count
        return self._key, self._r
