"""Exact derivatives of one step: step_jacobian(sim, u); along a rollout: rollout_jacobians.

The step is taken once by the engine, on a snapshot (`sim` is restored), and then replayed in
numpy by planarsim.step_replica under the decisions it took (its contacts' modes and slips,
the Newton correction's passes, the energy bound's branch, the rows it left out as
dependent). The replay must end where the engine ended (to FIT_TOL of the step's motion, plus
rounding), or the step is refused: what it computes is then the engine's map. Within those
decisions the step is smooth, and the replay is analytic in the state and the commands, so
it is differentiated by the complex step (a start x + i e dx: the imaginary part of the end
over e is the directional derivative, exact to rounding, with no difference taken): every
column of A = d x1 / d x and B = d x1 / d u in one batched replay. The step it replays
(docs/engine.md):

    v_lin = W_D (E_A v + h f(q, u)),          q_pred = q + h v_lin,
    P W_D F^T lam = -b,   v_new = v_lin + W_D F^T lam,
    q1 = q + h v_new + W_A P^T mu with every row held at q1 (Newton, along the start's rows),
    v1 = v_new + the correction's velocity change (its move / h for the joints and limits;
         nothing along a contact's normal, which moves positions only), as far as its energy
         bound keeps it,

P the rows at the step's start: the joints' (a hinge's x and y, a slider's perpendicular and
angle rows) and the touching ground contacts' (a normal row; a sticking contact's tangent
row), F = P but for a sliding contact's normal row, whose impulse pushes along n - mu s t;
b the joints' gaps at q_pred / h and the contacts' gaps at the start (a positive one: a
contact that starts inside the ground only stops approaching) / h. E_A = M + A is the
bodies' masses with the joints' rotors (armature), W_A its inverse, W_D the same with the
dampers taken implicitly; f holds gravity, pushes, the actuators' commands and the joints'
springs. A step taken in sub-steps (a body turning fast: step.turn_substeps) is the chain
rule through them, each a step of h / n.

A touching contact's gap at the start is a boundary of the step's pieces: a start lifted off
the ground by dz closes it in the step (its velocity solve aims at the surface), one pushed
into the ground by dz is moved out by the correction (positions only). For a contact resting
on its surface (within refine_tol) the derivative across it is the one from inside: where
the engine's correction took no pass, the replay adds the projection of the start's push
into the surface alone (its real part 0: the end is the engine's); for one lifted off it,
the lifted piece's; along the surface (the states a contact keeps) both pieces agree.

Covered so far: bodies held by hinges (pins), rods and sliders to each other and the world, free
bodies' coordinates (an MJCF root's slides and hinge), with joint limits (a limit row is
unilateral, as a contact's normal: the same two pieces at its surface; a slider's only where
its rate row is constant); armature, dampers and the springs the step resolves on every joint whose rate row g is
constant (hinges, and slides along a world axis whose anchor is their body's centre of mass:
MJCF roots, a cart on a rail); ground contacts of points and round soles on any terrain
(on hills the closest ground point is the engine's, continued by Newton for the complex
step) and shape pairs (the manifold point rebuilt from its features), sticking or sliding
(Coulomb), several sharing a load (the rows the engine leaves out as dependent, left out
alike); under gravity, constant pushes, pin torques, body forces
and torques, forces along such slides, axial forces between two bodies and hip torques (the
Simple Biped's legs and hip). Refused with a NotImplementedError naming the feature:
armature, dampers or springs on a slider whose rate row turns with its bodies (its rotor adds
velocity-product forces), the limit of such a slider reached in the step, dry
friction, springs too stiff for the step, a box's straight edge on hills, restitution, a step split at a time of impact, fluid drag, the other actuator kinds,
the accurate integrators.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .kernels.codes import (CONTACT_ARC, CONTACT_PAIR, CONTACT_POINT, INTEGRATOR_EULER,
                            JOINT_FREE_BIT, JOINT_SLIDE_BIT, MODE_FREE, MODE_PINNED)
from .kernels.geometry.collide import MAX_CORE_VERTICES
from .kernels.dynamics.forces import (ACT_AXIAL, ACT_BODY_FORCE, ACT_BODY_TORQUE, ACT_HIP_TORQUE,
                                      ACT_PIN_TORQUE, ACT_SLIDER_FORCE)
from .kernels.info import INFO_CCD_SPLITS, INFO_PROJECTIONS, INFO_SHAKE_WHOLE, INFO_TURN_SUBSTEPS
from .step_replica import ContactPlan, ReplicaRefused, StepPlan, replica

#: the replay must end where the engine's step ended to this share of the step's motion (plus
#: rounding) for its derivative to be the engine's map's
FIT_TOL = 1e-9

_LINEAR_ACTUATORS = {ACT_PIN_TORQUE: "pin torque", ACT_BODY_FORCE: "body force",
                     ACT_BODY_TORQUE: "body torque", ACT_SLIDER_FORCE: "slider force"}
#: actuators whose force's direction turns with the bodies (computed in the replay)
_TURNING_ACTUATORS = {ACT_AXIAL: "axial force", ACT_HIP_TORQUE: "hip torque"}


@dataclass(frozen=True)
class StepJacobian:
    """The derivative of one step x -> x1, x = (q.ravel(), v.ravel()) [m, rad, m/s, rad/s].

    A : (n_x, n_x) d x1 / d x
    B : (n_x, n_u) d x1 / d u (u: the actuators' commands [N or N m])
    modes_changed : True where an infinitesimal change of x or u would change a mode of the
        step (a command exactly at its saturation bound: B then holds the derivative from
        inside the range; a touching contact or active limit at the edge of its mode:
        _at_mode_boundary; a contact or limit held at the start that the step let go); the
        derivative is then the mode's the step took
    x1 : the state after the step, in the same layout
    """
    A: np.ndarray
    B: np.ndarray
    modes_changed: bool
    x1: np.ndarray


def _not_covered(what):
    return NotImplementedError(
        f"step_jacobian covers mechanisms of hinges, sliders and free bodies' coordinates "
        f"(armature, dampers and the springs the step resolves on joints whose rate row is "
        f"constant) and their limits, ground contacts of points and round soles and shape "
        f"pairs, under gravity, pushes, pin, body and hip torques, body forces, axial forces "
        f"and forces along such slides so far; this step has {what}")


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
        if kind not in _LINEAR_ACTUATORS and kind not in _TURNING_ACTUATORS:
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
                # a spring alone is a force of stage 1 (kernels/dynamics/forces.py spring_as_force)
                f_alone -= k * (coordinate - a.pin_rest[j]) * g
                K_alone -= k * gg
    # (M + X)^-1 = (I + W X)^-1 W, which holds where W has zeros (a point mass's turn); and
    # (M + D)^-1 (M + A) = (I + W D)^-1 (I + W A)
    eye = np.eye(3 * n)
    W_A = np.linalg.solve(eye + w[:, None] * A, np.diag(w))
    W_D = np.linalg.solve(eye + w[:, None] * D, np.diag(w))
    R = np.linalg.solve(eye + w[:, None] * D, eye + w[:, None] * A)
    return W_A, W_D, R, f, K, A, f_alone, K_alone


def force_terms(model, state, u):
    """(f (3 n_body,) [N, N m] the applied forces under commands u, but the actuators' whose
    direction turns with the bodies (_TURNING_ACTUATORS), F (3 n_body, n_act) their
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
        if kind in _TURNING_ACTUATORS:
            continue        # (the replay computes them: step_replica.turning_forces)
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


def step_jacobian(sim, u=None, _keep_end=False) -> StepJacobian:
    """The exact derivative of one step of `sim` (as `sim.step(u)` would take it) with respect
    to the state x = (q.ravel(), v.ravel()) and the commands u (module docstring). `sim` is
    left as it was (its state, options, audit and counters). Raises NotImplementedError for a
    model, option or step outside what is covered, naming it."""
    n_x = 6 * sim.model.n_body
    eye = np.eye(n_x + sim.model.n_act)
    t = _step_derivative(sim, u, (eye[:n_x], eye[n_x:]), _keep_end)
    return StepJacobian(A=t.dx1[:, :n_x], B=t.dx1[:, n_x:], modes_changed=t.modes_changed,
                        x1=t.x1)


@dataclass(frozen=True)
class StepTangents:
    """The derivatives of one step along k given directions (step_tangents).

    dx1 : (n_x, k) d x1 along each direction;  modes_changed, x1 : as StepJacobian's
    """
    dx1: np.ndarray
    modes_changed: bool
    x1: np.ndarray


def step_tangents(sim, u, dx, du=None, _keep_end=False) -> StepTangents:
    """The derivative of one step of `sim` along k directions of its start: dx (n_x, k) of the
    state x and du (n_u, k) of the commands (default none): forward mode, one replay of
    k + 1 rows instead of step_jacobian's n_x + n_u + 1. `sim` is left as it was (after the
    step with _keep_end)."""
    n_x = 6 * sim.model.n_body
    dx = np.asarray(dx, dtype=float)
    if dx.ndim == 1:
        dx = dx[:, None]
    if dx.ndim != 2 or dx.shape[0] != n_x or not np.all(np.isfinite(dx)):
        raise ValueError(f"dx must be finite directions of the state, shape ({n_x},) or "
                         f"({n_x}, k), got shape {np.shape(dx)}")
    k = dx.shape[1]
    du = np.zeros((sim.model.n_act, k)) if du is None else np.asarray(du, dtype=float)
    if du.ndim == 1 and k == 1:
        du = du[:, None]
    if du.shape != (sim.model.n_act, k):
        raise ValueError(f"du must have shape ({sim.model.n_act}, {k}), got {du.shape}")
    return _step_derivative(sim, u, (dx, du), _keep_end)


def _step_derivative(sim, u, directions, _keep_end):
    """StepTangents of one step along directions (dx (n_x, k), du (n_u, k)): step_tangents,
    and step_jacobian's along every coordinate and command."""
    model = sim.model
    h = float(sim.dt)
    check_covered(model, sim.options, h)
    u = np.zeros(model.n_act) if u is None else np.asarray(u, dtype=float)
    if u.shape != (model.n_act,) or not np.all(np.isfinite(u)):
        raise ValueError(f"commands u must be {model.n_act} finite numbers, got {u!r}")
    start = sim.snapshot()
    options = sim.options
    audit, info = sim.ws.audit.copy(), sim.ws.info.copy()
    ended = False
    try:
        sim.step(u)
        ended = True
        end = sim.state
        q1, v1 = end.q.copy(), end.v.copy()
        end_modes, end_slips = end.contact_mode.copy(), end.contact_slip.copy()
        impulses = end.last_contact_impulse.copy()
        features = end.contact_feature.copy()
        first_order = int(sim.ws.first_order[0])
        shake_whole = int(sim.ws.info[INFO_SHAKE_WHOLE]) > 0
        projections = int(sim.ws.info[INFO_PROJECTIONS])
        v_lin = sim.ws.v_lin.ravel().copy()
        limit_impulses = end.last_pin_impulse[:, 2:4].copy()
        substeps = int(sim.ws.info[INFO_TURN_SUBSTEPS])
        splits = int(sim.ws.info[INFO_CCD_SPLITS])
        limit_active = end.limit_active.copy()
        end_enabled = end.contact_enabled.copy()
    finally:
        if not (_keep_end and ended):
            sim.restore(start)
            if sim.options is not options:     # (the state setter resolves the speed bound)
                sim._options = options
                sim._new_options()
            sim.ws.audit[:] = audit
            sim.ws.info[:] = info
    if splits > 0:
        raise _not_covered(f"a step taken in {splits} time-of-impact splits")

    if substeps > 1:
        return _substeps_tangents(sim, u, substeps, start, q1, v1, _keep_end, audit, info,
                                  directions)
    jac, plan = _replica_tangents(sim, u, start, end_modes, end_slips, features, limit_active,
                                  q1, v1, first_order, projections, directions, shake_whole)
    if np.abs(plan.v_lin - v_lin).max(initial=0.0) > FIT_TOL * (np.abs(v_lin).max() + 1e-300):
        raise _not_covered("a velocity solve whose joints' target the step linearized again "
                           "at its first answer (step.relinearize)")
    near = plan.near is not None and plan.near.size > 0
    # a contact or limit held at the start that the step let go was on its surface: pressed
    # into it by an infinitesimal change of the start, it would have stayed
    released = (((start.contact_mode != MODE_FREE) & (end_modes == MODE_FREE)).any()
                or ((start.limit_active != 0) & (limit_active == 0)).any())
    if not jac.modes_changed and (released or near or _at_mode_boundary(
            model, end_modes, impulses, limit_active, limit_impulses, q1, v1, h,
            end_enabled)):
        jac = StepTangents(jac.dx1, True, jac.x1)
    return jac


#: the sub-steps taken one by one must end where the whole step ended, to this share of the
#: state's size (they are the same arithmetic: the same bits, measured)
SUBSTEPS_TOL = 1e-12


def _substeps_tangents(sim, u, n, start, q1, v1, keep_end, audit, info, directions):
    """The derivative of a step the engine took in n equal sub-steps (step.turn_substeps: a
    body turning fast), each a whole step of h / n of its own: the chain rule through them,
    each sub-step's tangents along the last one's (with the same command directions) at
    StepOptions.dt = h / n and max_substeps 1 (the engine's sub-steps do not decide again how
    to split themselves). `sim` ends as step_jacobian leaves it (audit, info: its audit and
    counters before the step); raises where the sub-steps do not end where the step did."""
    options = sim.options
    try:
        sim.restore(start)
        sim._options = options._replace(dt=sim.dt / n, max_substeps=1)
        sim._new_options()
        dx, du = directions
        changed = False
        for _ in range(n):
            part = _step_derivative(sim, u, (dx, du), True)
            dx, changed = part.dx1, changed or part.modes_changed
        tangents = StepTangents(dx, changed, part.x1)
    finally:
        sim.restore(start)
        sim._options = options
        sim._new_options()
        sim.ws.audit[:] = audit
        sim.ws.info[:] = info
    x1 = np.concatenate([q1.ravel(), v1.ravel()])
    if np.abs(tangents.x1 - x1).max() > SUBSTEPS_TOL * max(np.abs(x1).max(), 1.0):
        raise _not_covered(f"{n} sub-steps that end elsewhere than steps of h / {n}")
    if keep_end:
        sim.step(u)             # (from the audit and counters before the step: counted once)
    return tangents


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


def _sole(a, q, c):
    """Round sole c at q as kernels/geometry/contacts.py find_contact measures it: (how far [rad] its
    lowest direction lies inside its span, inf for a full circle, negative outside; the gap
    [m] of its lowest point; the gaps of its span's ends; those of its fallback vertices)."""
    from .kernels.geometry.terrain import closest_point
    coef = a.terrain_coef
    b = int(a.contact_body[c])
    cs, sn = np.cos(q[b, 2]), np.sin(q[b, 2])

    def gap(l):
        return float(closest_point(coef, *(q[b, :2] + np.array([cs * l[0] - sn * l[1],
                                                                  sn * l[0] + cs * l[1]])))[4])

    lc = np.asarray(a.contact_local[c], dtype=float)
    r = float(a.contact_radius[c])
    *_, nx, ny, centre_gap = closest_point(coef, *(q[b, :2] + np.array(
        [cs * lc[0] - sn * lc[1], sn * lc[0] + cs * lc[1]])))
    a0, a1 = a.contact_span[c]
    inside = np.inf
    if a1 - a0 < 2.0 * np.pi:
        down = np.arctan2(-(-sn * nx + cs * ny), -(cs * nx + sn * ny))
        inside = max(min(down + 2.0 * np.pi * w - a0, a1 - down - 2.0 * np.pi * w)
                     for w in (-1, 0, 1))
    ends = [gap(lc + r * np.array([np.cos(t), np.sin(t)])) for t in (a0, a1)]
    adr, num = int(a.contact_vert_adr[c]), int(a.contact_vert_num[c])
    return inside, float(centre_gap) - r, ends, [gap(v) for v in a.vert_local[adr:adr + num]]


def _ground_gap(a, q, c) -> float:
    """Ground contact c's gap [m] at q as kernels/geometry/contacts.py find_contact measures it: a
    point's; a round sole's lowest point where it lies within the sole's span, else the
    lowest of the span's ends; or a fallback vertex's, where lower."""
    from .kernels.geometry.terrain import closest_point
    if a.contact_kind[c] == CONTACT_POINT:
        b = int(a.contact_body[c])
        cs, sn = np.cos(q[b, 2]), np.sin(q[b, 2])
        lx, ly = a.contact_local[c]
        return float(closest_point(a.terrain_coef, q[b, 0] + cs * lx - sn * ly,
                                   q[b, 1] + sn * lx + cs * ly)[4])
    inside, sole_gap, ends, vertices = _sole(a, q, c)
    return min([sole_gap if inside >= 0.0 else min(ends)] + vertices)


#: [m] a free ground contact ending within this of the ground is at the edge of touching
FREE_GAP_EDGE = 1e-10
#: a touching contact is at the edge of its mode where its normal impulse, its friction
#: cone's margin (sticking) or its slip speed (sliding) is within this share of its scale
MODE_MARGIN = 1e-9


def _at_mode_boundary(model, modes, impulses, limit_active, limit_impulses, q1, v1, h,
                      enabled) -> bool:
    """A touching contact or an active joint limit at the edge of its mode at the step's end
    (impulses: the step's normal and tangential impulses [N s] per contact,
    State.last_contact_impulse; limit_impulses: its lower and upper limit impulses per joint,
    State.last_pin_impulse[:, 2:]): a contact or limit pushing with no impulse (about to
    leave), a contact sticking at its friction cone's edge or sliding with no slip (about to
    stick); an infinitesimal change of the start or the commands then changes the mode."""
    from .kernels.geometry.terrain import closest_point
    a = model.arrays
    touching = np.flatnonzero(modes != MODE_FREE)
    # a free ground contact (enabled) ending on the ground: an infinitesimal change engages it
    for c in np.flatnonzero((modes == MODE_FREE) & (enabled != 0)):
        if a.contact_kind[c] in (CONTACT_POINT, CONTACT_ARC) and \
                abs(_ground_gap(a, q1, c)) <= FREE_GAP_EDGE:
            return True
    if not touching.size and not limit_active.any():
        return False
    weight = float(a.body_mass.sum() * np.hypot(*a.gravity) * h)
    scale = (np.abs(impulses[touching]).sum() + np.abs(limit_impulses[limit_active != 0]).sum()
             + weight)
    for j, side in np.argwhere(limit_active != 0):
        if abs(limit_impulses[j, side]) <= MODE_MARGIN * scale:
            return True
    speed = np.abs(v1[:, :2]).max() + 1e-300
    for c in touching:
        lam_n, lam_t = impulses[c]
        mu = a.contact_mu[c]
        if lam_n <= MODE_MARGIN * scale:
            return True
        if modes[c] == MODE_PINNED and mu > 0.0:
            if mu * lam_n - abs(lam_t) <= MODE_MARGIN * (lam_n + abs(lam_t)) * max(mu, 1.0):
                return True
        elif mu > 0.0 and a.contact_kind[c] != CONTACT_PAIR:
            b = a.contact_body[c]
            th = q1[b, 2]
            lx, ly = a.contact_local[c]
            arm = np.array([np.cos(th) * lx - np.sin(th) * ly, np.sin(th) * lx + np.cos(th) * ly])
            # the ground's tangent at the point closest to the contact's point (centre)
            nx, ny = closest_point(a.terrain_coef, *(q1[b, :2] + arm))[2:4]
            tangent = np.array([ny, -nx])
            if a.contact_kind[c] == CONTACT_ARC:        # (the sole's point below its centre)
                arm -= a.contact_radius[c] * np.array([nx, ny])
            slip = tangent @ (v1[b, :2] + v1[b, 2] * np.array([-arm[1], arm[0]]))
            if abs(slip) <= MODE_MARGIN * speed:
                return True
    return False


#: [rad] a round sole's lowest direction at least this far inside its span's ends, and its
#: fallback vertices at least ARC_VERTEX_MARGIN above its point, for the step to be smooth
ARC_SPAN_MARGIN = 1e-9
ARC_VERTEX_MARGIN = 1e-9     # [m]
#: the complex step [m, rad, m/s, rad/s, N]: far below rounding, so the derivative is exact
COMPLEX_STEP = 1e-20


def _touching_contacts(model, start, modes, slips, features):
    """ContactPlan of the ground contacts touching (modes: the step's end modes) at the start
    q0, or NotImplementedError naming what is not covered (a shape pair, a straight edge over
    hills, restitution, a sole at the end of its span or level with a fallback vertex)."""
    a = model.arrays
    touching = np.flatnonzero(modes != MODE_FREE)
    coef = np.asarray(a.terrain_coef, dtype=float)
    slope, h0 = float(coef[1]), float(coef[0])
    flat_normal = np.array([-slope, 1.0]) / np.hypot(slope, 1.0)
    q0 = start.q
    body, local, radius, pinned, mu_slip, pairs = [], [], [], [], [], []
    for c in touching:
        name = model.contact_names[c]
        kind = int(a.contact_kind[c])
        if kind not in (CONTACT_POINT, CONTACT_ARC, CONTACT_PAIR):
            raise _not_covered(f"contact {name!r} of kind {kind} (a straight edge over hills) "
                               f"touching")
        if a.contact_restitution[c] != 0.0:
            raise _not_covered(f"contact {name!r} with restitution touching")
        mu = float(a.contact_mu[c])
        stick = modes[c] == MODE_PINNED and mu > 0.0
        if kind == CONTACT_PAIR:
            pair = _pair_features(model, c, int(features[c]))
            body.append(max(pair[0], pair[1]))
            local.append(np.zeros(2))
            radius.append(0.0)
            pinned.append(stick)
            mu_slip.append(0.0 if stick else mu * float(slips[c]))
            pairs.append(pair)
            continue
        pairs.append([-2] * 8)
        b = int(a.contact_body[c])
        lc = np.asarray(a.contact_local[c], dtype=float)
        r = float(a.contact_radius[c]) if kind == CONTACT_ARC else 0.0
        if kind == CONTACT_ARC:
            inside, sole_gap, _, vertices = _sole(a, q0, c)
            if inside <= ARC_SPAN_MARGIN:
                raise _not_covered(f"round sole {name!r} resting at (or beyond) an end of its "
                                   f"span")
            if min(vertices, default=np.inf) < sole_gap + ARC_VERTEX_MARGIN:
                raise _not_covered(f"round sole {name!r} level with one of its fallback "
                                   f"vertices")
        body.append(b)
        local.append(lc)
        radius.append(r)
        pinned.append(stick)
        mu_slip.append(0.0 if stick else mu * float(slips[c]))
    body = np.array(body, dtype=np.int64)
    return ContactPlan(index=np.asarray(touching, dtype=np.int64), body=body,
                       local=np.array(local).reshape(-1, 2), radius=np.array(radius),
                       pinned=np.array(pinned, dtype=bool), mu_slip=np.array(mu_slip),
                       terrain=coef, normal=flat_normal, offset=float(h0 * flat_normal[1]),
                       point_mass=a.body_inv_inertia[body] == 0.0,
                       pair=np.array(pairs, dtype=np.int64).reshape(-1, 8), model=model,
                       was_touching=np.asarray(start.contact_mode)[touching] != MODE_FREE)


def _pair_features(model, c, feature):
    """ContactPlan.pair's row of shape pair slot c from the feature id its manifold point had
    (kernels/geometry/collide.py): [reference body, incident body, reference shape, incident shape,
    distance kind, reference edge or vertex, incident vertex or edge, clip side]."""
    a = model.arrays
    if feature < 0:
        raise _not_covered(f"shape pair slot {model.contact_names[c]!r} touching without "
                           f"features")
    clip, rest = feature % 4, feature // 4
    inc, rest = rest % MAX_CORE_VERTICES, rest // MAX_CORE_VERTICES
    ref, rest = rest % MAX_CORE_VERTICES, rest // MAX_CORE_VERTICES
    dist, flip = rest % 2, rest // 2
    slot0 = c - int(a.contact_pair[c, 2])
    sa, sb = int(a.contact_pair[slot0, 0]), int(a.contact_pair[slot0, 1])
    s_ref, s_inc = (sa, sb) if flip == 0 else (sb, sa)
    return [int(a.shape_body[s_ref]), int(a.shape_body[s_inc]), s_ref, s_inc, dist, ref, inc,
            clip]


def _active_limits(model, limit_active) -> np.ndarray:
    """(k, 2) [joint, side] of the joint limits active at the step's end (limit_active: the
    State's), or NotImplementedError for a slider's limit whose rate row turns."""
    a = model.arrays
    out = np.argwhere(limit_active != 0).astype(np.int64).reshape(-1, 2)
    for j in out[:, 0]:
        if not _constant_rate_row(a, j):
            raise _not_covered(f"a limit reached in the step on slider {model.pin_names[j]!r}, "
                               f"whose rate row turns with its bodies")
    return out


def _engine_order(model, held, limits, contacts) -> np.ndarray:
    """The replica's rows (the held joint rows, the active limits' rows, then each touching
    contact's normal and sticking tangent row) in the order kernels/constraints/rows.py build_rows makes
    them: joint by joint in the model's order (its rows, then its limits' rows), merged with
    the contacts in theirs, a joint's before a contact whose body is not earlier than the
    later of the joint's bodies."""
    a = model.arrays
    joint_of_row = held // 2
    index = 0
    rows_of = {}
    for j in joint_of_row:
        rows_of.setdefault(int(j), []).append(index)
        index += 1
    rod_rows = list(range(index, index + model.n_rod))
    index += model.n_rod
    for j, _ in limits:
        rows_of.setdefault(int(j), []).append(index)
        index += 1
    contact_rows = []
    for k in range(contacts.count):
        width = 2 if contacts.pinned[k] else 1
        contact_rows.append((int(contacts.body[k]), list(range(index, index + width))))
        index += width
    order, k, jp, jr = [], 0, 0, 0
    big = model.n_body + 1
    while jp < model.n_pin or jr < model.n_rod:
        kp = int(a.pin_body[jp].max()) if jp < model.n_pin else big
        kr = int(a.rod_body[jr].max()) if jr < model.n_rod else big
        later = min(kp, kr)
        while k < len(contact_rows) and contact_rows[k][0] < later:
            order += contact_rows[k][1]
            k += 1
        if kp <= kr:
            order += rows_of.get(jp, [])
            jp += 1
        else:
            order.append(rod_rows[jr])
            jr += 1
    for _, rows in contact_rows[k:]:
        order += rows
    return np.array(order, dtype=np.int64)


def _replica_tangents(sim, u, start, modes, slips, features, limit_active, q1, v1,
                      first_order, projections, directions, shake_whole=False):
    """(StepTangents, its StepPlan) of a step the engine took in one piece, ending at (q1,
    v1): the step's equations replayed (planarsim.step_replica) from the start and from the
    start moved by i COMPLEX_STEP along each direction (dx, du), in one batch whose
    first row (the start itself) takes the decisions; that row must end where the engine
    ended."""
    model = sim.model
    h = float(sim.dt)
    nq = 3 * model.n_body
    q0, v0 = start.q.ravel().copy(), start.v.ravel().copy()
    f, F, saturated = force_terms(model, start, u)
    W_A, W_D, R, f_spring, K, rotors, f_alone, K_alone = rotor_terms(model, start.q, h)
    held = np.flatnonzero(np.repeat((model.arrays.pin_kind & JOINT_FREE_BIT) == 0, 2))
    contacts = _touching_contacts(model, start, modes, slips, features)
    limits = _active_limits(model, limit_active)
    if first_order:
        raise _not_covered("a velocity solve that gave up the joints' second-order target "
                           "(J v = 0: it added energy)")
    if projections:
        raise _not_covered("a complementarity projection of the positions after the "
                           "correction")
    lo, hi = model.arrays.act_range.T
    turning = np.flatnonzero(np.isin(model.arrays.act_kind, list(_TURNING_ACTUATORS)))
    E = np.vstack([np.zeros((1, 2 * nq + model.n_act)), np.vstack(directions).T]) \
        * (COMPLEX_STEP * 1j)
    eps = np.finfo(float).eps
    q_scale = np.abs(q1.ravel() - q0).max() + h * np.abs(v0).max()
    v_scale = np.abs(v1).max() + np.abs(v0).max()
    rounding = 64 * eps * (np.abs(q0).max() + 1.0)

    def attempt(flip):
        """The replay with the correction's leaving decisions of rows `flip` turned over;
        (q, v, q_off, v_off, plan)."""
        plan = StepPlan(model=model, h=h, q0=q0, u=u.copy(), W_A=W_A, W_D=W_D, R=R, f0=f, F=F,
                        fs0=f_spring, K=K, f_alone0=f_alone, K_force=K_alone, rotors=rotors,
                        held=held, turning=turning, u_held=(u < lo) | (u > hi),
                        contacts=contacts, limits=limits, shake_whole=shake_whole,
                        order=_engine_order(model, held, limits, contacts),
                        iters=int(sim.options.refine_iters),
                        tol=float(sim.options.refine_tol), flip=flip,
                        pivot_tol=float(sim.options.pivot_tol),
                        refine_pivot_tol=float(sim.options.refine_pivot_tol))
        q_c, v_c = replica(plan, q0[None] + E[:, :nq], v0[None] + E[:, nq:2 * nq],
                           u[None] + E[:, 2 * nq:])
        return (q_c, v_c, np.abs(q_c[0].real - q1.ravel()).max(),
                np.abs(v_c[0].real - v1.ravel()).max(), plan)

    # a row whose opening at the correction's start is within rounding of what the step's
    # turning explains may have been judged either way by the engine (integrate.py
    # drop_leaving_rows): both judgements are tried, the one that ends where the engine did
    # is the step's (the two differ by the correction's whole velocity change)
    tried, error = [()], None
    while tried:
        flip = tried.pop(0)
        try:
            q_c, v_c, q_off, v_off, plan = attempt(flip)
        except ReplicaRefused as err:
            error = error or err
            continue
        if q_off <= FIT_TOL * q_scale + rounding and v_off <= FIT_TOL * v_scale + rounding / h:
            break
        if flip == () and plan.near is not None and plan.near.size:
            near = plan.near[:3]
            tried += [tuple(near[[k for k in range(near.size) if bits >> k & 1]])
                      for bits in range(1, 2 ** near.size)]
        error = None
    else:
        if error is not None:
            raise _not_covered(str(error)) from None
        raise _not_covered(f"an end that the step's equations (the velocity solve, the Newton "
                           f"correction, the energy bound) do not reproduce: q off by "
                           f"{q_off:.3g}, v by {v_off:.3g} (a projection, a first-order "
                           f"target, the motion paying for a lift)")
    D = np.hstack([q_c[1:].imag, v_c[1:].imag]).T / COMPLEX_STEP      # (2 nq, k)
    return StepTangents(D, bool(saturated.any()), np.concatenate([q1.ravel(), v1.ravel()])), plan
