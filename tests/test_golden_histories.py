"""Golden histories: the four paper scenarios, on short runs, must reproduce stored histories bit for bit.

This is the guard for refactors: a change that claims "behaviour unchanged" keeps every digest below.
A change that alters the numerics on purpose (solver, contact detection, integration) regenerates the
digests and says so, with the reason, in its commit message::

    RERUN_ANALYTICS=0 python -m tests.test_golden_histories --regenerate

The stored file (``tests/data/golden_histories.json``) holds, per scenario and per history array, a
SHA-256 of (dtype, shape, bytes) plus four statistics (sum, sum of |x|, min, max, stored exactly as
float hex). On a mismatch the test names the arrays that changed and prints a lower bound of max |Δ| from
those statistics. For the exact per-array max |Δ|, save the arrays before the change and compare after::

    python -m tests.test_golden_histories --save /tmp/before      # on the old commit
    python -m tests.test_golden_histories --compare /tmp/before   # on the new commit

Bit-identical across processes relies on the same machine, numpy and numba; the digests were produced
on the CI machine (``.ci/run``).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
from pathlib import Path

import numpy as np
import pytest

from masonrycli.outputs.history import History
from masonrycli.run import simulate
from masonrycli.scenario.motion import Constant, Sine
from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder

GOLDEN = Path(__file__).parent / "data" / "golden_histories.json"

_SHAKE = Sine(amplitude=1.0, frequency=2.0)  # ground velocity 1 m/s at 2 Hz
_SETTLE = Constant(velocity=(0.0, -0.01))  # right foundation down at 1 cm/s

# name -> (builder, builder options, motions by support, simulated seconds, run settings other than the
# defaults). Short runs: the whole file stays within ~30 s of CPU, yet each run has contacts opening and
# closing under the loading. The last entry guards the reference solver (plain NLGS, --solver nlgs): its
# digests are those the default solver had before nlgs-accel replaced it.
SCENARIOS = {
    "wall_51_shaken": ("wall", {"blocks": 51}, {"ground": _SHAKE}, 0.5, {}),
    "wall_248_shaken": ("wall", {"blocks": 248}, {"ground": _SHAKE}, 0.3, {}),
    "arch_settlement": ("arch", {}, {"right-foundation": _SETTLE}, 0.5, {}),
    "aqueduct_settlement": ("aqueduct", {}, {"right-foundation": _SETTLE}, 0.2, {}),
    "wall_51_shaken_nlgs": ("wall", {"blocks": 51}, {"ground": _SHAKE}, 0.5, {"solver": "nlgs"}),
}


def run_history(name: str) -> dict[str, np.ndarray]:
    """Every history array of scenario ``name`` (default material, one frame every 10 steps)."""
    builder, options, motions, duration, run = SCENARIOS[name]
    run = RunConfig(duration=duration, record_every=10, **run)
    sc = scenario_from_builder(builder, options, run, Material(), motions)
    hist = History([b.name for b in sc.assembly.blocks], [s.name for s in sc.assembly.supports])
    result = simulate(sc, sinks=[hist])
    assert result.status == "completed", result.message
    return {k: np.asarray(v) for k, v in hist.arrays().items()}


def digest(a: np.ndarray) -> str:
    """SHA-256 of dtype, shape and C-order bytes: equal digests mean bit-identical arrays."""
    a = np.ascontiguousarray(a)
    h = hashlib.sha256()
    h.update(a.dtype.str.encode())
    h.update(repr(a.shape).encode())
    h.update(a.tobytes())
    return h.hexdigest()


def _stats(a: np.ndarray) -> list[str] | None:
    """(sum, sum |x|, min, max) of the finite values as exact float hex; None without any finite number.

    Tensor fields hold NaN where a quantity is undefined (a cell with no strain rate that step), hence
    the statistics skip non-finite entries; the digest still covers them.
    """
    if a.dtype.kind not in "biuf":
        return None
    x = a.astype(np.float64)
    x = x[np.isfinite(x)]
    if x.size == 0:
        return None
    return [float(v).hex() for v in (x.sum(), np.abs(x).sum(), x.min(), x.max())]


def fingerprint(arrays: dict[str, np.ndarray]) -> dict[str, dict]:
    return {
        k: {"sha256": digest(v), "dtype": v.dtype.str, "shape": list(v.shape), "stats": _stats(v)}
        for k, v in sorted(arrays.items())
    }


def _differences(stored: dict[str, dict], now: dict[str, dict]) -> list[str]:
    """One line per array that changed, with a lower bound of max |Δ| where the statistics allow."""
    lines = []
    for key in sorted(set(stored) | set(now)):
        a, b = stored.get(key), now.get(key)
        if a is None or b is None:
            lines.append(f"{key}: {'new array' if a is None else 'array gone'}")
        elif a["sha256"] != b["sha256"]:
            if (a["dtype"], a["shape"]) != (b["dtype"], b["shape"]):
                lines.append(f"{key}: {a['dtype']}{tuple(a['shape'])} -> {b['dtype']}{tuple(b['shape'])}")
            elif a["stats"] and b["stats"]:
                s, t = (np.array([float.fromhex(v) for v in x["stats"]]) for x in (a, b))
                size = max(int(np.prod(a["shape"])), 1)
                # Over the finite entries (same positions assumed): max|Δ| >= |Δmin|, |Δmax|, |Δsum| / size.
                bound = max(abs(t[2] - s[2]), abs(t[3] - s[3]), abs(t[0] - s[0]) / size)
                lines.append(f"{key}: max |Δ| >= {bound:.3e} (sum {s[0]:.17g} -> {t[0]:.17g})")
            else:
                lines.append(f"{key}: contents differ (not numbers, or no finite number)")
    return lines


@pytest.fixture(scope="module")
def stored():
    return json.loads(GOLDEN.read_text())


@pytest.mark.parametrize("name", list(SCENARIOS))
def test_history_is_bit_identical_to_the_stored_one(name, stored):
    assert name in stored, f"{name} not in {GOLDEN.name}: regenerate (see the module docstring)"
    now = fingerprint(run_history(name))
    diff = _differences(stored[name], now)
    assert not diff, f"{name}: history changed ({len(diff)} arrays):\n  " + "\n  ".join(diff)


def test_a_changed_array_is_reported_with_its_difference():
    a = {"x": np.array([0.0, 1.0, 2.0, np.nan]), "n": np.array(["a"])}
    b = {"x": np.array([0.0, 1.0, 2.5, np.nan]), "n": np.array(["a"])}
    diff = _differences(fingerprint(a), fingerprint(b))
    assert diff == ["x: max |Δ| >= 5.000e-01 (sum 3 -> 3.5)"]
    # One flipped low bit is caught too; same bits give no line.
    c = {"x": np.nextafter(a["x"], 3.0), "n": a["n"]}
    assert [line.split(":")[0] for line in _differences(fingerprint(a), fingerprint(c))] == ["x"]
    assert _differences(fingerprint(a), fingerprint({k: v.copy() for k, v in a.items()})) == []


def _main(argv: list[str]) -> int:
    p = argparse.ArgumentParser(prog="python -m tests.test_golden_histories", description=__doc__.split("\n")[0])
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument("--regenerate", action="store_true", help=f"rewrite {GOLDEN}")
    g.add_argument("--save", metavar="DIR", type=Path, help="write each scenario's arrays to DIR/<name>.npz")
    g.add_argument("--compare", metavar="DIR", type=Path, help="print max |Δ| per array against DIR/<name>.npz")
    args = p.parse_args(argv)
    if args.regenerate:
        data = {name: fingerprint(run_history(name)) for name in SCENARIOS}
        tmp = GOLDEN.with_suffix(".tmp")
        tmp.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
        tmp.replace(GOLDEN)
        print(f"wrote {GOLDEN}")
        return 0
    if args.save:
        args.save.mkdir(parents=True, exist_ok=True)
        for name in SCENARIOS:
            np.savez(args.save / f"{name}.npz", **run_history(name))
        print(f"saved {len(SCENARIOS)} histories in {args.save}")
        return 0
    changed = 0
    for name in SCENARIOS:
        before = dict(np.load(args.compare / f"{name}.npz"))
        now = run_history(name)
        for key in sorted(set(before) | set(now)):
            a, b = before.get(key), now.get(key)
            if a is None or b is None or a.shape != b.shape or a.dtype != b.dtype:
                print(f"{name}.{key}: shape/dtype/presence differs")
                changed += 1
            elif a.tobytes() != b.tobytes():
                d = np.abs(a.astype(np.float64) - b.astype(np.float64)).max() if a.dtype.kind in "biuf" else "n/a"
                print(f"{name}.{key}: max |Δ| = {d}")
                changed += 1
    print("bit-identical" if not changed else f"{changed} arrays differ")
    return 1 if changed else 0


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1:]))
