"""Compiled rollout of the quadruped and its Python front end (``Quadruped``, ``simulate``).

``rollout_quadruped`` runs physics + controller + recording + fall monitor without returning
to Python; it stops after the step where the robot fell (torso below fall_height or pitched
beyond fall_pitch). Per recorded frame, ``Trajectory.labels`` holds the controller's gait,
step counter, the four foot states (0 ground, 1 lift, 2 plant) and the measured torso speed.

Contact-mode strategy: "all" by default (every foot checked every step). With four feet the
the alternating strategy's check visits a given foot only every fourth step, so a foot being lifted
stays pinned and pulls on the ground until its turn: on a 30 s walk at 0.3 m/s the alternating
scheme recorded normal impulses down to -0.025 N s in one 1 ms step (a 25 N pull), the "all"
scheme none below 0; gait, distance and pitch were otherwise the same (benchmarks/quadruped.py
runs both). "alternating" stays selectable.
"""
from __future__ import annotations

import numpy as np

from planarsim.compiled import (RUN_FELL, audit_counts, check_run, jit, record_frame, step,
                                make_recorder)
import planarsim as ps
from planarsim.state import make_workspace
from planarsim.trajectory import Trajectory

from . import controller as C
from .model import build
from .params import QuadrupedParams

LABELS = ("gait", "step_i", "state_FL", "state_FR", "state_RL", "state_RR", "speed_estimate",
          "x_desired")
LABEL_SLOTS = np.array([C.M_GAIT, C.M_STEP_I, C.M_STATE, C.M_STATE + 1, C.M_STATE + 2,
                        C.M_STATE + 3, C.M_V_EST, C.M_X_DESIRED], dtype=np.int64)
GAITS = tuple(g.name.lower() for g in C.Gait)


@jit
def rollout_quadruped(m, s, ws, opt, p, mem, u, n, every, rec, lab, slots, k0):
    """n steps of control + physics, recording every `every`-th step into rec / lab from frame
    k0. Returns (run code, steps done, next frame): RUN_OK, an engine failure or RUN_FELL."""
    k = k0
    for i in range(n):
        C.control(m, s, p, mem, u)
        if mem[C.M_FELL] != 0.0:
            return RUN_FELL, i, k
        code = step(m, s, ws, opt, u)
        if code != 0:
            return code, i, k
        if s.step[0] % every == 0 and k < rec.t.shape[0]:
            record_frame(s, ws, rec, k)
            for c in range(slots.shape[0]):
                lab[k, c] = mem[slots[c]]
            k += 1
    return 0, n, k


class Quadruped:
    """The robot dog in the world: model, state, controller memory, recorded history.

    Parameters
    ----------
    params : QuadrupedParams (defaults if None)
    terrain : planarsim.terrain.Terrain or spec string (flat if None)
    dt : step size [s]
    gait : "stand" | "piaffe" | "walk"
    speed : commanded walking speed [m/s] (params.speed if None; negative walks backward)
    strategy : contact-mode strategy, "all" (default) or "alternating"
    seed : 0 starts from the exact standing pose; others shift the torso height by < 5 mm
    """

    def __init__(self, params=None, terrain=None, dt=1e-3, gait="walk", speed=None,
                 strategy="all", record_every=10, seed=0):
        self.params = params if params is not None else QuadrupedParams()
        if isinstance(terrain, str):
            terrain = ps.terrain.parse(terrain)
        self.model = build(self.params, terrain, dt)
        self.state = ps.make_state(self.model)
        if seed:
            lift = 0.005 * np.random.default_rng(seed).uniform()
            self.state.q[:, 1] += lift
        self.ws = make_workspace(self.model)
        self.options = ps.make_options(strategy)
        self.p = self.params.to_array()
        self.memory = C.make_memory(self.model, self.params, C.gait_id(gait),
                                    self.params.speed if speed is None else float(speed))
        self.memory[C.M_TARGET + 1:C.M_TARGET + 8:2] += self.state.q[0, 1] - self.model.q0[0, 1]
        self.u = np.zeros(self.model.n_act)
        self.record_every = int(record_every)
        self.x_start = float(self.state.q[0, 0])
        self._chunks = []

    def set_gait(self, gait, speed=None) -> None:
        """Switch gait ("stand" | "piaffe" | "walk") and optionally the speed [m/s] at run time."""
        self.memory[C.M_GAIT] = C.gait_id(gait)
        if speed is not None:
            self.memory[C.M_SPEED] = float(speed)

    @property
    def fell(self) -> bool:
        return bool(self.memory[C.M_FELL])

    def run(self, seconds: float) -> Trajectory:
        """Advance `seconds` [s] (stops early on a fall); return this chunk's Trajectory."""
        if not seconds >= 0:
            raise ValueError(f"seconds={seconds} must be >= 0")
        n = int(round(float(seconds) / self.model.dt))
        every = self.record_every
        rec = make_recorder(self.model, n // every + 1)
        lab = np.zeros((n // every + 1, len(LABELS)))
        code, done, k = rollout_quadruped(self.model.arrays, self.state, self.ws, self.options, self.p,
                                          self.memory, self.u, n, every, rec, lab, LABEL_SLOTS, 0)
        check_run(code, self.model, self.ws, self.options, "quadruped")
        traj = Trajectory.from_recorder(self.model, rec, k,
                                        labels={nm: lab[:k, j].copy() for j, nm in enumerate(LABELS)},
                                        info={"dt": self.model.dt, "walker": "quadruped"})
        self._chunks.append(traj)
        return traj

    def trajectory(self) -> Trajectory:
        """All chunks run so far, joined."""
        if not self._chunks:
            return Trajectory.from_recorder(self.model, make_recorder(self.model, 0), 0)
        return Trajectory.concatenate(self._chunks)

    def summary(self) -> dict:
        """distance [m] and mean_speed [m/s] of the torso since the start, steps (pair
        plantings), fell, max_pitch [deg], ik_clamps (control ticks with a clamped leg),
        cost_of_transport = positive motor work / (m g |distance|) (NaN below 0.1 m)."""
        t = float(self.state.time[0])
        dist = float(self.state.q[0, 0]) - self.x_start
        weight = float(self.memory[C.M_WEIGHT])
        cot = float(self.memory[C.M_WORK]) / (weight * abs(dist)) if abs(dist) >= 0.1 else float("nan")
        return {"time": t, "distance": dist, "mean_speed": dist / t if t > 0 else 0.0,
                "steps": int(self.memory[C.M_STEPS]), "fell": self.fell, "falls": int(self.fell),
                "max_pitch_deg": float(np.degrees(self.memory[C.M_MAX_PITCH])),
                "ik_clamps": int(self.memory[C.M_IK_CLAMPS]),
                "motor_work_positive": float(self.memory[C.M_WORK]), "cost_of_transport": cot,
                "gait": C.Gait(int(self.memory[C.M_GAIT])).name.lower(),
                "speed_command": float(C.command_speed(self.memory)),
                "audit": audit_counts(self.ws)}


def simulate(duration, gait="walk", terrain=None, dt=1e-3, seed=0, speed=None, params=None,
             strategy="all", record_every=10):
    """Run the quadruped from standing for `duration` [s] in `gait` ("stand" | "piaffe" | "walk")
    at the commanded `speed` [m/s] (walk only; default params.speed, 0.3). Returns
    (Trajectory, summary dict, Model)."""
    q = Quadruped(params, terrain, dt, gait, speed, strategy, record_every, seed)
    q.run(duration)
    return q.trajectory(), q.summary(), q.model


def live(gait="piaffe", terrain=None, speed=None, params=None, strategy="all") -> dict:
    """Hook for the interactive viewer (planarsim.render.viewer.view_walker): a Simulator and
    the Python-path Controller, keys w / p / s for walk / piaffe / stand, sliders for the
    commanded speed [m/s] and the servo stiffness kp [N m/rad]."""
    params = params if params is not None else QuadrupedParams()
    if isinstance(terrain, str):
        terrain = ps.terrain.parse(terrain)
    model = build(params, terrain)
    sim = ps.Simulator(model, ps.make_options(strategy))
    ctrl = C.Controller(model, params, gait, speed)
    mem = ctrl.memory

    def on_gait(name):
        mem[C.M_GAIT] = C.gait_id(name)

    def set_kp(x):
        ctrl.p[C.I_KP] = float(x)

    def labels(_sim):
        return {"gait": mem[C.M_GAIT], "step_i": mem[C.M_STEP_I]}

    return dict(sim=sim, controller=ctrl, on_gait=on_gait,
                gait_keys={"w": "walk", "p": "piaffe", "s": "stand"},
                gains={"speed [m/s]": (-0.5, 0.5, lambda: float(mem[C.M_SPEED]),
                                       lambda x: mem.__setitem__(C.M_SPEED, float(x))),
                       "kp [N m/rad]": (10.0, 300.0, lambda: float(ctrl.p[C.I_KP]), set_kp)},
                labels=labels, label_names={"gait": {int(g): g.name.lower() for g in C.Gait}})
