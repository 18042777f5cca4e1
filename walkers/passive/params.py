"""Parameters of the passive walkers: the simplest walking model, the compass gait and the
rimless wheel. One frozen dataclass each; every field carries doc, unit and bounds in its
metadata, and ``to_array()`` gives the float64 vector in field order.

Slopes are angles gamma [rad] of a plane falling toward +x; the model builders turn them into
``planarsim.terrain.slope(-degrees(gamma))`` (gravity stays vertical).
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, fields

import numpy as np


def _p(default, unit, doc, lo, hi):
    return field(default=default, metadata=dict(unit=unit, doc=doc, bounds=(lo, hi)))


class _Checked:
    """Bounds check on construction and the array view shared by the three dataclasses."""

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            lo, hi = f.metadata["bounds"]
            if not (isinstance(value, (int, float)) and math.isfinite(value) and lo <= value <= hi):
                raise ValueError(f"{type(self).__name__}.{f.name}={value!r} must be a finite number "
                                 f"in [{lo}, {hi}] ({f.metadata['unit']}: {f.metadata['doc']})")

    def to_array(self) -> np.ndarray:
        return np.array([float(getattr(self, f.name)) for f in fields(self)])

    def as_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class SimplestParams(_Checked):
    """Garcia, Chatterjee, Ruina and Coleman (1998): point-mass hip, point feet of mass ratio
    beta, massless rigid legs (rods)."""
    slope: float = _p(0.009, "rad", "slope gamma (downhill toward +x)", 0.0, 0.1)
    hip_mass: float = _p(1.0, "kg", "hip point mass M", 1e-3, 1e3)
    foot_mass_ratio: float = _p(1e-3, "-", "beta = m / M, foot point mass over hip mass", 1e-7, 0.5)
    leg_length: float = _p(1.0, "m", "leg (rod) length l", 0.1, 10.0)
    gravity: float = _p(9.81, "m/s^2", "gravitational acceleration g", 0.1, 100.0)
    mu: float = _p(10.0, "-", "foot friction (large: the model assumes no slip)", 0.0, 1e3)


@dataclass(frozen=True)
class CompassParams(_Checked):
    """Compass gait (Goswami, Thuilot, Espiau 1996) with rigid-body legs pinned at the hip.
    Defaults: hip 10 kg, legs 5 kg with their COM half way (a = b = 0.5 m)."""
    slope: float = _p(0.0524, "rad", "slope gamma (downhill toward +x), 3 degrees", 0.0, 0.3)
    hip_mass: float = _p(10.0, "kg", "hip point mass mH", 1e-3, 1e3)
    leg_mass: float = _p(5.0, "kg", "mass of each leg m", 1e-3, 1e3)
    leg_length: float = _p(1.0, "m", "leg length l = a + b", 0.1, 10.0)
    com_from_foot: float = _p(0.5, "m", "a: distance from the foot to the leg's COM", 0.0, 10.0)
    leg_gyration: float = _p(0.0, "m", "radius of gyration of a leg about its COM "
                             "(0: Goswami's point-mass legs, realised as 1e-3 m)", 0.0, 10.0)
    gravity: float = _p(9.81, "m/s^2", "gravitational acceleration g", 0.1, 100.0)
    mu: float = _p(10.0, "-", "foot friction", 0.0, 1e3)

    def __post_init__(self):
        super().__post_init__()
        if not self.com_from_foot < self.leg_length:
            raise ValueError(f"CompassParams.com_from_foot={self.com_from_foot} must be < "
                             f"leg_length={self.leg_length}")


@dataclass(frozen=True)
class RimlessParams(_Checked):
    """Rimless wheel: a rigid hub with n_spokes massless spokes; the feet are point contacts
    at the spoke ends."""
    slope: float = _p(0.1, "rad", "slope gamma (downhill toward +x)", 0.0, 0.5)
    n_spokes: int = _p(8, "-", "number of spokes N (half inter-spoke angle alpha = pi / N)", 3, 64)
    hub_mass: float = _p(1.0, "kg", "hub mass M", 1e-3, 1e3)
    hub_gyration: float = _p(0.1, "m", "radius of gyration of the hub about its centre", 1e-4, 10.0)
    spoke_length: float = _p(1.0, "m", "spoke length l", 0.05, 10.0)
    gravity: float = _p(9.81, "m/s^2", "gravitational acceleration g", 0.1, 100.0)
    mu: float = _p(10.0, "-", "foot friction", 0.0, 1e3)

    @property
    def half_angle(self) -> float:
        return math.pi / self.n_spokes
