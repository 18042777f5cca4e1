"""Exact derivatives of one step: step_jacobian(sim, u); along a rollout: rollout_jacobians.

The default step (symplectic Euler with SHAKE, docs/engine.md) of a mechanism held by hinges
and sliders ends at

    q1 = q + h v + h^2 W f(q, u) + W P^T L,   c(q1) = 0,   v1 = (q1 - q) / h,

with W the inverse of the bodies' masses and the hinges' rotors (M + A, A = sum a g^T g over
the joints' armature a and rate rows g), c the joints' equality rows (a hinge's x and y, a
slider's perpendicular and angle rows), P = dc/dq at the step's start and L the step's total
impulse of those rows (the velocity solve's and the position correction's together: both act
along W P^T, and the Newton correction ends where c(q1) = 0). Within its modes the step is
smooth, and the implicit function theorem on c(q1) = 0 gives its derivative exactly:

    dq1 = (I - W P^T S G) (dq + h dv + h^2 W (K dq + F du) + W H dq),   S = (G W P^T)^-1,
    dv1 = (dq1 - dq) / h,

with G = dc/dq at q1, K = df/dq (the joints' springs), F = df/du and H = d(P^T L)/dq (the
rows' curvature under the step's impulse: the anchors turn with their bodies, a slider's axis
with its body a). L is read back from the step's own answer (the engine's step is taken once,
on a snapshot, and `sim` is restored); a step that did not end as that equation says
(sub-steps, a correction held back by the energy bound) raises instead of giving a derivative
of a different map.

Covered so far: bodies held by hinges (pins) and sliders to each other and the world, with
joint limits the step does not reach, the hinges' armature and springs the step resolves
(taken at the step's start: kernels/soft.py with a rotor, kernels/forces.py spring_as_force
without), under gravity, constant pushes and pin torques, body forces and body torques.
Refused with a NotImplementedError naming the feature: a slider's armature or spring (its
rate row turns with body a), rods, a limit reached in the step, dampers, dry friction,
springs too stiff for the step, contacts and shape pairs that touch in the step, fluid drag,
the other actuator kinds (slider forces among them), the accurate integrators.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .kernels.codes import INTEGRATOR_EULER, JOINT_HINGE, JOINT_SLIDER, MODE_FREE
from .kernels.forces import ACT_BODY_FORCE, ACT_BODY_TORQUE, ACT_PIN_TORQUE
from .kernels.info import INFO_CCD_SPLITS, INFO_TURN_SUBSTEPS

#: the step's end must satisfy q1 = q + h v* + W P^T L to this share of |q1 - q| (plus
#: rounding) for its derivative to be this map's
FIT_TOL = 1e-9

_LINEAR_ACTUATORS = {ACT_PIN_TORQUE: "pin torque", ACT_BODY_FORCE: "body force",
                     ACT_BODY_TORQUE: "body torque"}


@dataclass(frozen=True)
class StepJacobian:
    """The derivative of one step x -> x1, x = (q.ravel(), v.ravel()) [m, rad, m/s, rad/s].

    A : (n_x, n_x) d x1 / d x
    B : (n_x, n_u) d x1 / d u (u: the actuators' commands [N or N m])
    modes_changed : True where an infinitesimal change of x or u would change a mode of the
        step (here: a command exactly at its saturation bound; B then holds the derivative
        from inside the range)
    x1 : the state after the step, in the same layout
    """
    A: np.ndarray
    B: np.ndarray
    modes_changed: bool
    x1: np.ndarray


#: [m, rad] the joints' gap at the step's end below which the step counts as closing them (the
#: derivative assumes c(q1) = 0; the default correction ends near 1e-15 m)
PINS_CLOSED_TOL = 1e-10
#: (G W P^T)'s condition number above which the joints count as dependent (an over-
#: constrained loop: the step is not smooth there)
DEPENDENT_COND = 1e10


def _not_covered(what):
    return NotImplementedError(
        f"step_jacobian covers mechanisms of hinges (with armature and springs the step "
        f"resolves) and sliders (without), with limits the step does not reach, under "
        f"gravity, pushes and pin / body torques and body forces so far; this step has {what}")


def check_covered(model, options, h) -> None:
    """Raise NotImplementedError naming the first feature of `model` or `options` (for steps
    of h [s]) that step_jacobian does not cover yet (module docstring)."""
    a = model.arrays
    if options.integrator != INTEGRATOR_EULER:
        raise _not_covered(f"the accurate integrator {options.integrator!r}")
    if options.refine_iters <= 0:
        raise _not_covered("no position correction (refine_iters = 0): its pins stay open")
    if model.n_rod:
        raise _not_covered(f"rods ({model.rod_names[0]!r}, ...)")
    if a.fluid_body.shape[0]:
        raise _not_covered("fluid drag")
    for j, name in enumerate(model.pin_names):
        kind = int(a.pin_kind[j])
        if kind not in (JOINT_HINGE, JOINT_SLIDER):
            raise _not_covered(f"joint {name!r}, which is neither a hinge nor a slider (kind "
                               f"{kind}: a free body's coordinate)")
        for field, label in (("pin_damping", "a damper"), ("pin_frictionloss", "dry friction")):
            if getattr(a, field)[j] != 0.0:
                raise _not_covered(f"{label} on joint {name!r}")
        k, arm = a.pin_stiffness[j], a.pin_armature[j]
        if kind == JOINT_SLIDER:
            # (its rate row turns with body a: the rotor and the spring would depend on q)
            if k != 0.0 or arm != 0.0:
                raise _not_covered(f"{'a spring' if k != 0.0 else 'armature'} on slider "
                                   f"{name!r}")
            continue
        if k > 0.0:
            kappa = sum(a.body_inv_inertia[b] for b in a.pin_body[j] if b >= 0)
            resolved = h * h * k * kappa / (1.0 + arm * kappa)
            if resolved > 0.5:
                raise _not_covered(f"a spring on joint {name!r} that the step takes at its end "
                                   f"(too stiff for the step)")
    for k, name in enumerate(model.act_names):
        if int(a.act_kind[k]) not in _LINEAR_ACTUATORS:
            raise _not_covered(f"actuator {name!r} of kind {int(a.act_kind[k])}")


def rotor_terms(model, q):
    """(W (3 n_body, 3 n_body): the inverse of the bodies' masses and the joints' rotors
    (M + A)^-1, f_spring (3 n_body,) [N m] the joints' springs at q, K = d f_spring / dq)."""
    a = model.arrays
    n = model.n_body
    w = np.column_stack([a.body_inv_mass, a.body_inv_mass, a.body_inv_inertia]).ravel()
    A = np.zeros((3 * n, 3 * n))
    K = np.zeros((3 * n, 3 * n))
    f = np.zeros(3 * n)
    for j in range(model.n_pin):
        if a.pin_kind[j] != JOINT_HINGE:
            continue                    # (a slider without rotor or spring: check_covered)
        g = np.zeros(3 * n)
        for e, sign in ((0, -1.0), (1, 1.0)):
            b = a.pin_body[j, e]
            if b >= 0:
                g[3 * b + 2] = sign
        A += a.pin_armature[j] * np.outer(g, g)
        k = a.pin_stiffness[j]
        if k > 0.0:
            stretch = g @ q.ravel() - a.pin_ref[j] - a.pin_rest[j]
            f -= k * stretch * g
            K -= k * np.outer(g, g)
    # (M + A)^-1 = (I + W A)^-1 W, which holds where W has zeros (a point mass's turn)
    W = np.linalg.solve(np.eye(3 * n) + w[:, None] * A, np.diag(w))
    return W, f, K


def joint_terms(model, q, impulse=None):
    """The joints' errors c (2 n_pin,) [m, rad] and Jacobian J (2 n_pin, 3 n_body) at q
    (n_body, 3): rows 2j and 2j + 1 of joint j, a hinge's x and y (anchor b minus anchor a,
    as kernels/pin.py), a slider's perpendicular and angle rows (kernels/slider.py); with
    `impulse` (2 n_pin,) [N s, N m s] also H (3 n_body, 3 n_body) = d (J^T impulse) / dq, the
    rows' curvature (J is each row's gradient, so H is the impulse-weighted sum of their
    Hessians)."""
    a = model.arrays
    n = q.shape[0]
    c = np.zeros(2 * model.n_pin)
    J = np.zeros((2 * model.n_pin, 3 * n))
    H = np.zeros((3 * n, 3 * n)) if impulse is not None else None
    _hinge_terms(a, q, np.flatnonzero(a.pin_kind == JOINT_HINGE), c, J, H, impulse)
    for j in np.flatnonzero(a.pin_kind == JOINT_SLIDER):
        _slider_terms(a, q, int(j), c, J, H, impulse)
    return c, J, H


def _hinge_terms(a, q, rows, c, J, H, impulse):
    """joint_terms' rows of the hinges `rows` (vectorised over them)."""
    for e, sign in ((0, -1.0), (1, 1.0)):
        body = a.pin_body[rows, e]
        ax, ay = a.pin_anchor[rows, e, 0], a.pin_anchor[rows, e, 1]
        moving = body >= 0
        b = np.where(moving, body, 0)
        th = np.where(moving, q[b, 2], 0.0)
        cs, sn = np.cos(th), np.sin(th)
        rx = np.where(moving, cs * ax - sn * ay, 0.0)   # the anchor's arm in the world [m]
        ry = np.where(moving, sn * ax + cs * ay, 0.0)
        px = np.where(moving, q[b, 0] + rx, ax)         # a world anchor's own coordinates
        py = np.where(moving, q[b, 1] + ry, ay)
        c[2 * rows] += sign * px
        c[2 * rows + 1] += sign * py
        m = rows[moving]
        bm = b[moving]
        np.add.at(J, (2 * m, 3 * bm), sign)
        np.add.at(J, (2 * m + 1, 3 * bm + 1), sign)
        np.add.at(J, (2 * m, 3 * bm + 2), -sign * ry[moving])
        np.add.at(J, (2 * m + 1, 3 * bm + 2), sign * rx[moving])
        if H is not None:
            lx, ly = impulse[2 * m], impulse[2 * m + 1]
            np.add.at(H, (3 * bm + 2, 3 * bm + 2),
                      -sign * (rx[moving] * lx + ry[moving] * ly))


def _turned(theta, x, y):
    """(x, y) turned by theta [rad]."""
    cs, sn = np.cos(theta), np.sin(theta)
    return np.array([cs * x - sn * y, sn * x + cs * y])


def _cross(u, w):
    """z of u x w (2-vectors)."""
    return u[0] * w[1] - u[1] * w[0]


def _slider_terms(a, q, j, c, J, H, impulse):
    """joint_terms' rows of slider j: c_perp = n.(p_b - p_a) with d = R(theta_a) d0, n = (-d_y,
    d_x), and c_angle = theta_b - theta_a - ref. n.R(theta_a) r_a is constant, so c_perp =
    n.(x_b - x_a) + n.R(theta_b) r_b + const: its Hessian has the terms theta_a theta_a
    -n.(p_b - x_a), theta_a x_b -d, theta_a x_a +d, theta_a theta_b -d.perp(R r_b), theta_b
    theta_b -n.R r_b (dn / dtheta_a = -d); the angle row is linear."""
    ba, bb = int(a.pin_body[j, 0]), int(a.pin_body[j, 1])
    r = 2 * j
    if ba >= 0:
        d = _turned(q[ba, 2], *a.pin_axis[j])
        pa = q[ba, :2] + _turned(q[ba, 2], *a.pin_anchor[j, 0])
    else:
        d = np.asarray(a.pin_axis[j], dtype=float)
        pa = np.asarray(a.pin_anchor[j, 0], dtype=float)
    nrm = np.array([-d[1], d[0]])
    arm_b = _turned(q[bb, 2], *a.pin_anchor[j, 1])
    pb = q[bb, :2] + arm_b
    c[r] = nrm @ (pb - pa)
    c[r + 1] = q[bb, 2] - a.pin_ref[j] - (q[ba, 2] if ba >= 0 else 0.0)
    J[r, 3 * bb:3 * bb + 2] += nrm
    J[r, 3 * bb + 2] += _cross(pb - q[bb, :2], nrm)
    J[r + 1, 3 * bb + 2] += 1.0
    if ba >= 0:
        J[r, 3 * ba:3 * ba + 2] -= nrm
        J[r, 3 * ba + 2] -= _cross(pb - q[ba, :2], nrm)
        J[r + 1, 3 * ba + 2] -= 1.0
    if H is None:
        return
    lam = impulse[r]
    tb = 3 * bb + 2
    H[tb, tb] -= lam * (nrm @ arm_b)
    if ba >= 0:
        ta = 3 * ba + 2
        H[ta, ta] -= lam * (nrm @ (pb - q[ba, :2]))
        perp_b = np.array([-arm_b[1], arm_b[0]])
        mixed = [(3 * bb, -d[0]), (3 * bb + 1, -d[1]), (3 * ba, d[0]), (3 * ba + 1, d[1]),
                 (tb, -(d @ perp_b))]
        for k, value in mixed:
            H[ta, k] += lam * value
            H[k, ta] += lam * value


def force_terms(model, state, u):
    """(f (3 n_body,) [N, N m] the applied forces under commands u, F (3 n_body, n_act) their
    derivative with respect to u (0 for a command at or past a bound: from inside the range),
    at_bound: a bool per actuator, its command exactly at a bound)."""
    a = model.arrays
    n = model.n_body
    f = np.zeros((n, 3))
    f[:, 0] = a.body_mass * a.gravity[0] + state.ext_force[:, 0]
    f[:, 1] = a.body_mass * a.gravity[1] + state.ext_force[:, 1]
    f[:, 2] = np.where(a.body_inv_inertia > 0.0, state.ext_force[:, 2], 0.0)
    F = np.zeros((n, 3, model.n_act))
    lo, hi = a.act_range[:, 0], a.act_range[:, 1]
    inside = (u > lo) & (u < hi)
    at_bound = (u == lo) | (u == hi)
    u_sat = np.clip(u, lo, hi)
    for k in range(model.n_act):
        kind = int(a.act_kind[k])
        if kind == ACT_PIN_TORQUE:
            j = a.act_ref[k]
            F[a.pin_body[j, 1], 2, k] += 1.0
            if a.pin_body[j, 0] >= 0:
                F[a.pin_body[j, 0], 2, k] -= 1.0
        elif kind == ACT_BODY_FORCE:
            F[a.act_body[k, 0], :2, k] = a.act_dir[k]
        elif kind == ACT_BODY_TORQUE and a.body_inv_inertia[a.act_body[k, 0]] > 0.0:
            F[a.act_body[k, 0], 2, k] = 1.0
    f += F @ u_sat
    F = F * inside                       # a saturated command moves nothing (from inside)
    return f.ravel(), F.reshape(3 * n, model.n_act), at_bound


def step_jacobian(sim, u=None, _keep_end=False) -> StepJacobian:
    """The exact derivative of one step of `sim` (as `sim.step(u)` would take it) with respect
    to the state x = (q.ravel(), v.ravel()) and the commands u (module docstring). `sim` is
    left as it was (its state, options, audit and counters). Raises NotImplementedError for a
    model, option or step outside what is covered, naming it."""
    model = sim.model
    h = float(sim.dt)
    check_covered(model, sim.options, h)
    u = np.zeros(model.n_act) if u is None else np.asarray(u, dtype=float)
    if u.shape != (model.n_act,) or not np.all(np.isfinite(u)):
        raise ValueError(f"commands u must be {model.n_act} finite numbers, got {u!r}")
    start = sim.snapshot()
    options = sim.options
    audit, info = sim.ws.audit.copy(), sim.ws.info.copy()
    q0 = start.q.copy()
    v0 = start.v.copy()
    ended = False
    try:
        sim.step(u)
        ended = True
        end = sim.state
        q1, v1 = end.q.copy(), end.v.copy()
        touching = bool((end.contact_mode != MODE_FREE).any())
        substeps = int(sim.ws.info[INFO_TURN_SUBSTEPS])
        splits = int(sim.ws.info[INFO_CCD_SPLITS])
        limits = bool(end.limit_active.any())
    finally:
        if not (_keep_end and ended):
            sim.restore(start)
            if sim.options is not options:     # (the state setter resolves the speed bound)
                sim._options = options
                sim._repack()
            sim.ws.audit[:] = audit
            sim.ws.info[:] = info
    if touching:
        raise _not_covered("a contact that touches in the step")
    if limits:
        raise _not_covered("a joint limit reached in the step")
    if substeps > 1 or splits > 0:
        raise _not_covered(f"a step taken in {max(substeps, 1)} sub-steps / {splits} "
                           f"time-of-impact splits")
    gap = np.abs(joint_terms(model, q1)[0]).max(initial=0.0)
    if gap > PINS_CLOSED_TOL:
        raise _not_covered(f"joints left open by {gap:.3g} m at its end (the position "
                           f"correction's refine_tol or a stalled correction)")
    n = model.n_body
    f, F, saturated = force_terms(model, start, u)
    W, f_spring, K = rotor_terms(model, q0)
    free = q0.ravel() + h * v0.ravel() + h * h * (W @ (f + f_spring))
    _, P, _ = joint_terms(model, q0)
    # the step's total impulse L from its answer: W P^T L = q1 - free (least squares; P has
    # full row rank where the joints are independent, checked below)
    move = q1.ravel() - free
    WPt = W @ P.T
    if P.shape[0]:
        L, *_ = np.linalg.lstsq(WPt, move, rcond=None)
    else:
        L = np.zeros(0)
    eps = np.finfo(float).eps
    scale = max(np.abs(move).max(initial=0.0), np.abs(q1 - q0).max(), h * np.abs(v0).max())
    rounding = 64 * eps * (np.abs(q0).max() + np.abs(move).max(initial=0.0))
    if np.abs(WPt @ L - move).max(initial=0.0) > FIT_TOL * scale + rounding:
        raise _not_covered("an end that is not the joints' SHAKE step q + h v + h^2 W f "
                           "+ W P^T L")
    secant = (q1.ravel() - q0.ravel()) / h
    if np.abs(v1.ravel() - secant).max() > FIT_TOL * (np.abs(secant).max() + np.abs(v0).max()) \
            + rounding / h:
        raise _not_covered("an end velocity other than (q1 - q) / h (the position "
                           "correction's velocity change held back by its energy bound)")
    _, _, H = joint_terms(model, q0, L)
    _, G, _ = joint_terms(model, q1)
    nq = 3 * n
    eye = np.eye(nq)
    if G.shape[0]:
        GWP = G @ WPt
        if np.linalg.cond(GWP) > DEPENDENT_COND:
            raise _not_covered("dependent joints (an over-constrained loop): the step is not "
                               "smooth there")
        S = np.linalg.solve(GWP, G)                # (G W P^T)^-1 G
        proj = eye - WPt @ S
    else:
        proj = eye
    # d(q + h v + h^2 W f + W P^T L) with respect to q, v and u
    dq_dq = proj @ (eye + W @ (H + h * h * K))
    dq_dv = proj * h
    dq_du = proj @ (h * h * (W @ F))
    A = np.zeros((2 * nq, 2 * nq))
    A[:nq, :nq] = dq_dq
    A[:nq, nq:] = dq_dv
    A[nq:, :nq] = (dq_dq - eye) / h
    A[nq:, nq:] = dq_dv / h
    B = np.vstack([dq_du, dq_du / h])
    return StepJacobian(A=A, B=B, modes_changed=bool(saturated.any()),
                        x1=np.concatenate([q1.ravel(), v1.ravel()]))


def rollout_jacobians(sim, us) -> list:
    """Step `sim` under each command vector of `us` (n_steps, n_act) in turn and return the
    StepJacobian of each step (taken at the state it started from); `sim` ends after the
    last step, as `for u in us: sim.step(u)` leaves it (each step taken once). The
    derivative of the whole rollout is the product of the A's (the last one on the left). A
    step it does not cover raises NotImplementedError, `sim` left after that step."""
    us = np.asarray(us, dtype=float)
    if us.ndim != 2 or us.shape[1] != sim.model.n_act:
        raise ValueError(f"us must have shape (n_steps, {sim.model.n_act}), got {us.shape}")
    out = []
    for u in us:
        out.append(step_jacobian(sim, u, _keep_end=True))   # (the step taken once)
    return out
