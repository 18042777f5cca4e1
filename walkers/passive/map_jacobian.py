"""The exact Jacobian of a passive walker's step-to-step map, with the event terms.

PassiveWalker.advance maps section coordinates x to those after the next touchdown: set the
state from x, convert its velocities to the step's (half_step.to_step_velocity), take engine
steps until a foot crosses the ground and NODES - 2 more, locate the touchdown on the
polynomials through those step states (PassiveWalker.locate_touchdown), resolve the impact
there and read the coordinates back. Each piece is differentiated:

- the conversions, the projections onto the constraints and the coordinates by the complex
  step through numpy versions of them (section_state, section_coords,
  step_replica.project_velocities_batch);
- each engine step by planarsim.derivatives.step_tangents (the step replayed under its
  decisions; forward mode along the d directions of x);
- the touchdown's phase phi in its sim step by the implicit function theorem on the foot's
  gap on the positions' polynomial, g(q(phi, x)) = 0: d phi = -(dg/dq dq/dx) / (dg/dq
  dq/dphi). This is the saltation term: without it the Jacobian is the one at a fixed
  event time;
- the impact's step of IMPACT_DT by step_tangents.

The result is the derivative of the map the engine computes (its steps, its event location),
exact to rounding within the steps' contact modes (a step other than the impact's at the
edge of its mode is warned of: MapJacobianWarning): its multipliers converge to the
continuous walker's as dt shrinks at the map's order, with no finite-difference step to
choose.
"""
from __future__ import annotations

import math

import numpy as np

from planarsim.derivatives import COMPLEX_STEP, step_tangents
from planarsim.half_step import kick, to_step_velocity
from planarsim.state import State
from planarsim.step_replica import project_velocities_batch

from .gait import IMPACT_DT, MAP_HORIZON, NODES, check_map_dt, lagrange_weights
from .rollout import DETECT, update_feet


def _atan2(y, x):
    """atan2 continued analytically for a complex step: the real angle plus the derivative's
    first-order term (x dy - y dx) / (x^2 + y^2) times i."""
    xr, yr = x.real, y.real
    return np.arctan2(yr, xr) + 1j * (xr * y.imag - yr * x.imag) / (xr * xr + yr * yr)


def _leg_up(theta, t, n):
    """leg_up for a batch of angles (B,) [rad]: (B, 2) unit vectors from foot to hip."""
    return -np.sin(theta)[:, None] * t + np.cos(theta)[:, None] * n


def _dup(theta, t, n):
    """d leg_up / d theta (B, 2) in the world."""
    return -np.cos(theta)[:, None] * t - np.sin(theta)[:, None] * n


def section_state(w, X):
    """(q, v) (B, 3 n) set by PassiveWalker.set_coords from section coordinates X (B, d),
    complex numbers passing through; the entries set_coords leaves at the model's own state
    are taken from the walker's state after set_coords of the first row."""
    w.set_coords(X[0].real)
    n = w.model.n_body
    B = X.shape[0]
    q = np.repeat(w.sim.state.q[None].astype(complex), B, axis=0)
    v = np.repeat(w.sim.state.v[None].astype(complex), B, axis=0)
    t, nn = w.t_hat, w.n_hat
    if w.kind == "rimless":
        p = w.params
        v[:, 0, :2] = p.spoke_length * X[:, :1] * _dup(np.full(B, p.half_angle), t, nn)
        v[:, 0, 2] = X[:, 0]
        return q.reshape(B, 3 * n), v.reshape(B, 3 * n)
    k = w.rate_scale
    th, thd, ph, phd = X[:, 0], X[:, 1] * k, X[:, 2], X[:, 3] * k
    psi, psid = th - ph, thd - phd
    l = w.length
    up_s, up_w = _leg_up(th, t, nn), _leg_up(psi, t, nn)
    hip = l * up_s
    vhip = l * thd[:, None] * _dup(th, t, nn)
    q[:, w.hip, :2], v[:, w.hip, :2] = hip, vhip
    if w.kind == "simplest":
        fb = w.model.body("foot_b")
        q[:, fb, :2] = hip - l * up_w
        v[:, fb, :2] = vhip - l * psid[:, None] * _dup(psi, t, nn)
    else:
        a = w.params.com_from_foot
        for name, up, ang, rate, stance in (("leg_a", up_s, th, thd, True),
                                            ("leg_b", up_w, psi, psid, False)):
            b = w.model.body(name)
            arm = a if stance else -(l - a)
            q[:, b, :2] = (0.0 if stance else hip) + arm * up
            v[:, b, :2] = (0.0 if stance else vhip) + arm * rate[:, None] * _dup(ang, t, nn)
            q[:, b, 2] = _atan2(-up[:, 0], up[:, 1])
            v[:, b, 2] = rate
    return q.reshape(B, 3 * n), v.reshape(B, 3 * n)


def foot_points(w, c, q, v):
    """World position and velocity (B, 2) of contact c's material point at q, v (B, 3 n)."""
    a = w.model.arrays
    n = w.model.n_body
    qq, vv = q.reshape(-1, n, 3), v.reshape(-1, n, 3)
    b = int(a.contact_body[c])
    lx, ly = a.contact_local[c]
    cs, sn = np.cos(qq[:, b, 2]), np.sin(qq[:, b, 2])
    r = np.stack([cs * lx - sn * ly, sn * lx + cs * ly], axis=-1)
    return qq[:, b, :2] + r, vv[:, b, :2] + vv[:, b, 2:3] * np.stack([-r[:, 1], r[:, 0]], axis=-1)


def section_coords(w, q, v, stance):
    """PassiveWalker.coords for a batch (B, 3 n) with stance contact `stance`, complex numbers
    passing through: (B, d)."""
    n = w.model.n_body
    qq, vv = q.reshape(-1, n, 3), v.reshape(-1, n, 3)
    if w.kind == "rimless":
        return vv[:, w.hip, 2:3]
    t, nn = w.t_hat, w.n_hat
    hp, hv = qq[:, w.hip, :2], vv[:, w.hip, :2]

    def angle_and_rate(d, dd, sign):
        ang = _atan2(sign * (d @ t), d @ nn) if sign < 0 else _atan2(d @ t, -(d @ nn))
        rate = (d[:, 0] * dd[:, 1] - d[:, 1] * dd[:, 0]) / np.sum(d * d, axis=1)
        return ang, rate

    ps_, vs = foot_points(w, stance, q, v)
    theta, theta_dot = angle_and_rate(hp - ps_, hv - vs, -1.0)
    swing = w.feet[1] if stance == w.feet[0] else w.feet[0]
    pw, vw = foot_points(w, swing, q, v)
    psi, psi_dot = angle_and_rate(pw - hp, vw - hv, 1.0)
    k = w.rate_scale
    return np.stack([theta, theta_dot / k, theta - psi, (theta_dot - psi_dot) / k], axis=1)


class _Options:
    """The walker's simulator with steps of dt [s] within the block (its resolved options
    otherwise as they are, as step_from_python takes them; restored as they were)."""

    def __init__(self, sim, dt):
        self.sim, self.dt = sim, float(dt)

    def __enter__(self):
        self.kept = self.sim.options
        self.sim._options = self.kept._replace(dt=self.dt)
        self.sim._new_options()

    def __exit__(self, *exc):
        self.sim._options = self.kept
        self.sim._new_options()


class MapJacobianWarning(UserWarning):
    """A step of the map other than the impact's sits at the edge of its contact mode
    (StepJacobian.modes_changed): the Jacobian is that of the mode the step took."""


def _batch(x, dx):
    """Rows x (real) and x + i COMPLEX_STEP dx[:, k] (n_x,), (n_x, k) -> (k + 1, n_x)."""
    return np.vstack([x[None].astype(complex), x[None] + (COMPLEX_STEP * 1j) * dx.T])


def _tangent(Y):
    """The directions' derivatives (n, k) from a complex batch (k + 1, n)."""
    return Y[1:].imag.T / COMPLEX_STEP


def map_jacobian(w, x):
    """(P(x), dP/dx (d, d)) of PassiveWalker w's step map at section coordinates x (module
    docstring). Raises StepMapError as advance does, NotImplementedError where a step is
    not covered by step_tangents, ValueError for a dt too small for the map (check_map_dt)."""
    from planarsim.analysis import StepMapError
    check_map_dt(w.dt)
    x = np.asarray(x, dtype=float)
    d = x.size
    model, sim = w.model, w.sim
    u0, h = w.u0, w.dt
    n3 = 3 * model.n_body
    if model.arrays.terrain_coef[2] != 0.0:
        raise NotImplementedError("the step map's Jacobian covers flat and sloped ground")
    Q, V = section_state(w, x[None] + (COMPLEX_STEP * 1j) * np.vstack([np.zeros(d), np.eye(d)]))
    T = np.vstack([_tangent(Q), _tangent(V)])            # (n_x, d) tangent of the state
    w.set_coords(x)
    s, ws = sim.state, sim.ws
    to_step_velocity(model, s, ws, h, u0)                # (a constant kick: no derivative)
    old = int(w.memory[0])
    start = w.foot_point(w.feet[old])[0]
    s.contact_enabled[w.feet[1:]] = 0
    edges = 0
    for _ in range(int(MAP_HORIZON / h)):
        step = step_tangents(sim, u0, T, _keep_end=True)
        edges += step.modes_changed
        if update_feet(model.arrays, s, ws, w.feet, w.memory, DETECT, w.min_ahead) >= 0:
            break
        T = step.dx1
        if w.fell():
            raise StepMapError(f"{w.kind}: the walker fell from x={x}")
    else:
        raise StepMapError(f"{w.kind}: no touchdown within {MAP_HORIZON:g} s from x={x}")
    c = int(w.feet[int(w.memory[0])])
    # the nodes: the crossing step's start and end and the steps after it, with tangents
    begin, crossing_end = State(*(a.copy() for a in ws.prev)), s.copy()
    pinned = [int(w.feet[old])]
    states, tangents = [begin, s.copy()], [T, step.dx1]
    T = step.dx1
    for _ in range(NODES - 2):
        after = step_tangents(sim, u0, T, _keep_end=True)
        T, edges = after.dx1, edges + after.modes_changed
        states.append(s.copy())
        tangents.append(T)
    s.restore(crossing_end)
    ws.prev.restore(begin)
    nodes = np.array([st.q.ravel() for st in states])
    Z = np.stack([_batch(st.q.ravel(), t[:n3]) for st, t in zip(states, tangents)])
    # each node's velocity at its instant (half a kick, projected): (NODES, d + 1, n3)
    gravity = _applied_velocity(w)
    R = np.stack([project_velocities_batch(model, Zk, _batch(st.v.ravel(), t[n3:])
                                           + 0.5 * h * gravity, pinned)
                  for Zk, st, t in zip(Z, states, tangents)])
    # the real path as locate_touchdown takes it, in the engine's arithmetic
    phi = w.touchdown_state(nodes.reshape((NODES,) + s.q.shape),
                            np.array([st.v for st in states]), pinned, c)
    # the phase's derivative: the foot's gap on the interpolant held at 0
    along_x = _gap(w, c, np.einsum("k,kbi->bi", lagrange_weights(phi), Z))
    along_phi = _gap(w, c, np.einsum("k,ki->i", lagrange_weights(phi + COMPLEX_STEP * 1j),
                                     nodes)[None])
    dphi = -_tangent(along_x[:, None])[0] / _tangent(np.r_[0.0, along_phi][:, None])[0]
    if phi == 0.0:
        dphi[:] = 0.0        # (the foot started the step on the ground: phi held at 0)
    weights = lagrange_weights(phi + (COMPLEX_STEP * 1j) * np.r_[0.0, dphi])
    Yq = np.einsum("kb,kbi->bi", weights, Z)
    Yv = project_velocities_batch(model, Yq, np.einsum("kb,kbi->bi", weights, R), pinned)
    # the impact, resolved in a step of IMPACT_DT and read at the touchdown (impact_at_instant)
    touch = s.q.copy()
    s.contact_enabled[c] = 1
    s.contact_mode[c] = 1
    with _Options(sim, IMPACT_DT):
        hit = step_tangents(sim, u0, np.vstack([_tangent(Yq), _tangent(Yv)]), _keep_end=True)
    s.q[...] = touch
    kick(model.arrays, s, ws, u0, -IMPACT_DT, IMPACT_DT)
    Yv = _batch(s.v.ravel(), hit.dx1[n3:])
    s.v[...] = w.project(s.q, s.v, [c])
    Yv = project_velocities_batch(model, Yq, Yv, [c])
    s.time[0] = begin.time[0] + phi * h
    w.last_release_ok = bool(s.contact_mode[w.feet[old]] == 0)
    s.contact_enabled[w.feet[old]] = 0
    if edges:
        import warnings
        warnings.warn(f"{w.kind}: {edges} step(s) of the map from x={x} at the edge of a "
                      f"contact mode: the Jacobian is that of the modes the steps took",
                      MapJacobianWarning, stacklevel=2)
    w.last_period = float(s.time[0])
    w.last_length = float((w.foot_point(c)[0] - start) @ w.t_hat)
    return w.coords(), _tangent(section_coords(w, Yq, Yv, c))


def _applied_velocity(w):
    """W f (3 n,) [m/s^2, rad/s^2]: the applied forces' acceleration, the same at every state
    of a passive walker (gravity alone)."""
    s = w.sim.state.copy()
    s.v[...] = 0.0
    kick(w.model.arrays, s, w.sim.ws, w.u0, 1.0, w.dt)
    return s.v.ravel().copy()


def _gap(w, c, q):
    """Contact c's gap [m] above flat or sloped ground (B,) at q (B, 3 n)."""
    p, _ = foot_points(w, c, q, q)
    coef = w.model.arrays.terrain_coef
    # (kernels/geometry/terrain.py: height coef[0] + coef[1] x; the gap along the unit normal)
    return (p[:, 1] - coef[0] - coef[1] * p[:, 0]) / math.sqrt(1.0 + coef[1] * coef[1])
