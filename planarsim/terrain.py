"""Analytic terrain: flat ground, a constant slope, and sums of sines (hills).

h(x) = h0 + s x + sum_k A_k sin(2 pi x / L_k + phi_k)   [m]

Heights, slopes and normals are exact; the compiled versions live in ``kernels/geometry/terrain.py``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .checks import number
from .errors import ModelError, plain


@dataclass(frozen=True)
class Terrain:
    """Ground profile. Build with :func:`flat`, :func:`slope`, :func:`hills` or :func:`parse`.

    coef : (3 + 3K,) array  [h0, s, K, A_1, L_1, phi_1, ...]
    name : what it is: flat, slope:DEG, hills (the default hills) or hills:A,L,PHI;... with
        every coefficient (parse reads these back to the same coefficients)
    """

    coef: np.ndarray
    name: str = "terrain"

    def __post_init__(self):
        coef = np.ascontiguousarray(np.asarray(self.coef, dtype=np.float64))
        validate_coef(coef)
        coef.setflags(write=False)
        object.__setattr__(self, "coef", coef)

    @property
    def n_sines(self) -> int:
        return int(self.coef[2])

    def _terms(self):
        c = self.coef
        for k in range(self.n_sines):
            yield c[3 + 3 * k], 2 * math.pi / c[4 + 3 * k], c[5 + 3 * k]

    def height(self, x):
        """Ground height [m] at x [m] (scalar or array)."""
        x = np.asarray(x, dtype=np.float64)
        h = self.coef[0] + self.coef[1] * x
        for a, w, phi in self._terms():
            h = h + a * np.sin(w * x + phi)
        return h

    def slope(self, x):
        """dh/dx [-] at x (scalar or array)."""
        x = np.asarray(x, dtype=np.float64)
        d = self.coef[1] + 0.0 * x
        for a, w, phi in self._terms():
            d = d + a * w * np.cos(w * x + phi)
        return d

    def normal(self, x):
        """Unit upward normal, shape (..., 2)."""
        d = self.slope(x)
        inv = 1.0 / np.sqrt(1.0 + d * d)
        return np.stack([-d * inv, inv], axis=-1)

    def tangent(self, x):
        """Unit tangent pointing toward +x, shape (..., 2)."""
        d = self.slope(x)
        inv = 1.0 / np.sqrt(1.0 + d * d)
        return np.stack([inv, d * inv], axis=-1)


def validate_coef(coef: np.ndarray) -> None:
    """Raise ModelError unless coef is a finite, well-formed terrain description."""
    if coef.ndim != 1 or coef.size < 3:
        raise ModelError(f"terrain: coef must be a 1-D array [h0, s, K, ...], got shape {coef.shape}")
    for i, v in enumerate(coef):
        if not math.isfinite(v):
            raise ModelError(f"terrain: coef[{i}]={v} must be finite")
    k = coef[2]
    if k != int(k) or k < 0 or coef.size != 3 + 3 * int(k):
        raise ModelError(f"terrain: K=coef[2]={k} must be a whole number with len(coef) == 3 + 3K "
                         f"(len is {coef.size})")
    for j in range(int(k)):
        wavelength = coef[4 + 3 * j]
        if not wavelength > 0:
            raise ModelError(f"terrain: sine {j}: wavelength={wavelength} must be > 0")


def _num(x) -> str:
    """x as short text that reads back to exactly x (%g where that is exact, else repr)."""
    x = float(x)
    short = f"{x:g}"
    return short if float(short) == x else repr(x)


def from_coef(coef, name: str | None = None) -> Terrain:
    """The Terrain of coefficients [h0, s, K, A_1, L_1, phi_1, ...] (a model's terrain_coef or
    a trajectory's recorded ``terrain_coef``), named as flat, slope or hills name theirs."""
    coef = np.asarray(coef, dtype=np.float64)
    validate_coef(coef)
    if name is None:
        h0, s, k = coef[0], coef[1], int(coef[2])
        if k == 0 and s == 0.0:
            name = "flat" if h0 == 0.0 else f"flat (height {_num(h0)} m)"
        elif k == 0:
            name = f"slope:{_num(math.degrees(math.atan(s)))}"
            name += "" if h0 == 0.0 else f" (height {_num(h0)} m)"
        else:
            name = _hills_name(coef[3::3], coef[4::3], coef[5::3], s, h0)
    return Terrain(coef, name=name)


def _hills_name(a, lam, phi, grade, height) -> str:
    """hills:A,L,PHI;... with every coefficient (exact, parse reads it back), then the grade
    and height when they are not 0 (which the spec cannot hold)."""
    name = "hills:" + ";".join(f"{_num(x)},{_num(y)},{_num(z)}" for x, y, z in zip(a, lam, phi))
    extra = []
    if grade != 0.0:
        extra.append(f"grade {_num(grade)}")
    if height != 0.0:
        extra.append(f"height {_num(height)} m")
    return name + (f" ({', '.join(extra)})" if extra else "")


def _number(what, value, finite=True) -> float:
    """An argument of flat, slope or hills as a float, or a ModelError naming it and its
    value (a string, None, a list, a bool; NaN or inf unless finite=False)."""
    return number(f"terrain: {what}", value, finite, error=ModelError)


def _numbers(what, values) -> np.ndarray:
    """hills' amplitudes, wavelengths or phases as a 1-D float array (one number: one
    sine), or a ModelError naming the argument and the entry that is not a finite number."""
    try:
        arr = np.atleast_1d(np.asarray(values, dtype=np.float64))
    except (TypeError, ValueError):
        arr = None
    if arr is None or arr.ndim != 1:
        raise ModelError(f"terrain: {what}={plain(values)!r} must be a number or a list of "
                         "numbers, one per sine")
    for i, x in enumerate(arr):
        if not math.isfinite(x):
            raise ModelError(f"terrain: {what}[{i}]={x} must be finite")
    return arr


def flat(height: float = 0.0) -> Terrain:
    """Level ground at `height` [m]."""
    return Terrain(np.array([_number("height", height), 0.0, 0.0]), name="flat")


def slope(angle_deg: float, height: float = 0.0) -> Terrain:
    """Constant slope rising toward +x by `angle_deg` degrees (negative: downhill)."""
    angle_deg = _number("slope angle", angle_deg, finite=False)
    if not math.isfinite(angle_deg) or abs(angle_deg) >= 89.0:
        raise ModelError(f"terrain: slope angle={angle_deg} deg must be finite and within (-89, 89)")
    return Terrain(np.array([_number("height", height), math.tan(math.radians(angle_deg)), 0.0]),
                   name=f"slope:{_num(angle_deg)}")


def hills(amplitudes, wavelengths, phases=None, grade: float = 0.0, height: float = 0.0) -> Terrain:
    """Sum of sines: amplitudes [m], wavelengths [m], phases [rad], plus a constant grade s [-]."""
    a = _numbers("amplitudes", amplitudes)
    lam = _numbers("wavelengths", wavelengths)
    phi = np.zeros_like(a) if phases is None else _numbers("phases", phases)
    grade, height = _number("grade", grade), _number("height", height)
    if not (a.shape == lam.shape == phi.shape):
        raise ModelError(f"terrain: amplitudes, wavelengths, phases must have one length, got "
                         f"{a.size}, {lam.size}, {phi.size}")
    coef = np.concatenate([[height, grade, float(a.size)], np.stack([a, lam, phi], axis=1).ravel()])
    return Terrain(coef, name=_hills_name(a, lam, phi, float(grade), float(height)))


def max_slope_deg(terrain: Terrain, x0: float = -50.0, x1: float = 150.0, n: int = 200001) -> float:
    """Largest |slope| in degrees over [x0, x1], sampled."""
    x = np.linspace(x0, x1, n)
    return float(np.degrees(np.max(np.abs(np.arctan(terrain.slope(x))))))


def parse(spec: str) -> Terrain:
    """Terrain from a command-line spec.

    ``flat`` | ``slope:DEG`` | ``hills`` (default hills) | ``hills:A,L[,PHI][;A,L[,PHI]...]``
    """
    if not isinstance(spec, str):
        raise ModelError(f"terrain spec {spec!r} must be a string: flat, slope:DEG, hills or "
                         f"hills:A,L[,PHI][;A,L[,PHI]...] (metres, radians)")
    spec = spec.strip()
    kind, _, arg = spec.partition(":")
    try:
        if kind == "flat" and not arg:
            return flat()
        if kind == "slope":
            return slope(float(arg))
        if kind == "hills":
            if not arg:
                return default_hills()
            amps, lams, phis = [], [], []
            for term in arg.split(";"):
                parts = [float(p) for p in term.split(",")]
                if len(parts) not in (2, 3):
                    raise ValueError(term)
                amps.append(parts[0])
                lams.append(parts[1])
                phis.append(parts[2] if len(parts) == 3 else 0.0)
            return hills(amps, lams, phis)
    except ModelError:
        raise
    except ValueError:
        pass
    raise ModelError(f"terrain spec {spec!r} not understood; use flat, slope:DEG, hills or "
                     f"hills:A,L[,PHI][;A,L[,PHI]...] (metres, radians)")


def default_hills() -> Terrain:
    """Rolling hills: max slope about 12 deg, peak-to-trough about 0.33 m (Kelly 2014's figure);
    named "hills" (the spec that parse reads back to them)."""
    return Terrain(hills([0.12, 0.045], [7.0, 2.9], [0.0, 1.3]).coef, name="hills")
