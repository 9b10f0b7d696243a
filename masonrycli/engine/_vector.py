"""Explicit 8-wide vectors of doubles for numba kernels: a type, its arithmetic, loads, gathers, scatters.

numba has no SIMD types; LLVM's loop vectoriser decides alone what runs in vectors, and it leaves loops
it cannot prove safe or profitable scalar (the solver lab's 8-contact groups: benchmarks/JOURNAL.md,
"Coloured SIMD sweeps"). This module gives kernels LLVM's own vector type ``<8 x double>`` as a numba
type, :data:`f64x8`, and ``<8 x i1>`` as :data:`mask8`, so that a kernel can say which operations run
side by side. Each operation below emits one LLVM instruction or intrinsic on the whole vector, the
same IEEE operation in every lane as the scalar code's (no fast-math flags: nothing is contracted into
an FMA or reassociated), so a lane computes the bits the scalar code computes. LLVM lowers
``<8 x double>`` to one zmm register with AVX-512 and splits it into two ymm (AVX2) or four xmm
operations on narrower hardware: correct everywhere, wide where the machine is.

What each one emits:

- ``a + b``, ``a - b``, ``a * b``, ``a / b`` (and the in-place forms), ``-a``: ``fadd``, ``fsub``,
  ``fmul``, ``fdiv``, ``fneg`` on ``<8 x double>`` (numba's scalar float operators emit the same).
- ``a >= b``, ``a > b``, ``a <= b``, ``a < b``, ``a == b``: ``fcmp oge/ogt/ole/olt/oeq`` (ordered, as
  numba's scalar comparisons: false on NaN), ``a != b``: ``fcmp une``; each a :data:`mask8`.
- ``m & n``, ``m | n``, ``~m`` on masks: ``and``, ``or``, ``xor`` with all ones on ``<8 x i1>``.
- ``select(m, a, b)``: ``select`` (a where m, else b): the vector form of ``a if m else b``.
- ``vabs(a)``: ``llvm.fabs.v8f64`` (clears the sign bits, as scalar ``abs``).
- ``splat(x)``: ``insertelement`` + ``shufflevector`` (x in every lane).
- ``lane(a, k)``: ``extractelement``.
- ``load(arr, i)``, ``store(arr, i, a)``: a plain (unaligned) vector load / store of ``arr[i : i + 8]``
  (1-d C-contiguous float64 arrays; no bounds check: the caller keeps ``i + 8 <= arr.size``).
- ``masked_store(arr, i, a, m)``: ``llvm.masked.store.v8f64.p0``: the lanes of m only.
- ``gather(arr, idx, i, shift, m)``: ``llvm.masked.gather.v8f64.v8p0`` of ``arr[idx[i + k] + shift]``,
  k = 0 … 7, the lanes of m (0.0 elsewhere); ``idx`` a 1-d C-contiguous int64/uint64 array of offsets.
- ``scatter(arr, idx, i, shift, a, m)``: ``llvm.masked.scatter.v8f64.v8p0``: ``arr[idx[i + k] + shift] =
  a[k]`` for the lanes of m (LLVM orders overlapping lanes from first to last).
- ``gather_scalar(arr, idx, i, shift)`` / ``scatter_scalar(arr, idx, i, shift, a)``: the same for all 8
  lanes as 8 scalar loads + ``insertelement`` / ``extractelement`` + 8 scalar stores in lane
  order: on Zen 5 cheaper than the hardware instructions for 8 scattered doubles, and a scalar store
  forwards to the next scalar load of the same double.
- ``gather_rows(arr, idx, i)`` / ``scatter_rows(arr, idx, i, x, y, w)``: for arrays of 4-double rows
  (a body's velocity and one padding double at ``idx[i + k]``): 8 ``<4 x double>`` loads and a tree of
  shuffles (``shufflevector``, an 8 × 4 transpose), giving the rows' first three components as three vectors
  (x, y, w); back, three vectors transposed into 8 rows ``(x_k, y_k, w_k, 0.0)`` stored by 8 ``<4 x
  double>`` stores in lane order. A third of the memory operations of the scalar forms.
- ``mask_bits(b)`` / ``bits_of(m)``: an integer's low 8 bits as a mask (lane k = bit k) and back
  (``trunc`` / ``zext`` and ``bitcast`` between ``i8`` and ``<8 x i1>``).

Used by the default solver's first stage (:mod:`masonrycli.engine.lane_sweeps`), which the solver lab
now calls too (its "lanes+vec"; the lab prototype it came from is in the history, benchmarks/JOURNAL.md).
"""

from __future__ import annotations

import operator

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.core.datamodel import models, register_default
from numba.core.imputils import lower_builtin
from numba.core.typing.templates import AbstractTemplate, infer_global, signature
from numba.extending import intrinsic

WIDTH = 8
_D = ir.DoubleType()
_I64 = ir.IntType(64)
_V8D = ir.VectorType(_D, WIDTH)
_V8I = ir.VectorType(_I64, WIDTH)
_V8B = ir.VectorType(ir.IntType(1), WIDTH)
_PD = ir.PointerType(_D)
_V8P = ir.VectorType(_PD, WIDTH)


class F64x8(types.Type):
    def __init__(self):
        super().__init__(name="f64x8")


class Mask8(types.Type):
    def __init__(self):
        super().__init__(name="mask8")


f64x8 = F64x8()
"""numba type of an LLVM ``<8 x double>``."""
mask8 = Mask8()
"""numba type of an LLVM ``<8 x i1>`` (one flag a lane)."""


@register_default(F64x8)
class _F64x8Model(models.PrimitiveModel):
    def __init__(self, dmm, fe_type):
        super().__init__(dmm, fe_type, _V8D)


@register_default(Mask8)
class _Mask8Model(models.PrimitiveModel):
    def __init__(self, dmm, fe_type):
        super().__init__(dmm, fe_type, _V8B)


def _register_binary(ops, operand, result, emit):
    # typing (operand, operand) -> result for each operator in ops, lowered by emit(builder, a, b)
    for op in ops:

        @infer_global(op)
        class _Template(AbstractTemplate):
            def generic(self, args, kws):
                if len(args) == 2 and args[0] == operand and args[1] == operand:
                    return signature(result, operand, operand)

        @lower_builtin(op, type(operand), type(operand))
        def _lower(context, builder, sig, args):
            return emit(builder, *args)


_register_binary((operator.add, operator.iadd), f64x8, f64x8, lambda b, x, y: b.fadd(x, y))
_register_binary((operator.sub, operator.isub), f64x8, f64x8, lambda b, x, y: b.fsub(x, y))
_register_binary((operator.mul, operator.imul), f64x8, f64x8, lambda b, x, y: b.fmul(x, y))
_register_binary((operator.truediv, operator.itruediv), f64x8, f64x8, lambda b, x, y: b.fdiv(x, y))
for _op, _pred in ((operator.ge, ">="), (operator.gt, ">"), (operator.le, "<="), (operator.lt, "<"),
                   (operator.eq, "==")):  # fmt: skip
    _register_binary((_op,), f64x8, mask8, lambda b, x, y, p=_pred: b.fcmp_ordered(p, x, y))
_register_binary((operator.ne,), f64x8, mask8, lambda b, x, y: b.fcmp_unordered("!=", x, y))
_register_binary((operator.and_, operator.iand), mask8, mask8, lambda b, x, y: b.and_(x, y))
_register_binary((operator.or_, operator.ior), mask8, mask8, lambda b, x, y: b.or_(x, y))


def _register_unary(op, operand, emit):
    @infer_global(op)
    class _Template(AbstractTemplate):
        def generic(self, args, kws):
            if len(args) == 1 and args[0] == operand:
                return signature(operand, operand)

    @lower_builtin(op, type(operand))
    def _lower(context, builder, sig, args):
        return emit(builder, args[0])


_register_unary(operator.neg, f64x8, lambda b, x: b.fneg(x))
_register_unary(operator.invert, mask8, lambda b, x: b.xor(x, ir.Constant(_V8B, [1] * WIDTH)))


def _splat(builder, value, vector_type):
    one = builder.insert_element(ir.Constant(vector_type, ir.Undefined), value, ir.Constant(ir.IntType(32), 0))
    zeros = ir.Constant(ir.VectorType(ir.IntType(32), WIDTH), [0] * WIDTH)
    return builder.shuffle_vector(one, ir.Constant(vector_type, ir.Undefined), zeros)


def _as_i64(context, builder, value, ty):
    return context.cast(builder, value, ty, types.int64)


def _data(context, builder, arrty, arr):
    return context.make_array(arrty)(context, builder, arr).data


def _intrinsic(builder, name, ret, argtys, args):
    fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(ret, argtys), name)
    return builder.call(fn, args)


def _addresses(context, builder, sig, args):
    # <8 x double*> of arr.data + idx[i + k] + shift (element offsets), k = 0 … 7
    arrty, idxty, ity, shty = sig.args[:4]
    arr, idx, i, shift = args[:4]
    ip = builder.gep(_data(context, builder, idxty, idx), [_as_i64(context, builder, i, ity)])
    offsets = builder.load(builder.bitcast(ip, _V8I.as_pointer()), align=8)
    offsets = builder.add(offsets, _splat(builder, _as_i64(context, builder, shift, shty), _V8I))
    base = _splat(builder, builder.ptrtoint(_data(context, builder, arrty, arr), _I64), _V8I)
    byte = builder.add(base, builder.mul(offsets, ir.Constant(_V8I, [8] * WIDTH)))
    return builder.inttoptr(byte, _V8P)


def _vector_pointer(context, builder, arrty, arr, ity, i):
    p = builder.gep(_data(context, builder, arrty, arr), [_as_i64(context, builder, i, ity)])
    return builder.bitcast(p, _V8D.as_pointer())


def _is_f64_array(t):
    return isinstance(t, types.Array) and t.dtype == types.float64 and t.ndim == 1 and t.layout == "C"


def _is_index_array(t):
    return isinstance(t, types.Array) and t.dtype in (types.int64, types.uint64) and t.ndim == 1 and t.layout == "C"


@intrinsic
def splat(typingctx, x):
    if not isinstance(x, (types.Float, types.Integer)):
        return None

    def codegen(context, builder, sig, args):
        return _splat(builder, context.cast(builder, args[0], sig.args[0], types.float64), _V8D)

    return signature(f64x8, x), codegen


@intrinsic
def select(typingctx, m, a, b):
    if m != mask8 or a != f64x8 or b != f64x8:
        return None
    return signature(f64x8, m, a, b), lambda context, builder, sig, args: builder.select(*args)


@intrinsic
def vabs(typingctx, a):
    if a != f64x8:
        return None

    def codegen(context, builder, sig, args):
        return _intrinsic(builder, "llvm.fabs.v8f64", _V8D, [_V8D], [args[0]])

    return signature(f64x8, a), codegen


@intrinsic
def lane(typingctx, a, k):
    if a != f64x8 or not isinstance(k, types.Integer):
        return None

    def codegen(context, builder, sig, args):
        return builder.extract_element(args[0], _as_i64(context, builder, args[1], sig.args[1]))

    return signature(types.float64, a, k), codegen


@intrinsic
def load(typingctx, arr, i):
    if not _is_f64_array(arr) or not isinstance(i, types.Integer):
        return None

    def codegen(context, builder, sig, args):
        return builder.load(_vector_pointer(context, builder, sig.args[0], args[0], sig.args[1], args[1]), align=8)

    return signature(f64x8, arr, i), codegen


@intrinsic
def store(typingctx, arr, i, a):
    if not _is_f64_array(arr) or not isinstance(i, types.Integer) or a != f64x8:
        return None

    def codegen(context, builder, sig, args):
        builder.store(args[2], _vector_pointer(context, builder, sig.args[0], args[0], sig.args[1], args[1]), align=8)
        return context.get_dummy_value()

    return signature(types.none, arr, i, a), codegen


@intrinsic
def masked_store(typingctx, arr, i, a, m):
    if not _is_f64_array(arr) or not isinstance(i, types.Integer) or a != f64x8 or m != mask8:
        return None

    def codegen(context, builder, sig, args):
        p = _vector_pointer(context, builder, sig.args[0], args[0], sig.args[1], args[1])
        _intrinsic(builder, "llvm.masked.store.v8f64.p0", ir.VoidType(), [_V8D, _V8D.as_pointer(), ir.IntType(32),
                   _V8B], [args[2], p, ir.Constant(ir.IntType(32), 8), args[3]])  # fmt: skip
        return context.get_dummy_value()

    return signature(types.none, arr, i, a, m), codegen


@intrinsic
def gather(typingctx, arr, idx, i, shift, m):
    ok = _is_f64_array(arr) and _is_index_array(idx) and isinstance(i, types.Integer) and m == mask8
    if not ok or not isinstance(shift, types.Integer):
        return None

    def codegen(context, builder, sig, args):
        ptrs = _addresses(context, builder, sig, args)
        return _intrinsic(builder, "llvm.masked.gather.v8f64.v8p0", _V8D, [_V8P, ir.IntType(32), _V8B, _V8D],
                          [ptrs, ir.Constant(ir.IntType(32), 8), args[4], ir.Constant(_V8D, [0.0] * WIDTH)])  # fmt: skip

    return signature(f64x8, arr, idx, i, shift, m), codegen


@intrinsic
def scatter(typingctx, arr, idx, i, shift, a, m):
    ok = _is_f64_array(arr) and _is_index_array(idx) and isinstance(i, types.Integer) and m == mask8
    if not ok or not isinstance(shift, types.Integer) or a != f64x8:
        return None

    def codegen(context, builder, sig, args):
        ptrs = _addresses(context, builder, sig, args)
        _intrinsic(builder, "llvm.masked.scatter.v8f64.v8p0", ir.VoidType(), [_V8D, _V8P, ir.IntType(32), _V8B],
                   [args[4], ptrs, ir.Constant(ir.IntType(32), 8), args[5]])  # fmt: skip
        return context.get_dummy_value()

    return signature(types.none, arr, idx, i, shift, a, m), codegen


@intrinsic
def mask_bits(typingctx, b):
    if not isinstance(b, types.Integer):
        return None

    def codegen(context, builder, sig, args):
        byte = builder.trunc(_as_i64(context, builder, args[0], sig.args[0]), ir.IntType(8))
        return builder.bitcast(byte, _V8B)

    return signature(mask8, b), codegen


@intrinsic
def bits_of(typingctx, m):
    if m != mask8:
        return None

    def codegen(context, builder, sig, args):
        return builder.zext(builder.bitcast(args[0], ir.IntType(8)), _I64)

    return signature(types.int64, m), codegen


def _lane_pointers(context, builder, sig, args):
    # the 8 scalar double* of arr.data + idx[i + k] + shift, k = 0 … 7
    arrty, idxty, ity, shty = sig.args[:4]
    data = _data(context, builder, arrty, args[0])
    ip = builder.gep(_data(context, builder, idxty, args[1]), [_as_i64(context, builder, args[2], ity)])
    shift = _as_i64(context, builder, args[3], shty)
    out = []
    for k in range(WIDTH):
        offset = builder.load(builder.gep(ip, [ir.Constant(_I64, k)]), align=8)
        out.append(builder.gep(data, [builder.add(offset, shift)]))
    return out


@intrinsic
def gather_scalar(typingctx, arr, idx, i, shift):
    ok = _is_f64_array(arr) and _is_index_array(idx) and isinstance(i, types.Integer)
    if not ok or not isinstance(shift, types.Integer):
        return None

    def codegen(context, builder, sig, args):
        out = ir.Constant(_V8D, ir.Undefined)
        for k, p in enumerate(_lane_pointers(context, builder, sig, args)):
            out = builder.insert_element(out, builder.load(p, align=8), ir.Constant(ir.IntType(32), k))
        return out

    return signature(f64x8, arr, idx, i, shift), codegen


@intrinsic
def scatter_scalar(typingctx, arr, idx, i, shift, a):
    ok = _is_f64_array(arr) and _is_index_array(idx) and isinstance(i, types.Integer)
    if not ok or not isinstance(shift, types.Integer) or a != f64x8:
        return None

    def codegen(context, builder, sig, args):
        for k, p in enumerate(_lane_pointers(context, builder, sig, args)):
            builder.store(builder.extract_element(args[4], ir.Constant(ir.IntType(32), k)), p, align=8)
        return context.get_dummy_value()

    return signature(types.none, arr, idx, i, shift, a), codegen


def _rows_type(t):
    return isinstance(t, types.Array) and t.dtype == types.float64 and t.ndim == 1 and t.layout == "C"


_V4D = ir.VectorType(_D, 4)


def _mask(values):
    return ir.Constant(ir.VectorType(ir.IntType(32), len(values)), list(values))


@intrinsic
def gather_rows(typingctx, arr, idx, i):
    # (x, y, w): lane k = arr[idx[i + k] + 0, 1, 2], read as one 4-double row a lane (offsets 4·body)
    if not (_rows_type(arr) and _is_index_array(idx) and isinstance(i, types.Integer)):
        return None
    ret = types.UniTuple(f64x8, 3)

    def codegen(context, builder, sig, args):
        data = _data(context, builder, sig.args[0], args[0])
        ip = builder.gep(
            _data(context, builder, sig.args[1], args[1]), [_as_i64(context, builder, args[2], sig.args[2])]
        )
        rows = []
        for k in range(WIDTH):
            p = builder.gep(data, [builder.load(builder.gep(ip, [ir.Constant(_I64, k)]), align=8)])
            rows.append(builder.load(builder.bitcast(p, _V4D.as_pointer()), align=8))
        # pairs of rows side by side, then component c of each: a two-level shuffle tree (a transpose)
        pairs = [builder.shuffle_vector(rows[2 * k], rows[2 * k + 1], _mask(range(8))) for k in range(4)]
        out = []
        for c in range(3):
            lo = builder.shuffle_vector(pairs[0], pairs[1], _mask([c, 4 + c, 8 + c, 12 + c]))
            hi = builder.shuffle_vector(pairs[2], pairs[3], _mask([c, 4 + c, 8 + c, 12 + c]))
            out.append(builder.shuffle_vector(lo, hi, _mask(range(8))))
        return context.make_tuple(builder, sig.return_type, out)

    return signature(ret, arr, idx, i), codegen


@intrinsic
def scatter_rows(typingctx, arr, idx, i, x, y, w):
    # arr[idx[i + k] + 0 … 3] = (x[k], y[k], w[k], 0.0) for k = 0 … 7 in lane order: one 4-double row a lane
    ok = _rows_type(arr) and _is_index_array(idx) and isinstance(i, types.Integer)
    if not ok or x != f64x8 or y != f64x8 or w != f64x8:
        return None

    def codegen(context, builder, sig, args):
        data = _data(context, builder, sig.args[0], args[0])
        ip = builder.gep(
            _data(context, builder, sig.args[1], args[1]), [_as_i64(context, builder, args[2], sig.args[2])]
        )
        x, y, w = args[3:6]
        zero = ir.Constant(_V8D, [0.0] * WIDTH)
        # (x_k, y_k) and (w_k, 0) pairs of even and odd lanes, then each lane's row from them
        xy = [builder.shuffle_vector(x, y, _mask([j + s for j in range(0, 8, 2) for s in (0, 8)])),
              builder.shuffle_vector(x, y, _mask([j + 1 + s for j in range(0, 8, 2) for s in (0, 8)]))]  # fmt: skip
        wz = [builder.shuffle_vector(w, zero, _mask([j + s for j in range(0, 8, 2) for s in (0, 8)])),
              builder.shuffle_vector(w, zero, _mask([j + 1 + s for j in range(0, 8, 2) for s in (0, 8)]))]  # fmt: skip
        for k in range(WIDTH):
            j = 2 * (k // 2)  # lane k sits at 2·(k // 2) of its parity's pair vectors
            row = builder.shuffle_vector(xy[k % 2], wz[k % 2], _mask([j, j + 1, 8 + j, 9 + j]))
            p = builder.gep(data, [builder.load(builder.gep(ip, [ir.Constant(_I64, k)]), align=8)])
            builder.store(row, builder.bitcast(p, _V4D.as_pointer()), align=8)
        return context.get_dummy_value()

    return signature(types.none, arr, idx, i, x, y, w), codegen
