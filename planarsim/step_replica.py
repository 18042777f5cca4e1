"""The default step's equations in numpy, written so that complex numbers pass through them:
the exact derivative of a step by the complex step (planarsim.derivatives).

A `StepPlan` holds what one step decided at its real start (its contacts' modes and slips, the
commands' saturation, the Newton correction's number of passes, the energy bound's branch)
and the matrices that do not depend on the state there (the bodies' inverse masses with the
joints' rotors and dampers). `replica(plan, q0, v0, u)` then computes the step's end from a
batch of starts (B, 3 n) with those decisions held:

    v_lin = R v0 + h W_D (f(u) + f_spring(q0)),              q_pred = q0 + h v_lin,
    P W_D F^T lam = -b,     b_joint = c(q_pred) / h,     b_contact = c(q0)^+ / h + P v_lin,
    v_new = v_lin + W_D F^T lam,
    q <- q0 + h v_new, then the Newton passes G(q) W_A P^T mu = -c(q), q += W_A P^T mu,
    v += W_A P^T mu / h (joints only) or W_A P^T kappa, G W_A P^T kappa = S (-c(q)) / h (S:
    1 on the bilateral rows, 0 on the contacts' normal rows, which move positions only),
    one more pass on the last factorisation where the engine takes one,
    v1 = v_new + k (v - v_new), k the energy bound's share (kernels/integrate.py).

P holds the rows at q0: the joints' (a hinge's x and y, a slider's perpendicular and angle)
and the touching ground contacts' (a normal row: the gap of a point, or of a round sole's
centre less its radius; a sticking contact's tangent row: its material point's move along the
ground from where it was at q0); F is P but for a sliding contact's normal row, whose impulse
pushes along n - mu s t (Coulomb). These are the rows kernels/rows.py builds, in the same
arithmetic up to rounding. Every operation is analytic in the state (no abs, max or branch on
it: those are the plan's), so a start q0 + i e dq gives the directional derivative as the
imaginary part over e, exact to rounding (Squire and Trapp 1998: no difference is taken).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .kernels.codes import JOINT_FREE_BIT, JOINT_HINGE, JOINT_SLIDE_BIT, JOINT_SLIDER
from .kernels.integrate import STALLED_RATIO
from .kernels.work import (CONSTRAINT_SHARE, CORRECTION_MOVE_FLOOR, RELATIVE_ROUNDING,
                           SHAKE_REGIME, VELOCITY_FLOOR)


class ReplicaRefused(Exception):
    """The step is outside what the replica reproduces (the message says why)."""


@dataclass
class ContactPlan:
    """The touching ground contacts (on flat or sloped ground), as decided at the real start."""
    index: np.ndarray           # (k,) int the contacts' indices in the model
    body: np.ndarray            # (k,) int
    local: np.ndarray           # (k, 2) [m] the normal row's body point: a point, a sole's centre
    radius: np.ndarray          # (k,) [m] 0 for a point
    pinned: np.ndarray          # (k,) bool: sticking (a tangent row); else sliding
    mu_slip: np.ndarray         # (k,) mu s of a sliding contact (its friction along -s t)
    normal: np.ndarray = field(default_factory=lambda: np.array([0.0, 1.0]))
    offset: float = 0.0         # [m] n . (any ground point)

    @property
    def count(self) -> int:
        return int(self.body.shape[0])


@dataclass
class StepPlan:
    """One step's decisions and state-independent matrices (module docstring)."""
    model: object
    h: float
    q0: np.ndarray              # (3 n,) the real start
    u: np.ndarray               # (n_act,) the real commands
    W_A: np.ndarray
    W_D: np.ndarray
    R: np.ndarray
    f0: np.ndarray              # applied forces at the real start and commands (no springs;
                                # not the actuators of `turning`)
    F: np.ndarray               # d f / d u (0 past a bound) of the others
    fs0: np.ndarray             # the joints' springs at q0
    K: np.ndarray               # d f_spring / dq
    f_alone0: np.ndarray        # the springs the step takes as forces (in ws.force), at q0
    K_force: np.ndarray
    rotors: np.ndarray          # the joints' rotors' inertia A (3 n, 3 n)
    held: np.ndarray            # the joints' rows that hold something (a free coordinate: none)
    turning: np.ndarray         # the actuators whose force turns with the bodies (axial, hip)
    u_held: np.ndarray          # (n_act,) bool: a command past its bound (held at it)
    contacts: ContactPlan
    limits: np.ndarray          # (k, 2) int: the active joint limits' [joint, side]
    order: np.ndarray           # the rows (joints' then contacts') in the engine's order
    iters: int
    tol: float
    passes: int | None = None   # Newton passes (None: decide, on the real run)
    extra_pass: bool | None = None
    bound: dict | None = None   # the energy bound's branch (None: decide)
    lifted: np.ndarray | None = None     # the mode rows whose start is off their surface
    solved: np.ndarray | None = None     # the velocity solve's independent rows
    corrected: np.ndarray | None = None  # the correction's


# --- rows -------------------------------------------------------------------------------------
def _turn(q, b, local):
    """World arm R(theta_b) local (B, 2) of body b at q (B, n, 3); local (2,) or (B, 2)."""
    cs, sn = np.cos(q[:, b, 2]), np.sin(q[:, b, 2])
    lx, ly = (local[..., 0], local[..., 1])
    return np.stack([cs * lx - sn * ly, sn * lx + cs * ly], axis=-1)


def _cross(r, d):
    """z of r x d, r (B, 2), d (2,) or (B, 2)."""
    return r[..., 0] * d[..., 1] - r[..., 1] * d[..., 0]


def joint_rows(model, q, held):
    """(c (B, m), J (B, m, 3 n)) of the joints' held rows at q (B, n, 3): kernels/pin.py's
    hinge rows (anchor b minus anchor a) and kernels/slider.py's rows."""
    a = model.arrays
    B, n = q.shape[0], q.shape[1]
    c = np.zeros((B, 2 * model.n_pin), dtype=q.dtype)
    J = np.zeros((B, 2 * model.n_pin, 3 * n), dtype=q.dtype)
    hinges = np.flatnonzero(a.pin_kind == JOINT_HINGE)
    for e, sign in ((0, -1.0), (1, 1.0)):
        # every hinge's end e at once (B, k): anchor b minus anchor a
        body = a.pin_body[hinges, e]
        world = hinges[body < 0]
        c[:, 2 * world] += sign * a.pin_anchor[world, e, 0]
        c[:, 2 * world + 1] += sign * a.pin_anchor[world, e, 1]
        j, b = hinges[body >= 0], body[body >= 0]
        cs, sn = np.cos(q[:, b, 2]), np.sin(q[:, b, 2])
        lx, ly = a.pin_anchor[j, e, 0], a.pin_anchor[j, e, 1]
        rx, ry = cs * lx - sn * ly, sn * lx + cs * ly
        c[:, 2 * j] += sign * (q[:, b, 0] + rx)
        c[:, 2 * j + 1] += sign * (q[:, b, 1] + ry)
        # (a hinge's two ends are two bodies: no index repeats within one end's assignment)
        J[:, 2 * j, 3 * b] += sign
        J[:, 2 * j + 1, 3 * b + 1] += sign
        J[:, 2 * j, 3 * b + 2] += -sign * ry
        J[:, 2 * j + 1, 3 * b + 2] += sign * rx
    for j in range(model.n_pin):
        kind = int(a.pin_kind[j])
        if kind & JOINT_FREE_BIT or kind == JOINT_HINGE:
            continue
        ba, bb = int(a.pin_body[j, 0]), int(a.pin_body[j, 1])
        r = 2 * j
        if kind == JOINT_SLIDER:
            if ba >= 0:
                d = _turn(q, ba, np.asarray(a.pin_axis[j], dtype=float))
                pa = q[:, ba, :2] + _turn(q, ba, np.asarray(a.pin_anchor[j, 0], dtype=float))
            else:
                d = np.broadcast_to(np.asarray(a.pin_axis[j], dtype=float), (B, 2))
                pa = np.broadcast_to(np.asarray(a.pin_anchor[j, 0], dtype=float), (B, 2))
            nrm = np.stack([-d[:, 1], d[:, 0]], axis=-1)
            pb = q[:, bb, :2] + _turn(q, bb, np.asarray(a.pin_anchor[j, 1], dtype=float))
            c[:, r] = np.sum(nrm * (pb - pa), axis=-1)
            c[:, r + 1] = q[:, bb, 2] - a.pin_ref[j] - (q[:, ba, 2] if ba >= 0 else 0.0)
            J[:, r, 3 * bb:3 * bb + 2] += nrm
            J[:, r, 3 * bb + 2] += _cross(pb - q[:, bb, :2], nrm)
            J[:, r + 1, 3 * bb + 2] += 1.0
            if ba >= 0:
                J[:, r, 3 * ba:3 * ba + 2] -= nrm
                J[:, r, 3 * ba + 2] -= _cross(pb - q[:, ba, :2], nrm)
                J[:, r + 1, 3 * ba + 2] -= 1.0
        else:
            raise ReplicaRefused(f"joint {model.pin_names[j]!r} of kind {kind}")
    return c[:, held], J[:, held]


def _sole_anchor(cp, q0, k):
    """The material point (B, 2) [m, body frame] contact k holds for the step: a point's own,
    a round sole's point below its centre at q0 (kernels/contacts.py find_contact)."""
    local = cp.local[k]
    if cp.radius[k] == 0.0:
        return np.broadcast_to(local, (q0.shape[0], 2))
    # R(-theta0) n in the body frame
    th = q0[:, cp.body[k], 2]
    cs, sn = np.cos(th), np.sin(th)
    nx, ny = cp.normal
    down = np.stack([cs * nx + sn * ny, -sn * nx + cs * ny], axis=-1)
    return local - cp.radius[k] * down


def contact_rows(cp, q, q0, n_coord):
    """(c (B, m), J (B, m, 3 n), F (B, m, 3 n)) of the touching contacts' rows at q, each
    contact's normal row then (sticking) its tangent row, the tangent rows measured from
    their material points at q0; F: the rows' impulse directions at q0 (J at q0 but a sliding
    contact's normal row, along n - mu s t at its point). Rows of kernels/contacts.py
    ground_row and rows.build_rows."""
    B = q.shape[0]
    n_rows = int(cp.count + cp.pinned.sum())
    dtype = np.result_type(q, q0)
    c = np.zeros((B, n_rows), dtype=dtype)
    J = np.zeros((B, n_rows, n_coord), dtype=dtype)
    F = np.zeros((B, n_rows, n_coord), dtype=dtype)
    nrm = cp.normal
    tan = np.array([nrm[1], -nrm[0]])
    r = 0
    for k in range(cp.count):
        b = int(cp.body[k])
        cols = slice(3 * b, 3 * b + 2)
        arm_n = _turn(q, b, cp.local[k])
        c[:, r] = (q[:, b, 0] + arm_n[:, 0]) * nrm[0] + (q[:, b, 1] + arm_n[:, 1]) * nrm[1] \
            - cp.offset - cp.radius[k]
        J[:, r, cols] = nrm
        J[:, r, 3 * b + 2] = _cross(arm_n, nrm)
        anchor = _sole_anchor(cp, q0, k)
        arm0 = _turn(q0, b, anchor)
        d = nrm - cp.mu_slip[k] * tan if not cp.pinned[k] else nrm
        F[:, r, cols] = d
        F[:, r, 3 * b + 2] = _cross(arm0, d)
        r += 1
        if cp.pinned[k]:
            arm = _turn(q, b, anchor)
            move = q[:, b, :2] - q0[:, b, :2] + arm - arm0
            c[:, r] = move[:, 0] * tan[0] + move[:, 1] * tan[1]
            J[:, r, cols] = tan
            J[:, r, 3 * b + 2] = _cross(arm, tan)
            F[:, r, cols] = tan
            F[:, r, 3 * b + 2] = _cross(arm0, tan)
            r += 1
    return c, J, F


def contact_unilateral(cp) -> np.ndarray:
    """(m,) bool over contact_rows' rows: a normal row (moves positions only in the correction)."""
    out = []
    for k in range(cp.count):
        out.append(True)
        if cp.pinned[k]:
            out.append(False)
    return np.array(out, dtype=bool)


def limit_rows(model, limits, q):
    """(c (B, k), J (B, k, 3 n)) of the active joint limits' rows at q (B, n, 3): limits (k, 2)
    [joint, side]; a hinge's angle theta_b - theta_a - ref, or a world slide's coordinate
    along its axis, less the lower limit (side 0) or taken from the upper (side 1), as
    kernels/limit.py writes them (their rate rows g are constant: derivatives.check_covered)."""
    from .derivatives import rate_row
    a = model.arrays
    B, n = q.shape[0], q.shape[1]
    c = np.zeros((B, limits.shape[0]), dtype=q.dtype)
    J = np.zeros((B, limits.shape[0], 3 * n))
    flat = q.reshape(B, 3 * n)
    for r, (j, side) in enumerate(limits):
        g = rate_row(a, j, n)
        coordinate = flat @ g
        if a.pin_kind[j] & JOINT_SLIDE_BIT:
            coordinate = coordinate - a.pin_axis[j] @ a.pin_anchor[j, 0]
        else:
            coordinate = coordinate - a.pin_ref[j]
        sign = 1.0 if side == 0 else -1.0
        c[:, r] = sign * (coordinate - a.pin_limit[j, side])
        J[:, r] = sign * g
    return c, J


def mode_rows(plan, q, q0):
    """(c, J, F, unilateral) of the rows with a mode at q (B, 3 n), measured from q0 where
    they need it: the active limits' rows, then the touching contacts' (contact_rows); the
    mask marks the unilateral ones (limits, contacts' normals: their correction moves
    positions only and their velocity target is clipped at the surface)."""
    n = plan.model.n_body
    qq, qq0 = q.reshape(-1, n, 3), q0.reshape(-1, n, 3)
    cl, Jl = limit_rows(plan.model, plan.limits, qq)
    cc, Jc, Fc = contact_rows(plan.contacts, qq, qq0, 3 * n)
    Jl = np.broadcast_to(Jl, (qq.shape[0],) + Jl.shape[1:]).astype(Jc.dtype)
    unilateral = np.concatenate([np.ones(cl.shape[1], bool), contact_unilateral(plan.contacts)])
    return (np.concatenate([cl, cc], axis=1), np.concatenate([Jl, Jc], axis=1),
            np.concatenate([Jl, Fc], axis=1), unilateral)


def _rows(plan, q, q0):
    """Every row's (c, J) at q (B, 3 n): the held joints', then mode_rows'."""
    n = plan.model.n_body
    cj, Jj = joint_rows(plan.model, q.reshape(-1, n, 3), plan.held)
    cm, Jm, _, _ = mode_rows(plan, q, q0)
    return np.concatenate([cj, cm], axis=1), np.concatenate([Jj, Jm], axis=1)


def turning_forces(plan, q, u):
    """(B, 3 n) [N, N m] the forces of the actuators whose direction turns with the bodies
    (kernels/forces.py apply_actuator): an axial force u along the line from its anchor on
    body a to its anchor on body b (on b, and its opposite on a, at the anchors), and a hip
    torque u as forces perpendicular to each leg from the hip body (-u on leg a, +u on leg
    b); commands past a bound held at it."""
    from .kernels.forces import ACT_AXIAL
    model = plan.model
    a = model.arrays
    n = model.n_body
    qq = q.reshape(-1, n, 3)
    B = qq.shape[0]
    f = np.zeros((B, n, 3), dtype=np.result_type(q, u))
    lo, hi = a.act_range[:, 0], a.act_range[:, 1]
    for k in plan.turning:
        uk = np.clip(plan.u[k], lo[k], hi[k]) + 0.0 * u[:, k] if plan.u_held[k] else u[:, k]
        ba, bb = int(a.act_body[k, 0]), int(a.act_body[k, 1])
        if a.act_kind[k] == ACT_AXIAL:
            ends = []
            for body, anchor in ((ba, a.act_anchor[k, 0]), (bb, a.act_anchor[k, 1])):
                anchor = np.asarray(anchor, dtype=float)
                if body < 0:
                    ends.append((body, np.broadcast_to(anchor, (B, 2)), None))
                else:
                    arm = _turn(qq, body, anchor)
                    ends.append((body, qq[:, body, :2] + arm, arm))
            d = ends[1][1] - ends[0][1]
            length = np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1])
            push = (uk / length)[:, None] * d
            for (body, _, arm), sign in zip(ends, (-1.0, 1.0)):
                if body < 0:
                    continue
                f[:, body, :2] += sign * push
                f[:, body, 2] += sign * _cross(arm, push)
        else:                                       # ACT_HIP_TORQUE
            hip = int(a.act_body[k, 2])
            for leg, sign in ((ba, -1.0), (bb, 1.0)):
                d = qq[:, leg, :2] - qq[:, hip, :2]
                d2 = d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1]
                fx, fy = -sign * uk * d[:, 1] / d2, sign * uk * d[:, 0] / d2
                f[:, leg, 0] += fx
                f[:, leg, 1] += fy
                f[:, hip, 0] -= fx
                f[:, hip, 1] -= fy
    return f.reshape(B, 3 * n)


def _solve(N, b):
    """N x = b for a batch (B, m, m), (B, m)."""
    return np.linalg.solve(N, b[..., None])[..., 0]


# --- the step ---------------------------------------------------------------------------------
def replica(plan: StepPlan, q0, v0, u):
    """The step's end (q1, v1) (B, 3 n) from starts q0, v0 (B, 3 n) and commands u (B, n_act)
    under plan's decisions (module docstring). Where plan.passes is None the first row of the
    batch (real, or with imaginary parts of a complex step only) takes the decisions, which
    are stored in plan and hold for every row; it raises ReplicaRefused where a decision
    leaves what the replica reproduces."""
    model, h = plan.model, plan.h
    n = model.n_body
    deciding = plan.passes is None
    du = u - plan.u
    f = plan.f0 + du @ plan.F.T
    if plan.turning.size:
        f = f + turning_forces(plan, q0, u)
    dq0 = q0 - plan.q0
    f_spring = plan.fs0 + dq0 @ plan.K.T
    v_lin = v0 @ plan.R.T + h * ((f + f_spring) @ plan.W_D.T)
    q_pred = q0 + h * v_lin
    # the velocity solve
    cj_pred, _ = joint_rows(model, q_pred.reshape(-1, n, 3), plan.held)
    _, Pj = joint_rows(model, q0.reshape(-1, n, 3), plan.held)
    cm0, Pm, Fm, unilateral_m = mode_rows(plan, q0, q0)
    mj = Pj.shape[1]
    unilateral = np.concatenate([np.zeros(mj, bool), unilateral_m])
    if deciding:
        plan.lifted = cm0[0].real > 0.0
    # a unilateral row that starts violated only stops approaching (solve.fill_row_b)
    target = np.where(plan.lifted | ~unilateral_m, cm0, 0.0)
    P = np.concatenate([Pj, Pm], axis=1)
    Fd = np.concatenate([Pj, Fm], axis=1)
    m = P.shape[1]
    if m:
        rhs = np.concatenate([-cj_pred / h,
                              -target / h - np.einsum("brk,bk->br", Pm, v_lin)], axis=1)
        WdFt = np.einsum("ij,brj->bir", plan.W_D, Fd)          # (B, 3n, m)
        N = np.einsum("brk,bks->brs", P, WdFt)
        if deciding:
            if mj and independent_rows(N[0, :mj, :mj].real, np.arange(mj)).size < mj:
                raise ReplicaRefused("dependent joints (an over-constrained loop): the step is "
                                     "not smooth there")
            plan.solved = independent_rows(N[0].real, plan.order)
        K = plan.solved
        lam = _solve(N[:, K][:, :, K], rhs[:, K])
        v_new = v_lin + np.einsum("bir,br->bi", WdFt[:, :, K], lam)
        if deciding:
            _check_held(P[0] @ (v_new[0] - v_lin[0]) - rhs[0],
                        np.abs(rhs[0]).max() + np.abs(P[0] @ v_lin[0]).max(), "velocity solve")
    else:
        v_new = v_lin
    # the Newton correction along W_A P^T (P at q0)
    q = q0 + h * v_new
    v = v_new.copy()
    if m:
        D = np.einsum("ij,brj->bir", plan.W_A, P)              # (B, 3n, m)
        S = (~unilateral).astype(float)
        any_unilateral = bool(unilateral.any())
        c, G = _rows(plan, q, q0)
        worst = np.abs(c[0].real).max(initial=0.0) if deciding else None
        passes = 0
        Nn = None
        for _ in range(plan.iters if deciding else plan.passes):
            if deciding and worst <= plan.tol:
                break
            Nn = np.einsum("brk,bks->brs", G, D)
            if plan.corrected is None:
                plan.corrected = independent_rows(Nn[0].real, plan.order)
            K = plan.corrected
            Nn, DK = Nn[:, K][:, :, K], D[:, :, K]
            mu = _solve(Nn, -c[:, K])
            q = q + np.einsum("bir,br->bi", DK, mu)
            if any_unilateral:
                kappa = _solve(Nn, -(c * S)[:, K]) / h
                v = v + np.einsum("bir,br->bi", DK, kappa)
            else:
                v = v + np.einsum("bir,br->bi", DK, mu) / h
            c, G = _rows(plan, q, q0)
            passes += 1
            if deciding:
                after = np.abs(c[0].real).max(initial=0.0)
                if after > STALLED_RATIO * worst:
                    raise ReplicaRefused(f"a Newton correction that stalls (its rows' errors "
                                         f"{worst:.3g} -> {after:.3g})")
                worst = after
        if deciding:
            plan.passes = passes
            plan.extra_pass = passes > 0 and 0.0 < worst <= plan.tol
            if worst > plan.tol:
                raise ReplicaRefused(f"a Newton correction that ends with its rows open by "
                                     f"{worst:.3g} (refine_tol {plan.tol:.3g})")
        if plan.extra_pass:
            # one more pass on the last factorisation (integrate.correct_positions)
            K = plan.corrected
            mu = _solve(Nn, -c[:, K])
            q = q + np.einsum("bir,br->bi", DK, mu)
            if any_unilateral:
                v = v + np.einsum("bir,br->bi", DK, _solve(Nn, -(c * S)[:, K]) / h)
            else:
                v = v + np.einsum("bir,br->bi", DK, mu) / h
    elif deciding:
        plan.passes, plan.extra_pass = 0, False
    if plan.passes > 0:
        v = _energy_bound(plan, q0, v0, q, v, v_new, f + plan.f_alone0 + dq0 @ plan.K_force.T,
                          deciding)
    return q, v


#: a row whose pivot keeps less than this share of its diagonal, eliminated in the engine's
#: order after the rows kept before it, is dependent on them (the engine's factorisations
#: leave it out; its equation then holds through the others where the targets agree)
DEPENDENT_PIVOT = 1e-9
#: the independent rows' matrix's condition number above which the step counts as not smooth
DEPENDENT_COND = 1e10
#: [m/s] the left-out rows' equations must hold to this (plus this share of the targets)
LEFT_OUT_TOL = 1e-9


def independent_rows(N, order) -> np.ndarray:
    """The rows of N (m, m) kept by elimination in `order` (each row's pivot after the rows
    kept before it: kept if it keeps more than DEPENDENT_PIVOT of its diagonal), as sorted
    indices; ReplicaRefused where the kept rows are still ill-conditioned."""
    if N.shape[0] == 0 or np.linalg.cond(N) <= DEPENDENT_COND:
        return np.arange(N.shape[0])
    kept = []
    for r in order:
        d = N[r, r]
        if kept:
            k = np.array(kept)
            pivot = d - N[r, k] @ np.linalg.solve(N[np.ix_(k, k)], N[k, r])
        else:
            pivot = d
        if abs(pivot) > DEPENDENT_PIVOT * abs(d):
            kept.append(int(r))
    kept = np.array(sorted(kept), dtype=np.int64)
    if kept.size and np.linalg.cond(N[np.ix_(kept, kept)]) > DEPENDENT_COND:
        raise ReplicaRefused("nearly dependent rows (a loop or contacts near a dead point): "
                             "the step is not smooth there")
    return kept


def _check_held(residual, scale, stage):
    """ReplicaRefused where a left-out row's equation does not hold (targets that disagree):
    residual over every row, scale [m/s] the size of its terms."""
    off = np.abs(residual).max(initial=0.0)
    if off > LEFT_OUT_TOL * (1.0 + scale):
        raise ReplicaRefused(f"rows left out of the {stage} as dependent whose equations do "
                             f"not hold through the others (off by {off:.3g})")


def _sabs(x):
    """|x| for real x, continued analytically (its sign held) for a complex step."""
    return x * np.sign(x.real)


def _energy_bound(plan, q0, v0, q1, v, v_s, f, deciding):
    """kernels/integrate.py bound_correction_work: v_s + k (v - v_s), k the largest share in
    [0, 1] of the correction's velocity change that adds no energy beyond its allowance (its
    branches the plan's); f (B, 3 n) [N, N m]: the step's applied forces (ws.force)."""
    model, h = plan.model, plan.h
    a_ = model.arrays
    n = model.n_body
    Mb = np.column_stack([a_.body_mass, a_.body_mass, a_.body_inertia]).ravel()
    E = np.diag(Mb) + plan.rotors
    dv = v - v_s
    move = q1 - (q0 + h * v_s)
    Ev, Edv = v_s @ E, dv @ E
    a = np.sum(v_s * Edv, axis=1)
    b = 0.5 * np.sum(dv * Edv, axis=1)
    kinetic = 0.5 * np.sum(v_s * Ev, axis=1)
    gravity = np.asarray(a_.gravity, dtype=float)
    g = float(np.hypot(*gravity))
    up = -gravity / g if g > 0.0 else np.zeros(2)
    f_g = np.zeros(3 * n)
    f_g[0::3] = a_.body_mass * gravity[0]
    f_g[1::3] = a_.body_mass * gravity[1]
    other = f - f_g
    start = 0.5 * np.sum(v0 * Mb * v0, axis=1)
    Up = np.zeros(3 * n)
    Up[0::3] = a_.body_mass * up[0]
    Up[1::3] = a_.body_mass * up[1]
    dp = (v_s - v0) @ Up
    total_mass = float(a_.body_mass.sum())
    lift = 0.5 * h * g * dp
    sink = -dp * dp / (2.0 * total_mass) if total_mass > 0.0 else 0.0 * dp
    gained0 = (0.5 * np.sum(v_s * Mb * v_s, axis=1) - start - h * np.sum(f * v_s, axis=1)
               + 0.5 * h * np.sum(other * (v_s - v0), axis=1))
    momentum = (_sabs(dv.reshape(-1, n, 3)[:, :, :2]).sum(axis=2)
                + _sabs(v_s.reshape(-1, n, 3)[:, :, :2]).sum(axis=2)) @ a_.body_mass
    forces = _sabs(f.reshape(-1, n, 3)[:, :, :2]).sum(axis=(1, 2))
    if deciding:
        owed_lift = total_mass > 0.0 and lift[0].real >= sink[0].real
        owed = lift if owed_lift else sink if total_mass > 0.0 else 0.0 * dp
        gained = gained0 - owed
        in_regime = bool(b[0].real <= SHAKE_REGIME * SHAKE_REGIME * kinetic[0].real)
        smaller_is_kinetic = bool(kinetic[0].real <= start[0].real)
        gained_on = bool(gained[0].real > 0.0)
        share_raw = CONSTRAINT_SHARE * (kinetic if smaller_is_kinetic else start) \
            - (gained if gained_on else 0.0)
        share_on = in_regime and bool(share_raw[0].real > 0.0)
        plan.bound = dict(owed_lift=owed_lift, share_on=share_on,
                          smaller_is_kinetic=smaller_is_kinetic, gained_on=gained_on,
                          sign_a=float(np.sign(a[0].real)))
    B_ = plan.bound
    if total_mass > 0.0:
        owed = lift if B_["owed_lift"] else sink
    else:
        owed = 0.0 * dp
    gained = gained0 - owed
    share = 0.0 * a
    if B_["share_on"]:
        share = CONSTRAINT_SHARE * (kinetic if B_["smaller_is_kinetic"] else start) \
            - (gained if B_["gained_on"] else 0.0)
    rounding = (VELOCITY_FLOOR * momentum + CORRECTION_MOVE_FLOOR * forces
                + RELATIVE_ROUNDING * (kinetic + B_["sign_a"] * a + b))
    room = share + np.sum(f * move, axis=1) + rounding
    if deciding:
        ar, br, rr = a[0].real, b[0].real, room[0].real
        if ar + br <= rr:
            branch = "whole"
        else:
            disc = ar * ar + 4.0 * br * rr
            k = (-ar + np.sqrt(disc)) / (2.0 * br) if disc >= 0.0 and br > 0.0 else -1.0
            short = k < 0.0 or (disc >= 0.0 and br > 0.0 and -ar - np.sqrt(disc) > 2.0 * br)
            if short:
                k = -ar / (2.0 * br) if br > 0.0 else 1.0
            branch = ("low" if k <= 0.0 else "whole" if k >= 1.0
                      else "least" if short else "root")
        B_["branch"] = branch
    branch = B_["branch"]
    if branch == "whole":
        return v
    if branch == "low":
        return v_s.copy()
    if branch == "least":
        k = -a / (2.0 * b)
    else:
        k = (-a + np.sqrt(a * a + 4.0 * b * room)) / (2.0 * b)
    return v_s + k[:, None] * dv
