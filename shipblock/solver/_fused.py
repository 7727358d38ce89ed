"""Fused multiply-add, ``a * b + c`` with one rounding, for the rocking step's dependent chain.

The rocking step's cost is the chain of dependent operations from one Runge-Kutta stage to the
next (a short Taylor series and a dot product per stage). A fused multiply-add halves the
latency of each link of such a chain. numba leaves contraction to LLVM only under
``fastmath``, and LLVM then fuses or not depending on what it inlined where, so the same run
could round differently in :func:`~shipblock.solver.simulate` and in a batch. An explicit
``llvm.fma`` is fused everywhere, or nowhere (it falls back to the C library's exact ``fma``
on a processor without the instruction): results stay reproducible bit for bit.
"""

from __future__ import annotations

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic


@intrinsic
def fma(typingctx, a, b, c):
    """``a * b + c`` rounded once (float64)."""
    if not all(isinstance(x, types.Float) for x in (a, b, c)):
        return None
    sig = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, signature, args):
        double = ir.DoubleType()
        fn = cgutils.get_or_insert_function(builder.module,
                                            ir.FunctionType(double, [double] * 3), "llvm.fma.f64")
        return builder.call(fn, args)

    return sig, codegen
