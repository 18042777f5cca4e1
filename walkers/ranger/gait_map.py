"""Step-to-step map of the walking Ranger, for planarsim.analysis.

Section: the controller's own mid-stance event (controller.choose_programs: the stance leg
passes vertical in single stance, MEM.mid_done 0 -> 1, and the step-to-step feedback sets this
step's push-off current MEM.push_i from the hip speed, i.e. the memory that would carry the
previous step over is rewritten from the state here). The section state is the simulation
just BEFORE the ``control`` call that fires the event: State, the last step's contact
impulses (the estimator's input), and the controller memory before that call (so replaying the
call runs the estimator filter exactly once). The other memory that carries over is the state of
the contact estimator's Butterworth filters (2 per foot): part of the section coordinates.

Section coordinates, stance side st (outer legs 0 by default), swing side sw = 1 - st (the
stance leg angle is the section condition, it stays at its reference value just past 0):
  x = (stance foot angle, swing leg angle, swing foot angle [rad],
       stance leg rate, swing leg rate, stance foot rate, swing foot rate [rad/s],
       filter state z0, z1 of the outer foot, z0, z1 of the inner foot [-])
The map runs one stride: to the next counted mid-stance of the same stance side. Counted are
only true crossings (stance leg within CROSS_TOL of vertical): with the shipped controller the
landing foot bounces, the estimator swaps the stance to the trailing leg for a few ms and the
mid-stance feedback fires there too, far behind vertical.

Findings (dt = 1 ms, shipped parameters, engine default StepOptions; figures
from ``python -c "from walkers.ranger.gait_map import RangerGaitMap; ..."``, see the test file):
the map is piecewise smooth with small jumps: the controller acts at 1 ms steps (contact
engagement, estimator hysteresis, program switches and the section event itself fall on step
boundaries), so P(x0 + t e_i) jumps by up to 1.6e-2 (rad/s, in the leg rates) between
perturbations t only 5e-4 apart (median 3e-4..4e-3). A central difference at eps = 1e-3 is
dominated by those jumps (spectral radius 0.3..12 depending on eps and on the 6th digit of a
parameter), so the Jacobian here is a least-squares slope over perturbations of +-0.5, 1, 2 eps
per coordinate, eps = 1e-2 (EPS), whose radius is consistent across eps = 2e-3..2e-2 (0.2..0.8
measured on the shipped and on nearby parameter sets).
The shipped gait settles on an exactly repeating stride on the engine at c758571
(|P(x0) - x0| = 3e-7: every event falls on the same step each stride); with the engine's
frictionless rule for a heel landing in Painleve's configuration it wanders within 1.9e-2
(spectral radius 0.48), and nearby parameter sets (1 % changes) mostly wander as well, within
~2e-2 of a mean section state (the jump scale) with multipliers of the same size (4 of 11 sets
measured return within 1e-3, spectral radius 0.37..0.78).
A perturbation rolls the stance foot on its sole (flat ground) and rebuilds every body pose
and velocity through the pins from it (walkers.common.section), the stance contact point at
rest, so the perturbed state is consistent with the pins and the pinned stance contact.
"""
from __future__ import annotations

import math

import numpy as np

from planarsim.analysis import StepMap, StepMapError
from planarsim.compiled import (RUN_FELL, RUN_NO_EVENT, RUN_OK, check_run, jit, step,
                                step_from_python as step_entry)

from walkers.common.section import GaitMapMixin, chain_poses, chain_velocities, copy_tuple, restore_tuple

from . import controller as C, tables as T
from .rollout import Run

NAMES = ("stance_foot_angle", "swing_leg_angle", "swing_foot_angle", "stance_leg_rate",
         "swing_leg_rate", "stance_foot_rate", "swing_foot_rate",
         "filter_outer_z0", "filter_outer_z1", "filter_inner_z0", "filter_inner_z1")
DT = 1e-3        # [s] the shipped step (the controller does not walk at dt = 1e-4)
SETTLE = 20.0    # [s] walking from the start pose before the reference section
EPS = 1e-2       # perturbation scale of the least-squares Jacobian [rad, rad/s, -]
LS_STEPS = (-2.0, -1.0, -0.5, 0.5, 1.0, 2.0)   # perturbations per coordinate, in units of eps
CROSS_TOL = 0.02   # [rad] a counted mid-stance has the stance leg within this of vertical


@jit
def rollout_to_midstance(m, s, ws, opt, tab, mem, mem_before, u, side, cross_tol, n_events,
                         max_steps):
    """Control + physics until the controller's mid-stance event has fired n_events times with
    leg `side` in stance and that leg within cross_tol [rad] of vertical (a true crossing: the
    event also fires when a landing foot's bounce makes the estimator swap the stance to the
    trailing leg, far behind vertical; those are not counted). On the last one, mem is put back
    to its value before that control call and the rollout stops before the physics step (s, ws
    untouched by it). Returns (code, steps done): 0 ok, 1/2 engine guard, 3 fell, 4 not enough
    events in max_steps."""
    count = 0
    for i in range(max_steps):
        for j in range(mem.shape[0]):
            mem_before[j] = mem[j]
        C.control(m, s, ws, tab, mem, u)
        st = int(mem[C.MEM.stance])
        if (mem_before[C.MEM.mid_done] == 0.0 and mem[C.MEM.mid_done] == 1.0 and st == side
                and int(mem_before[C.MEM.stance]) == side and s.q[st, 2] > -cross_tol):
            count += 1
            if count >= n_events:
                for j in range(mem.shape[0]):
                    mem[j] = mem_before[j]
                return 0, i
        code = step(m, s, ws, opt, u)
        if code != 0:
            return code, i
        if mem[C.MEM.fell] != 0.0:
            return RUN_FELL, i + 1
    return RUN_NO_EVENT, max_steps



class RangerGaitMap(GaitMapMixin):
    """Section snapshot of a walking Ranger and its stride map (two mid-stances).

    ``RangerGaitMap(settle=20.0, dt=1e-3)`` walks from the STAND pose (START phase) for `settle` [s],
    then on to the next mid-stance on side `stance` (0 outer): that section state is the
    reference (the converged limit cycle when settle is long enough). ``x0`` its coordinates;
    ``step_map()`` the StepMap.
    """

    SECTION = "controller mid-stance (outer stance leg passing vertical), stride map"
    names = NAMES

    def __init__(self, settle: float = SETTLE, dt: float = DT, params=None, stance: int = 0):
        self.dt, self.settle = float(dt), float(settle)
        self.rs = rs = Run(params, dt=dt, gait="walk", max_steps=16)
        self.model = rs.model
        self.m = rs.model.arrays
        self.tables = rs.tables._replace(steplog=T.make_step_log(16))
        self.mem_before = np.zeros_like(rs.memory)
        self.max_steps = int(round(3.0 / dt))
        self.stance = int(stance)
        if self.stance not in (0, 1):
            raise ValueError(f"stance={stance} must be 0 (outer legs) or 1 (inner legs)")
        s, ws, mem = rs.state, rs.ws, rs.memory
        code, _ = self._rollout(s, ws, mem, 10 ** 9, int(round(settle / dt)))
        if code not in (RUN_OK, RUN_NO_EVENT):
            raise StepMapError(f"Ranger failed while settling (code {code})")
        self._run(s, ws, mem, 1)
        self.state0, self.ws0, self.mem0 = s.copy(), copy_tuple(ws), mem.copy()
        self.x0 = self.coords(self.state0, self.mem0)
        self.s, self.ws, self.mem = s.copy(), copy_tuple(ws), mem.copy()
        # sole geometry of the stance foot (rolling perturbations) and the reference chain
        ci = self.stance                      # contact i sits on foot i (model.build order)
        a = self.m
        if int(a.contact_body[ci]) != 2 + ci:
            raise RuntimeError("Ranger model: sole contact order changed; update gait_map")
        self.sole_center = np.array(a.contact_local[ci], dtype=np.float64)
        self.sole_radius = float(a.contact_radius[ci])

    def _rollout(self, s, ws, mem, n_events, max_steps):
        return rollout_to_midstance(self.m, s, ws, self.rs.options, self.tables, mem, self.mem_before,
                                    self.rs.u, self.stance, CROSS_TOL, n_events, max_steps)

    def _run(self, s, ws, mem, n_events):
        code, n = self._rollout(s, ws, mem, n_events, self.max_steps)
        # an engine failure raises (it is not a fall of the walker)
        check_run(code, self.rs.model, ws, self.rs.options, "Ranger step map")
        if code != 0:
            what = {RUN_FELL: "fell", RUN_NO_EVENT: "no mid-stance"}[code]
            raise StepMapError(f"Ranger step map: {what} (t={s.time[0]:.3f} s)")
        return n

    def _step_once(self, s, ws, mem):
        """Get past a section state (one control + physics step) without stopping at it."""
        C.control(self.m, s, ws, self.tables, mem, self.rs.u)
        check_run(step_entry(self.m, s, ws, self.rs.options, self.rs.u), self.rs.model, ws,
                  self.rs.options, "Ranger step map")

    # coordinates ---------------------------------------------------------------------------------
    def coords(self, s, mem) -> np.ndarray:
        st = int(mem[C.MEM.stance])
        sw = 1 - st
        q, v = s.q, s.v
        z = mem[C.MEM.filt:C.MEM.filt + 4]
        return np.array([q[2 + st, 2], q[sw, 2], q[2 + sw, 2], v[st, 2], v[sw, 2], v[2 + st, 2],
                         v[2 + sw, 2], z[0], z[1], z[2], z[3]])

    def _pose(self, q, rates):
        """Body positions and velocities of the chain rooted at the stance foot rolling on flat
        ground with its sole centre where q puts it (contact point at rest)."""
        st = self.stance
        root = 2 + st
        th = q[root, 2]
        c, sn = math.cos(th), math.sin(th)
        lc = self.sole_center
        center = q[root, :2] + np.array([c * lc[0] - sn * lc[1], sn * lc[0] + c * lc[1]])
        pos = chain_poses(self.model, q[:, 2], root, q[root, :2])
        contact = center - np.array([0.0, self.sole_radius])
        w = rates[root]
        r = q[root, :2] - contact
        vel = chain_velocities(self.model, np.c_[pos, q[:, 2]], rates, root, np.array([-w * r[1], w * r[0]]))
        return pos, vel, center

    def set_section(self, x) -> None:
        """Scratch simulation := reference section with coordinates x."""
        restore_tuple(self.s, self.state0)
        restore_tuple(self.ws, self.ws0)
        self.mem[:] = self.mem0
        d = np.asarray(x, dtype=np.float64) - self.x0
        st, sw = self.stance, 1 - self.stance
        q0, v0 = self.state0.q, self.state0.v
        ang = q0[:, 2].copy()
        rate = v0[:, 2].copy()
        ang[2 + st] += d[0]
        ang[sw] += d[1]
        ang[2 + sw] += d[2]
        rate[st] += d[3]
        rate[sw] += d[4]
        rate[2 + st] += d[5]
        rate[2 + sw] += d[6]
        pos_ref, vel_ref, center = self._pose(q0, v0[:, 2])
        # the stance foot rolls by d[0] on flat ground: its sole centre moves by -r d[0] along x
        root = 2 + st
        lc = self.sole_center
        c, sn = math.cos(ang[root]), math.sin(ang[root])
        center_new = center + np.array([-self.sole_radius * d[0], 0.0])
        q_new = np.c_[np.zeros((self.model.n_body, 2)), ang]
        q_new[root, :2] = center_new - np.array([c * lc[0] - sn * lc[1], sn * lc[0] + c * lc[1]])
        pos_new, vel_new, _ = self._pose(q_new, rate)
        self.s.q[:, :2] += pos_new - pos_ref
        self.s.q[:, 2] = ang
        self.s.v[:] += vel_new - vel_ref
        self.mem[C.MEM.filt:C.MEM.filt + 4] += d[7:11]

    def advance(self, x) -> np.ndarray:
        """One stride (two mid-stances) from section coordinates x; the coordinates after it."""
        self.set_section(x)
        self._step_once(self.s, self.ws, self.mem)      # leave the section
        self._run(self.s, self.ws, self.mem, 1)
        return self.coords(self.s, self.mem)

    def step_map(self) -> StepMap:
        return StepMap(self.advance, dim=len(NAMES), names=NAMES)

    def jacobian(self, eps=EPS) -> np.ndarray:
        """Least-squares Jacobian (d, d) at x0: column i is the slope of P(x0 + a e_i) - P(x0)
        fitted over a in LS_STEPS * eps (the map jumps by up to ~1e-2 between nearby points,
        module doc; a two-point difference at small eps measures the jumps, not the slope)."""
        P = self.step_map()
        y0 = P(self.x0)
        n = len(self.x0)
        a = np.asarray(LS_STEPS) * float(eps)
        J = np.zeros((n, n))
        for i in range(n):
            d = np.array([P(self.x0 + ai * np.eye(n)[i]) - y0 for ai in a])
            J[:, i] = a @ d / (a @ a)
        return J
