"""Neighbours overlapping by a tracing slip (``--trim-overlaps``, a surveyed wall's reading:
:mod:`geometry_library.survey`): each overlapping pair cut along the chord of their overlap, where their
outlines cross; an overlap deeper than the depth given, or one no straight cut separates, refused.

Trimming, in pseudo-code::

    for each pair (A, B) of bodies whose overlap O has an area (not two supports):
        refuse if depth(O) > trim depth                 (a real overlap, not a slip)
        line L through P and Q, the two points where the outlines of A and B cross
        refuse if A's and B's centroids are on the same side of L
        A keeps its side of L, B the other                   (collected first, cut after: order-free)
    each body = its polygon clipped by all its half-planes   (a convex polygon stays convex)

The chord PQ splits O in two: the part of A beyond it is the cap of O between PQ and A's outline inside B,
and B's is the other cap, so each body gives up a part of the overlap and nothing else — a wide ground
under a stone sunk 1 mm into it at one end and lifted at the other is not touched (its outline inside the
stone is the chord), where a cut through the overlap's middle, tilted, lowered it metres away. After the cuts
A and B meet along PQ: they touch, as the stones do. A half-plane cut keeps a body convex and only removes
area; the area removed is said (largest fraction of a body).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import shapely
from shapely.geometry import Polygon
from shapely.strtree import STRtree

from .assembly_checks import overlap_depth
from .blocks import Assembly, GeometryError
from .checks import body_label, normalised_polygon


def _labels(assembly: Assembly) -> list[str]:
    return [body_label(i, b.name) for i, b in enumerate(assembly.blocks)] + [
        body_label(j, s.name, "support") for j, s in enumerate(assembly.supports)
    ]


def trim_overlaps(assembly: Assembly, depth: float, counts: dict | None = None) -> tuple[Assembly, str]:
    """``assembly`` with each pair of overlapping bodies (not two supports) cut along the chord of their
    overlap (module docstring), and a one-line note of what was trimmed ("" when nothing overlapped).
    Raises when an overlap is deeper than ``depth`` m (listing the pairs) or cannot be split. ``counts`` (a
    dict given) receives ``pairs`` trimmed and the ``deepest_m`` of their overlaps."""
    bodies = [*assembly.blocks, *assembly.supports]
    n_blocks = assembly.block_count
    polys = np.array([b.polygon for b in bodies], dtype=object)
    labels = _labels(assembly)
    left, right = STRtree(polys).query(polys, predicate="intersects")
    keep = (left < right) & (left < n_blocks)
    left, right = left[keep], right[keep]
    overlaps = shapely.intersection(polys[left], polys[right])
    cuts: list[list[tuple[np.ndarray, float]]] = [[] for _ in bodies]  # per body: (n, c) keeping n·x >= c
    deep, deepest = [], 0.0
    for a, b, overlap in zip(left.tolist(), right.tolist(), overlaps):
        if overlap.area <= 1e-12 * min(polys[a].area, polys[b].area):
            continue  # touching along an edge or at a point
        d = overlap_depth(overlap)
        if d > depth:
            deep.append((a, b, d, overlap.area >= 0.9 * min(polys[a].area, polys[b].area)))
            continue
        deepest = max(deepest, d)
        start, normal = _chord(polys[a], polys[b])
        side_a = float(normal @ (np.asarray(polys[a].centroid.coords[0]) - start))
        side_b = float(normal @ (np.asarray(polys[b].centroid.coords[0]) - start))
        if side_a * side_b >= 0.0:
            raise GeometryError(f"{labels[a]} and {labels[b]} overlap in a way no straight cut separates")
        normal = normal if side_a > 0.0 else -normal
        cuts[a].append((normal, float(normal @ start)))
        cuts[b].append((-normal, float(-normal @ start)))
    if deep:
        a, b, d, twice = deep[0]
        others = [f"{bodies[p].name}/{bodies[q].name}" for p, q, *_ in deep[1:6]]
        more = (
            f" (and {len(deep) - 1} more: {', '.join(others)}{', …' if len(deep) > 6 else ''})" if len(deep) > 1 else ""
        )
        raise GeometryError(
            f"{labels[a]} and {labels[b]} overlap {d * 1e3:.3g} mm deep, more than the {depth * 1e3:.3g} mm trimmed "
            + (
                "(one covers the other: the same stone drawn twice?)"
                if twice
                else "(a slip of the tracing that deep: a larger depth trims it; else redraw them)"
            )
            + more
        )
    pairs = sum(len(c) for c in cuts) // 2
    if counts is not None:
        counts.update(pairs=pairs, deepest_m=deepest)
    if not pairs:
        return assembly, ""
    new, worst = [], (0.0, "")
    for k, (body, body_cuts) in enumerate(zip(bodies, cuts)):
        if not body_cuts:
            new.append(body)
            continue
        xy = np.asarray(body.polygon.exterior.coords)[:-1]
        for normal, c in body_cuts:
            xy = clip_half_plane(xy, normal, c)
        polygon = normalised_polygon(xy, labels[k])
        lost = 1.0 - polygon.area / body.polygon.area
        worst = max(worst, (lost, labels[k]))
        new.append(dataclasses.replace(body, polygon=polygon))
    trimmed = Assembly(tuple(new[:n_blocks]), tuple(new[n_blocks:]))
    note = (
        f"{pairs} overlapping pair{'s' if pairs > 1 else ''} trimmed along the chord of their overlap "
        f"(--trim-overlaps; deepest {deepest * 1e3:.2g} mm, at most {worst[0]:.2%} of a body's area: {worst[1]})"
    )
    return trimmed, note


def _chord(a: Polygon, b: Polygon) -> tuple[np.ndarray, np.ndarray]:
    """A point and a unit normal of the line through the two points where the outlines of the overlapping
    convex bodies ``a`` and ``b`` cross. Edges lying along each other (two squares side by side, one 2 mm
    into the other: their tops and bottoms overlap 2 mm) give a stretch of points at each end of the chord:
    each end is the middle of its stretch (the farthest two points made a diagonal cut)."""
    crossing = shapely.get_coordinates(shapely.intersection(a.exterior, b.exterior))
    if len(crossing) < 2:
        return crossing[0] if len(crossing) else np.zeros(2), np.array([1.0, 0.0])  # refused: no cut
    centre = crossing.mean(axis=0)
    along = np.linalg.svd(crossing - centre, full_matrices=False)[2][0]  # the chord's direction
    t = (crossing - centre) @ along
    end = t > 0.5 * (t.min() + t.max())
    p, q = crossing[~end].mean(axis=0), crossing[end].mean(axis=0)
    along = (q - p) / np.hypot(*(q - p))
    return p, np.array([-along[1], along[0]])


def clip_half_plane(xy: np.ndarray, normal: np.ndarray, c: float) -> np.ndarray:
    """The convex ring ``xy`` (k, 2) clipped to the half-plane n·x ≥ c (Sutherland–Hodgman, one edge)."""
    s = xy @ normal - c
    out = []
    for i in range(len(xy)):
        j = (i + 1) % len(xy)
        if s[i] >= 0.0:
            out.append(xy[i])
        if (s[i] >= 0.0) != (s[j] >= 0.0):
            t = s[i] / (s[i] - s[j])
            out.append(xy[i] + t * (xy[j] - xy[i]))
    return np.array(out)
