"""A numba intrinsic that writes a row of a loop's output as one vector store.

Imported only by the generated loop modules (:mod:`.numba_backend`), on the
background thread, so that ``import rigidkit`` does not import numba.

Why: numba lowers ``o[i, c] = v`` to one scalar store per component, and LLVM's
vectorisers do not merge them. A 4x4 homogeneous matrix is 16 scalar stores per
element, which made SE(3) ``as_matrix`` slower than scipy's plain copy of stored
matrices at N = 1e3-1e4 (1.3x). Storing each 4-wide row as one ``<4 x double>``
(LLVM emits two 16-byte or one 32-byte store) cut the loop by ~10% there; a loop
that only stores constant rows this way is faster than a memcpy of the same bytes.
"""

from __future__ import annotations

from llvmlite import ir
from numba import types
from numba.extending import intrinsic

#: Part of the generated modules' source (see numba_backend.module_source): a
#: change to the code generated here must change it, so that numba's disk cache,
#: keyed by the module's source, never serves a loop built by an older version.
VERSION = 1


@intrinsic
def store_row(typingctx, arr, start, row):
    """``arr[start:start + len(row)] = row`` as one vector store (unchecked).

    ``arr``: a C-contiguous 1-D float array; ``row``: a tuple of numbers (a
    kernel's results, its constants float64 in a float32 loop: each is cast to
    the array's dtype). No bounds check: the generated loop's indices are in range
    by construction. The store is unaligned (element alignment only).
    """
    if not (
        isinstance(arr, types.Array)
        and arr.ndim == 1
        and arr.layout == "C"
        and arr.mutable
        and isinstance(arr.dtype, types.Float)
        and isinstance(start, types.Integer)
        and isinstance(row, types.BaseTuple)
        and all(isinstance(t, (types.Float, types.Integer)) for t in row)
    ):
        return None
    sig = types.void(arr, start, row)

    def codegen(context, builder, signature, args):
        aty, sty, rty = signature.args
        a, s, r = args
        data = context.make_array(aty)(context, builder, a).data
        elem = context.get_value_type(aty.dtype)
        vecty = ir.VectorType(elem, len(rty))
        vec = ir.Constant(vecty, ir.Undefined)
        for j, t in enumerate(rty):
            v = context.cast(builder, builder.extract_value(r, j), t, aty.dtype)
            vec = builder.insert_element(vec, v, ir.Constant(ir.IntType(32), j))
        s = context.cast(builder, s, sty, types.intp)
        ptr = builder.bitcast(builder.gep(data, [s]), vecty.as_pointer())
        builder.store(vec, ptr, align=context.get_abi_sizeof(elem))
        return context.get_dummy_value()

    return sig, codegen
