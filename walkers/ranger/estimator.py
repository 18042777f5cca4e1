"""Contact estimator (Kelly 2014, section 6.3): a second-order Butterworth low-pass filter on each
foot's contact signal, then a two-threshold (hysteresis) switch, so a foot that bounces off
the ground for a few milliseconds does not flip the stance/swing selection.

Contact signal of foot s: the normal contact impulse of the last step divided by dt and by the
robot's weight (the load fraction it carries: ~1 in single stance, 0 in the air); on the robot a
foot contact sensor plays this part. Filter: bilinear transform of the analogue prototype
H(s) = w^2 / (s^2 + sqrt(2) w s + w^2) with the cutoff prewarped, run in direct form II
transposed; its state lives in the controller memory.
"""
from __future__ import annotations

import math

import numpy as np

from planarsim.compiled import jit


def butterworth2(cutoff_hz: float, dt: float) -> np.ndarray:
    """(b0, b1, b2, a1, a2) of the discrete 2nd-order Butterworth low-pass (unit DC gain)."""
    if not 0 < cutoff_hz < 0.5 / dt:
        raise ValueError(f"estimator cutoff {cutoff_hz} Hz must lie in (0, {0.5 / dt}) Hz (Nyquist)")
    k = math.tan(math.pi * cutoff_hz * dt)
    norm = 1.0 / (1.0 + math.sqrt(2.0) * k + k * k)
    b0 = k * k * norm
    return np.array([b0, 2.0 * b0, b0, 2.0 * (k * k - 1.0) * norm, (1.0 - math.sqrt(2.0) * k + k * k) * norm])


@jit
def filter_step(x, coef, c0, z, i0):
    """One sample x through the biquad coef[c0:c0 + 5] = (b0, b1, b2, a1, a2); state z[i0],
    z[i0 + 1]; returns the output."""
    y = coef[c0] * x + z[i0]
    z[i0] = coef[c0 + 1] * x - coef[c0 + 3] * y + z[i0 + 1]
    z[i0 + 1] = coef[c0 + 2] * x - coef[c0 + 4] * y
    return y


@jit
def hysteresis(y, on, th_on, th_off):
    """New 0/1 contact flag from filtered signal y and the previous flag `on`."""
    if on == 0 and y > th_on:
        return 1
    if on == 1 and y < th_off:
        return 0
    return on


def filter_signal(x, cutoff_hz, dt):
    """Filter a whole recorded signal (Python; for tests and plots)."""
    coef = butterworth2(cutoff_hz, dt)
    z = np.zeros(2)
    return np.array([filter_step(float(v), coef, 0, z, 0) for v in np.asarray(x, dtype=np.float64)])
