"""masonrycli/engine/contact_key.py through the narrow phase: a contact's key stays the same while a joint opens
or rocks (the reference face flipping between its two faces) and for aligned corners, its bit layout is
unique, and a body's vertex count is checked against the key's limit (256 vertices work, keys included)."""

from __future__ import annotations

import numpy as np
import pytest

from masonrycli.engine.contact_key import KEY_LIMIT_VERTICES, check_topology, decode_contact_key
from masonrycli.engine.narrowphase import collide_polygons

import naive_collision as nv


def _keys_under_motion(a_poly, b_poly, rng, n, rot, shift, alert=1e-3, centre=None):
    base = collide_polygons(a_poly, b_poly, alert)[3]
    flips = {nv.reference_choice(a_poly, b_poly)[0]}
    centre = b_poly.mean(axis=0) if centre is None else centre
    for _ in range(n):
        moved = nv.rotate(b_poly, rng.uniform(-rot, rot), centre=centre) + rng.uniform(-shift, shift, 2)
        keys = collide_polygons(a_poly, moved, alert)[3]
        assert sorted(keys) == sorted(base)
        flips.add(nv.reference_choice(a_poly, moved)[0])
    return base, flips


def test_keys_stable_when_a_joint_opens_or_rocks():
    """Reference face flips between the two faces of a joint; the keys do not change."""
    rng = np.random.default_rng(7)
    lower = nv.rect(0.0, 0.0, 0.3, 0.2)
    upper = nv.rect(0.15, 0.2, 0.45, 0.4)
    base, flips = _keys_under_motion(lower, upper, rng, 300, rot=1e-4, shift=1e-5)
    assert len(base) == 2 and flips == {False, True}
    # block on the ground, rocking a little
    ground = nv.rect(-5.0, -1.0, 5.0, 0.0)
    block = nv.rect(1.0, 0.0, 1.3, 0.2)
    base, flips = _keys_under_motion(block, ground, rng, 300, rot=1e-4, shift=1e-5)
    assert len(base) == 2 and flips == {False, True}
    # vertical joint in a row
    base, flips = _keys_under_motion(lower, nv.rect(0.3, 0.0, 0.6, 0.2), rng, 300, rot=1e-4, shift=1e-5)
    assert len(base) == 2


def test_keys_stable_for_aligned_corners():
    """A column (corners exactly above each other): rounding-level motion keeps the keys."""
    rng = np.random.default_rng(8)
    lower = nv.rect(0.0, 0.0, 0.4, 0.2)
    upper = nv.rect(0.0, 0.2, 0.4, 0.4)
    base, _ = _keys_under_motion(lower, upper, rng, 300, rot=1e-9, shift=1e-9)
    assert len(base) == 2
    # aligned corners: labelled with body a's corners (lower: 2, 3) against b's bottom edge (0)
    _, _, own, vtx, edg = decode_contact_key(base)
    assert list(own) == [0, 0] and sorted(vtx) == [2, 3] and list(edg) == [0, 0]


def test_key_layout_and_uniqueness():
    point, normal, gap, key = collide_polygons(
        nv.rect(0, 0, 0.3, 0.2), nv.rect(0.15, 0.2, 0.45, 0.4), 1e-3, a=123456, b=8_000_000
    )
    a, b, own, vtx, edg = decode_contact_key(key)
    assert list(a) == [123456] * 2 and list(b) == [8_000_000] * 2
    assert len(set(key.tolist())) == 2 and np.all(key > 0)
    expected = {(123456 << 40) | (8_000_000 << 17) | (o << 16) | (v << 8) | e for o, v, e in zip(own, vtx, edg)}
    assert expected == set(key.tolist())


def test_topology_limits():
    check_topology(np.array([0, 3, 3 + KEY_LIMIT_VERTICES], dtype=np.int64))
    with pytest.raises(ValueError, match="body 1"):
        check_topology(np.array([0, 3, 4 + KEY_LIMIT_VERTICES], dtype=np.int64))
    with pytest.raises(ValueError, match="body 0"):
        check_topology(np.array([0, 2, 6], dtype=np.int64))
    with pytest.raises(ValueError):
        check_topology(np.array([0, 3, 6], dtype=np.int32))
    # a polygon with 256 vertices works, keys included
    ang = np.linspace(0, 2 * np.pi, KEY_LIMIT_VERTICES, endpoint=False)
    circle = np.column_stack([np.cos(ang), np.sin(ang)])
    point, _, gap, key = collide_polygons(circle, circle + [2.0, 0.0], 1e-3)
    assert len(point) >= 1 and np.all(np.abs(gap) < 1e-12)
