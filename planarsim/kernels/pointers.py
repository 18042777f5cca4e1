"""Three small numba intrinsics for table_step: an int64 address as a typed pointer (to build
an array over memory a Simulator owns) and a mutable array seen as read-only (the model's
arrays are read-only in the step's signature; the memory layout is the same)."""
from numba import types
from numba.core.imputils import impl_ret_borrowed
from numba.extending import intrinsic


def _pointer_intrinsic(dtype):
    @intrinsic
    def as_ptr(typingctx, address):
        if not isinstance(address, types.Integer):
            return None
        ptr_type = types.CPointer(dtype)

        def codegen(context, builder, signature, args):
            return builder.inttoptr(args[0], context.get_value_type(ptr_type))
        return ptr_type(address), codegen
    return as_ptr


as_float_ptr = _pointer_intrinsic(types.float64)
as_int_ptr = _pointer_intrinsic(types.int64)


@intrinsic
def readonly(typingctx, array):
    """The same array typed read-only (no copy)."""
    if not isinstance(array, types.Array):
        return None
    result = array.copy(readonly=True)

    def codegen(context, builder, signature, args):
        return impl_ret_borrowed(context, builder, signature.return_type, args[0])
    return result(array), codegen
