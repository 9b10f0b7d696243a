"""Shared by the tensor tests: a running-bond wall built with shapely, cell fans, state arrays."""

from __future__ import annotations

import numpy as np
from shapely.geometry import box

from masonrycli.analysis import triangulation

from naive_collision import course_edges


def running_bond(rows: int, per_row: int, w: float = 0.3, h: float = 0.2):
    """Straight-ended running bond: even rows `per_row` full blocks, odd rows a half block at each end.

    Returns the rectangles (shapely boxes), centroids (N, 2), areas (N,) and the touching pairs (P, 2)
    found by shapely (shared boundary of positive length).
    """
    boxes = []
    for r in range(rows):
        y0 = r * h
        xs = course_edges(r, per_row, w)
        boxes += [box(x0, y0, x1, y0 + h) for x0, x1 in zip(xs[:-1], xs[1:])]
    centroids = np.array([[b.centroid.x, b.centroid.y] for b in boxes])
    areas = np.array([b.area for b in boxes])
    pairs = [
        (i, j)
        for i in range(len(boxes))
        for j in range(i + 1, len(boxes))
        if boxes[i].intersection(boxes[j]).length > 1e-9
    ]
    return boxes, centroids, areas, np.array(pairs, np.int64)


def star(triangles, i):
    """The fan of cell i: the triangles with apex i."""
    return triangles[triangles[:, 0] == i]


def star_is_closed(triangles, i):
    """Every edge from i is shared by exactly two triangles of its fan (i is an interior block)."""
    edges = {}
    for t in star(triangles, i):
        for j in t:
            if j != i:
                edges[j] = edges.get(j, 0) + 1
    return len(edges) > 0 and all(c == 2 for c in edges.values())


def state_arrays(centroids, n_supports=1):
    n = len(centroids)
    q = np.zeros((n + n_supports, 3))
    q[:n, :2] = centroids
    return q, np.zeros((n + n_supports, 3))


def deformed(centroids, seed, amount=0.02):
    """Current centroids: a random irregular perturbation of the initial ones (the triangles follow)."""
    rng = np.random.default_rng(seed)
    return centroids + rng.normal(scale=amount, size=centroids.shape)


def triangulated_wall():
    """A 5-course running bond of 5 blocks a course and its triangles: (centroids, areas, pairs, triangles)."""
    boxes, centroids, areas, pairs = running_bond(5, 5)
    triangles = triangulation.build_triangles(centroids, pairs)
    return centroids, areas, pairs, triangles
