"""Explicit 16-wide vectors of floats for numba kernels: :mod:`masonrycli.engine._vector`'s operations on
``<16 x float>`` (one zmm register with AVX-512, as ``<8 x double>``).

The types :data:`f32x16` (LLVM ``<16 x float>``) and :data:`mask16` (``<16 x i1>``) with the operators
``+ - * /``, unary ``-``, the ordered comparisons and ``!=`` (a mask), ``& | ~`` on masks, and

- ``splat(x)`` (x rounded to float in every lane), ``select(m, a, b)``, ``vabs(a)``,
  ``lane(a, k)`` (lane k widened to a double, exactly);
- ``load(arr, i)`` / ``masked_store(arr, i, a, m)``: ``arr[i : i + 16]`` of a 1-d C-contiguous float32
  array;
- ``gather_rows(arr, idx, i)`` / ``scatter_rows(arr, idx, i, x, y, w)``: a float32 array of 4-float rows
  (a body's velocity and one padding float at ``idx[i + k]``, k = 0 … 15), read as 16 ``<4 x float>``
  loads and a shuffle tree (a 16 × 4 transpose) into (x, y, w); written back as rows ``(x_k, y_k, w_k,
  0)`` by 16 ``<4 x float>`` stores in lane order;
- ``mask_bits(b)`` / ``bits_of(m)``: an integer's low 16 bits as a mask and back.

Each emits one LLVM instruction or intrinsic on the whole vector, no fast-math flags: the IEEE single
precision operation in every lane, the same bits on every machine (LLVM splits the vector on narrower
hardware). Used by the float32 first stage of :mod:`masonrycli.engine.lane_sweeps32`.
"""

from __future__ import annotations

import operator

from llvmlite import ir
from numba import types
from numba.core.datamodel import models, register_default
from numba.core.typing.templates import signature
from numba.extending import intrinsic

from masonrycli.engine._vector import (
    _as_i64,
    _data,
    _intrinsic,
    _is_index_array,
    _mask,
    _register_binary,
    _register_unary,
)

WIDTH = 16
_F = ir.FloatType()
_I64 = ir.IntType(64)
_V16F = ir.VectorType(_F, WIDTH)
_V16B = ir.VectorType(ir.IntType(1), WIDTH)
_V4F = ir.VectorType(_F, 4)


class F32x16(types.Type):
    def __init__(self):
        super().__init__(name="f32x16")


class Mask16(types.Type):
    def __init__(self):
        super().__init__(name="mask16")


f32x16 = F32x16()
"""numba type of an LLVM ``<16 x float>``."""
mask16 = Mask16()
"""numba type of an LLVM ``<16 x i1>``."""


@register_default(F32x16)
class _F32x16Model(models.PrimitiveModel):
    def __init__(self, dmm, fe_type):
        super().__init__(dmm, fe_type, _V16F)


@register_default(Mask16)
class _Mask16Model(models.PrimitiveModel):
    def __init__(self, dmm, fe_type):
        super().__init__(dmm, fe_type, _V16B)


_register_binary((operator.add, operator.iadd), f32x16, f32x16, lambda b, x, y: b.fadd(x, y))
_register_binary((operator.sub, operator.isub), f32x16, f32x16, lambda b, x, y: b.fsub(x, y))
_register_binary((operator.mul, operator.imul), f32x16, f32x16, lambda b, x, y: b.fmul(x, y))
_register_binary((operator.truediv, operator.itruediv), f32x16, f32x16, lambda b, x, y: b.fdiv(x, y))
for _op, _pred in ((operator.ge, ">="), (operator.gt, ">"), (operator.le, "<="), (operator.lt, "<"),
                   (operator.eq, "==")):  # fmt: skip
    _register_binary((_op,), f32x16, mask16, lambda b, x, y, p=_pred: b.fcmp_ordered(p, x, y))
_register_binary((operator.ne,), f32x16, mask16, lambda b, x, y: b.fcmp_unordered("!=", x, y))
_register_binary((operator.and_, operator.iand), mask16, mask16, lambda b, x, y: b.and_(x, y))
_register_binary((operator.or_, operator.ior), mask16, mask16, lambda b, x, y: b.or_(x, y))
_register_unary(operator.neg, f32x16, lambda b, x: b.fneg(x))
_register_unary(operator.invert, mask16, lambda b, x: b.xor(x, ir.Constant(_V16B, [1] * WIDTH)))


def _is_f32_array(t):
    return isinstance(t, types.Array) and t.dtype == types.float32 and t.ndim == 1 and t.layout == "C"


def _pointer(context, builder, sig, args):
    p = builder.gep(_data(context, builder, sig.args[0], args[0]), [_as_i64(context, builder, args[1], sig.args[1])])
    return builder.bitcast(p, _V16F.as_pointer())


@intrinsic
def splat(typingctx, x):
    if not isinstance(x, (types.Float, types.Integer)):
        return None

    def codegen(context, builder, sig, args):
        one = builder.insert_element(ir.Constant(_V16F, ir.Undefined),
                                     context.cast(builder, args[0], sig.args[0], types.float32),
                                     ir.Constant(ir.IntType(32), 0))  # fmt: skip
        return builder.shuffle_vector(one, ir.Constant(_V16F, ir.Undefined), _mask([0] * WIDTH))

    return signature(f32x16, x), codegen


@intrinsic
def select(typingctx, m, a, b):
    if m != mask16 or a != f32x16 or b != f32x16:
        return None
    return signature(f32x16, m, a, b), lambda context, builder, sig, args: builder.select(*args)


@intrinsic
def vabs(typingctx, a):
    if a != f32x16:
        return None

    def codegen(context, builder, sig, args):
        return _intrinsic(builder, "llvm.fabs.v16f32", _V16F, [_V16F], [args[0]])

    return signature(f32x16, a), codegen


@intrinsic
def lane(typingctx, a, k):
    if a != f32x16 or not isinstance(k, types.Integer):
        return None

    def codegen(context, builder, sig, args):
        x = builder.extract_element(args[0], _as_i64(context, builder, args[1], sig.args[1]))
        return builder.fpext(x, ir.DoubleType())

    return signature(types.float64, a, k), codegen


@intrinsic
def load(typingctx, arr, i):
    if not _is_f32_array(arr) or not isinstance(i, types.Integer):
        return None

    def codegen(context, builder, sig, args):
        return builder.load(_pointer(context, builder, sig, args), align=4)

    return signature(f32x16, arr, i), codegen


@intrinsic
def masked_store(typingctx, arr, i, a, m):
    if not _is_f32_array(arr) or not isinstance(i, types.Integer) or a != f32x16 or m != mask16:
        return None

    def codegen(context, builder, sig, args):
        p = _pointer(context, builder, sig, args)
        _intrinsic(builder, "llvm.masked.store.v16f32.p0", ir.VoidType(), [_V16F, _V16F.as_pointer(),
                   ir.IntType(32), _V16B], [args[2], p, ir.Constant(ir.IntType(32), 4), args[3]])  # fmt: skip
        return context.get_dummy_value()

    return signature(types.none, arr, i, a, m), codegen


@intrinsic
def mask_bits(typingctx, b):
    if not isinstance(b, types.Integer):
        return None

    def codegen(context, builder, sig, args):
        bits = builder.trunc(_as_i64(context, builder, args[0], sig.args[0]), ir.IntType(WIDTH))
        return builder.bitcast(bits, _V16B)

    return signature(mask16, b), codegen


@intrinsic
def bits_of(typingctx, m):
    if m != mask16:
        return None

    def codegen(context, builder, sig, args):
        return builder.zext(builder.bitcast(args[0], ir.IntType(WIDTH)), _I64)

    return signature(types.int64, m), codegen


def _row_pointers(context, builder, sig, args):
    # the 16 <4 x float>* of arr.data + idx[i + k], k = 0 … 15
    data = _data(context, builder, sig.args[0], args[0])
    ip = builder.gep(_data(context, builder, sig.args[1], args[1]), [_as_i64(context, builder, args[2], sig.args[2])])
    out = []
    for k in range(WIDTH):
        p = builder.gep(data, [builder.load(builder.gep(ip, [ir.Constant(_I64, k)]), align=8)])
        out.append(builder.bitcast(p, _V4F.as_pointer()))
    return out


@intrinsic
def gather_rows(typingctx, arr, idx, i):
    # (x, y, w): lane k = arr[idx[i + k] + 0, 1, 2], one 4-float row a lane
    if not (_is_f32_array(arr) and _is_index_array(idx) and isinstance(i, types.Integer)):
        return None

    def codegen(context, builder, sig, args):
        rows = [builder.load(p, align=4) for p in _row_pointers(context, builder, sig, args)]
        # 4 rows a <16 x float> (row k at 4k), then component c of each: a shuffle tree (a transpose)
        pairs = [builder.shuffle_vector(rows[2 * k], rows[2 * k + 1], _mask(range(8))) for k in range(8)]
        quads = [builder.shuffle_vector(pairs[2 * k], pairs[2 * k + 1], _mask(range(16))) for k in range(4)]
        out = []
        for c in range(3):
            pick = [c + 4 * k for k in range(4)] + [16 + c + 4 * k for k in range(4)]
            lo = builder.shuffle_vector(quads[0], quads[1], _mask(pick))
            hi = builder.shuffle_vector(quads[2], quads[3], _mask(pick))
            out.append(builder.shuffle_vector(lo, hi, _mask(range(16))))
        return context.make_tuple(builder, sig.return_type, out)

    return signature(types.UniTuple(f32x16, 3), arr, idx, i), codegen


@intrinsic
def scatter_rows(typingctx, arr, idx, i, x, y, w):
    # arr[idx[i + k] + 0 … 3] = (x[k], y[k], w[k], 0) for k = 0 … 15 in lane order
    ok = _is_f32_array(arr) and _is_index_array(idx) and isinstance(i, types.Integer)
    if not ok or x != f32x16 or y != f32x16 or w != f32x16:
        return None

    def codegen(context, builder, sig, args):
        x, y, w = args[3:6]
        zero = ir.Constant(_V16F, [0.0] * WIDTH)
        # (x_k, y_k) and (w_k, 0) interleaved for lanes 0–7 and 8–15, then each lane's row from them
        xy = [builder.shuffle_vector(x, y, _mask([k + s for k in range(h, h + 8) for s in (0, 16)])) for h in (0, 8)]
        wz = [builder.shuffle_vector(w, zero, _mask([k + s for k in range(h, h + 8) for s in (0, 16)])) for h in (0, 8)]
        for k, p in enumerate(_row_pointers(context, builder, sig, args)):
            j = 2 * (k % 8)
            row = builder.shuffle_vector(xy[k // 8], wz[k // 8], _mask([j, j + 1, 16 + j, 17 + j]))
            builder.store(row, p, align=4)
        return context.get_dummy_value()

    return signature(types.none, arr, idx, i, x, y, w), codegen
