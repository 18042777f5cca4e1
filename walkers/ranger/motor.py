"""Ranger's three motors (hip, outer ankle, inner ankle) through the engine's motor model
(planarsim.actuators, seed eqs. 13-16): a table of motor rows and one compiled drive function
(current command + joint rate -> saturated current, joint torque, electrical power).
"""
from __future__ import annotations

import numpy as np

from planarsim.actuators import (MOTOR_GEAR, MOTOR_NPARAM, MOTOR_TORQUE_CONST, make_motor,
                                 motor_power, motor_torque, saturate_current)
from planarsim.compiled import jit

from .params import RangerParams


def motor_table(p: RangerParams) -> np.ndarray:
    """(3, MOTOR_NPARAM): rows hip, outer ankle, inner ankle (model actuator order)."""
    rows = []
    for gear in (p.hip_gear, p.ankle_gear, p.ankle_gear):
        rows.append(make_motor(gear=gear, torque_const=p.torque_const, resistance=p.resistance,
                               contact_voltage=p.contact_voltage, current_max=p.current_max,
                               viscous=p.viscous_friction, coulomb=p.coulomb_friction,
                               load_friction=p.load_friction, rotor_inertia=p.rotor_inertia,
                               current_smooth=p.current_smooth, rate_smooth=p.rate_smooth))
    return np.array(rows).reshape(3, MOTOR_NPARAM)


@jit
def drive_motor(mp, current, rate):
    """Saturate the current [A] to +-Imax, then (current, torque [N m], electrical power [W])."""
    i = saturate_current(current, mp)
    return i, motor_torque(i, rate, mp), motor_power(i, rate, mp)


@jit
def torque_constant(mp):
    """G K [N m/A]."""
    return mp[MOTOR_GEAR] * mp[MOTOR_TORQUE_CONST]
