"""Driving ``masonry sweep`` in tests: a sine-shaken block scenario, a velocity record, invoke at a wide terminal;
reading a study recording's static fields back."""

from __future__ import annotations

from pathlib import Path

from typer.testing import CliRunner

from masonrycli.cli.app import app

runner = CliRunner()
BLOCK = """
[run]
duration = 1.0
dt = 2e-3
[material]
friction = 0.8
[[block]]
polygon = [[-0.1, 0.0], [0.1, 0.0], [0.1, 0.6], [-0.1, 0.6]]
[[support]]
name = "ground"
polygon = [[-5.0, -0.5], [5.0, -0.5], [5.0, 0.0], [-5.0, 0.0]]
motion = { kind = "sine", amplitude = 0.1, frequency = 2.0 }
"""


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args], terminal_width=200)


def write_block(folder: Path) -> Path:
    """``folder/block.toml``: one 0.2 x 0.6 m block (friction 0.8) on a ground shaken at 0.1 m/s, 2 Hz, 1 s."""
    (folder / "block.toml").write_text(BLOCK)
    return folder / "block.toml"


def velocity_csv(path: Path) -> Path:
    """``path``: a 2-column velocity record, 30 samples 0.01 s apart alternating 0 and 0.05 m/s."""
    path.write_text("time,v\n" + "".join(f"{0.01 * i:.2f},{0.05 * (i % 2):.2f}\n" for i in range(30)))
    return path


def static_fields(chunks, entity: str) -> dict:
    out = {}
    for ch in chunks:
        if ch.entity_path == entity:
            batch = ch.to_record_batch()
            out |= {n: batch.column(n).to_pylist()[0] for n in batch.schema.names if ":" in n}
    return out
