"""Software prefetch of a particle's row for the pair loops of large samples.

A pair loop reads particle i's rows in order (the hardware prefetcher follows them) and particle
j's rows wherever j's neighbours lie in memory. Once the particle and pair arrays outgrow the
caches, the loop waits on those reads; asking for j's rows of the pair ``PREFETCH_AHEAD``
pairs further on hides most of that wait (LLVM's ``llvm.prefetch``, a hint with no effect on
results). Below ``PREFETCH_MIN_PAIRS`` the rows are in cache already and the hint costs more
than it saves.

It pays from about 30,000 spheres (docs/performance.md, "Measurements behind design
choices"); the same hint in the contact gather paid only at 100,000 spheres and is not used.
The pair loops also ask for j's radius (an item of a 1-D array).
"""

import llvmlite.binding
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

#: How many pairs ahead the pair loop asks for particle j's rows.
PREFETCH_AHEAD = 16

#: Fewest pairs for which the pair loop prefetches (a 10,000-sphere sample holds about
#: 37,000 candidate pairs, a 30,000-sphere one about 115,000).
PREFETCH_MIN_PAIRS = 80_000

# the intrinsic's name carries its pointer type: i8* before LLVM 15, an opaque ptr since
_PREFETCH_NAME = ("llvm.prefetch.p0" if llvmlite.binding.llvm_version_info >= (15,)
                  else "llvm.prefetch.p0i8")


@intrinsic
def prefetch_row(typingctx, array, row):
    """Ask the cache for the start of ``array[row]`` (a 2-D C-contiguous array's row: 24 bytes
    of float64 triples lie in one or two cache lines; a 1-D array's item), for reading, kept in
    all cache levels."""
    def codegen(context, builder, signature, args):
        array_type = signature.args[0]
        data = context.make_array(array_type)(context, builder, args[0])
        zero = context.get_constant(types.intp, 0)
        index = [args[1], zero][:array_type.ndim]
        pointer = cgutils.get_item_pointer(context, builder, array_type, data, index)
        byte_pointer = ir.IntType(8).as_pointer()
        int32 = ir.IntType(32)
        function = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(ir.VoidType(), [byte_pointer, int32, int32, int32]),
            _PREFETCH_NAME)
        builder.call(function, [builder.bitcast(pointer, byte_pointer), ir.Constant(int32, 0),
                                ir.Constant(int32, 3), ir.Constant(int32, 1)])
        return context.get_dummy_value()

    if not (isinstance(array, types.Array) and array.ndim in (1, 2)
            and isinstance(row, types.Integer)):
        return None
    return types.void(array, row), codegen


def prefetch_distance(pair_count):
    """How far ahead a pair loop over ``pair_count`` pairs prefetches (0: not at all)."""
    return PREFETCH_AHEAD if pair_count >= PREFETCH_MIN_PAIRS else 0

