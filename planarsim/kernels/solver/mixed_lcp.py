"""The rows of a step as one mixed complementarity problem, solved by Lemke's method (lcp.py).

Rows r with impulses x_r and residuals w = A x + b (A = J W J^T, dense here: an island's in
ws.lcp_A, b = ws.row_b):
  joints (pins x / y, rods):   x free,  w = 0
  unilateral (contact normals, joint limits):   x >= 0, w >= 0, x w = 0
  friction (a contact's tangent row t, after its normal row n):   |x_t| <= mu x_n, and
      w_t = 0 inside the cone (sticking) or x_t = -mu x_n sign(w_t) (sliding); a joint's
      friction row (joint_friction.py) the same with the constant bound F h for mu x_n
The joints are eliminated first (Schur complement: x_b = -A_bb^-1 (b_b + A_bx x_x); the joint
rows of a tree are independent, so A_bb is positive definite; a row of a joint-only loop that
depends exactly on others is consistent and is left out there, impulse 0; which rows those
are, a pivoted factorization decides wherever a row is left out or a pivot falls below
PIVOTING_SHARE of its diagonal). Friction takes the form of Stewart and Trinkle (1996):
x_t = beta+ - beta-, with a slip speed gamma,
  beta+ >= 0  _|_  w_t + gamma >= 0,   beta- >= 0  _|_  -w_t + gamma >= 0,
  gamma >= 0  _|_  mu x_n - beta+ - beta- >= 0,
which in the plane is Coulomb's law exactly (the cone has two edges). Variables are scaled to
unit diagonal before pivoting (masses 1:1000 apart give a well-scaled tableau).
The velocity stage calls this with b = c / h + J v*; the position projection with b = c.
"""
import math

from ...compile import kernel
from .lcp import LCP_INACCURATE, LCP_RAY, LCP_SOLVED, REVISED_SIZE, lemke, lemke_large, polish
from ..codes import CONTACT_PAIR
from ..geometry.contacts import pair_motion_scale
from ..constraints.rows import is_joint_row, is_soft_row, is_tangent_row
from ..constraints.joint_friction import is_joint_friction_row
from ..constraints.soft import soft_compliance
from .envelope import _entry

# a joint-only loop: a pivot below this share of its row's diagonal belongs to a row that is
# an exact combination of the others (consistent joints), left out with impulse 0
# (_factor_plain, _factor_pivoted)
JOINT_LOOP_TOL = 1e-12
# a pivot this small a share of its diagonal may be rounding of larger rows (a loop near a
# dependent configuration): the joint block is then factored again with pivoting
PIVOTING_SHARE = 1e-8
# friction within this share of mu lambda_n is at the cone's edge; a slip speed below this
# share of the contact's free-motion speed is rounding
CONE_EDGE_TOL = 1e-9
# diagonal terms (scaled units) tried in turn when Lemke's path ends on a ray or astray; the
# answer's basis is then re-solved for the problem itself (lcp.polish). Measured on the
# 16-box chains on hills, where some problems solve only at 1e-6: of 570k steps of the stress
# corpus 9 kept a regularised answer (polish failed), none broke an audit rule
REGULARISATION = (1e-12, 1e-10, 1e-8, 1e-6)
# a large problem with friction (lcp.REVISED_SIZE variables or more; friction makes M only
# copositive) starts at this attempt: the path on M + 1e-10 I (strictly copositive: it cannot
# end on a ray in exact arithmetic), then polish.
# Measured on 147 problems of a pile of 50 shapes poured into a U (132-316 variables): the
# path on M itself ended on a ray 100 times, each a whole path spent, and all were solved at
# 73,799 pivots; started here, 145 solved on the first path, 39,012 pivots, polish exact on
# every one. A small problem's path costs little, and one without friction (M positive
# semidefinite) ends at an answer: they try M itself first
LARGE_FIRST_ATTEMPT = 2
# a regularised answer that polish cannot make exact is kept where its contacts approach at
# most this share of the problem's fastest approach (scaled units; ws.lcp_eps[0] is the
# largest diagonal term a step kept)
SOFT_ANSWER_TOL = 1e-4


@kernel
def lcp_room(ws, count):
    """Do islands of `count` rows fit the dense complementarity storage? If not, and the
    storage may grow to hold them (ws.room[4]), ws.room asks for it (the step begins again
    with more: kernels/step.py, GUARD_ROOM). Returns True if they fit."""
    if count <= ws.lcp_A.shape[0]:
        return True
    if count <= ws.room[4]:
        ws.room[0] = 1
        ws.room[3] = max(ws.room[3], count)
    return False


@kernel
def assemble_dense(m, ws, rows, start, count):
    """ws.lcp_A = (J W J^T)[r, s] in full for the rows r, s in rows[start:start + count]
    (an island's: kernels/solver/islands.py; rows touching no common body give 0), row r at
    ws.row_local[r]. The rows must fit (lcp_room)."""
    for i in range(count):
        ri = rows[start + i]
        ws.row_local[ri] = i
        for j in range(i + 1):
            rj = rows[start + j]
            a = _entry(ws.row_J, ws.row_J, ws.row_body, m.body_inv_mass, m.body_inv_inertia,
                       ri, rj)
            if j == i and is_soft_row(ws.row_kind[ri]):
                a += soft_compliance(ws, ri)     # a joint's soft row (soft.py)
            ws.lcp_A[i, j] = a
            ws.lcp_A[j, i] = a


@kernel(inline="always")
def dense_entry(ws, r, c):
    """(J W J^T)[r, c] of two rows of the island assemble_dense filled."""
    return ws.lcp_A[ws.row_local[r], ws.row_local[c]]


@kernel
def _factor_plain(B, nb):
    """B = L D L^T in place (dense, lower triangle and diagonal) in the rows' order; a pivot
    below JOINT_LOOP_TOL of its diagonal is left out (zero). Returns the smallest share of
    its diagonal that a pivot has (0 if one was left out)."""
    smallest = 1.0
    for k in range(nb):
        scale = abs(B[k, k])
        for j in range(k):
            B[k, k] -= B[k, j] * B[k, j] * B[j, j]
        if abs(B[k, k]) <= JOINT_LOOP_TOL * scale or scale == 0.0:
            B[k, k] = 0.0
            smallest = 0.0
        else:
            smallest = min(smallest, abs(B[k, k]) / scale)
        for i in range(k + 1, nb):
            acc = B[i, k]
            for j in range(k):
                acc -= B[i, j] * B[k, j] * B[j, j]
            B[i, k] = acc / B[k, k] if B[k, k] != 0.0 else 0.0
    return smallest


@kernel
def _factor_pivoted(B, nb, rows, scratch):
    """B = L D L^T in place as _factor_plain (B full and symmetric on entry; no return), with
    symmetric pivoting: each step eliminates the row whose remaining pivot is the largest
    share of its own diagonal (pivoting on the unit-diagonal scaling of B, which no row's
    units change), and rows[:nb] (the rows' ids) are permuted with B. A loop's dependent
    rows come last, where all that is left of them is rounding: once the largest remaining
    share is below JOINT_LOOP_TOL, the remaining rows are left out (zero pivot). In the
    rows' order, a loop's last row could keep as its pivot the rounding of far larger rows
    (measured: a folded four-bar with inertias 1e-4..1e4 kg m^2 kept a pivot of 2e-12 of its
    diagonal on a loop singular to 1e-15, and its pins took 2e5 N s). scratch (>= nb, 2):
    the remaining pivots and the diagonals. Returns the smallest share of its diagonal that
    a pivot kept (0 if a row was left out)."""
    smallest = 1.0
    for i in range(nb):
        scratch[i, 0] = B[i, i]
        scratch[i, 1] = B[i, i]
    for k in range(nb):
        p = k
        best = -1.0
        for i in range(k, nb):
            share = scratch[i, 0] / scratch[i, 1] if scratch[i, 1] > 0.0 else 0.0
            if share > best:
                best = share
                p = i
        if p != k:
            for j in range(nb):
                B[k, j], B[p, j] = B[p, j], B[k, j]
            for i in range(nb):
                B[i, k], B[i, p] = B[i, p], B[i, k]
            rows[k], rows[p] = rows[p], rows[k]
            for c in range(2):
                scratch[k, c], scratch[p, c] = scratch[p, c], scratch[k, c]
        if best <= JOINT_LOOP_TOL:
            for i in range(k, nb):
                B[i, i] = 0.0
                for j in range(i + 1, nb):
                    B[j, i] = 0.0
            return 0.0
        smallest = min(smallest, best)
        piv = B[k, k]
        for i in range(k + 1, nb):
            B[i, k] = B[i, k] / piv
        for i in range(k + 1, nb):
            lik = B[i, k]
            if lik == 0.0:
                continue
            for j in range(k + 1, i + 1):
                B[i, j] -= lik * B[j, k] * piv
            scratch[i, 0] = B[i, i]
        for i in range(k + 1, nb):       # the remaining block full again, for the swaps
            for j in range(i + 1, nb):
                B[i, j] = B[j, i]
    return smallest


@kernel
def _factor_joints(A, local, B, nb, rows, scratch):
    """B = L D L^T of the joint rows rows[:nb] of the island's A (row r at local[r]; rows
    may be permuted; see _factor_pivoted). In the rows' order where every pivot is at least
    PIVOTING_SHARE of its diagonal, far above rounding, so that the rows are certainly
    independent (a tree's joints); pivoted otherwise: a loop, at or near a dependent
    configuration, whose rows left out must be the dependent ones whatever the rows' order.
    Returns the smallest share of its diagonal that a pivot kept (0 if a row was left out)."""
    _fill_joint_block(A, local, B, nb, rows)
    smallest = _factor_plain(B, nb)
    if smallest >= PIVOTING_SHARE:
        return smallest
    _fill_joint_block(A, local, B, nb, rows)
    return _factor_pivoted(B, nb, rows, scratch)


@kernel
def _fill_joint_block(A, local, B, nb, rows):
    """B[i, j] = A[local[rows[i]], local[rows[j]]] for i, j < nb (A: the island's dense
    matrix, assemble_dense; local: each row's place in it)."""
    for i in range(nb):
        for j in range(nb):
            B[i, j] = A[local[rows[i]], local[rows[j]]]


@kernel
def _solve_joints(B, nb, G, col):
    """G[:nb, col] <- (L D L^T)^-1 G[:nb, col] (a zero pivot gives 0)."""
    for i in range(nb):
        acc = G[i, col]
        for j in range(i):
            acc -= B[i, j] * G[j, col]
        G[i, col] = acc
    for i in range(nb):
        G[i, col] = G[i, col] / B[i, i] if B[i, i] != 0.0 else 0.0
    for i in range(nb - 1, -1, -1):
        acc = G[i, col]
        for j in range(i + 1, nb):
            acc -= B[j, i] * G[j, col]
        G[i, col] = acc


@kernel
def is_boxed_row(kind):
    """A friction row (three variables beta+, beta-, gamma): a contact's tangent row (bound
    mu x_n) or a stuck joint's friction row (bound F h, joint_friction.py)."""
    return is_tangent_row(kind) or is_joint_friction_row(kind)


@kernel
def friction_bound_of(m, ws, r):
    """The bound [N s or N m s] of friction row r's impulse as solved: mu x_n of a contact's
    (its normal row r - 1), F h of a joint's."""
    if is_joint_friction_row(ws.row_kind[r]):
        return ws.friction_bound[ws.row_owner[r]]
    return m.contact_mu[ws.row_owner[r]] * ws.lam[r - 1]


@kernel
def _exact_or_soft(Mx, qx, nv, ws, eps, floor):
    """After Lemke's path solved M + eps I (eps > 0) into ws.lcp_z on its basis, Mx holding M
    again: that basis's answer for M itself (lcp.polish), else the nearby answer, which misses
    the rules of M by eps z (scaled units: a compliance of eps, whose contacts may approach at
    eps z), kept where that is within SOFT_ANSWER_TOL of the fastest approach max -q (the
    position stage still ends the step on the surface): far nearer the rules than the
    frictionless rule's answer, which would drop the island's friction for the step (a
    20-domino run and a pour of 50 shapes met it). A large z (a load that redundant rows share
    without bound) is no answer. Returns (LCP_SOLVED or LCP_INACCURATE, the eps the answer
    kept: 0 where polished)."""
    if polish(Mx, qx, nv, ws.lcp_T, ws.lcp_basis, ws.lcp_z, floor) == LCP_SOLVED:
        return LCP_SOLVED, 0.0
    z_max = 0.0
    q_neg = 0.0
    for i in range(nv):
        z_max = max(z_max, ws.lcp_z[i])
        q_neg = max(q_neg, -qx[i])
    if eps * z_max > SOFT_ANSWER_TOL * max(q_neg, floor):
        return LCP_INACCURATE, 0.0
    return LCP_SOLVED, eps


@kernel(inline="never")
def solve_mixed_lcp(m, ws, rows, start, count, max_pivots, floor):
    """Impulses ws.lam[r] of the rows r in rows[start:start + count] (an island's, in their
    order: a tangent row follows its normal row; ws.lcp_A from assemble_dense, ws.row_b) that meet
    the complementarity rules above; ws.row_slip[r] of a tangent row its slip speed gamma.
    floor: a lower bound of the answers' check scale (lcp.lemke; 0: this problem's own).
    Returns (status lcp.LCP_*, pivots, this problem's own scale: its largest approach -q in
    scaled units); impulses are left at 0 unless solved."""
    nb = 0
    nx = 0
    for k in range(count):
        r = rows[start + k]
        ws.lam[r] = 0.0
        if is_joint_row(ws.row_kind[r]):
            ws.lcp_rows[nb] = r
            nb += 1
    for k in range(count):
        r = rows[start + k]
        if not is_joint_row(ws.row_kind[r]):
            ws.lcp_rows[nb + nx] = r
            nx += 1
    # joints: B = A_bb factored; G = A_bb^-1 [A_bx, b_b]
    B = ws.lcp_B
    G = ws.lcp_G
    if nb > 0:
        ws.joint_pivot[0] = min(ws.joint_pivot[0], _factor_joints(ws.lcp_A, ws.row_local, B, nb,
                                                               ws.lcp_rows, G))
    for j in range(nx + 1):
        for i in range(nb):
            ri = ws.lcp_rows[i]
            G[i, j] = dense_entry(ws, ri, ws.lcp_rows[nb + j]) if j < nx else ws.row_b[ri]
        _solve_joints(B, nb, G, j)
    # Schur complement S = A_xx - A_xb G_x, s = b_x - A_xb G_b (S in lcp_S)
    S = ws.lcp_S
    for i in range(nx):
        ri = ws.lcp_rows[nb + i]
        for j in range(nx + 1):
            acc = dense_entry(ws, ri, ws.lcp_rows[nb + j]) if j < nx else ws.row_b[ri]
            for k in range(nb):
                acc -= dense_entry(ws, ri, ws.lcp_rows[k]) * G[k, j]
            S[i, j] = acc
    # variables: a unilateral row one (x >= 0), a tangent row three (beta+, beta-, gamma)
    nv = 0
    for i in range(nx):
        r = ws.lcp_rows[nb + i]
        ws.lcp_var[r] = nv
        ws.lcp_pos[i] = nv
        nv += 3 if is_boxed_row(ws.row_kind[r]) else 1
    Mx = ws.lcp_M
    if nv > Mx.shape[0]:            # beyond the workspace's storage: the step begins again
        ws.room[0] = 1              # with more (kernels/step.py, GUARD_ROOM)
        ws.room[3] = max(ws.room[3], nv)
        return LCP_RAY, 0, 0.0
    qx = ws.lcp_q
    d = ws.lcp_scale
    for i in range(nv):
        qx[i] = 0.0
        for j in range(nv):
            Mx[i, j] = 0.0
    # scaling: unit diagonal for x and beta (1 / sqrt(S_ii)), gamma by sqrt(S_tt) so that its
    # couplings to beta stay 1
    for i in range(nx):
        r = ws.lcp_rows[nb + i]
        p = ws.lcp_pos[i]
        sii = S[i, i]
        sc = 1.0 / math.sqrt(sii) if sii > 0.0 else 1.0
        d[p] = sc
        if is_boxed_row(ws.row_kind[r]):
            d[p + 1] = sc
            d[p + 2] = 1.0 / sc
    for i in range(nx):
        ri = ws.lcp_rows[nb + i]
        pi = ws.lcp_pos[i]
        ti = is_boxed_row(ws.row_kind[ri])
        for j in range(nx):
            rj = ws.lcp_rows[nb + j]
            pj = ws.lcp_pos[j]
            sij = S[i, j]
            if is_boxed_row(ws.row_kind[rj]):
                Mx[pi, pj] = sij
                Mx[pi, pj + 1] = -sij
                if ti:
                    Mx[pi + 1, pj] = -sij
                    Mx[pi + 1, pj + 1] = sij
            else:
                Mx[pi, pj] = sij
                if ti:
                    Mx[pi + 1, pj] = -sij
        qx[pi] = S[i, nx]
        if ti:
            qx[pi + 1] = -S[i, nx]
            Mx[pi, pi + 2] = 1.0
            Mx[pi + 1, pi + 2] = 1.0
            # gamma's row: mu x_n - beta+ - beta-, x_n the normal row just before this one;
            # a joint's friction: F h - beta+ - beta- (a constant bound)
            o = ws.row_owner[ri]
            if is_joint_friction_row(ws.row_kind[ri]):
                qx[pi + 2] = ws.friction_bound[o]
            else:
                Mx[pi + 2, ws.lcp_var[ri - 1]] = m.contact_mu[o]
            Mx[pi + 2, pi] = -1.0
            Mx[pi + 2, pi + 1] = -1.0
    for i in range(nv):
        qx[i] *= d[i]
        for j in range(nv):
            Mx[i, j] *= d[i] * d[j]
    # Lemke's path can end on a ray of a solvable problem when M is only copositive (friction
    # makes it so), or rounding can send it astray in a degenerate problem (the answer check
    # in lcp.py catches that). M + eps I is strictly copositive, for which the path always
    # ends at a solution; its answer misses the rules of M by eps z (scaled units: a relative
    # error of eps): normal rows approach at eps z, each impulse still does no positive
    # work, but the cone row allows a sliding contact eps gamma of friction too much. Each
    # eps in turn, on the covering vector's path, then on a second covering vector's; then
    # the answer's basis is re-solved for M itself (polish), which removes the eps z.
    status = LCP_RAY
    pivots = 0
    eps = 0.0
    own_scale = 0.0
    for i in range(nv):
        own_scale = max(own_scale, -qx[i])
    for cover in range(2):
        first = LARGE_FIRST_ATTEMPT if nv >= REVISED_SIZE and nv > nx else 0
        for attempt in range(first, len(REGULARISATION) + 1):
            target = 0.0 if attempt == 0 else REGULARISATION[attempt - 1]
            for i in range(nv):
                Mx[i, i] += target - eps
            eps = target
            if nv >= REVISED_SIZE:      # a large problem: the path in revised form
                status, more = lemke_large(Mx, qx, nv, ws.lcp_T, ws.lcp_basis, ws.lcp_z,
                                           ws.lcp_nz, max_pivots, cover, floor)
            else:
                status, more = lemke(Mx, qx, nv, ws.lcp_T, ws.lcp_basis, ws.lcp_z, max_pivots,
                                     cover, floor)
            pivots += more
            if status == LCP_SOLVED:
                break
        if status == LCP_SOLVED and eps > 0.0:
            for i in range(nv):
                Mx[i, i] -= eps
            status, eps = _exact_or_soft(Mx, qx, nv, ws, eps, floor)
        if status == LCP_SOLVED:
            break
        # this covering vector's paths ended on rays, or at a nearby problem's answer too
        # far from M's: the second covering vector's path is another path through the same
        # problem (a pile on hills whose first path went astray at a near tie of two ratios,
        # 1.7e-6 apart, solved on the second at 1e-8, kept as a soft answer)
        for i in range(nv):
            Mx[i, i] -= eps
        eps = 0.0
    if status != LCP_SOLVED:
        return status, pivots, own_scale
    ws.lcp_eps[0] = max(ws.lcp_eps[0], eps)
    for i in range(nv):
        ws.lcp_z[i] *= d[i]
    for i in range(nx):
        r = ws.lcp_rows[nb + i]
        p = ws.lcp_pos[i]
        if is_boxed_row(ws.row_kind[r]):
            ws.row_slip[r] = ws.lcp_z[p + 2]
            ws.lam[r] = ws.lcp_z[p] - ws.lcp_z[p + 1]
            # rounding (or a regularised answer polish could not mend) may leave |x_t| a
            # hair above mu x_n (F h): clip to the cone (the clip changes other rows'
            # velocities by as much; the audit judges the result)
            bound = friction_bound_of(m, ws, r)
            if ws.lam[r] > bound:
                ws.lam[r] = bound
            elif ws.lam[r] < -bound:
                ws.lam[r] = -bound
        else:
            ws.lam[r] = ws.lcp_z[p]
    # joint impulses: x_b = -(G_b + G_x x_x)
    for k in range(nb):
        acc = G[k, nx]
        for j in range(nx):
            acc += G[k, j] * ws.lam[ws.lcp_rows[nb + j]]
        ws.lam[ws.lcp_rows[k]] = -acc
    return status, pivots, own_scale


@kernel
def is_sliding_solution(m, s, ws, r):
    """After solve_mixed_lcp: does the contact of tangent row r slide (slip speed gamma > 0
    and its friction at the cone's edge; a gamma of rounding size on a contact well inside
    its cone is not a slip; of a shape pair, rounding of both bodies' motion)? The edge is
    judged at the rounding of the contact's own impulse, lambda_n + |lambda_t|: with a tiny
    mu the friction mu lambda_n is far below it, and its last digits are rounding of the
    normal impulse's size (mu 1e-4: a contact sliding at 2 m/s once read as pinned, and
    the position correction then held it, throwing its body backwards)."""
    o = ws.row_owner[r]
    edge = m.contact_mu[o] * ws.lam[r - 1]
    scale = abs(ws.row_b[r]) + abs(ws.row_b[r - 1])
    if m.contact_kind[o] == CONTACT_PAIR:
        scale += pair_motion_scale(s, ws, o, ws.v_pred)
    slip_floor = CONE_EDGE_TOL * scale
    size = abs(ws.lam[r - 1]) + abs(ws.lam[r])
    return ws.row_slip[r] > slip_floor and abs(ws.lam[r]) >= edge - CONE_EDGE_TOL * size
