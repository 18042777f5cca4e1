"""Compiled Ranger rollout, its run class (``Run``, a walkers.base.WalkerRun) and the
uniform ``simulate(...)`` entry point.

``rollout_ranger`` runs physics + controller + recording without returning to Python; it stops
early when the walker falls. ``simulate`` returns (Trajectory, summary, model); the summary holds
distance, mean speed, steps, step length, fell, and the cost of transport averaged over whole
steps (second to last heel strike, from the controller memory's records of them, so a snapshot
of state and memory carries them; ``Run.heel_strikes()`` gives the step log's row per strike):
    CoT = E / (m g d)      (eq. 17 integrated; m the total mass, d the hip's travel)
for the electrical energy of the three motors counted positive only (Ranger's drivers do not
regenerate into the battery), the same plus the 4.5 W overhead ("total", the robot's 0.28 is of
this kind), the net electrical energy, and the positive mechanical work of the motors.
``instantaneous_cot(traj, model)`` gives eq. 17 frame by frame.
"""
from __future__ import annotations

import warnings

import numpy as np

from planarsim.compiled import jit, step
import planarsim as ps
from planarsim.checks import flag, whole
from planarsim.trajectory import Trajectory

from walkers.base import WalkerRun, check_controlled_dt, simulation, start_rng, terrain_of
from walkers.common.record import record_labelled
from walkers.common.slots import label_slots

from . import controller as C
from . import tables as T
from .controller import Controller, control, count_step_energy
from .model import build
from .params import RangerParams

# controller memory recorded with every frame (Trajectory.labels): label -> memory field
# ("field:k": its slot k)
LABELS = {"gait": "gait", "phase": "phase", "stance": "stance",
          "load_outer": "raw", "load_inner": "raw:1",
          "load_filtered_outer": "sig", "load_filtered_inner": "sig:1",
          "contact_outer": "contact", "contact_inner": "contact:1",
          "program_hip": "prog", "program_outer_ankle": "prog:1", "program_inner_ankle": "prog:2",
          "current_hip": "cur", "current_outer_ankle": "cur:1", "current_inner_ankle": "cur:2",
          "power_hip": "pel", "power_outer_ankle": "pel:1", "power_inner_ankle": "pel:2",
          "push_current": "push_i", "steps": "steps"}
LABEL_INDEX = label_slots(C.MEM, LABELS.values())
GAITS = ("walk", "stand", "gui")


@jit
def rollout_ranger(m, s, ws, opt, tab, mem, u, n, every, rec, lab, lab_idx, k0):
    """n control+physics steps; record every `every` steps from frame k0.
    Returns (guard code, steps done, next frame); stops after the step where the walker fell."""
    kf = k0
    for i in range(n):
        control(m, s, ws, tab, mem, u)
        code = step(m, s, ws, opt, u)
        if code != 0:
            return code, i, kf
        count_step_energy(m, s, ws, tab.k[T.CONST.dt], tab.motor, mem)
        kf = record_labelled(s, ws, rec, lab, mem, lab_idx, every, kf)
        if mem[C.MEM.fell] != 0.0:
            return 0, i + 1, kf
    return 0, n, kf


def _gravity(model) -> float:
    """The model's gravity [m/s^2] (its magnitude)."""
    return float(np.hypot(*model.arrays.gravity))


def step_options(strategy: str = "alternating") -> ps.StepOptions:
    """Ranger's StepOptions: the engine defaults with the chosen contact-mode strategy."""
    return ps.make_options(strategy)


class Run(WalkerRun):
    """Ranger in the world (a WalkerRun) with its Controller (tables, memory, gait switches).

    The model starts at rest in the STAND pose for every gait; WALK starts from it through the
    controller's START phase. ``options`` overrides Ranger's StepOptions (step_options()).

    >>> rs = Run(gait="stand")                # doctest: +SKIP
    >>> traj = rs.run(5.0); rs.set_gait("walk"); traj2 = rs.run(10.0)
    """

    NAME = "ranger"
    LABELS = tuple(LABELS)
    FELL_SLOT = C.MEM.fell
    ROLLOUT = staticmethod(rollout_ranger)
    LABEL_SLOTS = LABEL_INDEX

    def __init__(self, params: RangerParams | None = None, terrain=None, dt: float = 1e-3,
                 gait: str = "walk", strategy: str = "alternating", suspended: bool = False,
                 max_steps: int = 20000, options: ps.StepOptions | None = None,
                 record_every: int = 10, seed: int = 0):
        if gait not in GAITS:
            raise ValueError(f"Ranger gait {gait!r} unknown; use one of {GAITS}")
        whole(f"{self.NAME}: max_steps", max_steps, least=1,
              why="the most walking steps the controller keeps a record of")
        flag(f"{self.NAME}: suspended", suspended)
        start_rng(self.NAME, seed)      # (Ranger starts from one pose: checked all the same)
        params = params if params is not None else RangerParams()
        model = build(params, terrain_of(terrain), dt=dt, suspended=suspended)
        check_controlled_dt(self.NAME, model.dt)      # (before the controller's filters)
        self.controller = Controller(params, dt, max_steps=max_steps, gravity=_gravity(model))
        self.controller.reset(gait)
        super().__init__(model, params, self.controller.tables, self.controller.mem,
                         options=options if options is not None else step_options(strategy),
                         record_every=record_every)

    def set_gait(self, gait) -> None:
        """Switch to "walk" | "stand" | "gui" at run time."""
        self.controller.set_gait(gait)

    @property
    def steps(self) -> int:
        return int(self.memory[C.MEM.steps])

    def hip(self):
        """Hip position [m]."""
        q = self.state.q
        p = self.params
        return np.array([q[0, 0] - p.leg_com * np.sin(q[0, 2]), q[0, 1] + p.leg_com * np.cos(q[0, 2])])

    def numbers(self) -> dict:
        """Distance, speed, steps and the whole-step numbers (see the module doc), from the
        state and the controller memory alone: a run restored from a snapshot of state and
        memory reports what one run does."""
        mem, model = self.memory, self.model
        weight = _gravity(model) * float(model.arrays.body_mass.sum())
        out = {"steps": int(mem[C.MEM.steps]), "fell": self.fell, "time": self.time,
               "distance": float(self.state.q[0, 0] - model.q0[0, 0])}
        out["mean_speed"] = out["distance"] / out["time"] if out["time"] > 0 else 0.0
        out.update(whole_step_numbers(mem, weight, self.params.overhead_power))
        return out

    def heel_strikes(self) -> np.ndarray:
        """The step log's rows of this walk's heel strikes, one per strike in order (columns
        tables.LOG: time [s], hip x [m], the energies [J], push-off current [A]), at most
        max_steps of them (a warning says when later strikes are not logged). A ValueError
        where the log does not hold this walk's strikes: a snapshot of state and memory
        restored into another Run carries the whole-step numbers (in the memory) but not the
        rows of the strikes before it, which that Run's log never had."""
        n = int(self.memory[C.MEM.steps])
        rows = self.tables.steplog[:min(n, len(self.tables.steplog))]
        if not log_holds(rows, self.memory):
            raise ValueError(f"{self.NAME}: the step log does not hold this walk's {n} heel "
                             "strikes (its memory was restored from another run: a snapshot of "
                             "state and memory carries the whole-step numbers of summary(), not "
                             "the log's rows before it)")
        if n > len(rows):
            warnings.warn(f"{self.NAME}: the step log holds the first {len(rows)} of {n} heel "
                          "strikes (Run(max_steps=...) gives it more room)", stacklevel=2)
        return rows.copy()


WHOLE_STEP_KEYS = ("step_speed", "step_length", "step_period", "cost_of_transport",
                   "cost_of_transport_electrical", "cost_of_transport_electrical_net",
                   "cost_of_transport_mechanical", "cost_of_transport_mechanical_net",
                   "push_current_mean")


def strike_record(mem, slot: int) -> np.ndarray:
    """The heel-strike record (columns tables.LOG) at memory slot `slot` (MEM.strike_first or
    MEM.strike_last)."""
    return mem[slot:slot + T.N_LOG]


def whole_step_numbers(mem, weight: float, overhead_power: float) -> dict:
    """The numbers over whole steps, from the second heel strike to the last (the start-up
    step left out), of controller memory `mem`'s records of those strikes, for the robot's
    weight [N] and the computers' overhead_power [W]: speed [m/s], step length [m] and
    period [s], the costs of transport (module doc) and the mean push-off current [A] of the
    strikes from the second on; NaN for fewer than 3 strikes."""
    n = int(mem[C.MEM.steps])
    if n < 3:
        return dict.fromkeys(WHOLE_STEP_KEYS, float("nan"))
    first, last = strike_record(mem, C.MEM.strike_first), strike_record(mem, C.MEM.strike_last)
    d = last[T.LOG.hip_x] - first[T.LOG.hip_x]
    dt = last[T.LOG.t] - first[T.LOG.t]
    e = last[T.LOG.e:T.LOG.e + 4] - first[T.LOG.e:T.LOG.e + 4]
    # a cost of transport is per distance travelled forward: none (nan) for whole steps that
    # went nowhere or backwards (energy over a negative distance would read as a negative
    # cost, and a tuner would take it for a gain)
    per = weight * d if d > 0.0 else float("nan")
    whole = n - 2
    return dict(step_speed=d / dt, step_length=d / whole, step_period=dt / whole,
                cost_of_transport_electrical=e[0] / per,
                cost_of_transport=(e[0] + overhead_power * dt) / per,
                cost_of_transport_electrical_net=e[1] / per,
                cost_of_transport_mechanical=e[2] / per,
                cost_of_transport_mechanical_net=e[3] / per,
                push_current_mean=float(mem[C.MEM.push_sum] / (n - 1)))


def log_holds(rows, mem) -> bool:
    """Whether the step log's `rows` (its first min(steps, max_steps)) are the heel strikes of
    memory `mem`'s walk: none left unwritten (NaN), the second and (when logged) the last equal
    to the memory's records of them, and the logged push-off currents from the second strike
    on adding up, in order, to the memory's sum."""
    n = int(mem[C.MEM.steps])
    if np.isnan(rows).any():
        return False
    if n >= 2 and not np.array_equal(rows[1], strike_record(mem, C.MEM.strike_first)):
        return False
    if n == 0 or n > len(rows):
        return True
    if not np.array_equal(rows[-1], strike_record(mem, C.MEM.strike_last)):
        return False
    return n < 2 or np.cumsum(rows[1:, T.LOG.push_i])[-1] == mem[C.MEM.push_sum]


simulate = simulation(Run)


def instantaneous_cot(traj: Trajectory, model, overhead_power: float = 4.5, min_speed: float = 0.05):
    """Eq. 17 per frame: (motor electrical power, positive part, + overhead) / (weight * COM
    speed); NaN where the forward COM speed is below min_speed [m/s]."""
    power = sum(np.maximum(traj.labels[k], 0.0) for k in ("power_hip", "power_outer_ankle", "power_inner_ankle"))
    speed = traj.com_velocity(model)[:, 0]
    weight = _gravity(model) * float(model.arrays.body_mass.sum())
    cot = (power + overhead_power) / (weight * np.where(speed > min_speed, speed, np.nan))
    return cot


def live(gait: str = "walk", terrain=None, params: RangerParams | None = None,
         strategy: str = "alternating") -> dict:
    """Hook for the interactive viewer (planarsim.render.viewer.view_walker): a Simulator and the
    Python-path Controller; keys w / s / g for WALK / STAND / GUI; sliders for the GUI joint
    targets [rad] (Kelly 2014, 6.1: the GUI mode sets joint targets and gains)."""
    rs = Run(params, terrain, gait=gait, strategy=strategy)
    sim = ps.Simulator(rs.model, rs.options, rs.state)
    ctrl, mem, gui = rs.controller, rs.memory, rs.tables.gui

    def slider(j, lo, hi):
        return (lo, hi, lambda: float(gui[j, 0]), lambda x: ctrl.set_gui(j, float(x)))

    return dict(sim=sim, controller=ctrl, on_gait=ctrl.set_gait,
                gait_keys={"w": "walk", "s": "stand", "g": "gui"},
                gains={"GUI hip [rad]": slider(0, -0.8, 0.8), "GUI outer ankle [rad]": slider(1, -1.5, 1.5),
                       "GUI inner ankle [rad]": slider(2, -1.5, 1.5)},
                labels=lambda _sim: {"gait": mem[C.MEM.gait], "phase": mem[C.MEM.phase]},
                label_names={"gait": {int(g): g.name.lower() for g in C.Gait},
                             "phase": {int(p): p.name.lower() for p in T.Phase}})
