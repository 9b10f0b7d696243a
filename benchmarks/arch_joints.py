"""Joint-for-joint measures of a 2-D block assembly, independent of the code that moved it (pure numpy).

Used by ``benchmarks/lmgc90_arch.py`` to compare LMGC90 (3-D prisms) with our engine (2-D blocks) on the
same arch: both codes' results are reduced to the same 2-D quantities here, from the initial polygons,
the bodies' poses and the contact forces, so neither code's own joint bookkeeping is trusted.

* **Joints** (:func:`face_joints`): pairs of bodies whose polygons share a stretch of boundary in the
  initial configuration (two edges on one line, facing each other, overlapping by more than ``min_length``).
  Each joint has two *ends* (the ends of the shared stretch) and a normal from body a to body b.
* **Opening of an end** (:func:`end_openings`): the normal separation of the end's two material points,
  the one on a and the one on b, both carried rigidly with their bodies, along the normal turned with a:

      opening = (X_b − X_a) · R(θ_a) n₀      (m; > 0 open, 0 closed as built, < 0 interpenetrating)

  and the relative rotation of the joint θ_b − θ_a. An end is **open** above ``OPENING``; a joint is a
  **hinge** when exactly one of its ends is open (it turns about the other), **open** when both are.
* **Resultant of a joint** (:func:`joint_resultants`): Σ f_c of the normal forces of the contacts between
  its two bodies, and the eccentricity of their centre of pressure along the face, measured from the
  face's middle towards end 1 (m). LMGC90's 3-D prisms put 4 points on a face, ours 2: only these sums
  per joint are comparable.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

OPENING = 1e-4
"""m: an end opened by more than this is open (0.1 mm, as masonrycli.analysis.mechanism.OPENING)."""


class Joints(NamedTuple):
    body: np.ndarray
    """(J, 2) int bodies a < b (indices into the polygons passed)."""
    end: np.ndarray
    """(J, 2, 2) m: the two ends of the shared stretch, initial configuration."""
    normal: np.ndarray
    """(J, 2) unit normal from a to b, initial configuration."""


def face_joints(polygons, tol: float = 1e-6, min_length: float = 1e-3) -> Joints:
    """The face-to-face joints of ``polygons`` (a list of (V, 2) vertex arrays, counter-clockwise or not):
    every pair of edges on one line (within ``tol`` m) with opposite outward normals and an overlap longer
    than ``min_length`` m. Rows sorted by (a, b); one row per pair of bodies (the longest overlap)."""
    polys = [np.asarray(p, dtype=np.float64)[:, :2] for p in polygons]
    edges = []  # (body, start, end, outward normal)
    for i, p in enumerate(polys):
        area2 = np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1])
        sign = 1.0 if area2 > 0 else -1.0  # counter-clockwise: outward normal is the edge turned clockwise
        for k in range(len(p)):
            s, e = p[k], p[(k + 1) % len(p)]
            d = e - s
            length = np.hypot(*d)
            if length <= min_length:
                continue
            n = sign * np.array([d[1], -d[0]]) / length
            edges.append((i, s, e, n))
    lo = np.array([p.min(axis=0) for p in polys]).reshape(-1, 2)
    hi = np.array([p.max(axis=0) for p in polys]).reshape(-1, 2)
    best: dict[tuple[int, int], tuple[float, np.ndarray, np.ndarray]] = {}
    for a, b in _candidate_edge_pairs(edges, lo, hi, tol):  # in the order of a loop over all a, then all b
        (ia, sa, ea, na), (ib, sb, eb, nb) = edges[a], edges[b]
        if np.dot(na, nb) > -1 + 1e-9 or abs(np.dot(sb - sa, na)) > tol or abs(np.dot(eb - sa, na)) > tol:
            continue
        t = (ea - sa) / np.hypot(*(ea - sa))  # along edge a
        u = sorted((np.dot(sb - sa, t), np.dot(eb - sa, t)))
        first, last = max(0.0, u[0]), min(np.dot(ea - sa, t), u[1])
        if last - first <= min_length:
            continue
        if last - first > best.get((ia, ib), (0.0,))[0]:
            best[(ia, ib)] = (last - first, np.array([sa + first * t, sa + last * t]), na)
    keys = sorted(best)
    return Joints(
        body=np.array(keys, dtype=np.int64).reshape(-1, 2),
        end=np.array([best[k][1] for k in keys]).reshape(-1, 2, 2),
        normal=np.array([best[k][2] for k in keys]).reshape(-1, 2),
    )


def _candidate_edge_pairs(edges, lo, hi, tol: float) -> np.ndarray:
    """(K, 2) indices (a, b) into ``edges`` that may lie face to face, sorted by a then b: the edges of bodies
    ia < ib whose boxes (lo, hi) meet within ``tol``, nearly opposite normals and b's ends nearly on a's line.
    A superset of what :func:`face_joints` keeps (its tests on these few pairs decide, exactly as before):
    the pure-Python loop over every pair of edges took 3.8 s of CPU on the aqueduct (1 700 edges).

        boxes meet:      not (lo[ia] > hi[ib] + tol or lo[ib] > hi[ia] + tol) in x and y, ia < ib
        edge pairs:      every edge of ia with every edge of ib
        keep if:         na · nb <= -1 + 2e-9 and |(sb − sa) · na|, |(eb − sa) · na| <= 2 tol + 1e-9 m
    """
    if not edges:
        return np.zeros((0, 2), dtype=np.int64)
    body = np.array([e[0] for e in edges])
    s, e, n = (np.array([edge[k] for edge in edges]) for k in (1, 2, 3))
    apart = (lo[:, None, :] > hi[None, :, :] + tol).any(axis=2)  # B x B: a few hundred bodies
    ia, ib = np.nonzero(np.triu(~apart & ~apart.T, k=1))
    first = np.searchsorted(body, np.arange(len(lo)))  # edges are listed body by body
    count = np.searchsorted(body, np.arange(len(lo)), side="right") - first
    per = count[ia] * count[ib]
    pair = np.repeat(np.arange(len(ia)), per)
    k = np.arange(per.sum()) - np.repeat(np.cumsum(per) - per, per)
    a = first[ia][pair] + k // count[ib][pair]
    b = first[ib][pair] + k % count[ib][pair]
    na = n[a]
    keep = (np.einsum("ij,ij->i", na, n[b]) <= -1 + 2e-9) & (
        np.abs(np.einsum("ij,ij->i", s[b] - s[a], na)) <= 2 * tol + 1e-9
    )
    keep &= np.abs(np.einsum("ij,ij->i", e[b] - s[a], na)) <= 2 * tol + 1e-9
    order = np.lexsort((b[keep], a[keep]))
    return np.stack([a[keep][order], b[keep][order]], axis=1)


def _rot(theta):
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def end_openings(joints: Joints, q0, q) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(opening (J, 2) m, slip (J, 2) m, relative rotation (J,) rad) of every joint end in the
    configuration ``q`` (B, 3: x, y, θ of each body's reference point) from the initial ``q0`` (B, 3).

    slip is the tangential offset (X_b − X_a) · R(θ_a) t₀ of the end's material points, t₀ the normal
    turned by +90°."""
    q0, q = np.asarray(q0, dtype=np.float64), np.asarray(q, dtype=np.float64)
    a, b = joints.body[:, 0], joints.body[:, 1]
    ra, rb = _rot(q[a, 2] - q0[a, 2]), _rot(q[b, 2] - q0[b, 2])  # (J, 2, 2)
    arm_a = joints.end - q0[a, None, :2]  # (J, 2 ends, 2)
    arm_b = joints.end - q0[b, None, :2]
    xa = q[a, None, :2] + np.einsum("jik,jek->jei", ra, arm_a)
    xb = q[b, None, :2] + np.einsum("jik,jek->jei", rb, arm_b)
    n = np.einsum("jik,jk->ji", ra, joints.normal)
    t = np.stack([-n[:, 1], n[:, 0]], -1)
    d = xb - xa
    opening = np.einsum("jei,ji->je", d, n)
    slip = np.einsum("jei,ji->je", d, t)
    return opening, slip, (q[b, 2] - q0[b, 2]) - (q[a, 2] - q0[a, 2])


def joint_states(opening, threshold: float = OPENING) -> np.ndarray:
    """(J,) int: 0 closed, 1 hinge about end 0 (end 1 open), 2 hinge about end 1 (end 0 open), 3 open."""
    is_open = np.asarray(opening) > threshold
    return (
        np.where(is_open[:, 1] & ~is_open[:, 0], 1, 0)
        + np.where(is_open[:, 0] & ~is_open[:, 1], 2, 0)
        + (3 * (is_open[:, 0] & is_open[:, 1]))
    )


def joint_resultants(
    joints: Joints, contact_body, contact_point, contact_fn, q0=None, q=None
) -> tuple[np.ndarray, np.ndarray]:
    """(Σ f_n (J,) N, eccentricity (J,) m) of each joint from its contacts: ``contact_body`` (C, 2) the
    two bodies of each contact (either order), ``contact_point`` (C, 2) m in the plane, ``contact_fn`` (C,)
    N normal force (compression > 0). The eccentricity is the centre of pressure's offset from the face
    middle, positive towards end 1, measured along the initial face; NaN where Σ f_n ≤ 0. With the poses
    ``q0`` and ``q`` (B, 3: x, y, θ, as :func:`end_openings`) the points are first carried back with body a
    to the initial configuration (else they are taken as they are: the blocks have not moved)."""
    body = np.sort(np.asarray(contact_body, dtype=np.int64).reshape(-1, 2), axis=1)
    point = np.asarray(contact_point, dtype=np.float64).reshape(-1, 2)
    fn = np.asarray(contact_fn, dtype=np.float64).reshape(-1)
    total = np.zeros(len(joints.body))
    ecc = np.full(len(joints.body), np.nan)
    for j, (a, b) in enumerate(joints.body):
        mine = (body[:, 0] == a) & (body[:, 1] == b)
        f = fn[mine]
        total[j] = f.sum()
        if total[j] > 0:
            e0, e1 = joints.end[j]
            axis = (e1 - e0) / np.hypot(*(e1 - e0))
            p = point[mine]
            if q is not None:  # back into body a's initial configuration: X0 = x_a0 + R(−Δθ_a)(X − x_a)
                qa, qa0 = np.asarray(q[a], dtype=np.float64), np.asarray(q0[a], dtype=np.float64)
                p = qa0[:2] + (p - qa[:2]) @ _rot(qa[2] - qa0[2])  # row vectors: v @ R = (Rᵀ v)ᵀ
            s = (p - 0.5 * (e0 + e1)) @ axis
            ecc[j] = float(np.dot(f, s) / total[j])
    return total, ecc


def diff_stats(x, y) -> dict:
    """median / RMS / max of |x − y| (elementwise, or of the row norms for 2-D arrays), and the argmax."""
    d = np.asarray(x, dtype=np.float64) - np.asarray(y, dtype=np.float64)
    a = np.hypot(d[:, 0], d[:, 1]) if d.ndim == 2 else np.abs(d)
    return {
        "median": float(np.median(a)),
        "rms": float(np.sqrt(np.mean(a**2))),
        "max": float(a.max()),
        "argmax": int(a.argmax()),
    }
