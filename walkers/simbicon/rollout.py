"""Compiled rollout of the SIMBICON biped and the Python ``simulate`` entry point.

``rollout_simbicon`` runs physics + controller + recording + a torso push without returning to
Python. A push is (fx [N], fy [N], start [s], duration [s]) applied at the torso COM through
``State.ext_force``. The run stops early (code FELL) once the torso COM is below
``fall_height`` above the ground.
"""
from __future__ import annotations

import numpy as np

import planarsim as ps
from planarsim import Simulator, make_options
from planarsim.compiled import (RUN_FELL, RUN_NONFINITE, RUN_TOO_LARGE, RUN_WALKER, audit_counts,
                                check_run,
                                jit, record_frame, step, height, make_recorder)
from planarsim.trajectory import Trajectory

from .controller import (M_EFFORT, M_FELL, M_PHASE, M_STRIKES, M_TIMEOUTS, Phase, control, make_memory,
                         make_tables)
from .model import build, non_foot_clearance, start_state
from .params import SimbiconParams

FELL = RUN_FELL   # rollout return code: the torso came down
GLITCH = RUN_WALKER + 2  # rollout return code: the torso moved faster than a walker can (solver blow-up)
STRATEGY = "all"   # engine contact-mode strategy (see the report: "alternating" hits its cap often with box feet)
GLITCH_SPEED = 10.0   # [m/s] torso COM speed taken as a solver glitch
GLITCH_SPIN = 30.0    # [rad/s] torso angular speed taken as a solver glitch


@jit
def rollout_simbicon(m, s, ws, opt, tab, mem, u, n, every, rec, k0, push):
    """n steps; returns (code, steps done, frames recorded). code: 0 ok, guard code, or FELL."""
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
            mem[M_EFFORT] += ws.act_u[a] * ws.act_u[a] * m.dt
        jump = max(abs(s.q[tr, 0] - x_before), abs(s.q[tr, 1] - y_before)) / m.dt
        if (abs(s.v[tr, 0]) > GLITCH_SPEED or abs(s.v[tr, 1]) > GLITCH_SPEED
                or abs(s.v[tr, 2]) > GLITCH_SPIN or jump > GLITCH_SPEED):
            mem[M_FELL] = 1.0
            return GLITCH, i + 1, k
        if (s.step[0] % every) == 0 and k < rec.t.shape[0]:
            record_frame(s, ws, rec, k)
            k += 1
        if s.q[tr, 1] - height(m.terrain_coef, s.q[tr, 0]) < tab.fall_height:
            mem[M_FELL] = 1.0
            return FELL, i + 1, k
    return 0, n, k


def _push_array(push):
    """None | (fx, start, duration) | dict(force=fx or (fx, fy), start=, duration=) -> (4,)."""
    if push is None:
        return np.array([0.0, 0.0, -1.0, 0.0])
    if isinstance(push, dict):
        f = np.atleast_1d(np.asarray(push["force"], dtype=np.float64))
        fx, fy = (f[0], f[1]) if f.size > 1 else (f[0], 0.0)
        start, dur = push.get("start", 0.0), push.get("duration", 0.2)
    else:
        fx, start, dur = push
        fy = 0.0
    arr = np.array([fx, fy, start, dur], dtype=np.float64)
    if not np.all(np.isfinite(arr)) or arr[3] < 0:
        raise ValueError(f"push={push!r} must be finite with duration >= 0")
    return arr


def run(params: SimbiconParams, duration: float, terrain=None, dt=1e-3, push=None,
        record_every: int = 10, model=None, record: bool = True, strategy: str = STRATEGY,
        glitch_ok: bool = True):
    """Compiled rollout from the standing start pose. With glitch_ok (default) an engine
    divergence (SimulationDiverged) ends the run as a glitch instead of raising.

    Returns (Trajectory or None, summary dict, model). summary: distance [m] (torso x), speed
    [m/s] (distance / simulated time), steps (swing-foot strikes), timeouts (contact states
    ended by the timeout), fell (torso came down or a non-foot part touched the ground),
    time [s] simulated, effort [N^2 m^2 s] (integral of the sum of squared applied torques),
    min_clearance [m] (lowest non-foot part above the ground, when recorded).
    """
    model = model if model is not None else build(params, terrain, dt)
    sim = Simulator(model, make_options(strategy), state=start_state(model, params.start_lean,
                                                                             params.start_speed))
    tab = make_tables(params, model)
    mem = make_memory()
    u = np.zeros(model.n_act)
    n = int(round(duration / model.dt))
    every = int(record_every) if record else n + 1
    rec = make_recorder(model, n // every + 1 if record else 0)
    x0 = float(sim.state.q[tab.torso, 0])
    code, done, k = rollout_simbicon(model.arrays, sim.state, sim.ws, sim.options, tab, mem, u, n,
                                     every, rec, 0, _push_array(push))
    if code in (RUN_NONFINITE, RUN_TOO_LARGE) and glitch_ok:
        # the state blew up in the last step: a solver glitch (for tuning, a lost run)
        code = GLITCH
        sim.state.restore(sim.ws.prev)
    check_run(code, model, sim.ws, sim.options, "simbicon")   # any other engine failure raises
    t = float(sim.state.time[0])
    summary = dict(distance=float(sim.state.q[tab.torso, 0] - x0), time=t,
                   steps=int(mem[M_STRIKES]), timeouts=int(mem[M_TIMEOUTS]),
                   fell=bool(code in (FELL, GLITCH)), glitch=bool(code == GLITCH),
                   phase=int(mem[M_PHASE]), audit=audit_counts(sim.ws),
                   effort=float(mem[M_EFFORT]))
    summary["speed"] = summary["distance"] / t if t > 0 else 0.0
    traj = None
    if record:
        traj = Trajectory.from_recorder(model, rec, k, info={"dt": model.dt, "walker": "simbicon"})
        clearance = float(non_foot_clearance(model, traj.q).min()) if k else np.inf
        summary["min_clearance"] = clearance
        summary["fell"] = summary["fell"] or clearance < 0.0
    return traj, summary, model


def simulate(duration, gait="walk", terrain=None, dt=1e-3, seed=0, push=None, params=None,
             record_every=10):
    """Uniform walker entry point: (Trajectory, summary, model). The walker is deterministic;
    `seed` is accepted for the common interface and recorded in the trajectory info."""
    if gait != "walk":
        raise ValueError(f"simbicon gait {gait!r} unknown; gaits: ('walk',)")
    params = params if params is not None else SimbiconParams()
    traj, summary, model = run(params, duration, terrain=terrain, dt=dt, push=push,
                               record_every=record_every)
    traj.info["seed"] = seed
    return traj, summary, model


def live(gait="walk", terrain=None, params=None) -> dict:
    """Hook for the interactive viewer (planarsim.render.viewer.view_walker): a Simulator from
    the standing start and the compiled controller called from Python each step; a slider
    pushes the torso [N] (hold it to push)."""
    if gait != "walk":
        raise ValueError(f"simbicon gait {gait!r} unknown; gaits: ('walk',)")
    params = params if params is not None else SimbiconParams()
    if isinstance(terrain, str):
        terrain = ps.terrain.parse(terrain)
    model = build(params, terrain)
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
                labels=lambda _sim: {"phase": mem[M_PHASE]},
                label_names={"phase": {int(p): p.name.lower() for p in Phase}})
