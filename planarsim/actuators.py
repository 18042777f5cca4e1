"""DC motor + gearbox model (Kelly 2014, eqs. 13-16, with Ranger's published motor constants), as compiled pure functions.

A motor is one row of a float array laid out by the MOTOR_* indices below (build it with
``make_motor``). The command is the armature current I [A]; w [rad/s] is the joint rate
(output side of the gearbox). Friction opposes the joint rate:

    T = G K I - c1 w - c0 sgn(w) - mu G K |I| sgn(w)                      [N m]
    P = I^2 R + Vc |I| + G K w I                                           [W]

``sgn`` is smoothed (Kelly 2014, eq. 15): sgn(w) ~ w / sqrt(w^2 + w0^2), so the friction is
a continuous, bounded-slope function of the rate (a discontinuous Coulomb term chatters
under an explicit step on a light body). In the power, |I| is smoothed too,
|I| ~ I^2 / sqrt(I^2 + I0^2); the torque's load friction takes |I| as it is (continuous in I).
The rotor inertia (reflected G^2 Jm) is NOT part of the torque here: it is a body property
(an armature) that the model builder adds; see walkers/ranger/model.py.

Parallel springs of the joint are passive pin springs (``ModelBuilder.add_pin(stiffness=,
rest_angle=)``), not part of the motor either.
"""
from __future__ import annotations

import math

import numpy as np

from .compile import jit

MOTOR_GEAR = 0          # G [-] gear ratio
MOTOR_TORQUE_CONST = 1  # K [N m/A]
MOTOR_RESISTANCE = 2    # R [ohm] terminal resistance
MOTOR_CONTACT_V = 3     # Vc [V] brush contact voltage drop
MOTOR_CURRENT_SMOOTH = 4  # I0 [A] smoothing of |I|
MOTOR_VISCOUS = 5       # c1 [N m s/rad]
MOTOR_COULOMB = 6       # c0 [N m]
MOTOR_LOAD_FRICTION = 7  # mu [-] current-dependent friction
MOTOR_ROTOR_INERTIA = 8  # Jm [kg m^2] (rotor side)
MOTOR_CURRENT_MAX = 9   # Imax [A]
MOTOR_RATE_SMOOTH = 10  # w0 [rad/s] smoothing of sgn(w)
MOTOR_NPARAM = 11


def make_motor(gear, torque_const, resistance, contact_voltage, current_max, viscous=0.0,
               coulomb=0.0, load_friction=0.0, rotor_inertia=0.0, current_smooth=0.01,
               rate_smooth=0.5) -> np.ndarray:
    """One motor row (MOTOR_NPARAM,) in SI units; raises ValueError naming a bad field."""
    row = np.zeros(MOTOR_NPARAM)
    vals = dict(gear=(MOTOR_GEAR, gear), torque_const=(MOTOR_TORQUE_CONST, torque_const),
                resistance=(MOTOR_RESISTANCE, resistance),
                contact_voltage=(MOTOR_CONTACT_V, contact_voltage),
                current_smooth=(MOTOR_CURRENT_SMOOTH, current_smooth),
                viscous=(MOTOR_VISCOUS, viscous), coulomb=(MOTOR_COULOMB, coulomb),
                load_friction=(MOTOR_LOAD_FRICTION, load_friction),
                rotor_inertia=(MOTOR_ROTOR_INERTIA, rotor_inertia),
                current_max=(MOTOR_CURRENT_MAX, current_max), rate_smooth=(MOTOR_RATE_SMOOTH, rate_smooth))
    for name, (i, x) in vals.items():
        x = float(x)
        if not math.isfinite(x) or x < 0:
            raise ValueError(f"motor: {name}={x} must be finite and >= 0")
        row[i] = x
    for name in ("gear", "torque_const", "current_smooth", "rate_smooth"):
        if row[vals[name][0]] <= 0:
            raise ValueError(f"motor: {name}={row[vals[name][0]]} must be > 0")
    return row


@jit
def smooth_sign(x, eps):
    """x / sqrt(x^2 + eps^2): sign(x) for |x| >> eps, linear (slope 1/eps) near 0."""
    return x / math.sqrt(x * x + eps * eps)


@jit
def saturate_current(current, mp):
    """Clip the current command [A] to +-Imax of motor row mp."""
    imax = mp[MOTOR_CURRENT_MAX]
    if current > imax:
        return imax
    if current < -imax:
        return -imax
    return current


@jit
def motor_torque(current, rate, mp):
    """Joint torque [N m] for current [A] at joint rate [rad/s] (friction opposes the rate)."""
    gk = mp[MOTOR_GEAR] * mp[MOTOR_TORQUE_CONST]
    d = smooth_sign(rate, mp[MOTOR_RATE_SMOOTH])
    return (gk * current - mp[MOTOR_VISCOUS] * rate - mp[MOTOR_COULOMB] * d
            - mp[MOTOR_LOAD_FRICTION] * gk * abs(current) * d)


@jit
def motor_power(current, rate, mp):
    """Electrical power [W] drawn for current [A] at joint rate [rad/s]: I^2 R + Vc|I| + GKwI
    (negative when the motor would regenerate)."""
    gk = mp[MOTOR_GEAR] * mp[MOTOR_TORQUE_CONST]
    i0 = mp[MOTOR_CURRENT_SMOOTH]
    abs_i = current * current / math.sqrt(current * current + i0 * i0)
    return current * current * mp[MOTOR_RESISTANCE] + mp[MOTOR_CONTACT_V] * abs_i + gk * rate * current
