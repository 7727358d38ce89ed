"""A shared counter from which parallel workers claim the next case (dynamic scheduling).

numba's ``prange`` deals the iterations out in one contiguous block per thread before the
loop starts. Simulation costs differ by orders of magnitude between cases (a run that fails
in its first second against one that rocks through the whole record), so a fixed deal leaves
threads idle while one finishes the heavy block. Workers that each claim the next unclaimed
case keep every thread busy until the list is empty (the batch's workers are Python threads
running :func:`~shipblock.solver._kernel.run_cases`, see :mod:`shipblock.solver._threads`).
numba has no atomic operations on the CPU, so the claim is one LLVM ``atomicrmw add`` emitted
by an intrinsic.
"""

from __future__ import annotations

from numba import types
from numba.core import cgutils
from numba.extending import intrinsic


@intrinsic
def claim_next(typingctx, counter):
    """Atomically increment ``counter[0]`` (int64 array) and return its previous value.

    Each value is returned to exactly one caller, whatever the number of threads calling.
    Allocate ``counter`` outside the compiled function that runs the parallel loop: numba
    does not know the intrinsic writes it and may take a locally allocated array's later
    reads for its initial zeros.
    """
    if not (isinstance(counter, types.Array) and counter.dtype == types.int64):
        return None
    sig = types.int64(counter)

    def codegen(context, builder, signature, args):
        array = context.make_array(signature.args[0])(context, builder, args[0])
        first = cgutils.gep_inbounds(builder, array.data, 0)
        one = context.get_constant(types.int64, 1)
        # monotonic ordering suffices: each value is handed out once, and the results the
        # workers write are published by the join that ends the batch (the threads' join, or
        # a parallel region's barrier)
        return builder.atomic_rmw("add", first, one, "monotonic")

    return sig, codegen
