"""Tracking camera: a damped second-order system that follows the centre of mass.

Kelly 2014, section 2.1: a camera locked on the COM makes the picture jerk (every heel strike
kicks the view); a camera modelled as a dynamical system tracking the COM moves smoothly.
Each coordinate c of the camera centre obeys

    c'' = wn^2 (r - c) - 2 zeta wn c'                                            (1)

with r the tracked reference (the COM) [m], wn the natural frequency [rad/s] and zeta the
damping ratio [-]. For a step in r of size A from rest, an under-damped camera (zeta < 1)
overshoots by A exp(-zeta pi / sqrt(1 - zeta^2)) at t = pi / (wn sqrt(1 - zeta^2)); a
critically or over-damped one (zeta >= 1) never overshoots.

Form (1) lags a walker moving at speed v by 2 zeta v / wn (0.6 m at 1 m/s for the defaults),
so when the COM velocity r' is known (it is, exactly, in a Trajectory and a live State) the
damping acts on the velocity error instead:

    c'' = wn^2 (r - c) + 2 zeta wn (r' - c')                                     (2)

The error e = c - r then obeys e'' + 2 zeta wn e' + wn^2 e = -r'': the same damped
oscillator, driven only by the COM's accelerations (heel strikes), with no lag at steady
speed. For a step in r with r' = 0, (2) is (1), overshoot included.

The update is exact for a reference moving at constant velocity over the frame interval h:
[e, e'] is multiplied by expm(A h), A = [[0, 1], [-wn^2, -2 zeta wn]]. So the camera samples
the continuous response exactly at any frame interval, uneven ones included, and it is
stable for every h (no explicit-Euler blow-up at low fps).
"""
from __future__ import annotations

import math

import numpy as np


def _expm2(a: np.ndarray) -> np.ndarray:
    """exp(a) of a 2x2 matrix by scaling and squaring with a Taylor series (double precision)."""
    norm = float(np.abs(a).sum(axis=1).max())
    squarings = max(0, int(math.ceil(math.log2(norm / 0.25))) if norm > 0.25 else 0)
    b = a / 2.0 ** squarings
    out = np.eye(2)
    term = np.eye(2)
    for k in range(1, 18):
        term = term @ b / k
        out = out + term
    for _ in range(squarings):
        out = out @ out
    return out


def step_overshoot(damping_ratio: float) -> float:
    """Relative overshoot of (1) for a step from rest: exp(-zeta pi / sqrt(1 - zeta^2)), 0 if zeta >= 1."""
    z = float(damping_ratio)
    if z >= 1.0:
        return 0.0
    return math.exp(-z * math.pi / math.sqrt(1.0 - z * z))


class Camera:
    """Second-order tracking camera for the view centre (x, y).

    Parameters
    ----------
    natural_frequency : float, wn [rad/s] > 0 (higher: follows more tightly)
    damping_ratio : float, zeta [-] > 0 (1: critically damped, no overshoot)
    position : (2,) initial centre [m] (default: the first target given to `update`)
    track_y : bool, follow the vertical COM motion too (else y stays at its first value)
    """

    def __init__(self, natural_frequency: float = 3.0, damping_ratio: float = 0.9,
                 position=None, track_y: bool = True):
        wn, z = float(natural_frequency), float(damping_ratio)
        if not (math.isfinite(wn) and wn > 0):
            raise ValueError(f"camera natural_frequency={natural_frequency} must be finite and > 0 rad/s")
        if not (math.isfinite(z) and z > 0):
            raise ValueError(f"camera damping_ratio={damping_ratio} must be finite and > 0")
        self.natural_frequency = wn
        self.damping_ratio = z
        self.track_y = bool(track_y)
        self._a = np.array([[0.0, 1.0], [-wn * wn, -2.0 * z * wn]])
        self._cache = {}
        self.position = None if position is None else np.asarray(position, dtype=float).reshape(2).copy()
        self.velocity = np.zeros(2)

    def reset(self, position, velocity=(0.0, 0.0)) -> None:
        """Put the camera at `position` [m] with `velocity` [m/s]."""
        self.position = np.asarray(position, dtype=float).reshape(2).copy()
        self.velocity = np.asarray(velocity, dtype=float).reshape(2).copy()

    def transition(self, dt: float) -> np.ndarray:
        """2x2 map of [c - r, c'] over dt [s] (exact for a reference held constant)."""
        key = float(dt)
        phi = self._cache.get(key)
        if phi is None:
            phi = _expm2(self._a * key)
            if len(self._cache) > 256:
                self._cache.clear()
            self._cache[key] = phi
        return phi

    def update(self, target, dt: float, target_velocity=None) -> np.ndarray:
        """Advance by dt [s] >= 0 to the reference `target` (2,) [m] at the end of the interval,
        moving at `target_velocity` (2,) [m/s] (None: a reference at rest, form (1)).
        Returns the new centre (copy). The first call puts the camera on the target."""
        target = np.asarray(target, dtype=float).reshape(2)
        vel = np.zeros(2) if target_velocity is None else np.asarray(target_velocity, float).reshape(2)
        if self.position is None:
            self.reset(target, vel)
            return self.position.copy()
        dt = float(dt)
        if not (math.isfinite(dt) and dt >= 0):
            raise ValueError(f"camera update: dt={dt} must be finite and >= 0 s")
        phi = self.transition(dt)
        for i in range(2 if self.track_y else 1):
            # error to the reference at the start of the interval, propagated exactly
            e = self.position[i] - (target[i] - vel[i] * dt)
            w = self.velocity[i] - vel[i]
            self.position[i] = target[i] + phi[0, 0] * e + phi[0, 1] * w
            self.velocity[i] = vel[i] + phi[1, 0] * e + phi[1, 1] * w
        return self.position.copy()

    def track(self, times, targets, velocities=None) -> np.ndarray:
        """Camera centres (K, 2) [m] for a reference path `targets` (K, 2) [m] (with its
        velocities (K, 2) [m/s] if known) sampled at `times` (K,) [s]; starts on the first target
        unless a position was set."""
        times = np.asarray(times, dtype=float)
        targets = np.asarray(targets, dtype=float).reshape(len(times), 2)
        if velocities is not None:
            velocities = np.asarray(velocities, dtype=float).reshape(len(times), 2)
        out = np.empty((len(times), 2))
        prev = times[0] if len(times) else 0.0
        for k in range(len(times)):
            out[k] = self.update(targets[k], max(0.0, times[k] - prev),
                                 None if velocities is None else velocities[k])
            prev = times[k]
        return out


def camera_or_default(camera) -> Camera:
    """camera, or a Camera() for None; a TypeError naming anything else (camera=5 failed at
    the first frame with "'int' object has no attribute 'track'")."""
    if camera is None:
        return Camera()
    if not isinstance(camera, Camera):
        raise TypeError(f"camera={camera!r} must be a planarsim.render.Camera (e.g. "
                        "Camera(natural_frequency=3.0)), or None for the default one")
    return camera
