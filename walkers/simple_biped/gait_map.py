"""Step-to-step map of the walking Simple Biped, for planarsim.analysis.

Section: the controller's own touchdown (controller.next_state: WALK_SINGLE -> WALK_DOUBLE,
MEM.steps += 1), taken just after ``control`` made that switch and before the physics step, so
the section state is (State, controller memory) with the memory already reset for the new
step: the swing Bezier, lift-off / strike x and phase are rewritten at the next lift-off,
MEM.step_t / MEM.step_x equal the section time and hip x. The one memory value that carries over
is the adapted pendulum top speed MEM.v_top (an integrator). Replaying ``control`` on the
restored section state recomputes the same commands (t_in = 0 < ds_time_min: no transition).

Section coordinates (stance = the foot that just touched down, front foot; rear = the other;
both feet on the ground, pinned, at rest):
  x = (hip x - front foot x [m], hip y - front foot y [m], hip vx [m/s], hip vy [m/s],
       rear foot x - front foot x [m], v_top [m/s])
The map runs two touchdowns, back to the same stance foot (no symmetry assumption).
Perturbations move the hip (and MEM.step_x with it) and the rear foot along the ground; the foot
velocities and contact modes stay those of the reference section.
"""
from __future__ import annotations

import numpy as np

from planarsim.analysis import StepMap, StepMapError
from planarsim.compiled import RUN_FELL, RUN_NO_EVENT, RUN_OK, check_run, jit, step

from walkers.common.section import GaitMapMixin, copy_tuple, restore_tuple
from walkers.common.work import add_positive_work

from . import controller as C
from .rollout import Run, fell_down

NAMES = ("hip_dx", "hip_dy", "hip_vx", "hip_vy", "rear_dx", "v_top")
DT = 1e-4       # [s] analysis step: the controller switches at step boundaries, which makes the
                # map jump by O(dt) (about 2e-3 m/s in hip vx at dt = 1 ms, 1e-4 at 0.1 ms);
                # finite differences need steps well above those jumps
SETTLE = 20.0   # [s] walking before the reference section (the gait has converged by then)
EPS = 3e-3      # finite-difference step [m, m/s]


@jit
def rollout_to_touchdown(m, s, ws, opt, tab, mem, u, n_events, max_steps):
    """Control + physics until the controller has counted n_events more touchdowns; stops right
    after the ``control`` call that counted the last one (before its physics step). The
    actuators' positive work is kept in mem[MEM.work] as the walking run keeps it.
    Returns (code, steps done): 0 ok, 1/2 engine guard, 3 fell, 4 no touchdown in max_steps."""
    p = tab.p
    start = mem[C.MEM.steps]
    for i in range(max_steps):
        C.control(m, s, ws, tab, mem, u)
        if mem[C.MEM.steps] - start >= n_events:
            return 0, i
        code = step(m, s, ws, opt, u)
        if code != 0:
            return code, i
        add_positive_work(ws, mem, C.MEM.work, m.dt)
        if fell_down(m, s, p):
            mem[C.MEM.fallen] = 1.0
            return RUN_FELL, i + 1
    return RUN_NO_EVENT, max_steps


class SimpleBipedGaitMap(GaitMapMixin):
    """Section snapshot of a walking Simple Biped and its two-step map.

    ``SimpleBipedGaitMap(settle=20.0, speed=None)`` walks from rest for `settle` [s], then to
    the next touchdown of foot 0: that section state is the reference (the converged limit
    cycle when settle is long enough). ``x0`` its coordinates; ``step_map()`` the StepMap.
    """

    SECTION = "controller touchdown (WALK_SINGLE -> WALK_DOUBLE) of foot 0, stride map (2 steps)"
    names = NAMES

    def __init__(self, settle: float = SETTLE, speed=None, params=None, dt: float = DT, stance: int = 0):
        self.dt, self.settle = float(dt), float(settle)
        self.walker = w = Run(params, dt=dt, gait="walk", speed=speed, record_every=10 ** 9)
        self.m = w.model.arrays
        self.max_steps = int(round(4.0 / dt))
        code, _ = rollout_to_touchdown(self.m, w.state, w.ws, w.options, w.tables, w.memory, w.u, 10 ** 9,
                                       int(round(settle / dt)))
        if code not in (RUN_OK, RUN_NO_EVENT) or w.fell:
            raise StepMapError(f"the Simple Biped failed while settling (code {code})")
        for _ in range(3):   # to a touchdown of the requested foot
            self._run(w.state, w.ws, w.memory, 1)
            if int(w.memory[C.MEM.stance]) == stance:
                break
        else:
            raise StepMapError(f"no touchdown of foot {stance} while settling")
        self.stance = stance
        self.state0 = w.state.copy()
        self.ws0 = copy_tuple(w.ws)
        self.mem0 = w.memory.copy()
        self.x0 = self.coords(self.state0, self.mem0)
        # scratch simulation the map evaluations run in
        self.s = w.state.copy()
        self.ws = copy_tuple(w.ws)
        self.mem = w.memory.copy()

    def _run(self, s, ws, mem, n_events):
        w = self.walker
        code, n = rollout_to_touchdown(self.m, s, ws, w.options, w.tables, mem, w.u, n_events, self.max_steps)
        # an engine failure raises (it is not a fall of the walker); a fall or no touchdown
        # is the map's own failure
        check_run(code, w.model, ws, w.options, "Simple Biped step map")
        if code != 0:
            what = {RUN_FELL: "fell", RUN_NO_EVENT: "no touchdown"}[code]
            raise StepMapError(f"Simple Biped step map: {what} (t={s.time[0]:.3f} s)")
        return n

    def coords(self, s, mem) -> np.ndarray:
        """Section coordinates (see module doc) of a section state."""
        st = int(mem[C.MEM.stance])
        q, v = s.q, s.v
        f, r = st + 1, 2 - st
        return np.array([q[0, 0] - q[f, 0], q[0, 1] - q[f, 1], v[0, 0], v[0, 1], q[r, 0] - q[f, 0],
                         mem[C.MEM.v_top]])

    def set_section(self, x) -> None:
        """Scratch simulation := reference section with coordinates x."""
        restore_tuple(self.s, self.state0)
        restore_tuple(self.ws, self.ws0)
        self.mem[:] = self.mem0
        d = np.asarray(x, dtype=np.float64) - self.x0
        r = 2 - self.stance
        self.s.q[0, 0] += d[0]
        self.s.q[0, 1] += d[1]
        self.s.v[0, 0] += d[2]
        self.s.v[0, 1] += d[3]
        self.s.q[r, 0] += d[4]
        self.mem[C.MEM.v_top] += d[5]
        self.mem[C.MEM.step_x] = self.s.q[0, 0]

    def advance(self, x) -> np.ndarray:
        """Two touchdowns from section coordinates x; the coordinates at the second one."""
        self.set_section(x)
        self.advance_from_section()
        return self.coords(self.s, self.mem)

    def advance_from_section(self) -> None:
        """The scratch simulation (set_section) run through two touchdowns, back to the stance
        foot."""
        self._run(self.s, self.ws, self.mem, 2)
        if int(self.mem[C.MEM.stance]) != self.stance:
            raise StepMapError("Simple Biped step map: the two touchdowns did not alternate feet")

    def step_map(self) -> StepMap:
        return StepMap(self.advance, dim=len(NAMES), names=NAMES)

    def cycle(self, x) -> dict:
        """One period of the map from section coordinates x (advance's two touchdowns), measured
        as the walking run measures a walk: duration [s], distance [m] the hip moved forward,
        positive_work [J] of the actuators and weight [N] (cost of transport = work / (weight
        distance))."""
        self.set_section(x)
        t0, x_hip, work0 = float(self.s.time[0]), float(self.s.q[0, 0]), float(self.mem[C.MEM.work])
        self.advance_from_section()
        return {"duration": float(self.s.time[0]) - t0,
                "distance": float(self.s.q[0, 0]) - x_hip,
                "positive_work": float(self.mem[C.MEM.work]) - work0,
                "weight": self.walker.weight()}
