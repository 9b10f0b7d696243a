"""Small assemblies for the limit-analysis tests: rectangles on a ground, a semicircular arch on springers; the
built-in aqueduct as a survey would give it (moved, rounded to the millimetre)."""

from __future__ import annotations

import json

import numpy as np
from shapely.geometry import Polygon, box

from geometry_library.blocks import Assembly, Block, Support
from masonrycli.limit.command import resolve_structure
from masonrycli.scenario.motion import Fixed
from masonrycli.scenario.scenario import Material, RunConfig, Scenario

from cli_helpers import invoke

DENSITY = 2000.0


def scenario(blocks, supports, friction: float, name: str = "test", **run) -> Scenario:
    """Blocks ``[(name, polygon)]`` and fixed supports ``[(name, polygon)]`` as a scenario."""
    assembly = Assembly(
        blocks=tuple(Block(p, n, DENSITY, 1.0) for n, p in blocks),
        supports=tuple(Support(p, n) for n, p in supports),
    )
    return Scenario(
        name=name,
        run=RunConfig(**run),
        material=Material(density=DENSITY, friction=friction),
        assembly=assembly,
        motions=tuple(Fixed() for _ in supports),
    )


def column(count: int, width: float, height: float, friction: float, **run) -> Scenario:
    """``count`` blocks width × height stacked on a ground; block 0 at the bottom."""
    blocks = [(f"b{k}", box(0.0, k * height, width, (k + 1) * height)) for k in range(count)]
    return scenario(blocks, [("ground", box(-1.0, -0.5, width + 1.0, 0.0))], friction, **run)


def semicircular_arch(thickness: float, voussoirs: int, friction: float, radius: float = 1.0) -> Scenario:
    """A semicircular arch of mean radius ``radius`` and ring ``thickness``, ``voussoirs`` radial joints
    apart (quadrilateral voussoirs: straight chords), standing on two rigid springers at y = 0."""
    ri, re = radius - thickness / 2, radius + thickness / 2
    angle = np.linspace(0.0, np.pi, voussoirs + 1)
    blocks = []
    for k in range(voussoirs):
        a, b = angle[k], angle[k + 1]
        quad = [
            (ri * np.cos(a), ri * np.sin(a)),
            (re * np.cos(a), re * np.sin(a)),
            (re * np.cos(b), re * np.sin(b)),
            (ri * np.cos(b), ri * np.sin(b)),
        ]
        blocks.append((f"v{k:03d}", Polygon(quad)))
    springers = [
        ("right-springer", box(ri - 0.2, -0.5, re + 0.2, 0.0)),
        ("left-springer", box(-re - 0.2, -0.5, -ri + 0.2, 0.0)),
    ]
    return scenario(blocks, springers, friction, name="semicircle")


def surveyed_aqueduct(tmp_path, name: str, digits: int, dx: float = 0.0, dy: float = 0.0):
    """The aqueduct's GeoJSON (``masonry build aqueduct``) moved by (dx, dy) and rounded to ``digits`` decimals,
    read as ``masonry limit`` reads it with --trim-overlaps 0.002 (the rounding overlaps 36 pairs by up to 0.4 mm)."""
    exact = tmp_path / "aqueduct.geojson"
    if not exact.exists():
        assert invoke("build", "aqueduct", "-o", str(exact)).exit_code == 0
    doc = json.loads(exact.read_text())

    def move(c):
        if isinstance(c[0], (int, float)):
            return [round(c[0] + dx, digits), round(c[1] + dy, digits)]
        return [move(x) for x in c]

    for feature in doc["features"]:
        feature["geometry"]["coordinates"] = move(feature["geometry"]["coordinates"])
    path = tmp_path / f"{name}.geojson"
    path.write_text(json.dumps(doc))
    return resolve_structure(str(path), None, {"trim_overlaps": 0.002})
