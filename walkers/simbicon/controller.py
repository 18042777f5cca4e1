"""SIMBICON controller (Thachuk 2018 sections 2.1-2.3): four-state FSM, PD joints, torso control
through the stance hip, swing-hip balance feedback. One compiled ``control`` covers every state.

States (Table 1): 0 right swing, timed; 1 right swing, ends at right-foot contact; 2 and 3 the
mirror for the left leg. So ``swing = phase // 2`` (0 right, 1 left), ``stance = 1 - swing``
and ``half = phase % 2`` selects the target row: one table for both sides. States 1/3 also end
after ``contact_timeout`` without contact, so the machine never stalls (the thesis' complaint).

Torques [N m] (motor convention: +tau on the child body, -tau on the parent):
  knees, ankles: tau = kp (theta_d - theta) - kd theta_dot                       (eq. 1)
  swing hip:     tau_sw = kp_hip (theta_d - phi_thigh) - kd_hip phi_thigh_dot, with the thigh
                 angle phi in the WORLD frame (foot placement independent of torso pitch) and
                 theta_d = theta_d0 + c_d d + c_v v                              (eq. 3)
                 d = x_torso - x_stance_ankle [m], v = torso forward speed [m/s]; positive
                 theta is forward, so falling forward lengthens the step
  torso:         tau_torso = kp_t (theta_torso_d - theta_torso) - kd_t omega_torso
  stance hip:    tau_st = -tau_torso - tau_sw                                    (eq. 2)
Note: the thesis' listing adds c_d d + c_v v to the negated (PyBullet-frame) target, i.e. with
the opposite sign to SIMBICON's eq. 3 in its own frame; we follow eq. 3 as written.
"""
from __future__ import annotations

import math
from enum import IntEnum
from typing import NamedTuple

import numpy as np

from planarsim.compiled import jit_inline, kernel, pin_angle_rate

from walkers.common.slots import size, slots

from .params import SimbiconParams

# the target table's columns (each a parameter <column>_0 / _1 for the two halves of a step)
# and the joints of the gain tables (kp_<joint>, kd_<joint>; the pin and actuator tables
# take the first three)
TARGET = slots("SimbiconTarget", ("swing_hip", "swing_knee", "swing_ankle", "stance_knee",
                                  "stance_ankle"))
JOINT = slots("SimbiconJoint", ("hip", "knee", "ankle", "torso"))
# controller memory (float64 vector), the fields in this order
MEM = slots("SimbiconMemory", ("phase", "t0", "strikes", "timeouts", "fell", "last_strike_t",
                               "effort", "glitch"))
MEMORY_SIZE = size(MEM)


class Phase(IntEnum):
    RIGHT_SWING_UP = 0
    RIGHT_SWING_DOWN = 1
    LEFT_SWING_UP = 2
    LEFT_SWING_DOWN = 3


class Tables(NamedTuple):
    """Everything the compiled controller reads (arrays and scalars only)."""
    target: np.ndarray        # (2, 5) [half, column] target angles [rad]
    cd: np.ndarray            # (2,) eq. 3 gains [rad/m]
    cv: np.ndarray            # (2,) [rad s/m]
    kp: np.ndarray            # (4,) hip, knee, ankle, torso [N m/rad]
    kd: np.ndarray            # (4,) [N m s/rad]
    torso_target: float       # [rad]
    state_time: float         # [s]
    contact_timeout: float    # [s]
    min_contact_time: float   # [s]
    fall_height: float        # [m]
    torso: int
    thigh: np.ndarray         # (2,) body per side
    pin: np.ndarray           # (2, 3) pin per side and joint
    act: np.ndarray           # (2, 3) actuator per side and joint
    contact: np.ndarray       # (2, 4) foot corner contacts per side


def make_tables(p: SimbiconParams, model) -> Tables:
    """Params + the model's index maps -> Tables for the compiled controller."""
    mt = model.meta
    f = np.float64
    return Tables(
        target=np.array([[getattr(p, f"{col}_{half}") for col in TARGET._fields] for half in range(2)], f),
        cd=np.array([p.cd_0, p.cd_1], f), cv=np.array([p.cv_0, p.cv_1], f),
        kp=np.array([getattr(p, f"kp_{joint}") for joint in JOINT._fields], f),
        kd=np.array([getattr(p, f"kd_{joint}") for joint in JOINT._fields], f),
        torso_target=float(p.torso), state_time=float(p.state_time),
        contact_timeout=float(p.contact_timeout), min_contact_time=float(p.min_contact_time),
        fall_height=float(p.fall_height), torso=int(mt["torso"]),
        thigh=np.asarray(mt["thigh"], np.int64), pin=np.asarray(mt["pin"], np.int64),
        act=np.asarray(mt["act"], np.int64), contact=np.asarray(mt["contact"], np.int64))


def make_memory(phase=0, t0=0.0) -> np.ndarray:
    mem = np.zeros(MEMORY_SIZE)
    mem[MEM.phase] = phase
    mem[MEM.t0] = t0
    mem[MEM.last_strike_t] = t0
    return mem


@kernel
def foot_in_contact(s, tab, side):
    """1 if any corner of `side`'s foot is pinned or sliding."""
    for c in range(tab.contact.shape[1]):
        if s.contact_mode[tab.contact[side, c]] != 0:
            return 1
    return 0


@kernel
def next_phase(s, tab, mem):
    """Table 1 transitions (plus the contact timeout); updates mem in place."""
    t = s.time[0]
    phase = int(mem[MEM.phase])
    t_in = t - mem[MEM.t0]
    if phase % 2 == 0:
        if t_in >= tab.state_time:
            mem[MEM.phase] = phase + 1
            mem[MEM.t0] = t
        return
    contact = foot_in_contact(s, tab, phase // 2) == 1 and t_in >= tab.min_contact_time
    if contact or t_in >= tab.contact_timeout:
        mem[MEM.phase] = (phase + 1) % 4
        mem[MEM.t0] = t
        if contact:
            mem[MEM.strikes] += 1
            mem[MEM.last_strike_t] = t
        else:
            mem[MEM.timeouts] += 1


@jit_inline
def control(m, s, ws, tab, mem, u):
    """Write the six motor torques into u (n_act,) for the current state."""
    next_phase(s, tab, mem)
    phase = int(mem[MEM.phase])
    swing = phase // 2
    stance = 1 - swing
    half = phase % 2
    q = s.q
    v = s.v
    tr = tab.torso
    # eq. 3: swing-hip target from the torso's position over the stance ankle and its speed
    ankle = tab.pin[stance, JOINT.ankle]
    foot = m.pin_body[ankle, 1]
    phi = q[foot, 2]
    ax = q[foot, 0] + math.cos(phi) * m.pin_anchor[ankle, 1, 0] - math.sin(phi) * m.pin_anchor[ankle, 1, 1]
    d = q[tr, 0] - ax
    hip_d = tab.target[half, TARGET.swing_hip] + tab.cd[half] * d + tab.cv[half] * v[tr, 0]
    th = tab.thigh[swing]
    tau_swing = tab.kp[JOINT.hip] * (hip_d - q[th, 2]) - tab.kd[JOINT.hip] * v[th, 2]
    # eq. 2: the stance hip supplies the torso torque
    tau_torso = tab.kp[JOINT.torso] * (tab.torso_target - q[tr, 2]) - tab.kd[JOINT.torso] * v[tr, 2]
    u[tab.act[swing, JOINT.hip]] = tau_swing
    u[tab.act[stance, JOINT.hip]] = -tau_torso - tau_swing
    # eq. 1: knees and ankles
    for side in range(2):
        col = TARGET.swing_knee if side == swing else TARGET.stance_knee
        for jt in range(JOINT.knee, JOINT.ankle + 1):
            j = tab.pin[side, jt]
            ang, rate = pin_angle_rate(m, q, v, j)
            u[tab.act[side, jt]] = tab.kp[jt] * (tab.target[half, col + jt - JOINT.knee] - ang) - tab.kd[jt] * rate


class Controller:
    """Python-path controller: ``u = ctrl(sim)`` calls the same compiled ``control``."""

    def __init__(self, params: SimbiconParams, model):
        self.params = params
        self.model = model
        self.tables = make_tables(params, model)
        self.reset()

    def reset(self, phase: int = 0, t0: float = 0.0):
        self.memory = make_memory(phase, t0)
        self.u = np.zeros(self.model.n_act)

    @property
    def phase(self) -> Phase:
        return Phase(int(self.memory[MEM.phase]))

    def __call__(self, sim):
        control(self.model.arrays, sim.state, sim.ws, self.tables, self.memory, self.u)
        return self.u
