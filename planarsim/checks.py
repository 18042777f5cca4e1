"""Checks of plain arguments at the public entry points, shared so that every entry point
refuses a bad number alike, before anything is built or run.

Each check returns the value converted (a float, an int, a pair of floats) or raises an
error (ValueError unless `error` says otherwise) that names the argument as `said` gives it
("n", "terrain: height", "Hopper: healthy_z_range") and its value. True and False are never
taken for numbers (float(True) is 1.0: mass=True built a 1 kg body).
"""
from __future__ import annotations

import math
import numbers

import numpy as np

from .errors import plain

# the most steps one call of Simulator.steps or Simulator.run takes: at a microsecond a step
# (a small model) that is a quarter of an hour, at tens of microseconds hours; the compiled
# loop's count is an int64, which 10**30 overflowed inside numba
MAX_STEPS = 10 ** 9


def is_bool(value) -> bool:
    """True for Python's and numpy's booleans."""
    return isinstance(value, (bool, np.bool_))


def flag(said, value, error=TypeError) -> bool:
    """value where it is True or False (Python's or numpy's); else an error naming `said`
    (a string such as "no" is truthy: taken as True, it did the opposite of what it said)."""
    if not is_bool(value):
        raise error(f"{said}={plain(value)!r} must be True or False")
    return bool(value)


def to_float(value, strict: bool = False) -> float | None:
    """value as a float, or None where it is no number: a bool, or what float() refuses (a
    word, None, a list); strict: also a string of digits or a 0-d array (only real numbers)."""
    if is_bool(value) or (strict and not isinstance(value, numbers.Real)):
        return None
    try:
        return float(value)
    except (TypeError, ValueError, OverflowError):
        return None


def number(said, value, finite: bool = True, error=ValueError) -> float:
    """value as a float: `error` naming it where it is no number or (finite) NaN or inf."""
    x = to_float(value)
    if x is None:
        raise error(f"{said}={plain(value)!r} must be a number"
                    + (" (not True or False)" if is_bool(value) else ""))
    if finite and not math.isfinite(x):
        raise error(f"{said}={x} must be finite")
    return x


def finite_number(said, value, least=-math.inf, most=math.inf, strict: bool = True, unit: str = "",
                  expected: str | None = None, error=ValueError) -> float:
    """value as a float within [least, most]: `error` naming it ("{said}={value}{unit} must be
    {expected}", by default "a finite number" and its bounds) where it is no finite number
    there; strict as to_float."""
    x = to_float(value, strict)
    if x is None or not (math.isfinite(x) and least <= x <= most):
        if expected is None:
            expected = "a finite number" + _bounds(least, most)
        raise error(f"{said}={plain(value)!r}{unit} must be {expected}")
    return x


def positive(said, value, what: str = "", unit: str = "", error=ValueError) -> float:
    """value as a float: `error` naming it ("{said}={value}{unit} must be a finite number > 0
    ({what})") unless it is a finite real number > 0 (not a string, True or False)."""
    return finite_number(said, value, least=math.ulp(0.0), unit=unit, error=error,
                         expected="a finite number > 0" + (f" ({what})" if what else ""))


def _bounds(least, most) -> str:
    """" >= 0", " within [0, 3]" or "" as finite_number's words say them."""
    if math.isfinite(least) and math.isfinite(most):
        return f" within [{least:g}, {most:g}]"
    if math.isfinite(least):
        return f" >= {least:g}"
    if math.isfinite(most):
        return f" <= {most:g}"
    return ""


def whole(said, value, least=None, most=None, why: str = "", error=ValueError) -> int:
    """value as an int: `error` naming it unless it is a whole number (3 or 3.0; not 2.7,
    NaN, inf, True, "3") from least to most (either None: no bound); why, when given, says
    the upper bound's reason in the message of a value above it."""
    try:
        n = None if is_bool(value) or isinstance(value, (str, bytes)) else int(value)
    except (TypeError, ValueError, OverflowError):
        n = None
    if n is None or n != value:
        raise error(f"{said}={plain(value)!r} must be a whole number"
                    + (" (not True or False)" if is_bool(value) else ""))
    if (least is not None and n < least) or (most is not None and n > most):
        words = (f" >= {least}" if most is None else f" <= {most:,}" if least is None
                 else f" from {least} to {most:,}")
        raise error(f"{said}={plain(value)!r} must be a whole number{words}"
                    + (f" ({why})" if why and most is not None and n > most else ""))
    return n


def pair(said, value, expected: str = "a pair (low, high) of numbers", increasing: bool = False,
         error=ValueError) -> tuple:
    """value as two floats (lo, hi): `error` naming it unless it is two numbers; increasing:
    also lo < hi, lo < inf and hi > -inf (either may be infinite the other way)."""
    try:
        lo, hi = (to_float(x) for x in value)
    except (TypeError, ValueError):
        lo = hi = None
    if lo is None or hi is None:
        raise error(f"{said}={plain(value)!r} must be {expected}")
    if increasing and (not lo < hi or lo == math.inf or hi == -math.inf):
        raise error(f"{said}={plain(value)!r} must have low < high (and low < inf, high > -inf)")
    return lo, hi


def holds_bool(value) -> bool:
    """True where value, or an entry of it (a tuple, a list, an array), is True or False."""
    if is_bool(value):
        return True
    if isinstance(value, np.ndarray):
        return value.dtype == np.bool_
    if isinstance(value, (tuple, list)):
        return any(holds_bool(v) for v in value)
    return False


def callable_or_none(said, value, expected: str) -> None:
    """TypeError naming `value` unless it is None or callable (expected: what it should be,
    e.g. "a function controller(sim) -> u")."""
    if value is not None and not callable(value):
        raise TypeError(f"{said}={plain(value)!r} must be {expected}, or None")
