"""Exact derivatives of one step: step_jacobian(sim, u); along a rollout: rollout_jacobians.

The default step (symplectic Euler with SHAKE, docs/engine.md) of a mechanism held by hinges
and sliders ends at

    v_lin = W_D (E_A v + h f(q, u)),          q_pred = q + h v_lin,
    (P W_D P^T) lam = -c(q_pred) / h,          v_new = v_lin + W_D P^T lam,
    q1 = q + h v_new + W_A P^T mu,   c(q1) = 0,   v1 = (q1 - q) / h,

with c the joints' equality rows (a hinge's x and y, a slider's perpendicular and angle
rows), P = dc/dq at the step's start, lam the velocity solve's impulses and mu the Newton
correction's. E_A = M + A is the bodies' masses with the joints' rotors (A = sum a g g^T over
the joints' armature a and rate rows g), E_D = M + sum (a + h c) g g^T the same with the
dampers c taken implicitly (kernels/soft.py: the soft rows, solved with the pins and alone
for the linearisation v_lin); W_A = E_A^-1 and W_D = E_D^-1. f holds gravity, pushes, the
actuators' commands and the joints' springs, taken at the step's start. Without dampers W_D =
W_A and only lam h + mu matters; with them the velocity solve and the correction move along
different directions, so lam is the velocity solve's own (computed here from the equation
above and checked against the step's answer). Within its modes the step is smooth and the
implicit function theorem on c(q1) = 0 and on the velocity solve gives its derivative
exactly: the joints' Jacobians at the start, at q_pred and at q1, and their curvature (each
row's Hessian) under lam, mu and W_D P^T lam. The step is taken once, on a snapshot (`sim`
is restored). A step taken in sub-steps (a body turning fast: step.turn_substeps) is the
chain rule through them, each a step of h / n. Where the correction's energy bound
(kernels/integrate.py bound_correction_work) kept only a share k of the correction's velocity
change, v1 = v_new + k (q1 - q - h v_new) / h with k the bound's own root, differentiated with
the energies it weighs (_energy_bound). A step that did not end as those equations say (the
bound taking energy from the motion as well, a velocity solve that fell back to its
first-order target) raises instead of giving a derivative of a different map.

Covered so far: bodies held by hinges (pins) and sliders to each other and the world, free
bodies' coordinates (an MJCF root's slides and hinge), with joint limits the step does not
reach; armature, dampers and the springs the step resolves on every joint whose rate row g is
constant (hinges, and slides along a world axis whose anchor is their body's centre of mass:
MJCF roots, a cart on a rail); under gravity, constant pushes, pin torques, body forces and
torques and forces along such slides. Refused with a NotImplementedError naming the feature:
armature, dampers or springs on a slider whose rate row turns with its bodies (its rotor adds
velocity-product forces), rods, a limit reached in the step, dry friction, springs too stiff
for the step, contacts and shape pairs that touch in the step, fluid drag, the other
actuator kinds, the accurate integrators.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .kernels.codes import (INTEGRATOR_EULER, JOINT_FREE_BIT, JOINT_HINGE, JOINT_SLIDE_BIT,
                            JOINT_SLIDER, MODE_FREE)
from .kernels.forces import ACT_BODY_FORCE, ACT_BODY_TORQUE, ACT_PIN_TORQUE, ACT_SLIDER_FORCE
from .kernels.info import INFO_CCD_SPLITS, INFO_TURN_SUBSTEPS
from .kernels.work import (CONSTRAINT_SHARE, CORRECTION_MOVE_FLOOR, RELATIVE_ROUNDING,
                           SHAKE_REGIME, VELOCITY_FLOOR)

#: the step's end must satisfy q1 = q + h v* + W P^T L to this share of |q1 - q| (plus
#: rounding) for its derivative to be this map's
FIT_TOL = 1e-9

_LINEAR_ACTUATORS = {ACT_PIN_TORQUE: "pin torque", ACT_BODY_FORCE: "body force",
                     ACT_BODY_TORQUE: "body torque", ACT_SLIDER_FORCE: "slider force"}


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
        f"step_jacobian covers mechanisms of hinges, sliders and free bodies' coordinates "
        f"(armature, dampers and the springs the step resolves on joints whose rate row is "
        f"constant), with limits the step does not reach, under gravity, pushes, pin and "
        f"body torques, body forces and forces along such slides so far; this step has {what}")


def inverse_masses(a) -> np.ndarray:
    """The bodies' inverse masses and inertias per coordinate (3 n_body,) [1/kg, 1/(kg m^2)]
    of model arrays a (a point mass's turn: 0)."""
    return np.column_stack([a.body_inv_mass, a.body_inv_mass, a.body_inv_inertia]).ravel()


def _constant_rate_row(a, j) -> bool:
    """Joint j's rate row g is the same at every q: a hinge's (theta_b - theta_a), a free
    hinge's, or a slide's along a world axis (body a the world) whose anchor on body b is its
    centre of mass."""
    if not a.pin_kind[j] & JOINT_SLIDE_BIT:
        return True
    return a.pin_body[j, 0] < 0 and not np.any(a.pin_anchor[j, 1])


def rate_row(a, j, n) -> np.ndarray:
    """Joint j's rate row g (3 n,): its coordinate's rate is g v. Only for a constant row
    (_constant_rate_row): a hinge's -1 / +1 on its bodies' angles, a world slide's axis on
    its body's x and y."""
    g = np.zeros(3 * n)
    ba, bb = a.pin_body[j]
    if a.pin_kind[j] & JOINT_SLIDE_BIT:
        g[3 * bb:3 * bb + 2] = a.pin_axis[j]
        return g
    g[3 * bb + 2] = 1.0
    if ba >= 0:
        g[3 * ba + 2] = -1.0
    return g


def _soft_joints(a):
    """The joints with armature, a damper or a spring."""
    return np.flatnonzero((a.pin_armature > 0.0) | (a.pin_damping > 0.0)
                          | (a.pin_stiffness > 0.0))


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
    w = inverse_masses(a)
    for j, name in enumerate(model.pin_names):
        kind = int(a.pin_kind[j])
        if kind & ~(JOINT_SLIDE_BIT | JOINT_FREE_BIT):
            raise _not_covered(f"joint {name!r} of kind {kind}")
        if a.pin_frictionloss[j] != 0.0:
            raise _not_covered(f"dry friction on joint {name!r}")
        k, arm, damp = a.pin_stiffness[j], a.pin_armature[j], a.pin_damping[j]
        if k == 0.0 and arm == 0.0 and damp == 0.0:
            continue
        if not _constant_rate_row(a, j):
            # (its rate row turns with its bodies: the rotor adds velocity-product forces,
            # and the rotor, damper and spring depend on q)
            feature = "armature" if arm else "a damper" if damp else "a spring"
            raise _not_covered(f"{feature} on slider {name!r}, whose rate row turns with its "
                               f"bodies")
        if k > 0.0:
            g = rate_row(a, j, model.n_body)
            kappa = float(g @ (w * g))
            resolved = h * h * k * kappa / (1.0 + arm * kappa)
            if resolved > 0.5:
                raise _not_covered(f"a spring on joint {name!r} that the step takes at its end "
                                   f"(too stiff for the step)")
    for k, name in enumerate(model.act_names):
        kind = int(a.act_kind[k])
        if kind not in _LINEAR_ACTUATORS:
            raise _not_covered(f"actuator {name!r} of kind {kind}")
        if kind == ACT_SLIDER_FORCE and not _constant_rate_row(a, a.act_ref[k]):
            raise _not_covered(f"actuator {name!r}, a force along a slider whose axis or "
                               f"anchor turns with its bodies")


def rotor_terms(model, q, h):
    """The bodies' inverse masses with the joints' rotors and dampers (module docstring), for a
    step of h [s] from q (n_body, 3): (W_A = (M + A)^-1, W_D = (M + A + h C)^-1, R = W_D (M + A),
    each (3 n_body, 3 n_body); f_spring (3 n_body,) [N, N m] the joints' springs at q, K =
    d f_spring / dq; the rotors' inertia A; the springs without rotor or damper alone, which
    the step applies as forces (f_alone, K_alone)). Every joint with armature, a damper or a
    spring has a constant rate row (check_covered)."""
    a = model.arrays
    n = model.n_body
    w = inverse_masses(a)
    A = np.zeros((3 * n, 3 * n))
    D = np.zeros((3 * n, 3 * n))
    K = np.zeros((3 * n, 3 * n))
    f = np.zeros(3 * n)
    f_alone = np.zeros(3 * n)
    K_alone = np.zeros((3 * n, 3 * n))
    for j in _soft_joints(a):
        g = rate_row(a, j, n)
        gg = np.outer(g, g)
        A += a.pin_armature[j] * gg
        D += (a.pin_armature[j] + h * a.pin_damping[j]) * gg
        k = a.pin_stiffness[j]
        if k > 0.0:
            coordinate = g @ q.ravel()
            if a.pin_kind[j] & JOINT_SLIDE_BIT:
                coordinate -= a.pin_axis[j] @ a.pin_anchor[j, 0]   # (anchor a in the world)
            else:
                coordinate -= a.pin_ref[j]
            f -= k * (coordinate - a.pin_rest[j]) * g
            K -= k * gg
            if a.pin_armature[j] == 0.0 and a.pin_damping[j] == 0.0:
                # a spring alone is a force of stage 1 (kernels/forces.py spring_as_force)
                f_alone -= k * (coordinate - a.pin_rest[j]) * g
                K_alone -= k * gg
    # (M + X)^-1 = (I + W X)^-1 W, which holds where W has zeros (a point mass's turn); and
    # (M + D)^-1 (M + A) = (I + W D)^-1 (I + W A)
    eye = np.eye(3 * n)
    W_A = np.linalg.solve(eye + w[:, None] * A, np.diag(w))
    W_D = np.linalg.solve(eye + w[:, None] * D, np.diag(w))
    R = np.linalg.solve(eye + w[:, None] * D, eye + w[:, None] * A)
    return W_A, W_D, R, f, K, A, f_alone, K_alone


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


def joint_hessians(model, q):
    """T (2 n_pin, 3 n_body, 3 n_body): the Hessian of each of the joints' rows at q
    (joint_terms' H for a unit impulse on that row alone): a hinge's x and y rows bend only
    in their bodies' angles, d^2 (R(theta) r) / dtheta^2 = -R(theta) r; a slider's
    perpendicular row as _slider_terms says, its angle row not at all."""
    a = model.arrays
    n = q.shape[0]
    T = np.zeros((2 * model.n_pin, 3 * n, 3 * n))
    hinges = np.flatnonzero(a.pin_kind == JOINT_HINGE)
    for e, sign in ((0, -1.0), (1, 1.0)):
        body = a.pin_body[hinges, e]
        moving = body >= 0
        j, b = hinges[moving], body[moving]
        th = q[b, 2]
        ax, ay = a.pin_anchor[j, e, 0], a.pin_anchor[j, e, 1]
        rx = np.cos(th) * ax - np.sin(th) * ay
        ry = np.sin(th) * ax + np.cos(th) * ay
        T[2 * j, 3 * b + 2, 3 * b + 2] -= sign * rx
        T[2 * j + 1, 3 * b + 2, 3 * b + 2] -= sign * ry
    for j in np.flatnonzero(a.pin_kind == JOINT_SLIDER):
        unit = np.zeros(2 * model.n_pin)
        unit[2 * j] = 1.0
        H = np.zeros((3 * n, 3 * n))
        _slider_terms(a, q, int(j), np.zeros(2 * model.n_pin),
                      np.zeros((2 * model.n_pin, 3 * n)), H, unit)
        T[2 * j] = H
    return T


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
    derivative with respect to u (0 for a command past a bound; for one exactly at a bound,
    the derivative from inside the range), at_bound: a bool per actuator, its command exactly
    at a bound)."""
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
        elif kind == ACT_SLIDER_FORCE:
            # along a world slide's axis at its body's centre of mass (check_covered)
            F[:, :, k] = rate_row(a, a.act_ref[k], n).reshape(n, 3)
    f += F @ u_sat
    # a command past a bound moves nothing; one exactly at a bound: the derivative from inside
    # the range (StepJacobian.modes_changed says so)
    F = F * (inside | at_bound)
    return f.ravel(), F.reshape(3 * n, model.n_act), at_bound


def _energy_bound(model, h, q0, v0, v_s, dv, move, f, rotors):
    """The share k of the position correction's velocity change dv [m/s, rad/s] that its
    energy bound keeps (kernels/integrate.py bound_correction_work, its arithmetic in exact
    terms) after a velocity solve that ended at v_s, for a step of h [s] from (q0, v0) whose
    correction moved the positions by `move` under the applied forces f (ws.force); rotors:
    the joints' rotors' inertia A. Returns (k, the partial derivatives of k with respect to
    the bound's inputs, for _bound_derivative), or None where the bound took more than the
    correction's velocity change (the motion paid: not covered)."""
    a_ = model.arrays
    n = model.n_body
    Mb = np.column_stack([a_.body_mass, a_.body_mass, a_.body_inertia]).ravel()
    E = np.diag(Mb) + rotors                # the bodies' and the rotors' kinetic energy
    Ev, Edv = E @ v_s, E @ dv
    a = v_s @ Edv
    b = 0.5 * dv @ Edv
    kinetic = 0.5 * v_s @ Ev
    # velocity_stage_gain: the start's kinetic energy and the energy the solve gained
    gravity = np.asarray(a_.gravity, dtype=float)
    g = float(np.hypot(*gravity))
    up = -gravity / g if g > 0.0 else np.zeros(2)
    f_g = np.zeros(3 * n)
    f_g[0::3] = a_.body_mass * gravity[0]
    f_g[1::3] = a_.body_mass * gravity[1]
    other = f - f_g
    start = 0.5 * v0 @ (Mb * v0)
    Up = np.zeros(3 * n)
    Up[0::3] = a_.body_mass * up[0]
    Up[1::3] = a_.body_mass * up[1]
    dp = Up @ (v_s - v0)
    total_mass = float(a_.body_mass.sum())
    lift = 0.5 * h * g * dp
    sink = -dp * dp / (2.0 * total_mass) if total_mass > 0.0 else 0.0
    owed = max(lift, sink) if total_mass > 0.0 else 0.0
    gained = (0.5 * v_s @ (Mb * v_s) - start - h * f @ v_s + 0.5 * h * other @ (v_s - v0)
              - owed)
    in_regime = b <= SHAKE_REGIME * SHAKE_REGIME * kinetic
    smaller = min(kinetic, start)
    share = max(CONSTRAINT_SHARE * smaller - max(gained, 0.0), 0.0)
    force_work = f @ move
    dvx = np.abs(dv).reshape(n, 3)[:, :2]
    vsx = np.abs(v_s).reshape(n, 3)[:, :2]
    momentum = float(a_.body_mass @ (dvx.sum(axis=1) + vsx.sum(axis=1)))
    forces = float(np.abs(f.reshape(n, 3)[:, :2]).sum())
    rounding = (VELOCITY_FLOOR * momentum + CORRECTION_MOVE_FLOOR * forces
                + RELATIVE_ROUNDING * (kinetic + abs(a) + b))
    room = (share if in_regime else 0.0) + force_work + rounding
    if a + b <= room:
        return 1.0, None
    if not b > 0.0:
        return None
    disc = a * a + 4.0 * b * room
    root = np.sqrt(disc) if disc >= 0.0 else -1.0
    k = (-a + root) / (2.0 * b) if disc >= 0.0 else -1.0
    if k < 0.0 or (disc >= 0.0 and -a - root > 2.0 * b):
        # no k in [0, 1] keeps the energy within room: the k of least energy, -a / (2 b) in
        # [0, 1] (the kernel then pays what is left from the motion, which the caller's check
        # of the end velocity refuses)
        k = -a / (2.0 * b)
        if not 0.0 < k < 1.0:
            return min(max(k, 0.0), 1.0), None      # (clipped: the same k nearby)
        k_a, k_b, k_room = -1.0 / (2.0 * b), a / (2.0 * b * b), 0.0
    elif k > 1.0:
        return None
    else:
        # partial derivatives of k = (-a + sqrt(a^2 + 4 b room)) / (2 b)
        k_a = (-1.0 + a / root) / (2.0 * b)
        k_b = room / (b * root) - k / b
        k_room = 1.0 / root
    grads = dict(k_a=k_a, k_b=k_b, k_room=k_room, E=E, Mb=Mb, v_s=v_s, dv=dv, v0=v0, f=f,
                 other=other, f_g=f_g, Up=Up, h=h, move=move, in_regime=in_regime,
                 share_on=in_regime and CONSTRAINT_SHARE * smaller - max(gained, 0.0) > 0.0,
                 smaller_is_kinetic=kinetic <= start, gained_on=gained > 0.0,
                 owed_lift=lift >= sink, dp=dp, total_mass=total_mass, g=g,
                 sign_a=np.sign(a), n=n)
    return k, grads


def _bound_derivative(grads, dv_s, d_dv, d_move, df, d_v0):
    """dk (a row over the columns of the differentials) of _energy_bound's k from the
    differentials of its inputs: dv_s of the solve's answer, d_dv of the correction's velocity
    change, d_move of its move, df of the applied forces, d_v0 of the start's velocity."""
    if grads is None:                   # (k = 0 or 1 held for every nearby input)
        return np.zeros(dv_s.shape[1])
    G = grads
    E, Mb, v_s, dv, h, n = G["E"], G["Mb"], G["v_s"], G["dv"], G["h"], G["n"]
    d_a = (E @ dv) @ dv_s + (E @ v_s) @ d_dv
    d_b = (E @ dv) @ d_dv
    d_kin = (E @ v_s) @ dv_s
    d_room = np.zeros_like(d_a)
    if G["share_on"]:
        d_start = (Mb * G["v0"]) @ d_v0
        d_small = d_kin if G["smaller_is_kinetic"] else d_start
        d_share = CONSTRAINT_SHARE * d_small
        if G["gained_on"]:
            d_dp = G["Up"] @ (dv_s - d_v0)
            d_owed = (0.5 * h * G["g"] * d_dp if G["owed_lift"]
                      else -G["dp"] / G["total_mass"] * d_dp)
            d_gained = ((Mb * v_s) @ dv_s - d_start - h * (G["f"] @ dv_s + v_s @ df)
                        + 0.5 * h * (G["other"] @ (dv_s - d_v0) + (v_s - G["v0"]) @ df)
                        - d_owed)
            d_share = d_share - d_gained
        d_room = d_room + d_share
    d_room = d_room + G["f"] @ d_move + G["move"] @ df
    mass = np.repeat(np.asarray(Mb).reshape(n, 3)[:, 0], 3)
    planar = np.tile([1.0, 1.0, 0.0], n)
    d_room = d_room + VELOCITY_FLOOR * ((mass * planar * np.sign(dv)) @ d_dv
                                        + (mass * planar * np.sign(v_s)) @ dv_s)
    d_room = d_room + CORRECTION_MOVE_FLOOR * ((planar * np.sign(G["f"])) @ df)
    d_room = d_room + RELATIVE_ROUNDING * (d_kin + G["sign_a"] * d_a + d_b)
    return G["k_a"] * d_a + G["k_b"] * d_b + G["k_room"] * d_room


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
                sim._new_options()
            sim.ws.audit[:] = audit
            sim.ws.info[:] = info
    if touching:
        raise _not_covered("a contact that touches in the step")
    if limits:
        raise _not_covered("a joint limit reached in the step")
    if splits > 0:
        raise _not_covered(f"a step taken in {splits} time-of-impact splits")
    if substeps > 1:
        return _substeps_jacobian(sim, u, substeps, start, q1, v1, _keep_end, audit, info)
    gap = np.abs(joint_terms(model, q1)[0]).max(initial=0.0)
    if gap > PINS_CLOSED_TOL:
        raise _not_covered(f"joints left open by {gap:.3g} m at its end (the position "
                           f"correction's refine_tol or a stalled correction)")
    n = model.n_body
    nq = 3 * n
    f, F, saturated = force_terms(model, start, u)
    W_A, W_D, R, f_spring, K, rotors, f_alone, K_alone = rotor_terms(model, q0, h)
    # the rows of the joints that hold something (a free body's coordinate has none)
    held = np.flatnonzero(np.repeat((model.arrays.pin_kind & JOINT_FREE_BIT) == 0, 2))
    P = joint_terms(model, q0)[1][held]
    # the velocity solve (module docstring): its linearisation, target and impulses
    v_lin = R @ v0.ravel() + h * (W_D @ (f + f_spring))
    q_pred = q0.ravel() + h * v_lin
    c_pred, P_pred, _ = joint_terms(model, q_pred.reshape(n, 3))
    c_pred, P_pred = c_pred[held], P_pred[held]
    WdPt = W_D @ P.T
    WaPt = W_A @ P.T
    if P.shape[0]:
        N = P @ WdPt
        if np.linalg.cond(N) > DEPENDENT_COND:
            raise _not_covered("dependent joints (an over-constrained loop): the step is not "
                               "smooth there")
        lam = -np.linalg.solve(N, c_pred) / h
    else:
        lam = np.zeros(0)
    v_new = v_lin + WdPt @ lam
    # the correction's total impulse mu from the step's answer: W_A P^T mu = q1 - q - h v_new
    # (least squares; P has full row rank where the joints are independent, checked above)
    move = q1.ravel() - q0.ravel() - h * v_new
    mu = np.linalg.lstsq(WaPt, move, rcond=None)[0] if P.shape[0] else np.zeros(0)
    eps = np.finfo(float).eps
    scale = max(np.abs(move).max(initial=0.0), np.abs(q1 - q0).max(), h * np.abs(v0).max())
    rounding = 64 * eps * (np.abs(q0).max() + np.abs(move).max(initial=0.0))
    if np.abs(WaPt @ mu - move).max(initial=0.0) > FIT_TOL * scale + rounding:
        raise _not_covered("an end that is not the joints' SHAKE step q + h v_new + W P^T mu "
                           "(a velocity solve that took its first-order target)")
    secant = (q1.ravel() - q0.ravel()) / h
    speed_tol = FIT_TOL * (np.abs(secant).max() + np.abs(v0).max()) + rounding / h
    dv_move = secant - v_new            # the correction's velocity change, move / h
    bounded = np.abs(v1.ravel() - secant).max() > speed_tol
    if bounded:
        # the correction's energy bound kept v_new + k dv_move (kernels/integrate.py)
        bound = _energy_bound(model, h, q0.ravel(), v0.ravel(), v_new, dv_move,
                              q1.ravel() - q0.ravel() - h * v_new, f + f_alone, rotors)
        if bound is None or np.abs(v1.ravel() - (v_new + bound[0] * dv_move)).max() > speed_tol:
            raise _not_covered("an end velocity other than (q1 - q) / h that the position "
                               "correction's energy bound does not explain (its velocity "
                               "change paid for by the motion)")
    # differentials as linear maps of (dq, dv, du): matrices of 2 nq + n_act columns
    nu = model.n_act
    eye = np.eye(nq)
    zero_v = np.zeros((nq, nq + nu))
    d_q = np.hstack([eye, zero_v])                          # dq itself
    dv_lin = np.hstack([h * (W_D @ K), R, h * (W_D @ F)])
    dq_pred = d_q + h * dv_lin
    dv_new = dv_lin
    base = d_q
    if P.shape[0]:
        T = joint_hessians(model, q0)[held]                # each row's Hessian at q
        H_lam = np.tensordot(lam, T, axes=1)               # d (P^T lam) / dq
        H_mu = np.tensordot(mu, T, axes=1)
        T_x = T @ (WdPt @ lam)                             # d (P x) / dq, x = W_D P^T lam
        # N lam = -c(q_pred) / h, differentiated (W_D constant: check_covered)
        rhs = P_pred @ dq_pred / h
        rhs[:, :nq] += T_x + P @ (W_D @ H_lam)
        d_lam = -np.linalg.solve(N, rhs)
        dv_new = dv_lin + WdPt @ d_lam
        dv_new[:, :nq] += W_D @ H_lam
        base = d_q + W_A @ np.hstack([H_mu, zero_v])
        G = joint_terms(model, q1)[1][held]
        GWP = G @ WaPt
        if np.linalg.cond(GWP) > DEPENDENT_COND:
            raise _not_covered("dependent joints (an over-constrained loop): the step is not "
                               "smooth there")
        proj = eye - WaPt @ np.linalg.solve(GWP, G)
    else:
        proj = eye
    dq1 = proj @ (base + h * dv_new)
    dv1 = (dq1 - d_q) / h
    if bounded:
        # v1 = v_new + k dv_move: d v1 = dv_new + k d(dv_move) + dv_move dk
        d_move = dv1 - dv_new
        df = np.hstack([K_alone, np.zeros((nq, nq)), F])
        k, grads = bound
        dk = _bound_derivative(grads, dv_new, d_move, dq1 - d_q - h * dv_new, df,
                               np.hstack([np.zeros((nq, nq)), np.eye(nq), np.zeros((nq, nu))]))
        dv1 = dv_new + k * d_move + np.outer(dv_move, dk)
    A = np.vstack([dq1[:, :2 * nq], dv1[:, :2 * nq]])
    B = np.vstack([dq1[:, 2 * nq:], dv1[:, 2 * nq:]])
    return StepJacobian(A=A, B=B, modes_changed=bool(saturated.any()),
                        x1=np.concatenate([q1.ravel(), v1.ravel()]))


#: the sub-steps taken one by one must end where the whole step ended, to this share of the
#: state's size (they are the same arithmetic: the same bits, measured)
SUBSTEPS_TOL = 1e-12


def _substeps_jacobian(sim, u, n, start, q1, v1, keep_end, audit, info) -> StepJacobian:
    """The derivative of a step the engine took in n equal sub-steps (step.turn_substeps: a
    body turning fast), each a whole step of h / n of its own: the chain rule through them,
    A = A_n ... A_1 and B = sum_k A_n ... A_(k+1) B_k, each sub-step's from step_jacobian at
    StepOptions.dt = h / n and max_substeps 1 (the engine's sub-steps do not decide again how
    to split themselves). `sim` ends as step_jacobian leaves it (audit, info: its audit and
    counters before the step); raises where the sub-steps do not end where the step did."""
    options = sim.options
    try:
        sim.restore(start)
        sim._options = options._replace(dt=sim.dt / n, max_substeps=1)
        sim._new_options()
        parts = [step_jacobian(sim, u, _keep_end=True) for _ in range(n)]
    finally:
        sim.restore(start)
        sim._options = options
        sim._new_options()
        sim.ws.audit[:] = audit
        sim.ws.info[:] = info
    x1 = np.concatenate([q1.ravel(), v1.ravel()])
    if np.abs(parts[-1].x1 - x1).max() > SUBSTEPS_TOL * max(np.abs(x1).max(), 1.0):
        raise _not_covered(f"{n} sub-steps that end elsewhere than steps of h / {n}")
    A, B = parts[0].A, parts[0].B
    for part in parts[1:]:
        A, B = part.A @ A, part.A @ B + part.B
    if keep_end:
        sim.step(u)             # (from the audit and counters before the step: counted once)
    return StepJacobian(A=A, B=B, modes_changed=any(p.modes_changed for p in parts), x1=x1)


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
