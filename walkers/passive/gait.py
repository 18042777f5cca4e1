"""Passive walkers as simulations with a step-to-step map: set the state from section
coordinates, run the compiled rollout to the next touchdown, read the coordinates back.

Section coordinates (just after a touchdown, in stance / swing terms, so the left/right
relabelling is built in and the map of one step is the symmetric reduction):
- simplest walker and compass gait: x = (theta, theta_dot, phi, phi_dot) in Garcia et al.'s
  convention: theta = stance-leg angle from the slope normal (counter-clockwise, > 0 leaning
  back), phi = angle between the legs (swing-leg angle from the downward normal is
  theta - phi). Rates are in units of sqrt(g / l) for the simplest walker (Garcia's
  dimensionless time) and in rad/s for the compass gait.
- rimless wheel: x = (theta_dot,) [rad/s] of the hub (negative rolling downhill); the stance
  spoke sits at theta = alpha on the section.
"""
from __future__ import annotations

import math

import numpy as np

from planarsim import dense
from planarsim.compiled import check_run, gap_of_point, step_from_python
import planarsim as ps
from planarsim.analysis import StepMap, StepMapError
from planarsim.checks import finite_number, whole
from planarsim.errors import plain
from planarsim.half_step import kick, project_velocities, to_instant_velocity, to_step_velocity
from planarsim.state import State
from planarsim.trajectory import Trajectory, make_recorder, record_state

from .model import build_compass, build_rimless, build_simplest, leg_up, slope_frame
from .params import CompassParams, RimlessParams, SimplestParams
from .rollout import DETECT, ENGINE, FELL, NO_EVENT, TOGGLE, rollout_passive


IMPACT_DT = 1e-6   # [s] the step that resolves an impact at the section (impact);
                   # gravity acts 1e-6 s longer, residuals / IMPACT_DT < 1e-6 m/s
MAP_HORIZON = 20.0  # [s] how long one step-map evaluation waits for the next touchdown


def check_dt(dt, said: str = "dt") -> float:
    """dt [s] as a float; a ValueError naming it (as `said` gives it) unless it is a finite
    number > 0 (a string failed in float(), True was taken for 1 s, NaN built a model)."""
    x = finite_number(said, dt, 0.0, unit=" s",
                      expected="a finite step size > 0 [s]")
    if x <= 0.0:
        raise ValueError(f"{said}={plain(dt)!r} s must be a finite step size > 0 [s]")
    return x


def check_map_dt(dt, said: str = "dt") -> float:
    """check_dt, and a ValueError naming dt and the bound where one step-map evaluation
    (up to MAP_HORIZON s to the next touchdown: int(MAP_HORIZON / dt) steps) would need more
    than walkers.base.MAX_RUN_STEPS steps (at dt 1e-9 s, 2e10 steps: practically forever)."""
    from walkers.base import MAX_RUN_STEPS
    x = check_dt(dt, said)
    n = int(MAP_HORIZON / x)
    if n > MAX_RUN_STEPS:
        raise ValueError(f"{said}={x:g} s is too small for the step map: one evaluation runs up to "
                         f"{MAP_HORIZON:g} s to the next touchdown, {n:,} steps, more than "
                         f"MAX_RUN_STEPS={MAX_RUN_STEPS:,}; use dt >= "
                         f"{MAP_HORIZON / MAX_RUN_STEPS:g} s (1e-3 is usual)")
    return x


def _cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


def _dup(theta):
    """d leg_up / d theta in slope coordinates (t, n): (-cos theta, -sin theta)."""
    return np.array([-math.cos(theta), -math.sin(theta)])


#: step states the step map's touchdown is interpolated through: the crossing step's start and
#: end and those after the NODES - 2 steps that follow (polynomials of degree NODES - 1)
NODES = 6


def lagrange_weights(phi, nodes: int = NODES) -> np.ndarray:
    """(nodes,) weights of the values at 0, 1, ..., nodes - 1 in the polynomial through them
    (Lagrange), at phi (a number or an array); polynomial in phi, so complex numbers pass
    through."""
    from functools import reduce
    from operator import mul
    at = np.arange(float(nodes))
    return np.array([reduce(mul, [phi - b for b in np.delete(at, k)])
                     / np.prod(at[k] - np.delete(at, k)) for k in range(nodes)])


class PassiveWalker:
    """One passive walker, its simulator and its compiled rollout.

    Parameters
    ----------
    params : SimplestParams | CompassParams | RimlessParams
    dt : step size [s]
    strategy : contact-mode strategy, "all" (default: the old stance foot must leave the ground in the heel-strike step) or "alternating"
    """

    def __init__(self, params, dt: float = 1e-3, strategy: str = "all", terrain=None):
        self.params = params
        self.dt = check_dt(dt)
        if isinstance(params, SimplestParams):
            self.kind, self.model = "simplest", build_simplest(params, dt, terrain)
            self.feet = np.array([self.model.contact("foot_a"), self.model.contact("foot_b")])
            self.toggle, self.length = TOGGLE, params.leg_length
            self.rate_scale = math.sqrt(params.gravity / params.leg_length)
            self.names = ("theta", "theta_dot", "phi", "phi_dot")
        elif isinstance(params, CompassParams):
            self.kind, self.model = "compass", build_compass(params, dt, terrain)
            self.feet = np.array([self.model.contact("foot_a"), self.model.contact("foot_b")])
            self.toggle, self.length, self.rate_scale = TOGGLE, params.leg_length, 1.0
            self.names = ("theta", "theta_dot", "phi", "phi_dot")
        elif isinstance(params, RimlessParams):
            self.kind, self.model = "rimless", build_rimless(params, dt, terrain)
            self.feet = np.arange(params.n_spokes)
            self.toggle, self.length, self.rate_scale = ENGINE, params.spoke_length, 1.0
            self.names = ("theta_dot",)
        else:
            raise TypeError(f"params must be SimplestParams, CompassParams or RimlessParams, got "
                            f"{type(params).__name__}")
        self.gamma = params.slope
        self.t_hat, self.n_hat = slope_frame(self.gamma)
        self.sim = ps.Simulator(self.model, ps.make_options(strategy))
        self.u0 = np.zeros(self.model.n_act)   # passive: no actuator commands
        self.memory = np.zeros(2, np.int64)
        self.hip = self.model.body("hub" if self.kind == "rimless" else "hip")
        self.fall_height = 0.5 * self.length
        self.min_ahead = 0.02 * self.length   # [m] see rollout.update_feet
        self._no_rec = make_recorder(self.model, 0)
        self.event_time = np.zeros(1)
        self.event_contact = np.zeros(1, np.int64)
        self.last_period = math.nan
        self.last_length = math.nan

    # points ------------------------------------------------------------------------------------
    def foot_point(self, c, q=None, v=None):
        """World position and velocity [m, m/s] of contact c's material point."""
        q = self.sim.state.q if q is None else q
        v = self.sim.state.v if v is None else v
        a = self.model.arrays
        b = a.contact_body[c]
        th = q[b, 2]
        lx, ly = a.contact_local[c]
        r = np.array([math.cos(th) * lx - math.sin(th) * ly, math.sin(th) * lx + math.cos(th) * ly])
        return q[b, :2] + r, v[b, :2] + v[b, 2] * np.array([-r[1], r[0]])

    # section coordinates -------------------------------------------------------------------------
    def stance_angle(self, q=None, v=None, stance=None):
        """Angle theta [rad] of the leg (spoke) from `stance`'s foot to the hip, from the slope
        normal, and its rate [rad/s]."""
        q = self.sim.state.q if q is None else q
        v = self.sim.state.v if v is None else v
        stance = self.feet[self.memory[0]] if stance is None else int(stance)
        ps_, vs = self.foot_point(stance, q, v)
        r, rd = q[self.hip, :2] - ps_, v[self.hip, :2] - vs
        return math.atan2(-dense.dot(r, self.t_hat), dense.dot(r, self.n_hat)), _cross(r, rd) / dense.dot(r, r)

    def coords(self, q=None, v=None, stance=None) -> np.ndarray:
        """Section coordinates of the state (default: the simulator's) with stance contact
        `stance` (default: the current stance foot)."""
        q = self.sim.state.q if q is None else q
        v = self.sim.state.v if v is None else v
        stance = self.feet[self.memory[0]] if stance is None else int(stance)
        theta, theta_dot = self.stance_angle(q, v, stance)
        hp, hv = q[self.hip, :2], v[self.hip, :2]
        if self.kind == "rimless":
            return np.array([v[self.hip, 2]])
        swing = self.feet[1] if stance == self.feet[0] else self.feet[0]
        pw, vw = self.foot_point(swing, q, v)
        d, dd = pw - hp, vw - hv
        psi = math.atan2(dense.dot(d, self.t_hat), -dense.dot(d, self.n_hat))
        psi_dot = _cross(d, dd) / dense.dot(d, d)
        k = self.rate_scale
        return np.array([theta, theta_dot / k, theta - psi, (theta_dot - psi_dot) / k])

    def set_coords(self, x) -> None:
        """Set the simulator's state just after a touchdown: stance foot (foot_a / spoke0)
        pinned at the origin, the other feet free (swing contact disabled where toggled)."""
        x = np.asarray(x, dtype=np.float64)
        s = self.sim.state
        s.restore(ps.make_state(self.model))
        t, n = self.t_hat, self.n_hat

        def basis(d):                      # slope (t, n) coordinates -> world
            return t * d[0] + n * d[1]

        if self.kind == "rimless":
            p = self.params
            alpha = p.half_angle
            up = leg_up(alpha, self.gamma)
            s.q[0, :2] = p.spoke_length * up
            s.q[0, 2] = math.atan2(-up[0], up[1])
            s.v[0, :2] = p.spoke_length * x[0] * basis(_dup(alpha))
            s.v[0, 2] = x[0]
        else:
            k = self.rate_scale
            th, thd, ph, phd = x[0], x[1] * k, x[2], x[3] * k
            psi, psid = th - ph, thd - phd
            l = self.length
            up_s, up_w = leg_up(th, self.gamma), leg_up(psi, self.gamma)
            hip = l * up_s
            vhip = l * thd * basis(_dup(th))
            s.q[self.hip, :2], s.v[self.hip, :2] = hip, vhip
            if self.kind == "simplest":
                fb = self.model.body("foot_b")
                s.q[fb, :2] = hip - l * up_w
                s.v[fb, :2] = vhip - l * psid * basis(_dup(psi))
            else:
                a = self.params.com_from_foot
                for name, up, ang, rate, sgn in (("leg_a", up_s, th, thd, 1.0), ("leg_b", up_w, psi, psid, -1.0)):
                    b = self.model.body(name)
                    if sgn > 0:
                        s.q[b, :2] = a * up
                        s.v[b, :2] = a * rate * basis(_dup(ang))
                    else:
                        s.q[b, :2] = hip - (l - a) * up
                        s.v[b, :2] = vhip - (l - a) * rate * basis(_dup(ang))
                    s.q[b, 2] = math.atan2(-up[0], up[1])
                    s.v[b, 2] = rate
        s.contact_mode[self.feet[0]] = 1
        if self.toggle == TOGGLE:
            s.contact_enabled[self.feet[1]] = 0
        self.memory[:] = 0

    # running -----------------------------------------------------------------------------------
    def rollout(self, n_steps: int, stop_after: int, record_every: int = 0, max_events: int = 0):
        """Compiled rollout from the current state; returns (code, steps, Trajectory | None),
        the Trajectory's frame 0 the state it started from."""
        extra = max_events if self.toggle != DETECT else 0   # touchdown frames
        rec = make_recorder(self.model, n_steps // record_every + 2 + extra) if record_every > 0 else self._no_rec
        if max_events > self.event_time.size:
            self.event_time = np.zeros(max_events)
            self.event_contact = np.zeros(max_events, np.int64)
        sim = self.sim
        k0 = 0
        if record_every > 0:
            record_state(rec, 0, sim.state, sim.ws)
            k0 = 1
        code, done, k = self.run_compiled(n_steps, stop_after, rec, record_every, k0)
        check_run(code, self.model, sim.ws, sim.options, self.kind)
        traj = None
        if record_every > 0:
            traj = Trajectory.from_recorder(self.model, rec, k, info={"dt": self.dt, "walker": self.kind})
        return code, done, traj

    def run_compiled(self, n_steps: int, stop_after: int, rec, record_every: int, k0: int):
        """The compiled rollout (rollout_passive) from the current state into rec from frame k0,
        touchdowns logged in event_time / event_contact; returns (code, steps done, next frame)."""
        sim = self.sim
        return rollout_passive(self.model.arrays, sim.state, sim.ws, sim.options, self.u0, self.feet,
                               self.memory, self.toggle, self.min_ahead, int(n_steps), int(stop_after),
                               self.hip, self.fall_height, rec, int(record_every), int(k0),
                               self.event_time, self.event_contact)

    def refine_touchdown(self, old: int) -> float:
        """Move the state from the end of a DETECT rollout to the touchdown instant itself and
        resolve the impact there (a walker's run: the engine's velocities as they are).

        The rollout stopped after the step in which a foot (contact disabled) crossed the
        ground. This restores the start of that step, finds by root finding the sub-step
        tau in (0, dt] after which the foot is exactly on the ground, takes it, projects the
        velocities onto the constraints there (project_velocities), then enables and pins the
        foot and takes a step of IMPACT_DT, in which the engine resolves the
        impact and (with the "all" strategy) releases the old stance foot `old`.
        Returns tau [s]."""
        from scipy.optimize import brentq

        sim, s, ws = self.sim, self.sim.state, self.sim.ws
        m = self.model.arrays
        c = int(self.feet[int(self.memory[0])])
        pinned = [int(self.feet[old])]
        prev = State(*(a.copy() for a in ws.prev))
        # velocities consistent with the start configuration, so that a sub-step shorter
        # than dt does not read the O(dt) mismatch as the stance foot leaving the ground
        prev.v[...] = self.project(prev.q, prev.v, pinned)

        def sub_step(tau):
            s.restore(prev)
            if tau > 0.0:
                check_run(step_from_python(m, s, ws, sim.options._replace(dt=tau), self.u0),
                          self.model, ws, sim.options, self.kind)
            p = self.foot_point(c)[0]
            return gap_of_point(m.terrain_coef, p[0], p[1])

        tau = 0.0
        if sub_step(0.0) > 0.0:
            tau = brentq(sub_step, 0.0, m.dt, xtol=1e-16, rtol=1e-15, maxiter=200)
        sub_step(tau)
        s.v[...] = self.project(s.q, s.v, pinned)
        self.impact(c)
        s.time[0] = prev.time[0] + tau
        return tau

    def impact(self, c: int) -> None:
        """Enable and pin contact c (at the state's touchdown) and take a step of IMPACT_DT, in
        which the engine resolves the impact and (with the "all" strategy) releases the old
        stance foot."""
        s, ws, sim = self.sim.state, self.sim.ws, self.sim
        s.contact_enabled[c] = 1
        s.contact_mode[c] = 1
        check_run(step_from_python(self.model.arrays, s, ws, sim.options._replace(dt=IMPACT_DT),
                                   self.u0), self.model, ws, sim.options, self.kind)

    def impact_at_instant(self, c: int) -> None:
        """impact, read at the touchdown itself: the configuration before the step of
        IMPACT_DT, the velocity less that step's kick of the applied forces (else the section
        state is that of IMPACT_DT later: theta off by theta_dot IMPACT_DT), projected onto
        the constraints with c held."""
        s = self.sim.state
        touch = s.q.copy()
        self.impact(c)
        s.q[...] = touch
        kick(self.model.arrays, s, self.sim.ws, self.u0, -IMPACT_DT, IMPACT_DT)
        s.v[...] = self.project(s.q, s.v, [c])

    def locate_touchdown(self, old: int, extra) -> float:
        """The step map's touchdown: from the end of a DETECT rollout (the step in which a
        foot crossed the ground) and `extra` (steps_after: the positions and velocities after
        the NODES - 2 steps that follow it), the touchdown instant is located on the
        polynomials through the NODES step states (the crossing step's start and end and
        those), at phase phi in [0, 1] of the crossing step where the foot's point is on the
        ground (root finding on the positions' polynomial). The state there: the positions'
        polynomial, and the velocities' through each node's velocity at its instant
        (half_step.to_instant_velocity: the step's velocity plus half a kick, projected onto
        the constraints with the old stance foot held), projected again where they are read;
        the impact is resolved at that instant (impact_at_instant). Each sequence alone is
        smooth in time from step to step (its error a smooth function of the time), so the
        map is smooth in x; a velocity mixed into the positions' interpolation (a sub-step of
        the engine, a Hermite cubic) carries an error of another order that depends on phi
        and puts a sawtooth of first order in dt into the map's slope. The interpolation's
        own error is O(dt^NODES) in the positions and O(dt^(NODES - 1)) in the rates, the
        sawtooth it leaves O(dt^(NODES - 2)). Returns phi."""
        s, ws = self.sim.state, self.sim.ws
        c = int(self.feet[int(self.memory[0])])
        t0 = float(ws.prev.time[0])
        phi = self.touchdown_state(np.concatenate([ws.prev.q[None], s.q[None], extra[0]]),
                                   np.concatenate([ws.prev.v[None], s.v[None], extra[1]]),
                                   [int(self.feet[old])], c)
        self.impact_at_instant(c)
        s.time[0] = t0 + phi * self.dt
        return phi

    def touchdown_state(self, nodes, rates, pinned, c: int) -> float:
        """Set the simulator's state to the touchdown of contact c on the polynomials through
        the step states (positions `nodes`, step velocities `rates`, each (NODES, n, 3)),
        each velocity first made its instant's with the contacts `pinned` held
        (locate_touchdown); returns the touchdown's phase phi."""
        s, ws = self.sim.state, self.sim.ws
        node = s.copy()
        instant = np.empty_like(rates)
        for k in range(NODES):
            node.q[...], node.v[...] = nodes[k], rates[k]
            to_instant_velocity(self.model, node, ws, self.dt, self.u0, pinned)
            instant[k] = node.v
        phi = self.touchdown_phase(nodes, c)
        weights = lagrange_weights(phi)
        s.q[...] = np.tensordot(weights, nodes, axes=1)
        s.v[...] = self.project(s.q, np.tensordot(weights, instant, axes=1), pinned)
        return phi

    def touchdown_phase(self, nodes, c: int) -> float:
        """The phase phi in [0, 1] of the crossing step at which contact c's point is on the
        ground, on the polynomial through the positions `nodes` (NODES, n, 3) (root
        finding; 0 where the foot starts the step on or below the ground)."""
        from scipy.optimize import brentq
        coef = self.model.arrays.terrain_coef

        def gap(phi):
            q = np.tensordot(lagrange_weights(phi), nodes, axes=1)
            p = self.foot_point(c, q)[0]
            return gap_of_point(coef, p[0], p[1])

        if gap(0.0) <= 0.0:
            return 0.0
        return brentq(gap, 0.0, 1.0, xtol=1e-16, rtol=1e-15, maxiter=200)

    def steps_after(self):
        """(positions, velocities), each (NODES - 2, n, 3), after that many more steps from
        the current state (the state and the workspace's start of step restored):
        locate_touchdown's last nodes."""
        sim = self.sim
        start, prev = sim.snapshot(), State(*(a.copy() for a in sim.ws.prev))
        q = np.empty((NODES - 2,) + sim.state.q.shape)
        v = np.empty_like(q)
        try:
            for k in range(NODES - 2):
                check_run(step_from_python(self.model.arrays, sim.state, sim.ws, sim.options,
                                           self.u0), self.model, sim.ws, sim.options, self.kind)
                q[k], v[k] = sim.state.q, sim.state.v
        finally:
            sim.state.restore(start)
            sim.ws.prev.restore(prev)
        return q, v

    def fell(self) -> bool:
        """The watched body (hip, hub) came within fall_height [m] of the ground (the
        rollout's test)."""
        q = self.sim.state.q
        return gap_of_point(self.model.arrays.terrain_coef, q[self.hip, 0], q[self.hip, 1]) \
            < self.fall_height

    def project(self, q, v, pinned) -> np.ndarray:
        """Velocities v (n, 3) projected onto the constraints at q with contacts `pinned` held
        (planarsim.half_step.project_velocities)."""
        return project_velocities(self.model, q, v, pinned)

    def advance(self, x, record_every: int = 0) -> np.ndarray:
        """The step-to-step map: coordinates just after the next touchdown (StepMapError if
        the walker falls or takes no step within 20 s). With record_every > 0 the step (up to
        the end of the sim step containing the touchdown) is kept in self.last_traj.
        ValueError for a dt at which it would need more than MAX_RUN_STEPS steps
        (check_map_dt), before anything runs."""
        check_map_dt(self.dt)
        # (a string failed in the recorder's size, n_steps // "10"; True was every step)
        record_every = whole("record_every", record_every, 0)
        self.set_coords(x)
        # x holds velocities at the touchdown instant; the step wants them over its first step
        # (planarsim.half_step: with both ends converted the map is second order in dt)
        to_step_velocity(self.model, self.sim.state, self.sim.ws, self.dt, self.u0)
        old = int(self.memory[0])
        start = self.foot_point(self.feet[old])[0]
        toggle = self.toggle
        self.toggle = DETECT
        try:
            self.sim.state.contact_enabled[self.feet[1:]] = 0
            code, done, self.last_traj = self.rollout(int(MAP_HORIZON / self.dt), 1, record_every)
        finally:
            self.toggle = toggle
        if code == FELL:
            raise StepMapError(f"{self.kind}: the walker fell from x={x}")
        if code == NO_EVENT:
            raise StepMapError(f"{self.kind}: no touchdown within {MAP_HORIZON:g} s from x={x}")
        self.locate_touchdown(old, self.steps_after())
        self.last_release_ok = bool(self.sim.state.contact_mode[self.feet[old]] == 0)
        self.sim.state.contact_enabled[self.feet[old]] = 0
        self.last_period = float(self.sim.state.time[0])
        end = self.foot_point(self.feet[self.memory[0]])[0]
        self.last_length = float(dense.dot(end - start, self.t_hat))
        return self.coords()

    def step_map(self) -> StepMap:
        """The step-to-step map (advance), with its exact Jacobian (map_jacobian) on flat or
        sloped ground (on hills: none, the fits and differences then). ValueError for a dt too
        small for it (check_map_dt)."""
        check_map_dt(self.dt)
        covered = self.model.arrays.terrain_coef[2] == 0.0
        return StepMap(self.advance, dim=len(self.names), names=self.names,
                       derivative=self.advance_with_jacobian if covered else None)

    def advance_with_jacobian(self, x):
        """(advance(x), its exact Jacobian (d, d)): walkers.passive.map_jacobian."""
        from .map_jacobian import map_jacobian
        return map_jacobian(self, x)
