"""Parameters of the passive walkers: the simplest walking model, the compass gait and the
rimless wheel. One frozen dataclass each; every field carries doc, unit and bounds in its
metadata, and ``to_array()`` gives the float64 vector in field order.

Slopes are angles gamma [rad] of a plane falling toward +x; the model builders turn them into
``planarsim.terrain.slope(-degrees(gamma))`` (gravity stays vertical).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from walkers.common.params import WalkerParams, param as _p


@dataclass(frozen=True)
class SimplestParams(WalkerParams):
    """Garcia, Chatterjee, Ruina and Coleman (1998): point-mass hip, point feet of mass ratio
    beta, massless rigid legs (rods)."""
    slope: float = _p(0.009, "rad", "slope gamma (downhill toward +x)", 0.0, 0.1)
    hip_mass: float = _p(1.0, "kg", "hip point mass M", 1e-3, 1e3)
    foot_mass_ratio: float = _p(1e-3, "-", "beta = m / M, foot point mass over hip mass", 1e-7, 0.5)
    leg_length: float = _p(1.0, "m", "leg (rod) length l", 0.1, 10.0)
    gravity: float = _p(9.81, "m/s^2", "gravitational acceleration g", 0.1, 100.0)
    mu: float = _p(10.0, "-", "foot friction (large: the model assumes no slip)", 0.0, 1e3)


@dataclass(frozen=True)
class CompassParams(WalkerParams):
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
class RimlessParams(WalkerParams):
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
