"""What every walker's parameter dataclass shares: fields with unit, doc and bounds, the
bounds check on construction, the float64 vector the compiled controller reads, and the
``I_<FIELD>`` index constants generated from the field order.

>>> @dataclass(frozen=True)                                          # doctest: +SKIP
... class MyParams(WalkerParams):
...     hip_mass: float = param(10.0, "kg", "hip point mass", 0.1, 1e3)
>>> globals().update(index_constants(MyParams))   # I_HIP_MASS = 0, N_PARAMS = 1
"""
from __future__ import annotations

import math
from dataclasses import asdict, field, fields

import numpy as np


def param(default, unit, doc, lo, hi, **extra):
    """A dataclass field with metadata unit, doc, bounds (lo, hi) and any `extra` keys."""
    return field(default=default, metadata=dict(unit=unit, doc=doc, bounds=(lo, hi), **extra))


class WalkerParams:
    """Mixin for frozen parameter dataclasses (fields made with ``param``)."""

    def __post_init__(self):
        cls = type(self).__name__
        for f in fields(self):
            value = getattr(self, f.name)
            lo, hi = f.metadata["bounds"]
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ValueError(f"{cls}.{f.name}={value!r} must be a finite number in [{lo}, {hi}] "
                                 f"({f.metadata['unit']}: {f.metadata['doc']})")
            if not lo <= value <= hi:
                raise ValueError(f"{cls}.{f.name}={value!r} outside its bounds [{lo}, {hi}] "
                                 f"({f.metadata['unit']}: {f.metadata['doc']})")

    def to_array(self) -> np.ndarray:
        """Every field as float64 in declaration order (index with the I_<FIELD> constants)."""
        return np.array([float(getattr(self, f.name)) for f in fields(self)])

    def as_dict(self) -> dict:
        return asdict(self)

    def replace(self, **kw):
        """A copy with some fields changed (an unknown name is an error naming it)."""
        d = asdict(self)
        unknown = set(kw) - set(d)
        if unknown:
            raise ValueError(f"{type(self).__name__} has no field(s) {sorted(unknown)}")
        d.update(kw)
        return type(self)(**d)

    @classmethod
    def describe(cls) -> str:
        """One line per field: name, default, unit, doc."""
        return "\n".join(f"{f.name:22s} {f.default!s:>9} {f.metadata['unit']:10s} {f.metadata['doc']}"
                         for f in fields(cls))


def index_constants(cls) -> dict:
    """{"I_<FIELD>": index, ..., "N_PARAMS": count} for a module's globals: compile-time
    constants for the controller, generated from the field order so the two never disagree."""
    names = [f.name for f in fields(cls)]
    out = {f"I_{name.upper()}": i for i, name in enumerate(names)}
    out["N_PARAMS"] = len(names)
    return out
