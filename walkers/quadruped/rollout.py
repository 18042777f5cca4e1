"""Compiled rollout of the quadruped and its run class (``Run``, a walkers.base.WalkerRun;
``simulate``).

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

from planarsim.compiled import RUN_FELL, jit, step
import planarsim as ps

from walkers.base import WalkerRun, simulation, start_rng, target_speed, terrain_of
from walkers.common.record import record_labelled
from walkers.common.slots import label_slots

from . import controller as C
from .model import build
from .params import QuadrupedParams

LABELS = ("gait", "step_i", "state_FL", "state_FR", "state_RL", "state_RR", "speed_estimate",
          "x_desired")
# the memory fields recorded under those names
LABEL_SLOTS = label_slots(C.MEM, ("gait", "step_i", "state:0", "state:1", "state:2", "state:3",
                                  "v_est", "x_desired"))
GAITS = tuple(g.name.lower() for g in C.Gait)


@jit
def rollout_quadruped(m, s, ws, opt, p, mem, u, n, every, rec, lab, slots, k0):
    """n steps of control + physics, recording every `every`-th step into rec / lab from frame
    k0. Returns (run code, steps done, next frame): RUN_OK, an engine failure or RUN_FELL."""
    k = k0
    for i in range(n):
        C.control(m, s, ws, p, mem, u)
        if mem[C.MEM.fell] != 0.0:
            return RUN_FELL, i, k
        code = step(m, s, ws, opt, u)
        if code != 0:
            return code, i, k
        C.count_work(s, ws, mem, m.dt)
        k = record_labelled(s, ws, rec, lab, mem, slots, every, k)
    return 0, n, k


class Run(WalkerRun):
    """The robot dog in the world (a WalkerRun): model, state, controller memory, chunks. Its
    controller table is the parameter vector (params.to_array(), indices I_<FIELD>).

    Parameters
    ----------
    params : QuadrupedParams (defaults if None)
    terrain : planarsim.terrain.Terrain or spec string (flat if None)
    dt : step size [s]
    gait : "stand" | "piaffe" | "walk"
    speed : commanded walking speed [m/s] (params.speed if None; negative walks backward)
    strategy : contact-mode strategy, "all" (default) or "alternating"
    seed : 0 starts from the exact standing pose; others shift the torso height by < 5 mm
    extras : extras(builder) adds bodies and shapes to the scene (model.build)
    """

    NAME = "quadruped"
    LABELS = LABELS
    FELL_SLOT = C.MEM.fell
    ROLLOUT = staticmethod(rollout_quadruped)
    LABEL_SLOTS = LABEL_SLOTS

    def __init__(self, params=None, terrain=None, dt=1e-3, gait="walk", speed=None,
                 strategy="all", record_every=10, seed=0, extras=None):
        params = params if params is not None else QuadrupedParams()
        model = build(params, terrain_of(terrain), dt, extras=extras)
        state = ps.make_state(model)
        rng = start_rng(self.NAME, seed)
        if seed:
            state.q[:, 1] += 0.005 * rng.uniform()
        memory = C.make_memory(model, params, C.gait_id(gait),
                               params.speed if speed is None else target_speed(self.NAME, speed, params))
        memory[C.MEM.target + 1:C.MEM.target + 8:2] += state.q[0, 1] - model.q0[0, 1]
        super().__init__(model, params, params.to_array(), memory, state=state,
                         options=ps.make_options(strategy), record_every=record_every)
        self.x_start = float(self.state.q[0, 0])

    def set_gait(self, gait, speed=None) -> None:
        """Switch gait ("stand" | "piaffe" | "walk") and optionally the speed [m/s] at run time."""
        self.memory[C.MEM.gait] = C.gait_id(gait)
        if speed is not None:
            self.memory[C.MEM.speed] = target_speed(self.NAME, speed, self.params)

    @property
    def p(self) -> np.ndarray:
        """The parameter vector the controller reads (its table)."""
        return self.tables

    def numbers(self) -> dict:
        """distance [m] and mean_speed [m/s] of the torso since the start, steps (pair
        plantings), fell, max_pitch [deg], ik_clamps (control ticks with a clamped leg),
        cost_of_transport = positive motor work / (m g |distance|) (NaN below 0.1 m)."""
        t = self.time
        dist = float(self.state.q[0, 0]) - self.x_start
        weight = float(self.memory[C.MEM.weight])
        cot = float(self.memory[C.MEM.work]) / (weight * abs(dist)) if abs(dist) >= 0.1 else float("nan")
        return {"time": t, "distance": dist, "mean_speed": dist / t if t > 0 else 0.0,
                "steps": int(self.memory[C.MEM.steps]), "fell": self.fell, "falls": int(self.fell),
                "max_pitch_deg": float(np.degrees(self.memory[C.MEM.max_pitch])),
                "ik_clamps": int(self.memory[C.MEM.ik_clamps]),
                "motor_work_positive": float(self.memory[C.MEM.work]), "cost_of_transport": cot,
                "gait": C.Gait(int(self.memory[C.MEM.gait])).name.lower(),
                "speed_command": float(C.command_speed(self.memory))}


simulate = simulation(Run)


def live(gait="walk", terrain=None, speed=None, params=None, strategy="all") -> dict:
    """Hook for the interactive viewer (planarsim.render.viewer.view_walker): a Simulator and
    the Python-path Controller, keys w / p / s for walk / piaffe / stand, sliders for the
    commanded speed [m/s] and the servo stiffness kp [N m/rad]."""
    params = params if params is not None else QuadrupedParams()
    model = build(params, terrain_of(terrain))
    sim = ps.Simulator(model, ps.make_options(strategy))
    ctrl = C.Controller(model, params, gait, speed)
    mem = ctrl.memory

    def on_gait(name):
        mem[C.MEM.gait] = C.gait_id(name)

    def set_kp(x):
        ctrl.p[C.FIELD.kp] = float(x)

    def labels(_sim):
        return {"gait": mem[C.MEM.gait], "step_i": mem[C.MEM.step_i]}

    return dict(sim=sim, controller=ctrl, on_gait=on_gait,
                gait_keys={"w": "walk", "p": "piaffe", "s": "stand"},
                gains={"speed [m/s]": (-0.5, 0.5, lambda: float(mem[C.MEM.speed]),
                                       lambda x: mem.__setitem__(C.MEM.speed, float(x))),
                       "kp [N m/rad]": (10.0, 300.0, lambda: float(ctrl.p[C.FIELD.kp]), set_kp)},
                labels=labels, label_names={"gait": {int(g): g.name.lower() for g in C.Gait}})
