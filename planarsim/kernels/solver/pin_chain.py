"""Stages 4 and 8 for a model whose only rows are the pins of open chains
(planarsim/pin_chains.py says which models; step.chain_step runs them): the velocity solve and
the Newton-SHAKE correction by block elimination along each chain.

Pin j owns rows 2j (x) and 2j + 1 (y) (rows.build_rows makes them in that order when pins are
a model's only rows). Along a chain (Workspace.chain_pin: place k holds a pin, place k - 1 the
pin it shares a body with) the matrix A = J_L W J_R^T couples a pin only to its neighbours,
through the body they share: block tridiagonal in 2 x 2 blocks. Its block LU, pivot by pivot,

    P_k = A[k, k] - A[k, k-1] P_{k-1}^-1 A[k-1, k],

costs a few dozen flops a link and fills nothing (Baraff 1996 orders a tree's rows the same
way). The velocity solve is the general solve's (solve.solve_impulses: J W J^T lam =
-c(q + h v*) / h with J at the step's start); the correction is integrate.correct_positions'
Newton-SHAKE (q moved along the start's rows, J(q+) W J(q0)^T mu = -c(q+)), whose later
passes reuse the factorisation of an earlier one once every row is within CHORD_TOL (a chord
step: the rows moved by less than that since, so each pass still removes all but a share of
that order of the error). Both end where the general stages end, to rounding.

The rows are never written out as the general stages' row arrays (ws.row_J and the rest): a
pin's rows are fixed by its two anchors' levers from their bodies' centres of mass
(ws.chain_lever, at the step's start and at the iterate), from which each loop forms the few
products it needs (the blocks, the gaps, the moves, the joints' work).

Within a step the bodies' (cos, sin) are carried from the step's start through each turn
(carry_trig, in Workspace.chain_cs) rather than computed afresh at every configuration; the
step ends with them computed afresh at its end (update_trig), so that a step depends on the
State alone.
"""
import math

from ...compile import kernel
from ..dynamics.integrate import CHORD_TOL, STALLED_RATIO, clear_moved_impulses
from ..math2d import rotate, update_trig
from ..checks.work import VELOCITY_FLOOR, WORK_REL_TOL, fastest

# [rad] a body's (cos, sin) is carried through a turn of at most this by turn_by (the series'
# first left-out terms, d^9 / 9! and d^10 / 10!, are at most 1.4e-21; each carry's rounding,
# about an ulp, is what remains); beyond, computed afresh
SERIES_TURN = 0.02


@kernel(inline="always")
def turn_by(c, s, d):
    """(cos, sin) of an angle with cosine c and sine s turned by d [rad] (|d| <= SERIES_TURN):
    each less its change, 1 - cos d and sin d by their Taylor series to d^8 and d^7
    (multiplications only: the loops over bodies vectorise)."""
    d2 = d * d
    one_less_cos = 0.5 * d2 * (1.0 - d2 * (1.0 / 12.0) * (1.0 - d2 * (1.0 / 30.0) * (
        1.0 - d2 * (1.0 / 56.0))))
    sin_d = d * (1.0 - d2 * (1.0 / 6.0) * (1.0 - d2 * (1.0 / 20.0) * (1.0 - d2 * (1.0 / 42.0))))
    return c - (c * one_less_cos + s * sin_d), s - (s * one_less_cos - c * sin_d)


@kernel
def carry_trig(q, cs_from, cs_to):
    """cs_to[i] = (cos, sin, angle) of q[i, 2], carried from cs_from[i] (the same of a nearby
    angle; cs_to may be cs_from) by turn_by, or computed afresh for a turn beyond SERIES_TURN
    (or a NaN): one loop without calls, then the few far turns. Within a step only: the
    carried values differ from math.cos / sin in the last bits, so the step ends with
    update_trig's (the next step must not depend on them)."""
    far = 0
    for i in range(q.shape[0]):
        th = q[i, 2]
        d = th - cs_from[i, 2]
        c, sn = turn_by(cs_from[i, 0], cs_from[i, 1], d)
        near = abs(d) <= SERIES_TURN
        far += not near
        cs_to[i, 0] = c
        cs_to[i, 1] = sn
        cs_to[i, 2] = th if near else math.nan
    if far == 0:
        return
    for i in range(q.shape[0]):
        if not cs_to[i, 2] == q[i, 2]:
            th = q[i, 2]
            cs_to[i, 0] = math.cos(th)
            cs_to[i, 1] = math.sin(th)
            cs_to[i, 2] = th


@kernel(inline="always")
def _forward(ws, rhs, scale, k, linked, p0, p1):
    """Place k's step of the forward substitution: y_k = rhs_k / scale - G_k y_{k-1} (linked:
    place k - 1 holds the pin before k on its chain; p0, p1: y_{k-1}) into ws.chain_y[k], rhs_k
    divided in place; returns y_k. scale 1, or h [s] (the general solve's rhs / h,
    solve.fill_row_b)."""
    f = ws.chain_factor
    r = 2 * ws.chain_pin[k]
    if scale != 1.0:
        rhs[r] /= scale
        rhs[r + 1] /= scale
    y0 = rhs[r]
    y1 = rhs[r + 1]
    if linked:
        y0 -= f[k, 4] * p0 + f[k, 5] * p1
        y1 -= f[k, 6] * p0 + f[k, 7] * p1
    ws.chain_y[k, 0] = y0
    ws.chain_y[k, 1] = y1
    return y0, y1


@kernel(inline="always")
def _backward(ws, x):
    """The back substitution from ws.chain_y: x_k = P_k^-1 (y_k - A[k, k+1] x_{k+1}), rows
    2j, 2j + 1 of pin j in x (each x_{k+1} carried in registers, not read back)."""
    f = ws.chain_factor
    n = ws.chain_pin.shape[0]
    n0 = 0.0
    n1 = 0.0
    linked = False
    for k in range(n - 1, -1, -1):
        t0 = ws.chain_y[k, 0]
        t1 = ws.chain_y[k, 1]
        if linked:
            t0 -= f[k + 1, 8] * n0 + f[k + 1, 9] * n1
            t1 -= f[k + 1, 10] * n0 + f[k + 1, 11] * n1
        n0 = f[k, 0] * t0 + f[k, 1] * t1
        n1 = f[k, 2] * t0 + f[k, 3] * t1
        r = 2 * ws.chain_pin[k]
        x[r] = n0
        x[r + 1] = n1
        linked = ws.chain_end[k, 0] >= 0


@kernel
def chain_solve(ws, rhs, x):
    """x = A^-1 rhs by the factors of lever_factor_solve (rows 2j, 2j + 1 of pin j in both)."""
    p0 = 0.0
    p1 = 0.0
    for k in range(ws.chain_pin.shape[0]):
        p0, p1 = _forward(ws, rhs, 1.0, k, ws.chain_end[k, 0] >= 0, p0, p1)
    _backward(ws, x)


@kernel
def chain_prediction(s, ws, h):
    """ws.q_pred = q + h v_lin (integrate.predict_configuration) and its cos / sin carried from
    q's (ws.body_cs) into ws.chain_cs."""
    for i in range(s.q.shape[0]):
        for k in range(3):
            ws.q_pred[i, k] = s.q[i, k] + h * ws.v_lin[i, k]
    carry_trig(ws.q_pred, ws.body_cs, ws.chain_cs)


# ---- the pins' rows as levers ----
# Pin j's anchor on end e (0: body a, 1: body b; -1 bodies are the world) sits at r = R p
# from its body's centre of mass; ws.chain_lever[j, e] holds (r_x, r_y) at the step's start
# (q0) and at the iterate. Its rows' Jacobian blocks are sign(e) [[1, 0, -r_y], [0, 1, r_x]]
# (sign -1 at end a, +1 at end b: the gap is p_b - p_a), so a body's share of the 2 x 2
# block that couples pin j (end e, lever rL) to pin i (end f, lever rR through the same
# body) is sign(e) sign(f) (w_m I + w_i (-rL_y, rL_x) (-rR_y, rR_x)^T).


@kernel(inline="always")
def _lever(cs, body, anchor, j, e):
    """(x, y) [m] of pin j's anchor on end e from its body's centre of mass (cs: the bodies'
    cos, sin); (0, 0) for the world."""
    if body < 0:
        return 0.0, 0.0
    return rotate(cs[body, 0], cs[body, 1], anchor[j, e, 0], anchor[j, e, 1])


@kernel(inline="always")
def _anchor_point(m, q, cs, ws, j, e, at):
    """World point (x, y) [m] of pin j's anchor on end e at q (cs its cos / sin; the world's
    anchor as given), its lever into ws.chain_lever[j, e, at:at + 2]."""
    body = m.pin_body[j, e]
    rx, ry = _lever(cs, body, m.pin_anchor, j, e)
    ws.chain_lever[j, e, at] = rx
    ws.chain_lever[j, e, at + 1] = ry
    if body < 0:
        return m.pin_anchor[j, e, 0], m.pin_anchor[j, e, 1]
    return q[body, 0] + rx, q[body, 1] + ry


@kernel
def lever_gaps(m, q, cs, ws, at):
    """The pins' gaps p_b - p_a at q (cs its cos / sin) as targets ws.rhs = -c, their levers
    into ws.chain_lever[:, :, at:at + 2]; returns the largest |c| [m]."""
    worst = 0.0
    for j in range(m.pin_body.shape[0]):
        ax, ay = _anchor_point(m, q, cs, ws, j, 0, at)
        bx, by = _anchor_point(m, q, cs, ws, j, 1, at)
        gx = bx - ax
        gy = by - ay
        ws.rhs[2 * j] = -gx
        ws.rhs[2 * j + 1] = -gy
        worst = max(worst, abs(gx), abs(gy))
    return worst


@kernel(inline="always")
def _lever_share(m, ws, jl, el, at, jr, er, b):
    """Body b's share of the block coupling pin jl (end el, levers at column `at`) to pin jr
    (end er, levers of the step's start), row-major."""
    wm = m.body_inv_mass[b]
    wi = m.body_inv_inertia[b]
    lx = ws.chain_lever[jl, el, at]
    ly = ws.chain_lever[jl, el, at + 1]
    rx = ws.chain_lever[jr, er, 0]
    ry = ws.chain_lever[jr, er, 1]
    sg = 1.0 if el == er else -1.0
    return (sg * (wm + wi * ly * ry), -sg * (wi * ly * rx), -sg * (wi * lx * ry),
            sg * (wm + wi * lx * rx))


@kernel
def lever_factor_solve(m, ws, at, rhs, scale, x):
    """The block LU of A = J(levers at column `at`) W J0^T along the chains into
    ws.chain_factor (at 0: the symmetric matrix of the step's start, A[k-1, k] = A[k, k-1]^T):
    pivot by pivot as the module docstring says, each 2 x 2 pivot eliminated x row first, as
    the general L D L^T does, in the chains' order, which is the rows' where the model lists
    its pins along its chains; the forward substitution of rhs / scale (rhs divided in place)
    taken in the same sweep, then x = A^-1 (rhs / scale). Returns the smallest share of its
    own diagonal that a row's pivot kept (0: a pivot vanished, the rows are dependent)."""
    f = ws.chain_factor
    smallest = 1.0
    # P_{k-1}^-1 and y_{k-1}, carried from the last place
    i00 = 0.0
    i01 = 0.0
    i10 = 0.0
    i11 = 0.0
    y0 = 0.0
    y1 = 0.0
    for k in range(ws.chain_pin.shape[0]):
        j = ws.chain_pin[k]
        d00 = 0.0
        d01 = 0.0
        d10 = 0.0
        d11 = 0.0
        for e in range(2):
            b = m.pin_body[j, e]
            if b >= 0:
                a00, a01, a10, a11 = _lever_share(m, ws, j, e, at, j, e, b)
                d00 += a00
                d01 += a01
                d10 += a10
                d11 += a11
        p00 = d00
        p01 = d01
        p10 = d10
        p11 = d11
        ej = ws.chain_end[k, 0]
        if ej >= 0:
            ei = ws.chain_end[k, 1]
            i = ws.chain_pin[k - 1]
            b = m.pin_body[j, ej]
            e00, e01, e10, e11 = _lever_share(m, ws, j, ej, at, i, ei, b)     # A[k, k-1]
            if at == 0:         # (J0 W J0^T is symmetric: A[k-1, k] = A[k, k-1]^T)
                u00, u01, u10, u11 = e00, e10, e01, e11
            else:
                u00, u01, u10, u11 = _lever_share(m, ws, i, ei, at, j, ej, b)  # A[k-1, k]
            g00 = e00 * i00 + e01 * i10
            g01 = e00 * i01 + e01 * i11
            g10 = e10 * i00 + e11 * i10
            g11 = e10 * i01 + e11 * i11
            p00 -= g00 * u00 + g01 * u10
            p01 -= g00 * u01 + g01 * u11
            p10 -= g10 * u00 + g11 * u10
            p11 -= g10 * u01 + g11 * u11
            f[k, 4] = g00
            f[k, 5] = g01
            f[k, 6] = g10
            f[k, 7] = g11
            f[k, 8] = u00
            f[k, 9] = u01
            f[k, 10] = u10
            f[k, 11] = u11
        second = p11 - p10 * p01 / p00 if p00 != 0.0 else 0.0
        share0 = abs(p00) / d00 if d00 > 0.0 else 0.0
        share1 = abs(second) / d11 if d11 > 0.0 else 0.0
        smallest = min(smallest, share0, share1)
        det = p00 * p11 - p01 * p10
        if det == 0.0:
            i00 = 0.0
            i01 = 0.0
            i10 = 0.0
            i11 = 0.0
            smallest = 0.0
        else:
            i00 = p11 / det
            i01 = -p01 / det
            i10 = -p10 / det
            i11 = p00 / det
        f[k, 0] = i00
        f[k, 1] = i01
        f[k, 2] = i10
        f[k, 3] = i11
        y0, y1 = _forward(ws, rhs, scale, k, ej >= 0, y0, y1)
    _backward(ws, x)
    return smallest


@kernel
def lever_move(m, ws, x, q, q_scale, v, v_scale):
    """q += q_scale W J0^T x and v += v_scale W J0^T x (x: the pins' impulses, 2 a pin; J0
    from the levers of the step's start); a scale of 0 leaves its array alone."""
    for j in range(m.pin_body.shape[0]):
        px = x[2 * j]
        py = x[2 * j + 1]
        for e in range(2):
            b = m.pin_body[j, e]
            if b < 0:
                continue
            sg = -1.0 if e == 0 else 1.0
            wm = sg * m.body_inv_mass[b]
            dx = wm * px
            dy = wm * py
            dt = sg * m.body_inv_inertia[b] * (ws.chain_lever[j, e, 0] * py
                                               - ws.chain_lever[j, e, 1] * px)
            if q_scale != 0.0:
                q[b, 0] += q_scale * dx
                q[b, 1] += q_scale * dy
                q[b, 2] += q_scale * dt
            if v_scale != 0.0:
                v[b, 0] += v_scale * dx
                v[b, 1] += v_scale * dy
                v[b, 2] += v_scale * dt


@kernel
def lever_velocity_solve(m, s, ws, h):
    """Stage 4 on the chains: lam with J0 W J0^T lam = -c(q_pred) / h (J0 the pins' rows at the
    step's start, whose cos / sin ws.body_cs holds; c at q_pred with ws.chain_cs), v_new =
    v* + W J0^T lam; lam into ws.lam (rows 2j, 2j + 1). Returns the smallest pivot share."""
    # the gaps at q_pred (levers into columns 2, 3) and the levers at the start (columns 0, 1)
    for j in range(m.pin_body.shape[0]):
        ax, ay = _anchor_point(m, ws.q_pred, ws.chain_cs, ws, j, 0, 2)
        bx, by = _anchor_point(m, ws.q_pred, ws.chain_cs, ws, j, 1, 2)
        ws.rhs[2 * j] = -(bx - ax)
        ws.rhs[2 * j + 1] = -(by - ay)
        for e in range(2):
            rx, ry = _lever(ws.body_cs, m.pin_body[j, e], m.pin_anchor, j, e)
            ws.chain_lever[j, e, 0] = rx
            ws.chain_lever[j, e, 1] = ry
    share = lever_factor_solve(m, ws, 0, ws.rhs, h, ws.lam)
    for i in range(ws.v_new.shape[0]):
        for k in range(3):
            ws.v_new[i, k] = ws.v_pred[i, k]
    lever_move(m, ws, ws.lam, ws.v_new, 0.0, ws.v_new, 1.0)
    return share


@kernel
def lever_joint_work(m, ws, v):
    """joint_work of the pins' impulses ws.lam at velocity v on the levers of the step's start:
    (work [J], its rounding [J], the row doing the most work or -1)."""
    speed = fastest(v) + fastest(ws.v_pred)
    per = WORK_REL_TOL * speed + VELOCITY_FLOOR
    total = 0.0
    rounding = 0.0
    most = 0.0
    row = -1
    for j in range(m.pin_body.shape[0]):
        rel_x = 0.0
        rel_y = 0.0
        for e in range(2):
            b = m.pin_body[j, e]
            if b < 0:
                continue
            sg = -1.0 if e == 0 else 1.0
            rel_x += sg * (v[b, 0] - ws.chain_lever[j, e, 1] * v[b, 2])
            rel_y += sg * (v[b, 1] + ws.chain_lever[j, e, 0] * v[b, 2])
        lx = ws.lam[2 * j]
        ly = ws.lam[2 * j + 1]
        wx = lx * rel_x
        wy = ly * rel_y
        total += wx + wy
        rounding += (abs(lx) + abs(ly)) * per
        if wx > most:
            most = wx
            row = 2 * j
        if wy > most:
            most = wy
            row = 2 * j + 1
    return total, rounding, row


@kernel
def record_lever_impulses(ws, inv_h):
    """integrate.record_moved_impulses on the levers: a correction pass's impulses ws.lam
    (rows 2j, 2j + 1 of pin j) over h added to the pins' (ws.pin_impulse_moved)."""
    for j in range(ws.pin_impulse_moved.shape[0]):
        ws.pin_impulse_moved[j, 0] += inv_h * ws.lam[2 * j]
        ws.pin_impulse_moved[j, 1] += inv_h * ws.lam[2 * j + 1]


@kernel
def lever_correct(m, s, ws, h, iters, tol, pivot_tol):
    """Stage 8's Newton-SHAKE on the levers, integrate.correct_positions' passes: up to iters
    of J(q) W J0^T mu = -c(q), q += W J0^T mu, v += W J0^T mu / h until every gap is within
    tol [m] (a pass after one that left every gap within CHORD_TOL reuses its factorisation;
    one more pass on the last factorisation after the last, as correct_positions takes it
    (not after a last pass taken at gaps within CHORD_TOL): the end's derivative becomes the
    converged correction's; each pass's impulses over h into ws.pin_impulse_moved,
    record_lever_impulses); returns (the largest gap left, or -1: a pass that removed less
    than half of it, a pivot share at or below pivot_tol, the general stages take the step;
    the passes taken). ws.body_cs holds the cos / sin of the step's start on entry, of q on
    a return with a gap >= 0."""
    clear_moved_impulses(ws)
    carry_trig(s.q, ws.body_cs, ws.chain_cs)
    worst = lever_gaps(m, s.q, ws.chain_cs, ws, 2)
    fresh = True
    passes = 0
    taken_at = 0.0      # the largest gap the last pass was taken at
    inv_h = 1.0 / h
    for _ in range(iters):
        if worst <= tol:
            break
        if fresh:
            if lever_factor_solve(m, ws, 2, ws.rhs, 1.0, ws.lam) <= pivot_tol:
                return -1.0, passes
        else:
            chain_solve(ws, ws.rhs, ws.lam)
        lever_move(m, ws, ws.lam, s.q, 1.0, s.v, inv_h)
        record_lever_impulses(ws, inv_h)
        carry_trig(s.q, ws.chain_cs, ws.chain_cs)
        after = lever_gaps(m, s.q, ws.chain_cs, ws, 2)
        if after > STALLED_RATIO * worst:
            return -1.0, passes
        fresh = after > CHORD_TOL
        taken_at = worst
        worst = after
        passes += 1
    if passes > 0 and 0.0 < worst <= tol and taken_at > CHORD_TOL:
        chain_solve(ws, ws.rhs, ws.lam)
        lever_move(m, ws, ws.lam, s.q, 1.0, s.v, inv_h)
        record_lever_impulses(ws, inv_h)
    update_trig(s.q, ws.body_cs)
    return worst, passes
