"""The passive walkers' gait sensitivity norm (planarsim.analysis.sensitivity) for a tilt of the
ground under one step: the step from the section is walked on a slope steeper by e [rad]
(the floor there turned about the stance foot), every later one on the walker's own slope.
Indicators: the step's period [s] and its length along the ground [m].

The two-legged walkers' section coordinates measure the stance leg's angle from the slope's
normal (gait.py); the same leg is e further from the tilted floor's normal, so the disturbed
step starts from theta + e (the same world state) and its end is told back in the walker's
own frame as theta - e (the legs' angle between them and the rates are the same in both
frames). The rimless wheel's section has no angle (each step starts at its spoke's touchdown
angle from the floor's normal), so for it the tilt is that of the whole step, gravity turned
by e for one step: a different disturbance, whose norm is not comparable with the others'.

    from walkers.passive.sensitivity import tilt_sensitivity
    gsn = tilt_sensitivity(SimplestParams(), x_star).norm
"""
from __future__ import annotations

import numpy as np

from planarsim.analysis.sensitivity import GaitSensitivity, gait_sensitivity

from .gait import PassiveWalker, check_map_dt

#: [rad] central-difference step of the tilt (and of the section coordinates)
TILT_EPS = 1e-5


class TiltStep:
    """step(x, e) -> (next section coordinates, (period [s], length [m])) of a passive walker
    whose next step is on its slope + e[0] (module docstring); walkers per tilt kept."""

    def __init__(self, params, dt: float = 1e-3):
        self.params, self.dt = params, check_map_dt(dt)
        self.walkers: dict[float, PassiveWalker] = {}

    def walker(self, tilt: float) -> PassiveWalker:
        if tilt not in self.walkers:
            p = self.params.replace(slope=self.params.slope + tilt)
            self.walkers[tilt] = PassiveWalker(p, dt=self.dt)
        return self.walkers[tilt]

    def __call__(self, x, e):
        tilt = float(np.asarray(e, dtype=np.float64).reshape(-1)[0])
        w = self.walker(tilt)
        x = np.asarray(x, dtype=np.float64).copy()
        turned = w.kind != "rimless"
        if turned:
            x[0] += tilt
        y = w.advance(x)
        if turned:
            y[0] -= tilt
        return y, np.array([w.last_period, w.last_length])


def tilt_sensitivity(params, x, dt: float = 1e-3, eps: float = TILT_EPS,
                     steps: int = 20) -> GaitSensitivity:
    """The gait sensitivity norm [s, m per rad] of the passive walker's gait at fixed point x
    for a tilt of one step's ground, its map's Jacobian A exact (StepMap.jacobian)."""
    from planarsim.checks import positive, whole
    # (checked before the walker is built and its map's Jacobian run, not after)
    eps, steps = positive("eps", eps, "the tilt's finite-difference step [rad]"), whole("steps", steps, 1)
    step = TiltStep(params, dt)
    A = step.walker(0.0).step_map().jacobian(np.asarray(x, dtype=np.float64))
    return gait_sensitivity(step, x, 1, eps, A=A, steps=steps)
