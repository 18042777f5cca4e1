"""What every walker's parameter dataclass shares: fields with unit, doc and bounds, the
bounds check on construction and the float64 vector the compiled controller reads, by
name through walkers.common.slots.param_slots.

>>> @dataclass(frozen=True)                                          # doctest: +SKIP
... class MyParams(WalkerParams):
...     hip_mass: float = param(10.0, "kg", "hip point mass", 0.1, 1e3)
>>> FIELD = param_slots(MyParams)   # doctest: +SKIP   compiled code reads p[FIELD.hip_mass]
"""
from __future__ import annotations

import json
import math
from dataclasses import asdict, field, fields
from pathlib import Path
from typing import ClassVar

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
            if _is_int_field(f) and value != int(value):
                raise ValueError(f"{cls}.{f.name}={value!r} must be a whole number "
                                 f"({f.metadata['unit']}: {f.metadata['doc']})")
            if _is_int_field(f) and not isinstance(value, int):
                object.__setattr__(self, f.name, int(value))

    def to_array(self) -> np.ndarray:
        """Every field as float64 in declaration order (read by name: slots.param_slots)."""
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

    # tuning: a field is tunable when made with param(..., tune=True) or named in TUNABLE
    TUNABLE: ClassVar[tuple] = ()

    @classmethod
    def _tunable(cls, f) -> bool:
        return bool(f.metadata.get("tune", False)) or f.name in cls.TUNABLE

    @classmethod
    def names(cls, tunable_only=False) -> tuple:
        """Field names in declaration order (only the tunable ones with tunable_only)."""
        return tuple(f.name for f in fields(cls) if not tunable_only or cls._tunable(f))

    @classmethod
    def bounds(cls, tunable_only=False) -> np.ndarray:
        """(n, 2) lower and upper bounds of the (tunable) fields."""
        return np.array([f.metadata["bounds"] for f in fields(cls)
                         if not tunable_only or cls._tunable(f)], dtype=np.float64).reshape(-1, 2)

    def tunable_array(self) -> np.ndarray:
        """The tunable fields' values as float64 (the order of names(True))."""
        return np.array([getattr(self, n) for n in self.names(True)], dtype=np.float64)

    def with_tunable(self, x):
        """A copy with the tunable fields set from vector x (clipped to their bounds)."""
        b = self.bounds(True)
        x = np.clip(np.asarray(x, dtype=np.float64), b[:, 0], b[:, 1])
        return self.replace(**{n: float(v) for n, v in zip(self.names(True), x)})

    @classmethod
    def table(cls) -> list:
        """One dict per field: name, default, unit, lower and upper bound, tunable, doc."""
        return [dict(name=f.name, default=f.default, unit=f.metadata["unit"],
                     lower=f.metadata["bounds"][0], upper=f.metadata["bounds"][1],
                     tunable=cls._tunable(f), doc=f.metadata["doc"]) for f in fields(cls)]

    @classmethod
    def describe(cls) -> str:
        """One line per field: name, default, unit, doc."""
        return "\n".join(f"{f.name:22s} {f.default!s:>9} {f.metadata['unit']:10s} {f.metadata['doc']}"
                         for f in fields(cls))


def _is_int_field(f) -> bool:
    """A field declared `int` (a count, say the rimless wheel's spokes)."""
    return f.type in (int, "int")


def _typed(cls, name, value):
    """value as the field's type: an int field takes whole numbers only."""
    f = next(f for f in fields(cls) if f.name == name)
    if _is_int_field(f):
        if value != int(value):
            raise ValueError(f"{name}={value!r} must be a whole number ({f.metadata['doc']})")
        return int(value)
    return float(value)


def parse_assignments(items, cls) -> dict:
    """{name: value} from command-line items "name=value" for params class `cls` (an unknown
    name or a value that is not a number is a ValueError naming it and the known names)."""
    known = set(cls.names())
    out = {}
    for item in items:
        name, sep, text = str(item).partition("=")
        name = name.strip()
        if not sep or not name:
            raise ValueError(f"--set {item!r}: write NAME=VALUE (see 'planarsim params WALKER')")
        if name not in known:
            raise ValueError(f"--set {item!r}: {cls.__name__} has no parameter {name!r} "
                             f"(see 'planarsim params WALKER' for the {len(known)} names)")
        try:
            value = float(text)
        except ValueError:
            raise ValueError(f"--set {item!r}: {text!r} is not a number") from None
        if not math.isfinite(value):
            raise ValueError(f"--set {item!r}: {text!r} is not a finite number")
        try:
            out[name] = _typed(cls, name, value)
        except ValueError as e:
            raise ValueError(f"--set {item!r}: {e}") from None
    return out


def load_values(path, cls) -> dict:
    """{name: value} of params class `cls` from a JSON file: a tuning result (planarsim tune
    --out; its best parameters) or an object of parameter names and numbers. Errors name the
    file and the culprit."""
    path = Path(path)
    try:
        data = json.loads(path.read_text())
        if isinstance(data, dict):
            data = {k: v for k, v in data.items() if not k.startswith("_")}   # "_about" notes
    except OSError as e:
        raise ValueError(f"--params {path}: cannot read it ({e.strerror or e})") from None
    except json.JSONDecodeError as e:
        raise ValueError(f"--params {path}: not valid JSON ({e})") from None
    if isinstance(data, dict) and isinstance(data.get("best_params"), dict):
        data = data["best_params"]
    if not isinstance(data, dict):
        raise ValueError(f"--params {path}: expected an object of parameter names and numbers "
                         "or a tuning result")
    known = set(cls.names())
    unknown = sorted(set(data) - known)
    if unknown:
        raise ValueError(f"--params {path}: {cls.__name__} has no parameter(s) {unknown} "
                         "(a file for another walker?)")
    for name, value in data.items():
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ValueError(f"--params {path}: {name}={value!r} is not a number")
    try:
        return {k: _typed(cls, k, v) for k, v in data.items()}
    except (ValueError, OverflowError) as e:
        raise ValueError(f"--params {path}: {e}") from None
