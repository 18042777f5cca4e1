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

Within a step the bodies' (cos, sin) are carried from the step's start through each turn
(carry_trig, in Workspace.chain_cs) rather than computed afresh at every configuration; the
step ends with them computed afresh at its end (update_trig), so that a step depends on the
State alone.
"""
import math

from ..compile import kernel
from .codes import ROW_PIN_X, ROW_PIN_Y
from .integrate import STALLED_RATIO
from .math2d import update_trig
from .pin import pin_gap, pin_rows
from .solve import add_impulses

# [m] every row within this after a correction pass: the next reuses the factorisation
CHORD_TOL = 1e-9
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
def _body_share(m, JL, JR, rl, el, rr, er, b):
    """Body b's share of A[rl:rl + 2, rr:rr + 2] = JL W JR^T (JL's rows rl, rl + 1 at their
    end el, JR's rows rr, rr + 1 at their end er: pins' x and y rows, whose x row has no y
    entry and y row no x entry; the products with those zeros are left out), row-major."""
    wm = m.body_inv_mass[b]
    wi = m.body_inv_inertia[b]
    lx = JL[rl, el, 2]
    ly = JL[rl + 1, el, 2]
    rx = JR[rr, er, 2]
    ry = JR[rr + 1, er, 2]
    return (wm * (JL[rl, el, 0] * JR[rr, er, 0]) + wi * lx * rx, wi * lx * ry, wi * ly * rx,
            wm * (JL[rl + 1, el, 1] * JR[rr + 1, er, 1]) + wi * ly * ry)


@kernel
def chain_factor(m, ws, JL, JR, symmetric):
    """The block LU of A = JL W JR^T along the chains into ws.chain_factor (symmetric: JL is
    JR, so A[k-1, k] is A[k, k-1]^T); returns the smallest share of its own diagonal that a
    row's pivot kept (each 2 x 2 pivot eliminated x row first, as the general L D L^T does,
    in the chains' order, which is the rows' where the model lists its pins along its
    chains; 0: a pivot vanished, the rows are dependent)."""
    f = ws.chain_factor
    smallest = 1.0
    for k in range(ws.chain_pin.shape[0]):
        j = ws.chain_pin[k]
        r = 2 * j
        d00 = 0.0
        d01 = 0.0
        d10 = 0.0
        d11 = 0.0
        for e in range(2):
            b = m.pin_body[j, e]
            if b >= 0:
                a00, a01, a10, a11 = _body_share(m, JL, JR, r, e, r, e, b)
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
            ri = 2 * ws.chain_pin[k - 1]
            b = m.pin_body[j, ej]
            e00, e01, e10, e11 = _body_share(m, JL, JR, r, ej, ri, ei, b)     # A[k, k-1]
            if symmetric:
                u00, u01, u10, u11 = e00, e10, e01, e11
            else:
                u00, u01, u10, u11 = _body_share(m, JL, JR, ri, ei, r, ej, b)  # A[k-1, k]
            # G = A[k, k-1] P_{k-1}^-1, then P -= G A[k-1, k]
            g00 = e00 * f[k - 1, 0] + e01 * f[k - 1, 2]
            g01 = e00 * f[k - 1, 1] + e01 * f[k - 1, 3]
            g10 = e10 * f[k - 1, 0] + e11 * f[k - 1, 2]
            g11 = e10 * f[k - 1, 1] + e11 * f[k - 1, 3]
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
            for c in range(4):
                f[k, c] = 0.0
            smallest = 0.0
            continue
        f[k, 0] = p11 / det
        f[k, 1] = -p01 / det
        f[k, 2] = -p10 / det
        f[k, 3] = p00 / det
    return smallest


@kernel
def chain_solve(ws, rhs, x):
    """x = A^-1 rhs by the factors of chain_factor (rows 2j, 2j + 1 of pin j in both)."""
    f = ws.chain_factor
    y = ws.chain_y
    n = ws.chain_pin.shape[0]
    for k in range(n):
        r = 2 * ws.chain_pin[k]
        y0 = rhs[r]
        y1 = rhs[r + 1]
        if ws.chain_end[k, 0] >= 0:
            # y_k -= G_k y_{k-1}, G_k = A[k, k-1] P_{k-1}^-1
            y0 -= f[k, 4] * y[k - 1, 0] + f[k, 5] * y[k - 1, 1]
            y1 -= f[k, 6] * y[k - 1, 0] + f[k, 7] * y[k - 1, 1]
        y[k, 0] = y0
        y[k, 1] = y1
    for k in range(n - 1, -1, -1):
        r = 2 * ws.chain_pin[k]
        t0 = y[k, 0]
        t1 = y[k, 1]
        if k + 1 < n and ws.chain_end[k + 1, 0] >= 0:
            # t -= A[k, k+1] x_{k+1}
            rn = 2 * ws.chain_pin[k + 1]
            t0 -= f[k + 1, 8] * x[rn] + f[k + 1, 9] * x[rn + 1]
            t1 -= f[k + 1, 10] * x[rn] + f[k + 1, 11] * x[rn + 1]
        x[r] = f[k, 0] * t0 + f[k, 1] * t1
        x[r + 1] = f[k, 2] * t0 + f[k, 3] * t1


@kernel
def chain_rows(m, s, ws):
    """Stage 3 on the chains: pin j's rows 2j (x) and 2j + 1 (y), their Jacobian blocks and
    errors at q (ws.body_cs its cos / sin) and their errors at q_pred (ws.chain_cs): the rows
    rows.build_rows makes for such a model (but row_F, which this path does not read)."""
    n_pin = m.pin_body.shape[0]
    for j in range(n_pin):
        r = 2 * j
        a = m.pin_body[j, 0]
        b = m.pin_body[j, 1]
        ws.row_kind[r] = ROW_PIN_X
        ws.row_kind[r + 1] = ROW_PIN_Y
        ws.row_owner[r] = j
        ws.row_owner[r + 1] = j
        ws.row_body[r, 0] = a
        ws.row_body[r, 1] = b
        ws.row_body[r + 1, 0] = a
        ws.row_body[r + 1, 1] = b
        pin_rows(s.q, ws.body_cs, m.pin_anchor, j, a, b, ws.row_J, ws.row_c, r)
        gx, gy = pin_gap(ws.q_pred, ws.chain_cs, m.pin_anchor, j, a, b)
        ws.row_c_pred[r] = gx
        ws.row_c_pred[r + 1] = gy
    ws.n_row[0] = 2 * n_pin


@kernel
def chain_prediction(s, ws, h):
    """ws.q_pred = q + h v_lin (integrate.predict_configuration) and its cos / sin carried from
    q's (ws.body_cs) into ws.chain_cs."""
    for i in range(s.q.shape[0]):
        for k in range(3):
            ws.q_pred[i, k] = s.q[i, k] + h * ws.v_lin[i, k]
    carry_trig(ws.q_pred, ws.body_cs, ws.chain_cs)


@kernel
def chain_residual(m, s, ws, jacobian):
    """The pins' errors c at q as the correction's targets, ws.rhs = -c (and, jacobian, their
    rows' Jacobian blocks into ws.row_Jp); returns the largest |c| [m]. ws.chain_cs must hold
    q's cos / sin."""
    worst = 0.0
    for j in range(m.pin_body.shape[0]):
        r = 2 * j
        a = m.pin_body[j, 0]
        b = m.pin_body[j, 1]
        if jacobian:
            pin_rows(s.q, ws.chain_cs, m.pin_anchor, j, a, b, ws.row_Jp, ws.rhs, r)
            gx = ws.rhs[r]
            gy = ws.rhs[r + 1]
        else:
            gx, gy = pin_gap(s.q, ws.chain_cs, m.pin_anchor, j, a, b)
        ws.rhs[r] = -gx
        ws.rhs[r + 1] = -gy
        worst = max(worst, abs(gx), abs(gy))
    return worst


@kernel
def chain_velocity_solve(m, ws, h):
    """Stage 4 on the chains: lam with J W J^T lam = -c(q_pred) / h (J and W at the step's
    start, c(q_pred) the pins' gaps at the predicted end, rows.build_rows) and v_new = v* +
    W J^T lam. Returns the smallest pivot share (chain_factor)."""
    n = ws.n_row[0]
    share = chain_factor(m, ws, ws.row_J, ws.row_J, True)
    for r in range(n):
        ws.rhs[r] = -ws.row_c_pred[r] / h
    chain_solve(ws, ws.rhs, ws.lam)
    for i in range(ws.v_new.shape[0]):
        for k in range(3):
            ws.v_new[i, k] = ws.v_pred[i, k]
    add_impulses(ws.row_J, ws.row_body, m.body_inv_mass, m.body_inv_inertia, ws.lam, n,
                 ws.v_new, 1.0)
    return share


@kernel(inline="always")
def _move_by(m, ws, n, q, v, inv_h):
    """q += W J(q0)^T mu and v += W J(q0)^T mu / h (mu in ws.lam, J(q0) ws.row_J) in one sweep
    of the rows: solve.add_impulses' arithmetic for each, the same bits."""
    for r in range(n):
        mu = ws.lam[r]
        if mu == 0.0:
            continue
        rate = mu * inv_h
        for e in range(2):
            b = ws.row_body[r, e]
            if b < 0:
                continue
            wm = m.body_inv_mass[b]
            wi = m.body_inv_inertia[b]
            dx = wm * ws.row_J[r, e, 0]
            dy = wm * ws.row_J[r, e, 1]
            dt = wi * ws.row_J[r, e, 2]
            q[b, 0] += dx * mu
            q[b, 1] += dy * mu
            q[b, 2] += dt * mu
            if rate != 0.0:     # (as add_impulses skips a row whose scaled impulse is 0)
                v[b, 0] += dx * rate
                v[b, 1] += dy * rate
                v[b, 2] += dt * rate


@kernel(inline="always")
def _chain_pass(m, s, ws, n, h):
    """One correction pass on the factors in ws: mu from the targets in ws.rhs, q += W J(q0)^T
    mu, v += W J(q0)^T mu / h, the bodies' cos / sin at the new q carried (ws.chain_cs)."""
    chain_solve(ws, ws.rhs, ws.lam)
    _move_by(m, ws, n, s.q, s.v, 1.0 / h)
    carry_trig(s.q, ws.chain_cs, ws.chain_cs)


@kernel
def chain_correct(m, s, ws, h, iters, tol, pivot_tol):
    """Stage 8's Newton-SHAKE on the chains: up to iters passes of J(q) W J(q0)^T mu = -c(q),
    q += W J(q0)^T mu, v += W J(q0)^T mu / h, until every row is within tol [m]; a pass
    after one that left every row within CHORD_TOL reuses its factorisation. Returns
    the largest row error left, or -1 where a pass removed less than half of it or a
    factorisation kept a pivot share at or below pivot_tol (StepOptions.refine_pivot_tol:
    the general correction would drop that row; its safeguards then decide, the step is
    taken by the general stages). ws.body_cs holds the cos / sin of the step's start on entry,
    of q on a return >= 0 (on -1, still the start's)."""
    n = ws.n_row[0]
    carry_trig(s.q, ws.body_cs, ws.chain_cs)
    worst = chain_residual(m, s, ws, True)
    fresh = True
    passes = 0
    for _ in range(iters):
        if worst <= tol:
            break
        if fresh and chain_factor(m, ws, ws.row_Jp, ws.row_J, False) <= pivot_tol:
            return -1.0
        _chain_pass(m, s, ws, n, h)
        after = chain_residual(m, s, ws, False)
        if after > STALLED_RATIO * worst:
            return -1.0
        fresh = after > CHORD_TOL
        if fresh and after > tol:
            chain_residual(m, s, ws, True)      # (the next pass factors J at this q)
        worst = after
        passes += 1
    if passes > 0 and 0.0 < worst <= tol:
        # one more pass on the last factorisation, as integrate.correct_positions takes it
        # (it says why: the end's derivative becomes the converged correction's)
        _chain_pass(m, s, ws, n, h)
    update_trig(s.q, ws.body_cs)
    return worst
