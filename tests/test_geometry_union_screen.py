"""The union screen of the assembly checks: it clears what the pairwise search would clear, and leaves
everything else (overlaps, bodies touching nothing, supports on supports) to it, so validate_assembly
answers exactly as the pairwise search alone; and it keeps a fine arch's check linear (the STRtree's
box pairs of its slivers grow as N²)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from shapely import affinity
from shapely.geometry import box
from shapely.strtree import STRtree

import geometry_library.assembly_checks as checks
from geometry_library import Assembly, Block, GeometryError, Support, build_aqueduct, build_arch, validate_assembly
from geometry_library.union_screen import union_screen

GROUND = Support(box(-5, -1, 5, 0), "ground")


def _answer(assembly: Assembly, **kwargs):
    """validate_assembly's warnings, or its error message."""
    try:
        return validate_assembly(assembly, **kwargs)
    except GeometryError as exc:
        return f"error: {exc}"


def _both(assembly: Assembly, monkeypatch, **kwargs):
    """(with the screen, pairwise search alone)."""
    screened = _answer(assembly, **kwargs)
    with monkeypatch.context() as m:
        m.setattr(checks, "union_screen", lambda *args: None)
        return screened, _answer(assembly, **kwargs)


def _replace(assembly: Assembly, index: int, polygon) -> Assembly:
    blocks = list(assembly.blocks)
    blocks[index] = dataclasses.replace(blocks[index], polygon=polygon)
    return Assembly(tuple(blocks), assembly.supports)


ARCH = build_arch(voussoirs=400)


def _rotated_voussoir(degrees: float) -> Assembly:
    k = next(i for i, b in enumerate(ARCH.blocks) if b.name == "v150")
    return _replace(ARCH, k, affinity.rotate(ARCH.blocks[k].polygon, degrees, origin="centroid"))


@pytest.mark.parametrize(
    "assembly, expected",
    [
        (ARCH, []),
        (build_aqueduct(), []),  # cut spandrel blocks: joints off by float noise, below the tolerance
        # one voussoir of 400 turned by 0.5° about its centre: into both neighbours
        (_rotated_voussoir(0.5), 'error: blocks 183 ("v149") and 184 ("v150") overlap by'),
        # 5e-9 m² into each neighbour, float32-rounding size: below the tolerance, 1e-3 of a voussoir's area
        # (5.4e-6 m²); it was refused at 1e-9 m²
        (_rotated_voussoir(1e-4), []),
        (_rotated_voussoir(0.1), "error: blocks 183"),  # 5e-5 m² into each neighbour
        # a block floating above the arch, and a foundation sunk into the other
        (
            Assembly(ARCH.blocks + (Block(box(0, 9, 0.3, 9.2), "loose"),), ARCH.supports),
            ['block 469 ("loose") touches nothing'],
        ),
        (
            Assembly(ARCH.blocks, ARCH.supports + (Support(box(-3, -0.6, 3, -0.4), "slab"),)),
            ['support 1 ("left-foundation") and support 3 ("slab") overlap by', 'support 2 ("right-foundation") and'],
        ),
        (Assembly((Block(box(0, 0, 1, 1), "a"), Block(box(1.0005, 0, 2, 1), "b")), (GROUND,)), []),  # gap < 1 mm
        (Assembly((Block(box(0, 0, 1, 1), "a"), Block(box(1.0011, 0, 2, 1), "b")), (GROUND,)), []),  # on the ground
        (Assembly((Block(box(0, 0.0011, 1, 1), "a"), Block(box(0.9, 1, 2, 2), "b"))), ["no supports"]),
    ],
)
def test_the_screen_answers_as_the_pairwise_search(assembly, expected, monkeypatch):
    screened, pairwise = _both(assembly, monkeypatch)
    assert screened == pairwise
    if isinstance(expected, str):
        assert isinstance(screened, str) and screened.startswith(expected), screened
    else:
        assert len(screened) == len(expected) and all(w.startswith(e) for w, e in zip(screened, expected)), screened


def test_many_overlaps_below_the_tolerance_are_left_to_the_pairwise_search(monkeypatch):
    # 400 joints each 6e-10 m² into the next block: each pair is accepted (tolerance 1e-9 m²), their sum is
    # not; the screen cannot tell the two apart and must not decide
    blocks = tuple(Block(box(i * (1 - 6e-10), 0, i * (1 - 6e-10) + 1, 1), f"b{i}") for i in range(400))
    assembly = Assembly(blocks, (Support(box(-1, -1, 500, 0), "ground"),))
    geoms = np.array([b.polygon for b in blocks] + [assembly.supports[0].polygon], dtype=object)
    assert union_screen(geoms, 400, 1e-9) is None
    assert _both(assembly, monkeypatch) == ([], [])


def test_a_fine_arch_is_checked_without_the_box_pairs_of_its_slivers(monkeypatch):
    # 3000 voussoirs: their bounding boxes meet 450 000 times. Every exact test ran on each of them
    # (3.2 million at 8000 voussoirs, 5.7 s); a voussoir moved into its neighbour is still caught.
    arch = build_arch(voussoirs=3000)
    tested = []

    class CountingTree(STRtree):
        def query(self, geometry, predicate=None, **kwargs):
            tested.append(super().query(geometry).shape[1])  # box pairs the predicate is evaluated on
            return super().query(geometry, predicate=predicate, **kwargs)

    monkeypatch.setattr(checks, "STRtree", CountingTree)
    boxes = CountingTree(np.array([b.polygon for b in arch.blocks], dtype=object)).query(
        np.array([b.polygon for b in arch.blocks], dtype=object)
    )
    assert boxes.shape[1] > 400_000
    tested.clear()
    assert validate_assembly(arch) == []
    assert sum(tested) <= 10 * arch.block_count, tested
    k = next(i for i, b in enumerate(arch.blocks) if b.name == "v1500")
    moved = _replace(arch, k, affinity.translate(arch.blocks[k].polygon, xoff=2e-4))
    with pytest.raises(GeometryError, match=r'blocks \d+ \("v1500"\) and \d+ \("v1501"\) overlap by'):
        validate_assembly(moved)
