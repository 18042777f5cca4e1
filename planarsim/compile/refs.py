"""NamedTuples of arrays reach compiled code as one pointer each (the engine's model, state,
workspace and options: planarsim/link/engine.py registers them).

numba passes a NamedTuple of arrays to a compiled function field by field: every array is a
struct of 7-9 machine words, so a call with the model, state and workspace (about 80 arrays)
passes some 600 arguments. That made every call between kernels cost 0.3-0.4 us and made the
step's code so large that its first-ever compile took most of a minute.

Here a NamedTuple registered with ``register`` is typed as a ``TableRef``: a pointer to an int64
table holding, for each field in order, the address and shape of an array (4 slots), a scalar
(1 slot, float64 stored as its bits) or an embedded table (a nested registered NamedTuple such
as ``Workspace.prev``). ``ref.field`` in compiled code reads the table and rebuilds the array
(no copy: the same memory). The table never changes while compiled code runs, so its loads
carry LLVM's ``invariant.load``: they are hoisted out of loops and shared like local variables.

A NamedTuple passed from Python is packed on its first call (a few microseconds per array)
and its table kept, keyed by the object's identity: a NamedTuple cannot change its fields, so
its table stays right while the cache holds it (the newest _CACHE_SIZE objects). A
``TableHandle`` is unboxed without any Python call (the Simulator's step). Arrays must be
C-contiguous float64 or int64 (writeable unless the class is registered read-only), which
``pack`` checks, naming the field; the dtypes and ndims make the compiled type.
"""
from __future__ import annotations

import hashlib
import threading

import numpy as np
from llvmlite import ir
from numba.core import cgutils, types
from numba.core.imputils import impl_ret_borrowed
from numba.core.typing.templates import AttributeTemplate
from numba.extending import (NativeValue, infer_getattr, intrinsic, lower_getattr_generic, models,
                             register_model, typeof_impl, unbox)

SLOTS_PER_ARRAY = 4  # address, shape[0], shape[1], shape[2]
_DTYPES = {"float64": types.float64, "int64": types.int64}
# the names of those dtypes by dtype (numpy's dtype.name is built afresh on every read: a
# workspace of hundreds of arrays spent milliseconds there each time a state was put in)
_DTYPE_NAMES = {np.dtype(name): name for name in _DTYPES}


def _dtype_name(value):
    """The name of ndarray `value`'s dtype if compiled code takes it ("float64" or "int64"),
    else its own name."""
    name = _DTYPE_NAMES.get(value.dtype)
    return value.dtype.name if name is None else name


class Layout:
    """Where each field of a registered NamedTuple lives in its table.

    fields: ((name, kind, dtype, ndim, readonly, offset, sub_layout), ...) with kind 'array',
    'float', 'int' or 'ref' (an embedded table of sub_layout); size: slots in the table.
    """

    def __init__(self, cls_name, fields, size):
        self.cls_name = cls_name
        self.fields = fields
        self.size = size
        self.by_name = {f[0]: f for f in fields}
        text = repr((cls_name, tuple(f[:6] + ((f[6].key,) if f[6] else (),) for f in fields)))
        self.key = f"{cls_name}_{hashlib.blake2b(text.encode(), digest_size=6).hexdigest()}"

    def __reduce__(self):
        return (Layout, (self.cls_name, self.fields, self.size))


class TableRef(types.Type):
    """numba type of a registered NamedTuple in compiled code: a pointer to its table."""

    def __init__(self, layout):
        self.layout = layout
        super().__init__(name=f"TableRef[{layout.key}]")

    def field_type(self, name):
        f = self.layout.by_name.get(name)
        if f is None:
            return None
        _, kind, dtype, ndim, readonly, _, sub = f
        if kind == "array":
            return types.Array(_DTYPES[dtype], ndim, "C", readonly=readonly)
        if kind == "float":
            return types.float64
        if kind == "int":
            return types.int64
        return TableRef(sub)


register_model(TableRef)(models.OpaqueModel)

_REGISTERED = {}   # NamedTuple class -> {"readonly": bool, "layouts": {signature: Layout}}


def _scalar_kind(cls, name, value):
    """'float' or 'int' for a scalar field, from its annotation (a float field given an int
    stays a float, so that the compiled types do not depend on how a value was written)."""
    note = getattr(cls, "__annotations__", {}).get(name, "")
    note = getattr(note, "__name__", str(note))   # the class float, or the string 'float'
    if note in ("float", "int"):
        return note
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"{cls.__name__}.{name} is {type(value).__name__}; compiled code takes "
                        "arrays, floats and ints")
    return "float" if isinstance(value, (float, np.floating)) else "int"


def layout_of(obj) -> Layout:
    """The Layout of registered NamedTuple `obj` (from its fields' dtypes and ndims; arrays are
    read-only in compiled code when the class was registered read-only)."""
    cls = type(obj)
    spec = _REGISTERED[cls]
    fields = []
    offset = 0
    for name in cls._fields:
        value = getattr(obj, name)
        if isinstance(value, np.ndarray):
            dtype = _dtype_name(value)
            if dtype not in _DTYPES or value.ndim > 3:
                raise TypeError(f"{cls.__name__}.{name} is a {value.ndim}-d {value.dtype} array; "
                                "compiled code takes float64 or int64 arrays of at most 3 dimensions")
            fields.append((name, "array", dtype, value.ndim, spec["readonly"], offset, None))
            offset += SLOTS_PER_ARRAY
        elif type(value) in _REGISTERED:
            sub = layout_of(value)
            fields.append((name, "ref", None, 0, False, offset, sub))
            offset += sub.size
        else:
            fields.append((name, _scalar_kind(cls, name, value), None, 0, False, offset, None))
            offset += 1
    key = tuple(f[1:5] + ((f[6].key,) if f[6] else ()) for f in fields)
    layout = spec["layouts"].get(key)
    if layout is None:
        layout = spec["layouts"][key] = Layout(cls.__name__, tuple(fields), offset)
    return layout


def fill(obj, layout, table, base):
    """Write NamedTuple `obj`'s fields into `table` from slot `base` (its layout's order)."""
    for name, kind, dtype, ndim, readonly, offset, sub in layout.fields:
        value = getattr(obj, name)
        k = base + offset
        if kind == "array":
            if (not isinstance(value, np.ndarray) or _dtype_name(value) != dtype
                    or value.ndim != ndim or not value.flags.c_contiguous):
                raise TypeError(f"{type(obj).__name__}.{name} must be a C-contiguous {ndim}-d {dtype} "
                                f"array, got {_describe(value)}")
            if not readonly and not value.flags.writeable:
                raise TypeError(f"{type(obj).__name__}.{name} is read-only; compiled code writes it")
            table[k] = value.ctypes.data
            table[k + 1:k + 1 + ndim] = value.shape
        elif kind == "ref":
            fill(value, sub, table, k)
        elif kind == "float":
            if not isinstance(value, (int, float, np.integer, np.floating)):
                raise TypeError(f"{type(obj).__name__}.{name} must be a float, got {value!r}")
            table[k] = np.float64(value).view(np.int64)
        else:
            if not isinstance(value, (int, np.integer)):
                raise TypeError(f"{type(obj).__name__}.{name} must be an int, got {value!r}")
            table[k] = int(value)


def _describe(value):
    if isinstance(value, np.ndarray):
        return f"{value.ndim}-d {value.dtype} (C-contiguous: {value.flags.c_contiguous})"
    return type(value).__name__


def pack(obj, layout=None) -> np.ndarray:
    """The int64 table of registered NamedTuple `obj` (valid while its arrays live)."""
    layout = layout_of(obj) if layout is None else layout
    table = np.zeros(max(layout.size, 1), np.int64)
    fill(obj, layout, table, 0)
    return table


# NamedTuples packed for calls from Python, by identity. A NamedTuple cannot change (its arrays
# and scalars are fixed when it is made), so its table stays right while the entry holds it
# alive; the oldest entries are dropped beyond _CACHE_SIZE (a call in progress holds its own
# reference to its table).
_CACHE = {}
_CACHE_SIZE = 128
_CACHE_LOCK = threading.Lock()


def _entry(obj):
    hit = _CACHE.get(id(obj))
    if hit is not None and hit[0] is obj:
        return hit
    layout = layout_of(obj)
    hit = (obj, TableRef(layout), pack(obj, layout))
    with _CACHE_LOCK:   # batch threads pack concurrently; eviction iterates the dict
        _CACHE[id(obj)] = hit
        while len(_CACHE) > _CACHE_SIZE:
            _CACHE.pop(next(iter(_CACHE)), None)
    return hit


def _table_of(obj):
    """Called by the unboxing code of a TableRef argument: the table of NamedTuple `obj`."""
    return _entry(obj)[2]


def register(cls=None, *, readonly=False):
    """Type NamedTuple class `cls` as a TableRef in compiled code (returns cls). readonly: its
    arrays are read-only there (the model); otherwise compiled code may write them and they
    must be writeable. Use as ``@register`` or ``@register(readonly=True)``."""
    if cls is None:
        return lambda c: register(c, readonly=readonly)
    _REGISTERED.setdefault(cls, {"readonly": readonly, "layouts": {}})

    @typeof_impl.register(cls)
    def _typeof(val, c):
        return _entry(val)[1]
    return cls


class HandleType(TableRef):
    """numba type of a TableHandle: the same pointer as a TableRef, unboxed without a Python
    call (the handle's table attribute is read directly)."""

    def __init__(self, layout):
        self.layout = layout
        types.Type.__init__(self, name=f"TableHandle[{layout.key}]")


register_model(HandleType)(models.OpaqueModel)


class TableHandle:
    """Registered NamedTuple `obj` with its table packed once, for code that calls compiled
    functions often from Python (Simulator.step): unboxing it is one attribute read. Compiled
    code reads its fields like the NamedTuple's. Call ``repack(obj)`` to point it elsewhere."""

    __slots__ = ("obj", "layout", "table", "numba_type")

    def __init__(self, obj):
        self.repack(obj)

    def repack(self, obj):
        self.obj = obj
        self.layout = layout_of(obj)
        self.table = pack(obj, self.layout)
        self.numba_type = HandleType(self.layout)

    def refill(self, obj, name):
        """Rewrite only field `name`'s slots from `obj` (of the same layout): a new StepOptions
        costs a few slots, not the whole table."""
        field = self.layout.by_name[name]
        fill(getattr(obj, name), field[6], self.table, field[5])
        self.obj = obj


@typeof_impl.register(TableHandle)
def _typeof_handle(val, c):
    return val.numba_type


def _unbox_table(c, table):
    """NativeValue of the data pointer of int64 array object `table` (a new reference,
    released after the call; NULL: error set)."""
    failed = cgutils.is_null(c.builder, table)
    ptr = cgutils.alloca_once_value(c.builder, cgutils.voidptr_t(None))
    with c.builder.if_then(c.builder.not_(failed), likely=True):
        arrty = types.Array(types.int64, 1, "C")
        native = c.unbox(arrty, table)
        ary = c.context.make_array(arrty)(c.context, c.builder, value=native.value)
        c.builder.store(c.builder.bitcast(ary.data, cgutils.voidptr_t), ptr)

    def cleanup():
        c.pyapi.decref(table)
    return NativeValue(c.builder.load(ptr), is_error=failed, cleanup=cleanup)


@unbox(TableRef)
def _unbox_ref(typ, obj, c):
    """The table's address; the table (a new reference) is released after the call."""
    fn = c.pyapi.unserialize(c.pyapi.serialize_object(_table_of))
    table = c.pyapi.call_function_objargs(fn, [obj])
    c.pyapi.decref(fn)
    return _unbox_table(c, table)


@unbox(HandleType)
def _unbox_handle(typ, obj, c):
    return _unbox_table(c, c.pyapi.object_getattr_string(obj, "table"))


@infer_getattr
class _TableRefAttributes(AttributeTemplate):
    key = TableRef

    def generic_resolve(self, typ, attr):
        return typ.field_type(attr)


@infer_getattr
class _HandleAttributes(_TableRefAttributes):
    key = HandleType


_ITEMSIZE = {}


def _itemsize(context, dtype):
    """Bytes per item of dtype (LLVM's ABI size, asked once per dtype: each question builds
    and parses a small LLVM module)."""
    size = _ITEMSIZE.get(dtype)
    if size is None:
        size = _ITEMSIZE[dtype] = context.get_abi_sizeof(context.get_data_type(dtype))
    return size


def _c_array(context, builder, arrty, data, shape):
    """Array value of C-contiguous type arrty over pointer `data` with the given shape (LLVM
    i64 values): strides follow from the shape, no memory is owned (null meminfo and parent).

    The struct value is built with insertvalue. numba's own populate_array builds it in stack
    memory field by field with checks, which made this function about 2 s of the first-ever
    compile (it runs for every field read of the model, state and workspace); both give the
    same struct, so LLVM's optimised code is the same."""
    i64 = ir.IntType(64)
    itemsize = _itemsize(context, arrty.dtype)
    strides = [ir.Constant(i64, itemsize)]
    for d in range(len(shape) - 1, 0, -1):
        strides.insert(0, builder.mul(strides[0], shape[d]))
    nitems = shape[0]
    for d in shape[1:]:
        nitems = builder.mul(nitems, d)
    model = context.data_model_manager[arrty]
    value = ir.Constant(model.get_value_type(), None)     # meminfo and parent null
    for name, field in (("nitems", nitems), ("itemsize", ir.Constant(i64, itemsize)),
                        ("data", data), ("shape", cgutils.pack_array(builder, shape, i64)),
                        ("strides", cgutils.pack_array(builder, strides, i64))):
        value = builder.insert_value(value, field, model.get_field_position(name))
    return value


def _load_slot(builder, base, k):
    ptr = builder.gep(base, [ir.Constant(ir.IntType(64), k)])
    value = builder.load(ptr)
    value.set_metadata("invariant.load", builder.module.add_metadata([]))
    return value


@lower_getattr_generic(HandleType)
@lower_getattr_generic(TableRef)
def _getattr(context, builder, typ, value, attr):
    name, kind, dtype, ndim, readonly, offset, sub = typ.layout.by_name[attr]
    i64 = ir.IntType(64)
    base = builder.bitcast(value, i64.as_pointer())
    if kind == "float":
        return builder.bitcast(_load_slot(builder, base, offset), ir.DoubleType())
    if kind == "int":
        return _load_slot(builder, base, offset)
    if kind == "ref":
        return builder.bitcast(builder.gep(base, [ir.Constant(i64, offset)]), cgutils.voidptr_t)
    arrty = typ.field_type(attr)
    data = builder.inttoptr(_load_slot(builder, base, offset),
                            context.get_data_type(arrty.dtype).as_pointer())
    shape = [_load_slot(builder, base, offset + 1 + d) for d in range(ndim)]
    ary = _c_array(context, builder, arrty, data, shape)
    return impl_ret_borrowed(context, builder, arrty, ary)


@intrinsic
def array_1d(typingctx, data, n):
    """The float64 array of n items at pointer `data` (no copy, owns nothing)."""
    if not (isinstance(data, types.CPointer) and data.dtype == types.float64
            and isinstance(n, types.Integer)):
        return None
    arrty = types.Array(types.float64, 1, "C")

    def codegen(context, builder, signature, args):
        return _c_array(context, builder, arrty, args[0], [args[1]])
    return arrty(data, n), codegen
