"""Compiled Ranger rollout and the uniform ``simulate(...)`` entry point.

``rollout_ranger`` runs physics + controller + recording without returning to Python; it stops
early when the walker falls. ``simulate`` returns (Trajectory, summary, model); the summary holds
distance, mean speed, steps, step length, fell, and the cost of transport averaged over whole
steps (first to last heel strike):
    CoT = E / (m g d)      (eq. 17 integrated; m the total mass, d the hip's travel)
for the electrical energy of the three motors counted positive only (Ranger's drivers do not
regenerate into the battery), the same plus the 4.5 W overhead ("total", the robot's 0.28 is of
this kind), the net electrical energy, and the positive mechanical work of the motors.
``instantaneous_cot(traj, model)`` gives eq. 17 frame by frame.
"""
from __future__ import annotations

import numpy as np

from planarsim.compiled import audit_counts, check_run, jit, record_frame, step, make_recorder
import planarsim as ps
from planarsim.trajectory import Trajectory

from . import controller as C
from . import tables as T
from .controller import Controller, control_ranger
from .model import build
from .params import RangerParams

# controller memory recorded with every frame (Trajectory.labels)
LABELS = {"gait": C.M_GAIT, "phase": C.M_PHASE, "stance": C.M_STANCE,
          "load_outer": C.M_RAW, "load_inner": C.M_RAW + 1,
          "load_filtered_outer": C.M_SIG, "load_filtered_inner": C.M_SIG + 1,
          "contact_outer": C.M_CONTACT, "contact_inner": C.M_CONTACT + 1,
          "program_hip": C.M_PROG, "program_outer_ankle": C.M_PROG + 1, "program_inner_ankle": C.M_PROG + 2,
          "current_hip": C.M_CUR, "current_outer_ankle": C.M_CUR + 1, "current_inner_ankle": C.M_CUR + 2,
          "power_hip": C.M_PEL, "power_outer_ankle": C.M_PEL + 1, "power_inner_ankle": C.M_PEL + 2,
          "push_current": C.M_PUSH_I, "steps": C.M_STEPS}
LABEL_INDEX = np.array(list(LABELS.values()), dtype=np.int64)
GAITS = ("walk", "stand", "gui")


@jit
def rollout_ranger(m, s, ws, opt, k, prog, motor, mem, gui, steplog, u, n, every, rec, lab, lab_idx, k0):
    """n control+physics steps; record every `every` steps from frame k0.
    Returns (guard code, steps done, next frame); stops after the step where the walker fell."""
    kf = k0
    for i in range(n):
        control_ranger(m, s, ws, k, prog, motor, mem, gui, steplog, u)
        code = step(m, s, ws, opt, u)
        if code != 0:
            return code, i, kf
        if (s.step[0] % every) == 0 and kf < rec.t.shape[0]:
            record_frame(s, ws, rec, kf)
            for c in range(lab_idx.shape[0]):
                lab[kf, c] = mem[lab_idx[c]]
            kf += 1
        if mem[C.M_FELL] != 0.0:
            return 0, i + 1, kf
    return 0, n, kf


def step_options(strategy: str = "alternating") -> ps.StepOptions:
    """Ranger's StepOptions: the engine defaults (cap_policy=1: a contact engaged in a step
    whose mode rounds hit the cap sticks) with the chosen contact-mode strategy."""
    return ps.make_options(strategy)


class RangerSim:
    """A Simulator plus the compiled controller; ``run(duration)`` extends the recording.

    The model starts at rest in the STAND pose for every gait; WALK starts from it through the
    controller's START phase. ``options`` overrides Ranger's StepOptions (step_options()).

    >>> rs = RangerSim(gait="stand")          # doctest: +SKIP
    >>> traj = rs.run(5.0); rs.controller.set_gait("walk"); traj2 = rs.run(10.0)
    """

    def __init__(self, params: RangerParams | None = None, terrain=None, dt: float = 1e-3,
                 gait: str = "walk", strategy: str = "alternating", suspended: bool = False,
                 max_steps: int = 20000, options: ps.StepOptions | None = None):
        self.params = params if params is not None else RangerParams()
        self.model = build(self.params, terrain, dt=dt, suspended=suspended)
        self.sim = ps.Simulator(self.model, options if options is not None else step_options(strategy))
        self.controller = Controller(self.params, dt, max_steps=max_steps)
        self.controller.reset(gait)
        self.u = np.zeros(self.model.n_act)

    def run(self, duration: float, record_every: int = 10) -> Trajectory:
        m, s, ws, opt = self.model.arrays, self.sim.state, self.sim.ws, self.sim.options
        n = int(round(duration / m.dt))
        rec = make_recorder(self.model, n // record_every + 1)
        lab = np.zeros((len(rec.t), len(LABEL_INDEX)))
        c = self.controller
        code, done, kf = rollout_ranger(m, s, ws, opt, c.k, c.prog, c.motor, c.mem, c.gui, c.steplog,
                                        self.u, n, int(record_every), rec, lab, LABEL_INDEX, 0)
        check_run(code, self.model, ws, opt, "ranger")
        labels = {name: lab[:kf, i] for i, name in enumerate(LABELS)}
        return Trajectory.from_recorder(self.model, rec, kf, labels=labels,
                                        info={"dt": m.dt, "walker": "ranger"})

    @property
    def fell(self) -> bool:
        return bool(self.controller.mem[C.M_FELL])

    @property
    def steps(self) -> int:
        return int(self.controller.mem[C.M_STEPS])

    def hip(self):
        """Hip position [m]."""
        q = self.sim.state.q
        p = self.params
        return np.array([q[0, 0] - p.leg_com * np.sin(q[0, 2]), q[0, 1] + p.leg_com * np.cos(q[0, 2])])

    def summary(self) -> dict:
        return {**summarize(self.controller, self.model, self.sim.state, self.params),
                "audit": audit_counts(self.sim.ws)}


def summarize(ctrl: Controller, model, state, p: RangerParams) -> dict:
    """Distance, speed, steps and whole-step costs of transport from the step log."""
    n = int(ctrl.mem[C.M_STEPS])
    log = ctrl.steplog[:min(n, len(ctrl.steplog))]
    weight = 9.81 * float(model.arrays.body_mass.sum())
    out = {"steps": n, "fell": bool(ctrl.mem[C.M_FELL]), "time": float(state.time[0]),
           "distance": float(state.q[0, 0] - model.q0[0, 0])}
    out["mean_speed"] = out["distance"] / out["time"] if out["time"] > 0 else 0.0
    if len(log) >= 3:
        first, last = 1, len(log) - 1          # skip the start-up step
        d = log[last, 1] - log[first, 1]
        dt = log[last, 0] - log[first, 0]
        e = log[last, 2:6] - log[first, 2:6]
        out.update(step_speed=d / dt, step_length=d / (last - first), step_period=dt / (last - first),
                   cost_of_transport_electrical=e[0] / (weight * d),
                   cost_of_transport=(e[0] + p.overhead_power * dt) / (weight * d),
                   cost_of_transport_electrical_net=e[1] / (weight * d),
                   cost_of_transport_mechanical=e[2] / (weight * d),
                   cost_of_transport_mechanical_net=e[3] / (weight * d),
                   push_current_mean=float(log[first:last + 1, 6].mean()))
    else:
        out.update(step_speed=float("nan"), step_length=float("nan"), step_period=float("nan"),
                   cost_of_transport=float("nan"), cost_of_transport_electrical=float("nan"),
                   cost_of_transport_electrical_net=float("nan"),
                   cost_of_transport_mechanical=float("nan"),
                   cost_of_transport_mechanical_net=float("nan"), push_current_mean=float("nan"))
    return out


def instantaneous_cot(traj: Trajectory, model, overhead_power: float = 4.5, min_speed: float = 0.05):
    """Eq. 17 per frame: (motor electrical power, positive part, + overhead) / (weight * COM
    speed); NaN where the forward COM speed is below min_speed [m/s]."""
    power = sum(np.maximum(traj.labels[k], 0.0) for k in ("power_hip", "power_outer_ankle", "power_inner_ankle"))
    speed = traj.com_velocity(model)[:, 0]
    weight = 9.81 * float(model.arrays.body_mass.sum())
    cot = (power + overhead_power) / (weight * np.where(speed > min_speed, speed, np.nan))
    return cot


def live(gait: str = "walk", terrain=None, params: RangerParams | None = None,
         strategy: str = "alternating") -> dict:
    """Hook for the interactive viewer (planarsim.render.viewer.view_walker): a Simulator and the
    Python-path Controller; keys w / s / g for WALK / STAND / GUI; sliders for the GUI joint
    targets [rad] (Kelly 2014, 6.1: the GUI mode sets joint targets and gains)."""
    if gait not in GAITS:
        raise ValueError(f"Ranger gait {gait!r} unknown; use one of {GAITS}")
    if isinstance(terrain, str):
        terrain = ps.terrain.parse(terrain)
    rs = RangerSim(params, terrain, gait=gait, strategy=strategy)
    ctrl, mem, gui = rs.controller, rs.controller.mem, rs.controller.gui

    def slider(j, lo, hi):
        return (lo, hi, lambda: float(gui[j, 0]), lambda x: ctrl.set_gui(j, float(x)))

    return dict(sim=rs.sim, controller=ctrl, on_gait=ctrl.set_gait,
                gait_keys={"w": "walk", "s": "stand", "g": "gui"},
                gains={"GUI hip [rad]": slider(0, -0.8, 0.8), "GUI outer ankle [rad]": slider(1, -1.5, 1.5),
                       "GUI inner ankle [rad]": slider(2, -1.5, 1.5)},
                labels=lambda _sim: {"gait": mem[C.M_GAIT], "phase": mem[C.M_PHASE]},
                label_names={"gait": {int(g): g.name.lower() for g in C.Gait},
                             "phase": {int(p): p.name.lower() for p in T.Phase}})


def simulate(duration: float, gait: str = "walk", terrain=None, dt: float = 1e-3, seed: int = 0,
             params: RangerParams | None = None, strategy: str = "alternating", record_every: int = 10):
    """Run Ranger from rest in the STAND pose (WALK starts through the START phase).
    Returns (Trajectory, summary dict, model).

    gait : 'walk' | 'stand' | 'gui'. The run is deterministic; `seed` is accepted for the
    uniform walker interface (no randomness is used).
    """
    if gait not in GAITS:
        raise ValueError(f"Ranger gait {gait!r} unknown; use one of {GAITS}")
    if isinstance(terrain, str):
        terrain = ps.terrain.parse(terrain)
    rs = RangerSim(params, terrain, dt, gait, strategy)
    traj = rs.run(duration, record_every)
    summary = rs.summary()
    traj.info.update({"gait": gait, "seed": seed})
    return traj, summary, rs.model
