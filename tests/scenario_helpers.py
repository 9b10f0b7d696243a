"""Shared by the scenario tests: small TOML snippets, writing and loading a file, comparing two scenarios."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from masonrycli.errors import InputError
from masonrycli.scenario.scenario import Scenario
from masonrycli.scenario.toml_file import load_scenario

DATA = Path(__file__).parent / "data"

BLOCK = '[[block]]\nname = "b1"\npolygon = [[0.0, 0.0], [0.4, 0.0], [0.4, 0.2], [0.0, 0.2]]\n'
BLOCK2 = '[[block]]\nname = "b2"\npolygon = [[0.0, 0.2], [0.4, 0.2], [0.4, 0.4], [0.0, 0.4]]\n'
# a three-column record file: time, then the x and y velocity
XY_CSV = "0 0 0\n0.5 1e-3 -2e-3\n1.5 0.25 0.125\n"
GROUND = '[[support]]\nname = "ground"\npolygon = [[-5.0, -0.5], [5.0, -0.5], [5.0, 0.0], [-5.0, 0.0]]\n'


def write(tmp_path: Path, text: str, name: str = "wall.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def load_error(tmp_path: Path, text: str, name: str = "wall.toml") -> str:
    path = write(tmp_path, text, name)
    with pytest.raises(InputError) as exc:
        load_scenario(path)
    msg = str(exc.value)
    assert "\n" not in msg and msg == msg.strip()
    where = re.match(
        rf"{re.escape(str(path))}(:[1-9][0-9]*)?: ", msg
    )  # the key's line: tests/test_scenario_toml_lines.py
    assert where, msg
    return msg[where.end() :]  # the part after "<file>: " or "<file>:<line>: "


def assert_same_scenario(a: Scenario, b: Scenario):
    """Same run, material, motions, names, roles, vertices (1e-12), densities, thicknesses, velocities."""
    assert a.name == b.name
    assert a.run == b.run
    assert a.material == b.material
    assert a.motions == b.motions
    assert a.assembly.block_count == b.assembly.block_count
    assert a.assembly.support_count == b.assembly.support_count
    for x, y in zip(a.assembly.blocks, b.assembly.blocks):
        assert x.name == y.name
        assert x.vertices.shape == y.vertices.shape
        np.testing.assert_allclose(x.vertices, y.vertices, rtol=0, atol=1e-12)
        assert (x.density, x.thickness, tuple(x.velocity)) == (y.density, y.thickness, tuple(y.velocity))
    for x, y in zip(a.assembly.supports, b.assembly.supports):
        assert (x.name, x.role) == (y.name, y.role)
        np.testing.assert_allclose(x.vertices, y.vertices, rtol=0, atol=1e-12)
