"""Compiled rollout of the Simple Biped and its run class (``Run``, a walkers.base.WalkerRun;
``simulate``).

``rollout_simple_biped`` runs physics + controller + recording + fall monitor without returning
to Python. ``Run`` keeps model, state and controller memory between chunks, so the gait (and
the target speed) can be switched at run time: ``w.set_gait("jump"); w.run(5.0)``.
Per recorded frame, ``Trajectory.labels`` holds the controller's ``gait``, ``state`` (see
controller.State), ``stance`` foot, ``phase``, ``steps`` and ``jumps``.
"""
from __future__ import annotations

import math

import numpy as np

from planarsim.compiled import RUN_FELL, jit, step, height
import planarsim as ps

from walkers.base import WalkerRun, simulation, start_rng, target_speed, terrain_of
from walkers.common.gaits import gait_number
from walkers.common.record import record_labelled
from walkers.common.slots import label_slots
from walkers.common.work import add_positive_work

from . import controller as C
from .model import build
from .params import FIELD, SimpleBipedParams

LABELS = ("gait", "state", "stance", "phase", "steps", "jumps")
LABEL_SLOTS = label_slots(C.MEM, LABELS)   # the memory fields of those names


@jit
def _longest_leg(q):
    """Longer of the two hip-foot distances [m]."""
    a = math.hypot(q[1, 0] - q[0, 0], q[1, 1] - q[0, 1])
    b = math.hypot(q[2, 0] - q[0, 0], q[2, 1] - q[0, 1])
    return max(a, b)


@jit
def fell_down(m, s, p):
    """The walker has fallen: the hip below fall_height above the ground, or a leg longer than
    fall_leg_length (p: the parameter table)."""
    return (s.q[0, 1] - height(m.terrain_coef, s.q[0, 0]) < p[FIELD.fall_height] * p[FIELD.leg_length]
            or _longest_leg(s.q) > p[FIELD.fall_leg_length] * p[FIELD.leg_length])


@jit
def rollout_simple_biped(m, s, ws, opt, tab, mem, u, n, every, rec, lab, slots, k0):
    """n steps of control + physics, recording every `every`-th step into rec / lab (memory
    slots `slots`) from frame k0. Stops on a fall (RUN_FELL, mem[MEM.fallen]=1): the hip below
    fall_height above the ground, or a leg longer than fall_leg_length; or on an engine failure
    (planarsim.compiled run codes). Returns (code, steps done, next frame)."""
    p = tab.p
    k = k0
    for i in range(n):
        C.control(m, s, ws, tab, mem, u)
        code = step(m, s, ws, opt, u)
        if code != 0:
            return code, i, k
        add_positive_work(ws, mem, C.MEM.work, m.dt)
        k = record_labelled(s, ws, rec, lab, mem, slots, every, k)
        if fell_down(m, s, p):
            mem[C.MEM.fallen] = 1.0
            return RUN_FELL, i + 1, k
    return 0, n, k


def _gait_id(gait) -> int:
    return gait_number(C.Gait, gait, "simple-biped")


class Run(WalkerRun):
    """A Simple Biped in the world (a WalkerRun): model, state, controller memory, chunks.

    Parameters
    ----------
    params : SimpleBipedParams (default values if None)
    terrain : planarsim.terrain.Terrain or spec string (flat if None)
    dt : step size [s]
    gait : initial gait, "stand" | "walk" | "jump"
    speed : target walking speed [m/s] (params.speed if None)
    record_every : steps between recorded frames
    seed : 0 starts from the exact standing pose; other seeds shift the hip by up to 1 cm in x
    options : StepOptions (the engine defaults if None)
    extras : extras(builder) adds bodies and shapes to the scene (stairs, obstacles; model.build)
    """

    NAME = "simple-biped"
    LABELS = LABELS
    FELL_SLOT = C.MEM.fallen
    ROLLOUT = staticmethod(rollout_simple_biped)
    LABEL_SLOTS = LABEL_SLOTS

    def __init__(self, params=None, terrain=None, dt=1e-3, gait="walk", speed=None,
                 record_every=10, seed=0, options=None, extras=None):
        params = params if params is not None else SimpleBipedParams()
        model = build(params, terrain_of(terrain), dt, extras=extras)
        memory = np.zeros(C.N_MEMORY)
        memory[C.MEM.state] = C.ST_STAND
        memory[C.MEM.speed] = params.speed if speed is None else target_speed(self.NAME, speed, params)
        memory[C.MEM.gait] = _gait_id(gait)
        super().__init__(model, params, C.make_tables(params), memory, options=options,
                         record_every=record_every)
        rng = start_rng(self.NAME, seed)
        if seed:
            self.state.q[0, 0] += 0.01 * params.leg_length * rng.uniform(-1, 1)
        self.x_start = float(self.state.q[0, 0])

    # run-time switches ------------------------------------------------------------------------
    def set_gait(self, gait) -> None:
        """Request gait "stand" | "walk" | "jump"; the state machine switches when it safely can."""
        self.memory[C.MEM.gait] = _gait_id(gait)

    def set_speed(self, speed: float) -> None:
        """Target walking speed [m/s]."""
        self.memory[C.MEM.speed] = target_speed(self.NAME, speed, self.params)

    @property
    def gait(self) -> str:
        return C.Gait(int(self.memory[C.MEM.gait])).name.lower()

    def weight(self) -> float:
        """The walker's weight [N] (cost of transport = positive work / (weight distance))."""
        return self.model.total_mass * float(np.hypot(*self.model.arrays.gravity))

    # the contract -----------------------------------------------------------------------------
    def numbers(self) -> dict:
        """distance [m] and mean_speed [m/s] of the hip since the start, positive actuator work
        [J] and cost of transport (that work per weight and distance [-]), steps, jumps, fell."""
        t = self.time
        dist = float(self.state.q[0, 0]) - self.x_start
        weight = self.weight()
        work = float(self.memory[C.MEM.work])
        return {"time": t, "distance": dist, "mean_speed": dist / t if t > 0 else 0.0,
                "positive_work": work,
                "cost_of_transport": work / (weight * dist) if dist > 0.1 else float("nan"),
                "steps": int(self.memory[C.MEM.steps]), "jumps": int(self.memory[C.MEM.jumps]),
                "scuffs": int(self.memory[C.MEM.scuffs]),
                "retries": int(self.memory[C.MEM.retries]), "fell": self.fell, "falls": int(self.fell),
                "gait": self.gait, "state": C.State(int(self.memory[C.MEM.state])).name.lower()}


simulate = simulation(Run)


def live(gait="walk", terrain=None, params=None, speed=None) -> dict:
    """Hook for the interactive viewer (planarsim.render.viewer.view_walker): a Simulator and the
    compiled controller called from Python each step; keys s / w / j for STAND / WALK / JUMP,
    a slider for the target walking speed [m/s]."""
    w = Run(params, terrain, gait=gait, speed=speed)
    sim = ps.Simulator(w.model, w.options, w.state)
    m, tab, mem, u = w.model.arrays, w.tables, w.memory, w.u

    def controller(sim):
        C.control(m, sim.state, sim.ws, tab, mem, u)
        return u

    return dict(sim=sim, controller=controller, on_gait=w.set_gait,
                gait_keys={"s": "stand", "w": "walk", "j": "jump"},
                gains={"speed [m/s]": (0.0, 2.0, lambda: float(mem[C.MEM.speed]), w.set_speed)},
                labels=lambda _sim: {"gait": mem[C.MEM.gait], "state": mem[C.MEM.state]},
                label_names={"gait": {int(g): g.name.lower() for g in C.Gait},
                             "state": {int(s): s.name.lower() for s in C.State}})
