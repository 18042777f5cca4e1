"""Compiled rollout of the SIMBICON biped, its run class (``Run``, a
walkers.base.WalkerRun), ``simulate`` and the tuning entry point ``run``.

``rollout_simbicon`` runs physics + controller + recording + a torso push without returning to
Python. A push is (fx [N], fy [N], start [s], duration [s]) applied at the torso COM through
``State.ext_force``. The run stops early (code FELL) once the torso COM is below
``fall_height`` above the ground.
"""
from __future__ import annotations

import numpy as np

from planarsim import Simulator, make_options
from planarsim.compiled import RUN_FELL, RUN_NONFINITE, RUN_TOO_LARGE, RUN_WALKER, jit, step, height

from walkers.base import WalkerRun, simulation, terrain_of
from walkers.common.record import record_labelled

from .controller import MEM, Phase, control, make_memory, make_tables
from .model import build, non_foot_clearance, start_state
from .params import SimbiconParams

FELL = RUN_FELL   # rollout return code: the torso came down
GLITCH = RUN_WALKER + 2  # rollout return code: the torso moved faster than a walker can (solver blow-up)
STRATEGY = "all"   # engine contact-mode strategy: every contact's mode decided together (box feet)
GLITCH_SPEED = 10.0   # [m/s] torso COM speed taken as a solver glitch
GLITCH_SPIN = 30.0    # [rad/s] torso angular speed taken as a solver glitch
GAITS = ("walk",)


@jit
def rollout_simbicon(m, s, ws, opt, tab, mem, u, n, every, rec, lab, slots, k0, push):
    """n steps (WalkerRun.ROLLOUT's arguments, then the push); returns (code, steps done,
    frames recorded). code: 0 ok, guard code, or FELL."""
    k = k0
    tr = tab.torso
    for i in range(n):
        t = s.time[0]
        on = push[2] <= t < push[2] + push[3]
        s.ext_force[tr, 0] = push[0] if on else 0.0
        s.ext_force[tr, 1] = push[1] if on else 0.0
        x_before = s.q[tr, 0]
        y_before = s.q[tr, 1]
        control(m, s, ws, tab, mem, u)
        code = step(m, s, ws, opt, u)
        if code != 0:
            return code, i, k
        for a in range(u.shape[0]):
            mem[MEM.effort] += ws.act_u[a] * ws.act_u[a] * m.dt
        jump = max(abs(s.q[tr, 0] - x_before), abs(s.q[tr, 1] - y_before)) / m.dt
        if (abs(s.v[tr, 0]) > GLITCH_SPEED or abs(s.v[tr, 1]) > GLITCH_SPEED
                or abs(s.v[tr, 2]) > GLITCH_SPIN or jump > GLITCH_SPEED):
            mem[MEM.fell] = 1.0
            return GLITCH, i + 1, k
        k = record_labelled(s, ws, rec, lab, mem, slots, every, k)
        if s.q[tr, 1] - height(m.terrain_coef, s.q[tr, 0]) < tab.fall_height:
            mem[MEM.fell] = 1.0
            return FELL, i + 1, k
    return 0, n, k


_PUSH_FORM = "None, (fx [N], start [s], duration [s]) or dict(force=fx or (fx, fy), start=, duration=)"
_PUSH_KEYS = ("force", "start", "duration")


def _push_array(push):
    """None | (fx, start, duration) | dict(force=fx or (fx, fy), start=, duration=) -> (4,);
    any other form, an unknown key, a force of more than two components or a value that is
    not a finite number is a ValueError naming push."""
    if push is None:
        return np.array([0.0, 0.0, -1.0, 0.0])
    try:
        if isinstance(push, dict):
            unknown = [k for k in push if k not in _PUSH_KEYS]
            if unknown or "force" not in push:
                raise ValueError(f"keys {sorted(push)}; the keys are {list(_PUSH_KEYS)}, force "
                                 "required")
            f = np.atleast_1d(np.asarray(push["force"], dtype=np.float64))
            if f.ndim != 1 or not 1 <= f.size <= 2:
                raise ValueError("force is fx or (fx, fy) [N]")
            fx, fy = (f[0], f[1]) if f.size > 1 else (f[0], 0.0)
            start, dur = push.get("start", 0.0), push.get("duration", 0.2)
        else:
            if isinstance(push, (str, bytes)) or np.ndim(push) != 1 or len(push) != 3:
                raise ValueError("a sequence is (fx, start, duration)")
            fx, start, dur = push
            fy = 0.0
        arr = np.array([fx, fy, start, dur], dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise ValueError(f"push={push!r}: {e}; a push is {_PUSH_FORM}") from None
    if not np.all(np.isfinite(arr)) or arr[3] < 0:
        raise ValueError(f"push={push!r} must be finite with duration >= 0")
    return arr


class Run(WalkerRun):
    """The SIMBICON biped in the world (a WalkerRun), from the standing start pose.

    Parameters
    ----------
    params : SimbiconParams (defaults if None)
    terrain : planarsim.terrain.Terrain or spec string (flat if None)
    dt : step size [s]
    gait : "walk" (its only gait)
    push : None | (fx [N], start [s], duration [s]) | dict(force=fx or (fx, fy), start=, duration=):
           a push at the torso COM, by absolute time (chunked runs push at the same instant)
    seed : accepted for the common interface (the walker is deterministic)
    record_every : steps between recorded frames (0: none, and no min_clearance)
    strategy : engine contact-mode strategy
    glitch_ok : an engine divergence (a non-finite or too large state) ends the run as a glitch
           (a fall) instead of raising; off by default, so a divergence raises as in every
           walker (tuning's objective turns it on: a parameter set the engine cannot run
           loses its run)
    model : a model built already (build(params, terrain, dt)), to skip the build
    """

    NAME = "simbicon"
    FELL_SLOT = MEM.fell
    LABEL_SLOTS = np.zeros(0, np.int64)   # no per-frame labels

    def __init__(self, params: SimbiconParams | None = None, terrain=None, dt=1e-3, gait="walk",
                 push=None, seed=0, record_every=10, strategy: str = STRATEGY, glitch_ok: bool = False,
                 model=None):
        if gait not in GAITS:
            raise ValueError(f"simbicon gait {gait!r} unknown; gaits: {GAITS}")
        params = params if params is not None else SimbiconParams()
        model = model if model is not None else build(params, terrain_of(terrain), dt)
        super().__init__(model, params, make_tables(params, model), make_memory(),
                         state=start_state(model, params.start_lean, params.start_speed),
                         options=make_options(strategy), record_every=record_every)
        self.push = _push_array(push)
        self.glitch_ok = bool(glitch_ok)
        self.x_start = float(self.state.q[self.tables.torso, 0])

    def advance(self, n, every, rec, lab):
        code, done, k = rollout_simbicon(self.model.arrays, self.state, self.ws, self.options, self.tables,
                                         self.memory, self.u, n, every, rec, lab, self.LABEL_SLOTS, 0,
                                         self.push)
        return code, k

    def stopped(self, code: int) -> int:
        """A state that blew up in the last step is a solver glitch when glitch_ok (for tuning,
        a lost run): the state before that step is kept. A glitch is a fall."""
        if code in (RUN_NONFINITE, RUN_TOO_LARGE) and self.glitch_ok:
            code = GLITCH
            self.state.restore(self.ws.prev)
        if code == GLITCH:
            self.memory[MEM.fell] = 1.0
            self.memory[MEM.glitch] = 1.0
        return code

    def numbers(self) -> dict:
        """distance [m] (torso x), speed [m/s] (distance / simulated time), steps (swing-foot
        strikes), timeouts (states ended by the timeout), fell (torso came down, a glitch, or a
        non-foot part touched the ground), time [s] simulated, effort [N^2 m^2 s] (integral of
        the sum of squared applied torques), min_clearance [m] (lowest non-foot part above the
        ground, when recorded)."""
        mem = self.memory
        t = self.time
        out = dict(distance=float(self.state.q[self.tables.torso, 0] - self.x_start), time=t,
                   steps=int(mem[MEM.strikes]), timeouts=int(mem[MEM.timeouts]), fell=self.fell,
                   glitch=bool(mem[MEM.glitch]), phase=int(mem[MEM.phase]), effort=float(mem[MEM.effort]))
        out["speed"] = out["distance"] / t if t > 0 else 0.0
        if self.record_every:
            traj = self.trajectory()
            clearance = float(non_foot_clearance(self.model, traj.q).min()) if len(traj) else np.inf
            out["min_clearance"] = clearance
            out["fell"] = out["fell"] or clearance < 0.0
        return out


simulate = simulation(Run)


def run(params: SimbiconParams, duration: float, terrain=None, dt=1e-3, push=None,
        record_every: int = 10, model=None, record: bool = True, strategy: str = STRATEGY,
        glitch_ok: bool = False):
    """A SIMBICON Run of `duration` [s] (tuning's entry point; record=False records nothing).
    Returns (Trajectory or None, summary dict, model); see Run.numbers for the keys."""
    r = Run(params, terrain, dt, push=push, record_every=record_every if record else 0,
            strategy=strategy, glitch_ok=glitch_ok, model=model)
    r.run(duration)
    return (r.trajectory() if record else None), r.summary(), r.model


def live(gait="walk", terrain=None, params=None) -> dict:
    """Hook for the interactive viewer (planarsim.render.viewer.view_walker): a Simulator from
    the standing start and the compiled controller called from Python each step; a slider
    pushes the torso [N] (hold it to push)."""
    if gait not in GAITS:
        raise ValueError(f"simbicon gait {gait!r} unknown; gaits: {GAITS}")
    params = params if params is not None else SimbiconParams()
    model = build(params, terrain_of(terrain))
    sim = Simulator(model, make_options(STRATEGY),
                    state=start_state(model, params.start_lean, params.start_speed))
    tab, mem, u = make_tables(params, model), make_memory(), np.zeros(model.n_act)
    push = [0.0]

    def controller(sim):
        sim.state.ext_force[tab.torso, 0] = push[0]
        control(model.arrays, sim.state, sim.ws, tab, mem, u)
        return u

    def set_push(x):
        push[0] = float(x)

    return dict(sim=sim, controller=controller,
                gains={"push [N]": (-150.0, 150.0, lambda: push[0], set_push)},
                labels=lambda _sim: {"phase": mem[MEM.phase]},
                label_names={"phase": {int(p): p.name.lower() for p in Phase}})
