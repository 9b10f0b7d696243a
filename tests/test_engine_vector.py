"""masonrycli.engine._vector: each explicit vector operation against numpy on random data, lane by lane and
bit for bit (numpy's float64 operations are the same IEEE operations), on the host's vectors and on
Haswell's (AVX2: LLVM splits the 8-wide vectors, and has no scatter instruction)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from masonrycli.engine import _vector as V
from masonrycli.engine._jit import njit

ROOT = Path(__file__).resolve().parent.parent


@njit(cache=False, error_model="numpy")
def _arithmetic(a, b, out):
    # rows of out: a + b, a − b, a · b, a / b, −a, |a|, splat(b[0]), in-place a − b
    x = V.load(a, 0)
    y = V.load(b, 0)
    V.store(out, 0, x + y)
    V.store(out, 8, x - y)
    V.store(out, 16, x * y)
    V.store(out, 24, x / y)
    V.store(out, 32, -x)
    V.store(out, 40, V.vabs(x))
    V.store(out, 48, V.splat(b[0]))
    z = x
    z -= y
    V.store(out, 56, z)


@njit(cache=False)
def _masks(a, b, out_bits, out_sel):
    # bits of ≥ > ≤ < == ≠ and of (≥ & ≠) | ~(<); select(a < b, a, b); lanes of a one by one
    x = V.load(a, 0)
    y = V.load(b, 0)
    out_bits[0] = V.bits_of(x >= y)
    out_bits[1] = V.bits_of(x > y)
    out_bits[2] = V.bits_of(x <= y)
    out_bits[3] = V.bits_of(x < y)
    out_bits[4] = V.bits_of(x == y)
    out_bits[5] = V.bits_of(x != y)
    out_bits[6] = V.bits_of(((x >= y) & (x != y)) | ~(x < y))
    out_bits[7] = V.bits_of(V.mask_bits(out_bits[6]))
    V.store(out_sel, 0, V.select(x < y, x, y))
    for k in range(8):
        out_sel[8 + k] = V.lane(x, k)


@njit(cache=False)
def _memory(src, idx, at, bits, dst_scatter, dst_scalar, dst_masked, out):
    # gathers (masked, scalar loads) of src[idx[at + k] + 1]; scatters of src[at : at + 8] · 2 (masked,
    # scalar stores); a masked store of the same at dst_masked[3 :]
    m = V.mask_bits(bits)
    V.store(out, 0, V.gather(src, idx, at, 1, m))
    V.store(out, 8, V.gather_scalar(src, idx, at, 1))
    x = V.load(src, at) * V.splat(2.0)
    V.scatter(dst_scatter, idx, at, 0, x, m)
    V.scatter_scalar(dst_scalar, idx, at, 0, x)
    V.masked_store(dst_masked, 3, x, m)


@njit(cache=False)
def _rows(src, idx, at, dst, out):
    # gather_rows of src's 4-double rows idx[at + k] into out (x, y, w); scatter_rows of (x + 1, y, w) to dst
    x, y, w = V.gather_rows(src, idx, at)
    V.store(out, 0, x)
    V.store(out, 8, y)
    V.store(out, 16, w)
    V.scatter_rows(dst, idx, at, x + V.splat(1.0), y, w)


def _random(rng, n=8):
    # normal values with some zeros of both signs, infinities, NaNs and ties between a and b
    a, b = rng.normal(size=n), rng.normal(size=n)
    a[rng.random(n) < 0.15] = rng.choice([0.0, -0.0, np.inf, -np.inf, np.nan])
    b[rng.random(n) < 0.15] = rng.choice([0.0, -0.0, np.inf, np.nan])
    tie = rng.random(n) < 0.2
    b[tie] = a[tie]
    return a, b


def _same(x, y):
    return np.array_equal(np.asarray(x).view(np.int64), np.asarray(y).view(np.int64))


def _bits(mask):
    return int(np.sum(mask.astype(np.int64) << np.arange(8)))


@pytest.mark.parametrize("seed", range(20))
def test_arithmetic_and_masks_are_numpys_bit_for_bit(seed):
    rng = np.random.default_rng(seed)
    a, b = _random(rng)
    out = np.empty(64)
    _arithmetic(a, b, out)
    with np.errstate(all="ignore"):
        expected = [a + b, a - b, a * b, a / b, -a, np.abs(a), np.full(8, b[0]), a - b]
    for k, e in enumerate(expected):
        assert _same(out[8 * k : 8 * k + 8], e), k
    bits, sel = np.empty(8, np.int64), np.empty(16)
    _masks(a, b, bits, sel)
    with np.errstate(invalid="ignore"):
        masks = [a >= b, a > b, a <= b, a < b, a == b, a != b, ((a >= b) & (a != b)) | ~(a < b)]
        assert bits[:7].tolist() == [_bits(m) for m in masks]
        assert bits[7] == bits[6]
        assert _same(sel[:8], np.where(a < b, a, b)) and _same(sel[8:], a)


@pytest.mark.parametrize("seed", range(20))
def test_gathers_and_scatters_are_numpys(seed):
    rng = np.random.default_rng(seed)
    n = 40
    src = rng.normal(size=n)
    idx = np.r_[np.zeros(3), rng.choice(n - 1, 8, replace=False), np.zeros(2)].astype(np.int64)
    if seed % 2:
        idx = idx.astype(np.uint64)
    at, bits = 3, int(rng.integers(0, 256))
    lanes = (bits >> np.arange(8)) & 1 == 1
    dst = [rng.normal(size=n) for _ in range(3)]
    before = [d.copy() for d in dst]
    out = np.empty(16)
    _memory(src, idx, at, bits, dst[0], dst[1], dst[2], out)
    where = idx[at : at + 8].astype(np.int64)
    assert _same(out[:8], np.where(lanes, src[where + 1], 0.0)) and _same(out[8:], src[where + 1])
    x = src[at : at + 8] * 2.0
    expect = [d.copy() for d in before]
    expect[0][where[lanes]] = x[lanes]
    expect[1][where] = x
    expect[2][3:11] = np.where(lanes, x, before[2][3:11])
    for d, e in zip(dst, expect):
        assert _same(d, e)


@pytest.mark.parametrize("seed", range(10))
def test_rows_are_numpys(seed):
    rng = np.random.default_rng(seed)
    bodies = 20
    src, dst = rng.normal(size=4 * bodies), rng.normal(size=4 * bodies)
    before = dst.copy()
    pick = rng.choice(bodies, 8, replace=False)
    idx = np.r_[np.zeros(2), 4 * pick].astype(np.int64)
    out = np.empty(24)
    _rows(src, idx, 2, dst, out)
    rows = src.reshape(bodies, 4)[pick]
    assert _same(out, np.r_[rows[:, 0], rows[:, 1], rows[:, 2]])
    expect = before.reshape(bodies, 4).copy()
    expect[pick] = np.column_stack([rows[:, 0] + 1.0, rows[:, 1], rows[:, 2], np.zeros(8)])
    assert _same(dst, expect.ravel())


def test_scatter_to_one_address_keeps_the_last_lane():
    idx = np.full(8, 2, np.int64)
    for kernel_bits in (0b00010110, 0xFF):
        src, dst, dst2, dst3 = np.arange(8.0), np.zeros(4), np.zeros(4), np.zeros(12)
        _memory(src, idx, 0, kernel_bits, dst, dst2, dst3, np.empty(16))
        assert dst[2] == 2.0 * (kernel_bits.bit_length() - 1) and dst2[2] == 14.0


def test_the_same_on_narrower_vectors():
    # Haswell (AVX2): LLVM splits <8 x double> into two ymm halves and scalarises the scatters; the
    # results must not change. A fresh process (numba reads the CPU name at import), its own cache.
    env = dict(os.environ, NUMBA_CPU_NAME="haswell", NUMBA_CPU_FEATURES="", PYTHONPATH=str(ROOT),
               NUMBA_CACHE_DIR=str(ROOT / ".pytest_cache" / "numba-haswell"))  # fmt: skip
    code = (
        "import sys; sys.path.insert(0, 'tests'); import test_engine_vector as t\n"
        "for s in range(6): t.test_arithmetic_and_masks_are_numpys_bit_for_bit(s); "
        "t.test_gathers_and_scatters_are_numpys(s)\n"
        "t.test_scatter_to_one_address_keeps_the_last_lane(); t.test_rows_are_numpys(0)\n"
        "asm = ''.join(t._memory.inspect_asm().values())\n"
        "assert 'zmm' not in asm and 'ymm' in asm and 'vscatter' not in asm, 'not compiled for AVX2'\n"
        "print('ok')\n"
    )
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True, text=True)
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr[-2000:]
