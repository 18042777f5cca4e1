"""Named slots of a walker's float64 arrays (its parameter table, its controller's memory),
declared once.

``slots(name, fields)`` takes the fields in order, each a name or (name, doc) or (name, size,
doc), and returns a NamedTuple of their first indices: a field's index follows from the
declaration, so two fields cannot share a slot and nothing is numbered by hand. Compiled code
reads ``mem[MEM.gait]`` or ``mem[MEM.target + 2 * leg]``: numba takes a global NamedTuple of
ints as a compile-time constant, so this is the same machine code as a written-out number.

>>> MEM = slots("Memory", ("gait", ("stance", "stance foot"), ("target", 4, "x, y of two feet")))
>>> MEM.target, size(MEM)
(2, 6)
"""
from __future__ import annotations

from collections import namedtuple
from dataclasses import fields as dataclass_fields

import numpy as np


def slots(name: str, fields) -> tuple:
    """NamedTuple `name` of the first index of each field (see the module's docstring); its
    type carries SIZES (slots per field), DOCS and SIZE (slots in all)."""
    names, sizes, docs = [], [], []
    for f in fields:
        f = (f,) if isinstance(f, str) else tuple(f)
        n, k, doc = (f[0], 1, "") if len(f) == 1 else (f[0], 1, f[1]) if len(f) == 2 else f
        if not (isinstance(k, int) and k >= 1):
            raise ValueError(f"{name}.{n}: size {k!r} must be a whole number >= 1")
        names.append(n)
        sizes.append(k)
        docs.append(doc)
    if len(set(names)) != len(names):
        raise ValueError(f"{name}: a field is declared twice in {names}")
    cls = namedtuple(name, names)
    cls.SIZES = dict(zip(names, sizes))
    cls.DOCS = dict(zip(names, docs))
    cls.SIZE = int(sum(sizes))
    return cls(*np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(int).tolist())


def size(layout) -> int:
    """Slots of all the fields of `layout` (the length of the array it names)."""
    return type(layout).SIZE


def param_slots(params_cls) -> tuple:
    """The slots of a WalkerParams dataclass's to_array() (its fields in declaration order)."""
    return slots(f"{params_cls.__name__}Slots", [f.name for f in dataclass_fields(params_cls)])


def read(array, layout, names=None) -> dict:
    """{field: value} of one-slot fields of `layout` in `array` (all of them, or `names`)."""
    sizes = type(layout).SIZES
    names = [n for n in layout._fields if sizes[n] == 1] if names is None else names
    return {n: array[getattr(layout, n)] for n in names}


def label_slots(layout, names) -> np.ndarray:
    """int64 slots of `names` in `layout`, for a walker's LABELS (per-frame copies of its
    memory): a name is a one-slot field, or "field:k" for slot k of a longer one."""
    out = []
    for name in names:
        field, _, k = name.partition(":")
        k = int(k) if k else 0
        if not 0 <= k < type(layout).SIZES[field]:
            raise ValueError(f"{name}: {field} has {type(layout).SIZES[field]} slot(s)")
        out.append(getattr(layout, field) + k)
    return np.array(out, dtype=np.int64)
