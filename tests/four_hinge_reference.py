"""An independent slow reference for the collapse load of a voussoir ring on two rigid springers: the
least load factor over every kinematically admissible four-hinge mechanism (the upper-bound theorem of
limit analysis for a no-tension ring that cannot slide; Heyman, *The Masonry Arch*, 1982, ch. 4;
Oppenheim 1992 and Ochsendorf 2002 for the arch under horizontal acceleration).

It shares nothing with ``masonrycli.limit``: no LP, no contact detection. The ring is given by its joints —
joint j has an intrados point I_j and an extrados point E_j; voussoir k lies between joints k and k+1 — and
the voussoirs' masses and centroids. A mechanism hinges at joints a < b < c < d, each hinge at I or E:

    body 1 = voussoirs a … b−1 turns (ω1 = 1) about the hinge H_a on the left springer's side
    body 3 = voussoirs c … d−1 turns (ω3) about H_d
    body 2 = voussoirs b … c−1 turns (ω2) about I2 = line(H_a, H_b) ∩ line(H_d, H_c)
    ω2 from the common velocity of H_b, ω3 from that of H_c; the other voussoirs stay still.

It is admissible when every hinge opens its joint at the other end (relative rotation of the right body
with respect to the left one, read at the joint's far end, moves it away along the joint's normal), for ω1
or for −ω1; then λ = −P(dead) / P(live), with P the power of the loads, taken with the sign making
P(live) > 0. The collapse factor is the least λ over all admissible mechanisms (every 4-hinge choice and
all 16 intrados/extrados patterns, vectorised with prefix sums: P of a body turning ω about O is
ω (Σ (c × f) − O × Σ f)).
"""

from __future__ import annotations

import itertools

import numpy as np


def _cross(ax, ay, bx, by):
    return ax * by - ay * bx


def _power(prefix_sums, bodies) -> np.ndarray:
    """Power of one load on the three turning bodies (ω, first voussoir, end, centre of rotation) of each mechanism."""
    fx, fy, m = prefix_sums
    total = 0.0
    for omega, lo, hi, centre in bodies:
        sfx, sfy, sm = fx[hi] - fx[lo], fy[hi] - fy[lo], m[hi] - m[lo]
        total = total + omega * (sm - _cross(centre[:, 0], centre[:, 1], sfx, sfy))
    return total


def least_load_factor(
    intrados: np.ndarray,
    extrados: np.ndarray,
    centroid: np.ndarray,
    dead: np.ndarray,
    live: np.ndarray,
    live_at: np.ndarray | None = None,
    extra: tuple = (),
) -> tuple[float, tuple]:
    """(λ, (joints a b c d, sides)) of the weakest admissible four-hinge mechanism.

    intrados, extrados : (n+1, 2) joint end points, left to right; centroid : (n, 2) voussoir centroids;
    dead, live : (n, 2) forces on each voussoir (the live one multiplied by λ); live_at : (n, 2) where each
    live force acts (default: the centroids; a deck load acts on the extrados). extra : more loads on the
    voussoirs, each (kind, forces (n, 2), at (n, 2)) with kind "dead" or "live": a bridge's fill, whose
    weight (dead) and, under a horizontal acceleration, inertia (live) act at the fill column's centroid.
    """

    def prefix(forces, at):
        m = _cross(at[:, 0], at[:, 1], forces[:, 0], forces[:, 1])
        return [np.concatenate([[0.0], np.cumsum(v)]) for v in (forces[:, 0], forces[:, 1], m)]

    sums = {"dead": prefix(dead, centroid), "live": prefix(live, centroid if live_at is None else live_at)}
    for kind, forces, at in extra:  # loads add: so do their prefix sums
        sums[kind] = [a + b for a, b in zip(sums[kind], prefix(np.asarray(forces), np.asarray(at)))]
    best = (np.inf, None)
    for combos, sides, ok, bodies, _ in _four_hinge_mechanisms(intrados, extrados):
        p_dead, p_live = (_power(sums[kind], bodies) for kind in ("dead", "live"))
        ok = ok & (p_live > 1e-12 * np.abs(p_dead).max())
        lam = np.where(ok, -p_dead / np.where(ok, p_live, 1.0), np.inf)
        k = int(np.argmin(lam))
        if lam[k] < best[0]:
            best = (float(lam[k]), (tuple(int(x) for x in combos[k]), sides))
    return best


def _four_hinge_mechanisms(intrados: np.ndarray, extrados: np.ndarray):
    """For each intrados/extrados pattern of the hinges: (joints (M, 4), sides, admissible (M,), the three
    bodies (ω, first voussoir, end, centre of rotation) turned the way that opens every hinge, the far-end
    opening rate of each hinge (4, M))."""
    n = len(intrados) - 1
    radial = extrados - intrados
    radial /= np.hypot(radial[:, 0], radial[:, 1])[:, None]
    normal = np.stack([radial[:, 1], -radial[:, 0]], axis=1)  # along the ring, left to right
    combos = np.array(list(itertools.combinations(range(n + 1), 4)))
    a, b, c, d = combos.T
    for sides in itertools.product((0, 1), repeat=4):  # 0: hinge on the intrados, 1: on the extrados
        ends = [(intrados, extrados) if s == 0 else (extrados, intrados) for s in sides]
        h = [ends[i][0][j] for i, j in enumerate((a, b, c, d))]  # hinge points
        far = [ends[i][1][j] for i, j in enumerate((a, b, c, d))]  # the joints' other ends
        # I2: H_a + s (H_b − H_a) on the line through H_d and H_c
        u, w = h[1] - h[0], h[2] - h[3]
        den = _cross(u[:, 0], u[:, 1], w[:, 0], w[:, 1])
        ok = np.abs(den) > 1e-12
        den = np.where(ok, den, 1.0)
        r = h[3] - h[0]
        s = _cross(r[:, 0], r[:, 1], w[:, 0], w[:, 1]) / den
        centre2 = h[0] + s[:, None] * u
        hb, hc = h[1] - centre2, h[2] - centre2
        w2 = np.einsum("ij,ij->i", u, hb) / np.maximum(np.einsum("ij,ij->i", hb, hb), 1e-300)
        hd = h[2] - h[3]
        w3 = w2 * np.einsum("ij,ij->i", hc, hd) / np.maximum(np.einsum("ij,ij->i", hd, hd), 1e-300)
        ok &= (np.einsum("ij,ij->i", hb, hb) > 1e-18) & (np.einsum("ij,ij->i", hd, hd) > 1e-18)
        omega = [np.ones_like(w2), w2, w3]  # bodies 1, 2, 3; the springers' sides are still (0)
        turn = [omega[0], omega[1] - omega[0], omega[2] - omega[1], -omega[2]]  # right minus left, per hinge
        opening = []
        for k, j in enumerate((a, b, c, d)):
            arm = far[k] - h[k]
            rel = turn[k][:, None] * np.stack([-arm[:, 1], arm[:, 0]], axis=1)
            opening.append(np.einsum("ij,ij->i", rel, normal[j]))
        opening = np.array(opening)
        forward, backward = np.all(opening > 1e-12, axis=0), np.all(opening < -1e-12, axis=0)
        sign = np.where(forward, 1.0, np.where(backward, -1.0, 0.0))
        ok &= sign != 0.0
        bodies = ((sign * omega[0], a, b, h[0]), (sign * omega[1], b, c, centre2), (sign * omega[2], c, d, h[3]))
        yield combos, sides, ok, bodies, sign * opening


def least_opening_mechanism(
    intrados: np.ndarray, extrados: np.ndarray, centroid: np.ndarray, dead: np.ndarray
) -> tuple[float, tuple]:
    """(opening per work, (joints a b c d, sides)) of the four-hinge mechanism that the dead load drives with the
    least opening of its joints for the work it does: min Σ_hinges (far-end opening rate) / P(dead) over the
    admissible mechanisms with P(dead) > 0 (a ring that cannot stand has some). The far-end opening of a hinge
    is its joint's whole opening: the hinge end stays shut."""
    m = _cross(centroid[:, 0], centroid[:, 1], dead[:, 0], dead[:, 1])
    sums = [np.concatenate([[0.0], np.cumsum(v)]) for v in (dead[:, 0], dead[:, 1], m)]
    best = (np.inf, None)
    for combos, sides, ok, bodies, opening in _four_hinge_mechanisms(intrados, extrados):
        work = _power(sums, bodies)
        ok = ok & (work > 1e-12)
        ratio = np.where(ok, opening.sum(axis=0) / np.where(ok, work, 1.0), np.inf)
        k = int(np.argmin(ratio))
        if ratio[k] < best[0]:
            best = (float(ratio[k]), (tuple(int(x) for x in combos[k]), sides))
    return best


def right_support_thrust(
    intrados: np.ndarray, extrados: np.ndarray, centroid: np.ndarray, dead: np.ndarray
) -> tuple[float, float]:
    """(least, greatest) horizontal force the ring pushes on its right springer towards +x (outward), under
    ``dead`` alone, from the three-hinge mechanisms of a springer that moves (Heyman's spreading supports).

    The right springer moves by u = (s, 0), s = +1 (spreading) or −1 (pushed together); hinges at joints
    a < b < c: voussoirs a … b−1 turn ω1 about H_a, b … c−1 turn ω2 about H_b's velocity, c … n−1 move with the
    springer, so ω1 k×(H_b − H_a) + ω2 k×(H_c − H_b) = u. Each hinge must open its joint (as above). The
    joints' forces do no positive power on an opening mechanism, so the power of the dead load P and of the
    springer's reaction −H x̂ satisfy P − s H ≤ 0 for every admissible one: H ≥ P (s = 1) and H ≤ −P (s = −1).
    The least thrust is the largest such P, the greatest the least −P (the lower- and upper-bound theorems
    meet at a three-hinge mechanism).
    """
    n = len(centroid)
    radial = extrados - intrados
    radial /= np.hypot(radial[:, 0], radial[:, 1])[:, None]
    normal = np.stack([radial[:, 1], -radial[:, 0]], axis=1)
    m = _cross(centroid[:, 0], centroid[:, 1], dead[:, 0], dead[:, 1])
    fx, fy, mm = (np.concatenate([[0.0], np.cumsum(v)]) for v in (dead[:, 0], dead[:, 1], m))
    combos = np.array(list(itertools.combinations(range(n + 1), 3)))
    a, b, c = combos.T
    bounds = []
    for s in (1.0, -1.0):
        best = -np.inf
        for sides in itertools.product((0, 1), repeat=3):
            ends = [(intrados, extrados) if side == 0 else (extrados, intrados) for side in sides]
            h = [ends[i][0][j] for i, j in enumerate((a, b, c))]
            far = [ends[i][1][j] for i, j in enumerate((a, b, c))]
            r1, r2 = h[1] - h[0], h[2] - h[1]
            det = _cross(-r1[:, 1], r1[:, 0], -r2[:, 1], r2[:, 0])  # columns k×r1, k×r2
            ok = np.abs(det) > 1e-12
            det = np.where(ok, det, 1.0)
            w1 = _cross(s, 0.0, -r2[:, 1], r2[:, 0]) / det  # Cramer on [k×r1 k×r2] (ω1, ω2) = (s, 0)
            w2 = _cross(-r1[:, 1], r1[:, 0], s, 0.0) / det
            turn = [w1, w2 - w1, -w2]  # right minus left at each hinge (the springer's part does not turn)
            opens = ok
            for k, j in enumerate((a, b, c)):
                arm = far[k] - h[k]
                rel = turn[k][:, None] * np.stack([-arm[:, 1], arm[:, 0]], axis=1)
                opens = opens & (np.einsum("ij,ij->i", rel, normal[j]) > 1e-12)
            v_b = w1[:, None] * np.stack([-r1[:, 1], r1[:, 0]], axis=1)  # velocity of H_b
            p1 = w1 * ((mm[b] - mm[a]) - _cross(h[0][:, 0], h[0][:, 1], fx[b] - fx[a], fy[b] - fy[a]))
            f2x, f2y = fx[c] - fx[b], fy[c] - fy[b]
            p2 = v_b[:, 0] * f2x + v_b[:, 1] * f2y + w2 * ((mm[c] - mm[b]) - _cross(h[1][:, 0], h[1][:, 1], f2x, f2y))
            p3 = s * (fx[n] - fx[c])
            power = p1 + p2 + p3  # P: the bound is H ≥ P (s = 1) or −H ≥ P (s = −1)
            best = max(best, float(np.max(np.where(opens, power, -np.inf))))
        bounds.append(s * best)
    return bounds[0], bounds[1]
