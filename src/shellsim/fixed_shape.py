"""Arrays whose trailing axes have lengths known when the kernel is compiled.

numba addresses a C-contiguous array through lengths it reads at run time, so in a loop
over a group's lanes LLVM cannot tell how far apart two rows of one work array are
(``q[0, 0, lane]`` and ``q[1, 0, lane]``): it must assume that a store to one may overlap
a later load of the other and leaves the loop scalar. Viewed with its trailing lengths
constant (``(3, 3, LANES)``), each row lies a known number of bytes from the next, the
loop is vectorised over the lanes, and each lane still does the same arithmetic in the
same order (the same bits).
"""

from __future__ import annotations

from numba import types
from numba.core import cgutils
from numba.extending import intrinsic
from numba.np.arrayobj import make_array, populate_array


@intrinsic(prefer_literal=True)
def fixed_trailing(typingctx, array, trailing):
    """``array`` (..., *trailing), its trailing axes contiguous in C order, as a view whose
    trailing axes have the lengths of the literal tuple ``trailing`` (and the strides they
    give) in the compiled code; the leading axes keep their run-time lengths and strides.
    Raises ValueError when the array's trailing lengths or strides differ. The view does
    not own its data (no reference is counted): it must not outlive ``array`` (use it
    within the function that made it)."""
    if not (isinstance(array, types.Array) and isinstance(trailing, types.BaseTuple)
            and all(isinstance(n, types.IntegerLiteral) for n in trailing) and len(trailing) <= array.ndim):
        return None
    lengths = [n.literal_value for n in trailing]

    def codegen(context, builder, signature, args):
        aryty = signature.args[0]
        source = make_array(aryty)(context, builder, args[0])
        view = make_array(aryty)(context, builder)
        shape = cgutils.unpack_tuple(builder, source.shape, aryty.ndim)
        strides = cgutils.unpack_tuple(builder, source.strides, aryty.ndim)
        intp = context.get_value_type(types.intp)
        step = context.get_abi_sizeof(context.get_data_type(aryty.dtype))
        first = aryty.ndim - len(lengths)
        for axis in range(aryty.ndim - 1, first - 1, -1):
            length = lengths[axis - first]
            differs = builder.or_(builder.icmp_signed("!=", shape[axis], intp(length)),
                                  builder.icmp_signed("!=", strides[axis], intp(step)))
            with cgutils.if_unlikely(builder, differs):
                message = f"trailing axes are not {tuple(lengths)}, contiguous"
                context.call_conv.return_user_exc(builder, ValueError, (message,))
            shape[axis], strides[axis] = intp(length), intp(step)
            step *= length
        populate_array(view, data=source.data, shape=shape, strides=strides, itemsize=source.itemsize,
                       meminfo=None, parent=None)
        return view._getvalue()

    return array(array, trailing), codegen
