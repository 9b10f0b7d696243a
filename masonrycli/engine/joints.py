"""Kernels of the joint states (:mod:`masonrycli.analysis.mechanism`): openings, hinge flags, per-block fields; and
the sums behind the recording's joint resultants (:mod:`masonrycli.analysis.joint_forces`).

They are computed for every recorded frame. In numpy each was a dozen small array operations (fancy
indexing, ``ufunc.at``, ``bincount``), ~200 µs a frame on the 51-block wall; one pass here does the
same arithmetic in the same order, so the results are the same bits: ``(0 + p₀) + p₁`` is how
``einsum`` sums a two-term dot product, bins start at 0 and add their weights in contact order as
``bincount`` does, and maxima propagate NaN as ``np.maximum``.

Conventions as in :mod:`masonrycli.analysis.mechanism`: a joint *end* is an initial contact point followed with
its two bodies; ``end_joint[e]`` is the joint of end e (−1 for a single corner contact); joint keys are
``a·B + b`` (B bodies), sorted.
"""

from __future__ import annotations

import math

import numpy as np

from masonrycli.engine._jit import kernel_only, njit
from masonrycli.engine.contact import ContactStatus
from masonrycli.engine.contact_key import first_at_least

_OPEN, _STICK, _SLIP = int(ContactStatus.OPEN), int(ContactStatus.STICK), int(ContactStatus.SLIP)


@njit
def _openings(body_q, end_body, local_a, local_b, normal0, gap0, out):
    # for each end e between bodies a and b:
    #     X_a = x_a + R(θ_a)·local_a[e],  X_b = x_b + R(θ_b)·local_b[e],  n = R(θ_a)·normal0[e]
    #     out[e] = (X_b − X_a)·n + gap0[e]
    # cos θ and sin θ once per body (a body has several ends: the same values, a fifth of the calls)
    cos = np.empty(body_q.shape[0], np.float64)
    sin = np.empty(body_q.shape[0], np.float64)
    for k in range(body_q.shape[0]):
        cos[k] = math.cos(body_q[k, 2])
        sin[k] = math.sin(body_q[k, 2])
    for e in range(end_body.shape[0]):
        a = end_body[e, 0]
        b = end_body[e, 1]
        ca = cos[a]
        sa = sin[a]
        cb = cos[b]
        sb = sin[b]
        xax = body_q[a, 0] + (ca * local_a[e, 0] - sa * local_a[e, 1])
        xay = body_q[a, 1] + (sa * local_a[e, 0] + ca * local_a[e, 1])
        xbx = body_q[b, 0] + (cb * local_b[e, 0] - sb * local_b[e, 1])
        xby = body_q[b, 1] + (sb * local_b[e, 0] + cb * local_b[e, 1])
        nx = ca * normal0[e, 0] - sa * normal0[e, 1]
        ny = sa * normal0[e, 0] + ca * normal0[e, 1]
        out[e] = ((0.0 + (xbx - xax) * nx) + (xby - xay) * ny) + gap0[e]


@kernel_only
def _nan_max(x, y):
    # np.maximum's rule: x if x ≥ y or x is NaN, else y (so NaN from either side).
    return x if x >= y or x != x else y


@kernel_only
def _key_row(key, k, hint):
    # the row of k in the sorted, distinct keys `key`, or −1. The contacts come sorted by pair, so the next
    # contact's key is at or just after the row found for the last one (`hint`): contact_key.first_at_least
    # (a gallop, then a bisection; the warm start's search) from there, from row 0 when key[hint] > k.
    # Distinct keys: the first row ≥ k is k's row if any. A contact costs a few comparisons instead of a
    # search over all the joints.
    n = key.shape[0]
    lo = first_at_least(key, n, k, hint if hint < n and key[hint] <= k else 0)
    return lo if lo < n and key[lo] == k else -1


@njit
def _hinged(opening, end_joint, key, body_count, contact_body, contact_rn, dt, opening_limit, min_force, out):
    # widest[j] = max opening over the ends of joint j
    # for each current contact c of a joint j (its pair key found in `key`), with F = r_n / dt:
    #     loaded[j] += 1 if F > 0;  total[j] += F if F > 0 else 0
    # out[j] = exactly one loaded contact, widest > opening_limit, total ≥ min_force
    j_count = key.shape[0]
    widest = np.empty(j_count, np.float64)
    widest[:] = -np.inf
    for e in range(opening.shape[0]):
        j = end_joint[e]
        if j >= 0:
            widest[j] = _nan_max(widest[j], opening[e])
    loaded = np.empty(j_count, np.float64)
    loaded[:] = 0.0
    total = np.empty(j_count, np.float64)
    total[:] = 0.0
    pos = np.int64(0)  # not 0: numba would compile _key_row for the literal 0 as well (broadphase.py)
    for c in range(contact_body.shape[0]):
        k = np.int64(contact_body[c, 0]) * body_count + contact_body[c, 1]
        row = _key_row(key, k, pos)
        if row < 0:
            continue
        pos = row
        force = contact_rn[c] / dt
        if force > 0.0:
            loaded[pos] += 1.0
            total[pos] += force
        else:
            total[pos] += 0.0
    for j in range(j_count):
        out[j] = loaded[j] == 1.0 and widest[j] > opening_limit and total[j] >= min_force


@njit
def _hinge_contacts(key, hinged, body_count, contact_body, contact_rn, out):
    # out[c] = contact c carries normal force (r_n > 0) and its pair is a hinged joint
    pos = np.int64(0)  # as in _hinged
    for c in range(contact_body.shape[0]):
        k = np.int64(contact_body[c, 0]) * body_count + contact_body[c, 1]
        row = _key_row(key, k, pos)
        if row >= 0:
            pos = row
        out[c] = contact_rn[c] > 0.0 and row >= 0 and hinged[row]


@njit
def _block_fields(opening, end_body, end_joint, block_count, contact_body, contact_rn, status, out_opening, out_ratio):
    # out_opening[k] = max(0, largest opening of the ends of k's joints)    (0 without any)
    # out_ratio[k]   = Σ r_n of k's slipping contacts / Σ r_n of its closed contacts (0 if none)
    # Sums per side of the contact, as two bincounts added to zeros.
    for k in range(block_count):
        out_opening[k] = 0.0
    for side in range(2):
        for e in range(opening.shape[0]):
            owner = end_body[e, side]
            if owner < block_count and end_joint[e] >= 0:
                out_opening[owner] = _nan_max(out_opening[owner], _nan_max(opening[e], 0.0))
    load = np.empty((2, block_count), np.float64)
    load[:] = 0.0
    slide = np.empty((2, block_count), np.float64)
    slide[:] = 0.0
    for side in range(2):
        for c in range(contact_body.shape[0]):
            owner = contact_body[c, side]
            if owner < block_count:
                load[side, owner] += contact_rn[c] if status[c] != _OPEN else 0.0
                slide[side, owner] += contact_rn[c] if status[c] == _SLIP else 0.0
    for k in range(block_count):
        total = (0.0 + load[0, k]) + load[1, k]
        sliding = (0.0 + slide[0, k]) + slide[1, k]
        out_ratio[k] = sliding / total if total > 0.0 else 0.0


@njit
def _contact_states(status, tangential_velocity, contact_r, friction, slip_speed, out_status, out_mobilised):
    # reported status: slip only where |u_t| > slip_speed (else stick)
    # mobilised friction: |r_t| / (μ r_n) on closed contacts where μ r_n > 0, else 0
    for c in range(status.shape[0]):
        s = status[c]
        if s == _SLIP and abs(tangential_velocity[c]) <= slip_speed:
            s = _STICK
        out_status[c] = s
        denom = friction * contact_r[c, 1]
        out_mobilised[c] = abs(contact_r[c, 0]) / denom if s != _OPEN and denom > 0.0 else 0.0


@njit
def _joint_keys(body, frame, keys, flip):
    # base = 1 + the largest body index (1 without contacts)
    # for each contact c: flip[c] = a > b;  keys[c] = (frame[c]·base + min(a, b))·base + max(a, b)
    # returns base
    base = 0
    for c in range(body.shape[0]):
        base = max(base, body[c, 0], body[c, 1])
    base += 1
    for c in range(body.shape[0]):
        a = np.int64(body[c, 0])
        b = np.int64(body[c, 1])
        flip[c] = a > b
        keys[c] = (frame[c] * base + min(a, b)) * base + max(a, b)
    return base


@njit
def _resultants(body, frame, force, normal, point, status, out_body, out_point, out_force, out_state, out_frame):
    # keys, flips, base of the contacts (_joint_keys: key = (frame·base + min(a, b))·base + max(a, b))
    # if the keys are not in order: return −1 (the caller puts the contacts in order first)
    # a joint = a run of equal keys; over its contacts in order, with s = −1 if a > b (flipped), else 1:
    #     f = s·force, n = s·normal, fn = max((0 + f_x n_x) + f_y n_y, 0)   (einsum's sum, np.maximum)
    #     weight += fn;  resultant += f;  centre += fn · point;  slipping |= SLIP;  opened |= OPEN
    #     (sums from 0 in contact order: bincount's)
    # a joint with weight > 0 is a row: bodies (low, high), centre / weight, resultant, state (SLIP if
    # slipping, else OPEN if opened, else STICK: joint_forces' 1, 2, 0), frame; returns the row count
    n = body.shape[0]
    keys = np.empty(n, np.int64)
    flip = np.empty(n, np.bool_)
    base = _joint_keys(body, frame, keys, flip)
    for c in range(1, n):
        if keys[c] < keys[c - 1]:
            return -1
    rows = 0
    c = 0
    while c < n:
        key = keys[c]
        weight = 0.0
        rx = 0.0
        ry = 0.0
        cx = 0.0
        cy = 0.0
        slipping = False
        opened = False
        while c < n and keys[c] == key:
            s = -1.0 if flip[c] else 1.0
            fx = force[c, 0] * s
            fy = force[c, 1] * s
            fn = _nan_max((0.0 + fx * (normal[c, 0] * s)) + fy * (normal[c, 1] * s), 0.0)
            weight += fn
            rx += fx
            ry += fy
            cx += fn * point[c, 0]
            cy += fn * point[c, 1]
            slipping |= status[c] == _SLIP
            opened |= status[c] == _OPEN
            c += 1
        if weight > 0.0:
            out_body[rows, 0] = key // base % base
            out_body[rows, 1] = key % base
            out_point[rows, 0] = cx / weight
            out_point[rows, 1] = cy / weight
            out_force[rows, 0] = rx
            out_force[rows, 1] = ry
            out_state[rows] = 1 if slipping else (2 if opened else 0)
            out_frame[rows] = key // (base * base)
            rows += 1
    return rows


def openings(body_q, end_body, local_a, local_b, normal0, gap0) -> np.ndarray:
    """(E,) m: opening of every joint end (``end_body`` (E, 2) int64, the other arrays (E, 2) / (E,)
    float64 in the bodies' frames) in configuration ``body_q`` (B, 3)."""
    out = np.empty(end_body.shape[0], np.float64)
    _openings(body_q, end_body, local_a, local_b, normal0, gap0, out)
    return out


def hinged(opening, end_joint, key, body_count, contact_body, contact_rn, dt, opening_limit, min_force) -> np.ndarray:
    """(J,) bool: joints with exactly one loaded current contact (r_n > 0), an end opened by more than
    ``opening_limit`` (m), and a normal force (N) of at least ``min_force``."""
    out = np.zeros(key.shape[0], dtype=np.bool_)
    if key.shape[0] == 0:
        return out
    rn = np.ascontiguousarray(contact_rn, dtype=np.float64)
    _hinged(opening, end_joint, key, body_count, contact_body, rn, float(dt), opening_limit, min_force, out)
    return out


def hinge_contacts(key, hinged, body_count, contact_body, contact_rn) -> np.ndarray:
    """(C,) bool: the contacts with r_n > 0 of the joints flagged in ``hinged`` (the hinges themselves)."""
    out = np.zeros(contact_body.shape[0], dtype=np.bool_)
    rn = np.ascontiguousarray(contact_rn, dtype=np.float64)
    _hinge_contacts(key, np.ascontiguousarray(hinged, dtype=np.bool_), body_count, contact_body, rn, out)
    return out


def block_fields(opening, end_body, end_joint, block_count, contact_body, contact_rn, status):
    """((N,) largest joint opening ≥ 0 (m), (N,) share of the normal load carried by slipping contacts)."""
    max_opening = np.empty(block_count, np.float64)
    ratio = np.empty(block_count, np.float64)
    rn = np.ascontiguousarray(contact_rn, dtype=np.float64)
    _block_fields(opening, end_body, end_joint, block_count, contact_body, rn, status, max_opening, ratio)
    return max_opening, ratio


def contact_states(status, tangential_velocity, contact_r, friction: float, slip_speed: float):
    """((C,) int8 reported status, (C,) mobilised friction) of the solver's contacts (mechanism module)."""
    out_status = np.empty(status.shape[0], np.int8)
    mobilised = np.empty(status.shape[0], np.float64)
    _contact_states(status, tangential_velocity, contact_r, float(friction), float(slip_speed), out_status, mobilised)
    return out_status, mobilised


def joint_keys(body, frame) -> tuple[np.ndarray, np.ndarray, int]:
    """((C,) int64 key (frame·B + low body)·B + high body, (C,) bool flip (a > b), B = 1 + the largest body
    index) of contacts between bodies ``body`` (C, 2) int in frames ``frame`` (C,) int ≥ 0."""
    keys, flip = np.empty(body.shape[0], dtype=np.int64), np.empty(body.shape[0], dtype=np.bool_)
    base = _joint_keys(np.ascontiguousarray(body), np.ascontiguousarray(frame, dtype=np.int64), keys, flip)
    return keys, flip, int(base)


def resultants(body, frame, force, normal, point, status):
    """The loaded joints of contacts whose keys (:func:`joint_keys`) are in order, one row each, in that order:
    (bodies (J, 2) int64, point (J, 2), force (J, 2), state (J,) int8, frame (J,) int64); None when the keys
    are not in order. ``body`` (C, 2) int; ``frame`` (C,) int; the forces and normals turned by −1 where
    a > b; ``status`` (C,) int8."""
    n = body.shape[0]
    out = (np.empty((n, 2), np.int64), np.empty((n, 2)), np.empty((n, 2)), np.empty(n, np.int8), np.empty(n, np.int64))
    rows = _resultants(
        np.ascontiguousarray(body),
        np.ascontiguousarray(frame, dtype=np.int64),
        np.ascontiguousarray(force, dtype=np.float64),
        np.ascontiguousarray(normal, dtype=np.float64),
        np.ascontiguousarray(point, dtype=np.float64),
        np.ascontiguousarray(status, dtype=np.int8),
        *out,
    )
    return None if rows < 0 else tuple(x[:rows] for x in out)
