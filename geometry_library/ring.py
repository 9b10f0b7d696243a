"""An arch's ring traced in a survey, found among its stones, and the same ring thinner about its centre line
(``masonry limit FILE --min-thickness``: Heyman's geometric factor of safety of a surveyed arch).

A ring is a chain of voussoirs: quadrilaterals, each joined to the next by a face, two opposite edges of each
being its joints (the first's and the last's outer joint on a springer: a stone or a support), and those two
joints not parallel (a wedge: courses of rectangular stones are no ring). Finding it::

    joint edges: each edge of a quadrilateral block lying along an edge of another body (within JOINT_GAP, the two
        overlapping over half the shorter)
    wedge: a quadrilateral whose two opposite edges, and only those, are joint edges, at more than WEDGE_ANGLE
    chains: wedges joined through those joint edges; the ring is the longest (at least MIN_VOUSSOIRS), a path
    refused: another body along a voussoir's face anywhere but at the ring's two outer joints (a spandrel stone on the
        extrados: a thinner ring would leave it hanging, and the factor would say nothing of the ring); a corner
        touching a corner is no such face

Thinner by a factor f: each voussoir's two joint edges scaled by f about their midpoints. The ring's centre line
keeps its place, a joint two voussoirs share stays shared, the springing joints shrink on their springers, and a
traced fill reaches down to the thinner ring's extrados (its outline's top is the fill's surface: it is carried
again, :func:`geometry_library.traced_fill.carry_fills`).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import shapely

from .blocks import Assembly, GeometryError
from .checks import body_label, polygon_from_coords
from .traced_fill import carry_fills

JOINT_GAP = 1e-3
"""m: how far apart two edges may lie and still be one joint (the limit analysis's alert distance)."""
WEDGE_ANGLE = math.radians(2.0)
"""The least angle between a voussoir's two joints: a tracing's rectangle is off by less."""
MIN_VOUSSOIRS = 3
"""The fewest voussoirs a ring has (fewer: a lintel, a corbel)."""


@dataclasses.dataclass(frozen=True)
class Ring:
    """The voussoirs of a traced ring, springer to springer."""

    blocks: tuple[int, ...]
    """Block indices, in order along the ring."""
    joint_edge: tuple[int, ...]
    """For each voussoir k: its joints are its edges k and k + 2 (counter-clockwise vertices, edge k from vertex k)."""
    thickness: float
    """m: the mean length of the voussoirs' joints (the ring's thickness as traced)."""

    def describe(self, assembly: Assembly) -> str:
        first, last = (assembly.blocks[self.blocks[i]].name for i in (0, -1))
        return f"{first} … {last}, {len(self.blocks)} voussoirs"


def _edges(vertices: np.ndarray) -> np.ndarray:
    """(k, 2, 2): edge i from vertex i to vertex i + 1."""
    return np.stack([vertices, np.roll(vertices, -1, axis=0)], axis=1)


def _along(e: np.ndarray, f: np.ndarray) -> bool:
    """True if edge ``f`` lies along edge ``e``: parallel, within JOINT_GAP of its line, overlapping over half the
    shorter of the two."""
    d = e[1] - e[0]
    length = float(np.hypot(*d))
    other = float(np.hypot(*(f[1] - f[0])))
    if length <= 0.0 or other <= 0.0:
        return False
    u = d / length
    off = np.abs((f - e[0]) @ np.array([-u[1], u[0]]))
    if off.max() > JOINT_GAP:
        return False
    s = np.sort((f - e[0]) @ u)
    return min(s[1], length) - max(s[0], 0.0) > 0.5 * min(length, other)


def _angle(edges: np.ndarray, k: int) -> float:
    """The angle between edges k and k + 2 of a quadrilateral (0: parallel; they run opposite ways)."""
    d0, d2 = (np.diff(edges[n], axis=0)[0] for n in (k, k + 2))
    return math.atan2(abs(d0[0] * d2[1] - d0[1] * d2[0]), -(d0 @ d2))


def find_ring(assembly: Assembly) -> Ring:
    """The traced ring of ``assembly`` (module docstring); GeometryError, one line, when there is none or other
    stones rest on it."""
    bodies = [*assembly.blocks, *assembly.supports]
    vertices = [b.vertices for b in bodies]
    edges = [_edges(v) for v in vertices]
    polys = np.array([b.polygon for b in bodies], dtype=object)
    left, right = shapely.STRtree(polys).query(polys, predicate="dwithin", distance=JOINT_GAP)
    near: dict[int, set[int]] = {}
    for a, b in zip(left.tolist(), right.tolist()):
        if a != b:
            near.setdefault(a, set()).add(b)
    quads = [i for i, v in enumerate(vertices[: assembly.block_count]) if len(v) == 4]
    joined: dict[int, list[set[int]]] = {}  # quadrilateral -> the bodies along each of its edges
    for i in quads:
        joined[i] = [{j for j in near.get(i, ()) if any(_along(e, f) for f in edges[j])} for e in edges[i]]
    wedges: dict[int, int] = {}  # block -> k: its joints are edges k and k + 2
    for i, sides in joined.items():
        pairs = [k for k in (0, 1) if sides[k] and sides[k + 2] and _angle(edges[i], k) > WEDGE_ANGLE]
        if len(pairs) == 1:  # a stone on its other edges is said below: it rests on the ring
            wedges[i] = pairs[0]
    link = {i: [j for n in (k, k + 2) for j in joined[i][n] if j in wedges] for i, k in wedges.items()}
    ring, seen = [], set()
    for start in sorted(wedges):
        if start in seen:
            continue
        part, todo = [], [start]
        while todo:
            i = todo.pop()
            if i not in seen:
                seen.add(i)
                part.append(i)
                todo += link[i]
        if len(part) > len(ring) and all(len(link[i]) <= 2 for i in part):
            ends = [i for i in part if len(link[i]) < 2]
            if len(ends) == 2 or len(part) == 1:
                order, previous = [min(ends) if ends else part[0]], None
                while len(order) < len(part):
                    step = [j for j in link[order[-1]] if j != previous]
                    previous = order[-1]
                    order.append(step[0])
                ring = order
    if len(ring) < MIN_VOUSSOIRS:
        raise GeometryError(
            f"no ring of {MIN_VOUSSOIRS} or more voussoirs found (quadrilateral stones, each joined to the next by a "
            "face, wedge-shaped, springer to springer)"
        )
    names = [b.name for b in bodies]
    members = set(ring)
    for n, i in enumerate(ring):
        k = wedges[i]
        allowed = members | (joined[i][k] | joined[i][k + 2] if n in (0, len(ring) - 1) else set())
        other = sorted(set().union(*joined[i]) - allowed)  # along a face: a corner on a corner holds nothing up
        if other:
            raise GeometryError(
                f"{names[other[0]]} touches the ring's voussoir {body_label(i, names[i])} elsewhere than at its joints "
                "(a stone resting on the ring): a thinner ring would leave it hanging, so the ring alone has no least "
                "thickness here"
            )
    lengths = [float(np.hypot(*np.diff(edges[i][n], axis=0)[0])) for i in ring for n in (wedges[i], wedges[i] + 2)]
    return Ring(tuple(ring), tuple(wedges[i] for i in ring), float(np.mean(lengths)))


def thinner(assembly: Assembly, ring: Ring, factor: float) -> Assembly:
    """``assembly`` with ``ring``'s voussoirs thinned by ``factor`` about its centre line and its traced fills
    carried again (module docstring)."""
    blocks, fills = assembly.traced_fills()
    blocks = list(blocks)
    for i, k in zip(ring.blocks, ring.joint_edge):
        v = blocks[i].vertices
        out = v.copy()
        for a, b in ((k, (k + 1) % 4), ((k + 2) % 4, (k + 3) % 4)):
            middle = 0.5 * (v[a] + v[b])
            out[a], out[b] = middle + factor * (v[a] - middle), middle + factor * (v[b] - middle)
        blocks[i] = dataclasses.replace(blocks[i], polygon=polygon_from_coords(out, i, blocks[i].name))
    bare = Assembly(tuple(blocks), assembly.supports)
    outlines = [(f"fill {f.name!r}", f.name, f.density, f.outline) for f in fills]
    return carry_fills(bare, outlines, None)
