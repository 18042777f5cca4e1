"""Stage 4: position-level impulses, one linear solve.

Impulses lambda make every active row hold at the END of the step (symplectic Euler inside):
    c + h J (v* + W F^T lambda) = 0   =>   (J W F^T) lambda = -(c / h + J v*)
with W = M^-1 (diagonal: 1/m, 1/m, 1/I per body) and F = J except for sliding contacts.
Joint rows (pins, rods) use their exact error at the predicted end of the step instead,
c(q + h v*) = c + h J v* + O(h^2 w^2 r): the drift of rotating anchors is then removed by the
impulses too, and the position correction (integrate.py) starts from a far smaller residual.
A ground contact held through the step (touching at its start) adds the second-order part of
its gap over the step at the start's velocity, c(q + h v0) - c - h J v0 (held_contact_curve): it
follows a curved ground, or a sole's rolling, to second order as a pin follows its anchor.
The matrix is assembled and eliminated only where it has entries (matrix.py): inside its
envelope for chains and trees (rows touch at most two bodies, so a chain's matrix is banded:
the cost grows linearly with the number of links), in a dense square for a walker's few
rows that fill most of their envelope (the same factors, vectorised loops), in a
nested-dissection order for the many rows of piles and walls.
Closed loops (Ranger in double stance, a box on two corners) make J W F^T singular: Gaussian
elimination drops a row whose pivot falls below pivot_tol times its own diagonal, i.e. a row
that is a combination of earlier ones; its impulse is zero and the rows it depends on carry
the load. This is the guess solve: which rows carry the load is arbitrary here, so its answer
is checked (modes.rule_breaks) and one that pulls or misses a row goes to the
complementarity solve (complementarity.py), which needs no threshold.
A joint's soft row (armature and implicit spring-damper, soft.py) is an equality with a
compliance gamma > 0: it adds gamma to its diagonal, (J W F^T + diag(gamma)) lambda = -b.
Without sliding contacts F = J and the matrix is symmetric: it is assembled in its lower
triangle only and factored as L D L^T (half the work of LU, the same pivot test).
"""
from ...compile import kernel
from .matrix import (SPARSE, add_to_diagonal, arrange, assemble, diagonal_and_pivot,
                     factor_ws, scale_diagonal, substitute_ws)
from ..info import INFO_KEPT_FACTORS
from ..codes import MODE_FREE
from ..constraints.rows import (HELD_GAP, dependent_bit, held_contact, is_joint_row,
                                is_normal_row, is_soft_row, is_tangent_row)
from ..constraints.soft import soft_compliance, soft_row_b
from .warm_start import start_impulses


@kernel
def add_impulses(F, row_body, inv_mass, inv_inertia, lam, n, vel, scale):
    """vel += scale * W F^T lam (rows 0..n-1)."""
    for r in range(n):
        l = lam[r] * scale
        if l == 0.0:
            continue
        for e in range(2):
            b = row_body[r, e]
            if b < 0:
                continue
            vel[b, 0] += inv_mass[b] * F[r, e, 0] * l
            vel[b, 1] += inv_mass[b] * F[r, e, 1] * l
            vel[b, 2] += inv_inertia[b] * F[r, e, 2] * l


@kernel
def apply_impulses(m, ws, F, lam, n, vel, scale):
    """vel += scale * W F^T lam (rows 0..n-1)."""
    add_impulses(F, ws.row_body, m.body_inv_mass, m.body_inv_inertia, lam, n, vel, scale)


@kernel
def row_dot(ws, r, J, vel):
    """J_r . vel."""
    acc = 0.0
    for e in range(2):
        b = ws.row_body[r, e]
        if b < 0:
            continue
        acc += J[r, e, 0] * vel[b, 0] + J[r, e, 1] * vel[b, 1] + J[r, e, 2] * vel[b, 2]
    return acc


@kernel
def fill_row_b(m, ws, h, n):
    """ws.row_b: each row's end-of-step residual without impulses [m/s], w = A lam + b."""
    # the joints' target is linearized at v_lin: v* but where soft rows or a second
    # linearization (step.relinearize) moved it
    moved = False
    for i in range(ws.v_lin.shape[0]):
        for k in range(3):
            moved = moved or ws.v_lin[i, k] != ws.v_pred[i, k]
    for r in range(n):
        if is_soft_row(ws.row_kind[r]):
            # armature and implicit spring-damper (soft.py); its compliance is set here
            ws.row_b[r] = soft_row_b(ws, r, h, row_dot(ws, r, ws.row_J, ws.v_pred))
            continue
        if is_joint_row(ws.row_kind[r]):
            # a joint's error at the end of the step without impulses, c(q + h v*): c + h J v*
            # plus the second-order drift of its rotating anchors, which the position
            # correction would otherwise remove (one Newton iteration fewer). Where that
            # target added energy (ws.first_order, kernels/step.py): J v = 0, a projection,
            # which cannot add energy; the position correction, whose work is bounded,
            # closes the joints' errors (c / h as velocity would be energy from nowhere
            # after a time-of-impact split moved the bodies off their joints)
            if ws.first_order[0] == 0:
                # linearized at q + h v_lin: c(q_pred) + h J (v_new - v_lin) = 0
                ws.row_b[r] = ws.row_c_pred[r] / h
                if moved:
                    ws.row_b[r] += (row_dot(ws, r, ws.row_J, ws.v_pred)
                                    - row_dot(ws, r, ws.row_J, ws.v_lin))
            else:
                ws.row_b[r] = row_dot(ws, r, ws.row_J, ws.v_pred)
            continue
        c = ws.row_c[r]
        if c < 0.0 and not is_tangent_row(ws.row_kind[r]):
            # a unilateral row that starts violated only stops approaching; the position
            # correction removes the overlap without turning it into velocity (energy)
            c = 0.0
        bounce = 0.0
        if is_normal_row(ws.row_kind[r]):
            bounce = ws.contact_bounce[ws.row_owner[r]]
            if bounce > 0.0:
                # an impact with restitution: the rebound e v_approach, from the surface (the
                # gap left at the step's start, at most h v_approach, is not waited for)
                c = 0.0
        ws.row_b[r] = c / h + row_dot(ws, r, ws.row_J, ws.v_pred) - bounce
        if is_normal_row(ws.row_kind[r]):
            curve = 0.0
            if bounce == 0.0 and ws.first_order[0] == 0:
                curve = held_contact_curve(m, ws, r, h)
                if curve != 0.0:
                    ws.row_b[r] += curve
            # (the audit's work rule allows this target's work, as it allows a rebound's)
            ws.contact_curve[ws.row_owner[r]] = -curve


@kernel(inline="always")
def held_contact_curve(m, ws, r, h):
    """The second-order part [m/s] of contact normal row r's target: s / h, s the second-order
    part of its gap over the step at the start's velocity v0 (rows.predict_contact_parts:
    c(q + h v0) - c - h J v0, computed so that it is exact where the motion is linear); 0
    unless the contact is held (rows.held_contact, and one free at the start not
    approaching its surface). With it a held contact keeps to its surface to second order,
    as a pin keeps to its anchor: the position correction, which moves a contact's positions
    only, then has little to remove, where the first-order target left it the surface's
    curvature times the step's motion squared, and the energy that move took (a rolling sole
    lost 5.5 % of its swing in 30 periods at dt 1e-3, a disk rolling over hills 0.41 % of its
    kinetic energy in 40 s; a point sliding over a crest hopped off it). At v0, not at the
    prediction q + h v_lin the pins take: a body resting on a hill would aim at the gap of a
    fall of h^2 g it does not take, whose second-order part on the curved ground (about
    1e-13 m a step) the correction then removed; at a loop's dead point (a chain of 16 boxes
    on hills) that took moves of 1e-7 m against gravity."""
    o = ws.row_owner[r]
    if not held_contact(m, ws, o):
        return 0.0
    approach = -h * row_dot(ws, r, ws.row_J, ws.prev.v)
    if ws.prev.contact_mode[o] == MODE_FREE and approach > HELD_GAP:
        return 0.0
    return ws.row_c_pred[r] / h


@kernel
def add_compliance(ws, n):
    """A[r, r] += gamma of each soft row (soft.py; after fill_row_b, which sets gamma)."""
    for r in range(n):
        if is_soft_row(ws.row_kind[r]):
            add_to_diagonal(ws, r, soft_compliance(ws, r))


@kernel
def joint_pivot_share(ws, n):
    """Right after factor / factor_symmetric (ws.lam holding each row's diagonal before
    elimination, matrix.diagonal_and_pivot): the smallest share of its diagonal that a
    joint row's pivot kept (0: one dropped as dependent; 1: no joint row)."""
    smallest = 1.0
    for k in range(n):
        kind = ws.row_kind[k]
        if is_joint_row(kind) and not is_soft_row(kind):
            scale, pivot = diagonal_and_pivot(ws, k)
            share = abs(pivot) / scale if scale > 0.0 else 0.0
            smallest = min(smallest, share)
    return smallest


# [-] the share of its own diagonal added to each row of a statically indeterminate set for
# the least-change solve (least_change_impulses), and how many rounds of refinement it takes
LEAST_CHANGE_SHARE = 1e-8
LEAST_CHANGE_ROUNDS = 4
# [-] how much more a friction row's change weighs in that least change than a normal's: the
# load goes to the normals, friction takes only what they cannot (a box beside another leans
# on it through friction only if nothing is below it)
TANGENT_WEIGHT = 1e4


@kernel
def residual_rhs(ws, n):
    """ws.rhs = -w, w = A lam + b the rows' residual at the impulses already applied to
    ws.v_new: b + J (v_new - v*)."""
    for r in range(n):
        ws.rhs[r] = -(ws.row_b[r] + row_dot(ws, r, ws.row_J, ws.v_new)
                      - row_dot(ws, r, ws.row_J, ws.v_pred))


@kernel
def least_change_impulses(m, s, ws, tol, n):
    """lambda of the rows (symmetric, some dependent: a box resting on two others) that
    changes the start impulses (the last step's, warm_start.py) least, in the norm of
    A's diagonal, and v_new = v* + W J^T lambda. Where the factorisation drops a dependent
    row, the others carry its load in whatever split the elimination order gives (a box on
    two boxes could hang from one of its four corners and press twice with another); the
    least change spreads it over the set as the rows' geometry does. Iterated Tikhonov: A +
    s D factored once (s = LEAST_CHANGE_SHARE, D = diag A: no pivot vanishes), then each round
    solves for the equations' residual at the current answer; its limit is the least change
    that meets the equations (the dependent directions are never entered), a friction row's
    change weighing TANGENT_WEIGHT times a normal's."""
    assemble(m, ws, ws.row_J, ws.row_F, n, True)
    add_compliance(ws, n)
    for r in range(n):
        share = LEAST_CHANGE_SHARE
        if is_tangent_row(ws.row_kind[r]):
            share *= TANGENT_WEIGHT
        scale_diagonal(ws, r, 1.0 + share)
    factor_ws(ws, n, tol, True)
    for i in range(ws.v_new.shape[0]):
        for k in range(3):
            ws.v_new[i, k] = ws.v_pred[i, k]
    if not start_impulses(s, ws, n, 1):
        for r in range(n):
            ws.lam_start[r] = 0.0
    apply_impulses(m, ws, ws.row_F, ws.lam_start, n, ws.v_new, 1.0)
    for _ in range(LEAST_CHANGE_ROUNDS):
        residual_rhs(ws, n)
        substitute_ws(ws, ws.rhs, ws.lam, n, True)
        apply_impulses(m, ws, ws.row_F, ws.lam, n, ws.v_new, 1.0)
        for r in range(n):
            ws.lam_start[r] += ws.lam[r]
    for r in range(n):
        ws.lam[r] = ws.lam_start[r]


# refinement rounds a solve on kept factors may take (refine_on_kept_factors), and how small
# each kept row's residual must end: REFINE_TOL (|b| + 1) [m/s], 1e-4 of the tolerance the
# rules check every equation to (modes.SOLVE_REL_TOL (|b| + 1))
REFINE_ROUNDS = 4
REFINE_TOL = 1e-13


@kernel
def same_rows_factored(ws, n):
    """True if the sparse storage holds the velocity solve's factors of exactly rows 0..n-1
    (kind, owner and bodies; ws.sp_kept_rows)."""
    if ws.sp_kept[0] == 0 or ws.sp_kept[1] != n or ws.factor_kind[0] != SPARSE:
        return False
    for r in range(n):
        if (ws.sp_kept_rows[r, 0] != ws.row_kind[r] or ws.sp_kept_rows[r, 1] != ws.row_owner[r]
                or ws.sp_kept_rows[r, 2] != ws.row_body[r, 0]
                or ws.sp_kept_rows[r, 3] != ws.row_body[r, 1]):
            return False
    return True


@kernel
def keep_factors(ws, n, dropped):
    """Mark the sparse factors just made of rows 0..n-1 as the velocity solve's, for reuse;
    not where a row is soft (its compliance is not in the matrix-free residual that
    refine_on_kept_factors measures)."""
    for r in range(n):
        if is_soft_row(ws.row_kind[r]):
            return
    for r in range(n):
        ws.sp_kept_rows[r, 0] = ws.row_kind[r]
        ws.sp_kept_rows[r, 1] = ws.row_owner[r]
        ws.sp_kept_rows[r, 2] = ws.row_body[r, 0]
        ws.sp_kept_rows[r, 3] = ws.row_body[r, 1]
    ws.sp_kept[0] = 1
    ws.sp_kept[1] = n
    ws.sp_kept[2] = dropped
    ws.sp_kept_pivot[0] = ws.joint_pivot[0]


@kernel
def refine_on_kept_factors(m, ws, n):
    """Iterative refinement of the answer in ws.lam, v_new against this step's matrix (its
    residual b + J (v_new - v*) is matrix-free) with the kept factors of last step's: up to
    REFINE_ROUNDS corrections. Returns True if every row the factors keep (not dropped as
    dependent) ends within REFINE_TOL (|b| + 1)."""
    big_b = 0.0
    for r in range(n):
        big_b = max(big_b, abs(ws.row_b[r]))
    tol = REFINE_TOL * (big_b + 1.0)
    for rounds in range(REFINE_ROUNDS + 1):
        residual_rhs(ws, n)
        worst = 0.0
        for r in range(n):
            if ws.sp_pivot[ws.sp_iperm[r]] != 0.0:
                worst = max(worst, abs(ws.rhs[r]))
        if worst <= tol:
            return True
        if rounds == REFINE_ROUNDS:
            break
        substitute_ws(ws, ws.rhs, ws.lam_start, n, True)
        apply_impulses(m, ws, ws.row_F, ws.lam_start, n, ws.v_new, 1.0)
        for r in range(n):
            ws.lam[r] += ws.lam_start[r]
    return False


@kernel(inline="always")
def solve_impulses(m, s, ws, h, tol, symmetric, keep):
    """lambda for the active rows and v_new = v* + W F^T lambda; returns #dropped rows.
    Where a row is dropped as dependent, the solve finds the change from the last step's
    impulses (ws.lam_start; warm_start.py), so the dropped row keeps its impulse.
    symmetric: F = J (no sliding contact), so J W F^T is symmetric (L D L^T on its lower half).
    keep (StepOptions.keep_factors): a pile at rest keeps its rows from step to step, and
    its matrix changes by rounding: where the sparse storage holds the factors of this
    step's very rows (same_rows_factored), they are reused and the answer refined against
    this step's matrix to rounding (refine_on_kept_factors; where it does not converge, the
    rows are factored afresh)."""
    n = ws.n_row[0]
    for i in range(ws.v_new.shape[0]):
        for k in range(3):
            ws.v_new[i, k] = ws.v_pred[i, k]
    if n == 0:
        return 0
    reuse = keep and symmetric and ws.least_change[0] == 0 and same_rows_factored(ws, n)
    if reuse:
        fill_row_b(m, ws, h, n)
        dropped = ws.sp_kept[2]
        ws.joint_pivot[0] = ws.sp_kept_pivot[0]
        warm = start_impulses(s, ws, n, dropped)
        if warm:
            for r in range(n):
                ws.lam[r] = ws.lam_start[r]
        else:
            for r in range(n):
                ws.lam[r] = 0.0
        apply_impulses(m, ws, ws.row_F, ws.lam, n, ws.v_new, 1.0)
        if refine_on_kept_factors(m, ws, n) and excluded_rows_hold(ws, n):
            ws.info[INFO_KEPT_FACTORS] += 1
            return dropped
        for i in range(ws.v_new.shape[0]):
            for k in range(3):
                ws.v_new[i, k] = ws.v_pred[i, k]
    # first without the rows the last step dropped as dependent (a pile at rest drops the
    # same ones step after step); where one of their equations fails, with every row
    for attempt in range(2):
        exclude = attempt == 0 and ws.least_change[0] == 0
        if not arrange(s.q, ws, n, ws.v_new.shape[0], s.contact_dependent, exclude):
            for r in range(n):
                ws.lam[r] = 0.0
            return 0                    # (no room: the step begins again with more)
        assemble(m, ws, ws.row_J, ws.row_F, n, symmetric)
        fill_row_b(m, ws, h, n)
        add_compliance(ws, n)
        dropped = factor_ws(ws, n, tol, symmetric)
        ws.joint_pivot[0] = joint_pivot_share(ws, n)
        if dropped > 0 and symmetric and ws.least_change[0] == 1:
            remember_dependent(s, ws, n)
            least_change_impulses(m, s, ws, tol, n)
            return dropped
        warm = start_impulses(s, ws, n, dropped)
        if warm:
            apply_impulses(m, ws, ws.row_F, ws.lam_start, n, ws.v_new, 1.0)
            residual_rhs(ws, n)
        else:
            for r in range(n):
                ws.rhs[r] = -ws.row_b[r]
        substitute_ws(ws, ws.rhs, ws.lam, n, symmetric)
        apply_impulses(m, ws, ws.row_F, ws.lam, n, ws.v_new, 1.0)
        if warm:
            for r in range(n):
                ws.lam[r] += ws.lam_start[r]
        if excluded_rows_hold(ws, n):
            break
        for i in range(ws.v_new.shape[0]):
            for k in range(3):
                ws.v_new[i, k] = ws.v_pred[i, k]
    if keep and symmetric and ws.factor_kind[0] == SPARSE:
        keep_factors(ws, n, dropped)
    remember_dependent(s, ws, n)
    return dropped


# how small the equation of each row left out of the factors as dependent must end:
# EXCLUDED_TOL (|b| + 1) [m/s], 1e-2 of the tolerance the rules check every equation to
# (modes.SOLVE_REL_TOL (|b| + 1)); at rest a 210-box and a 1,035-box pyramid's left-out
# rows end within 4.4e-13 and 1.1e-13 m/s (their targets' rounding: gaps of 1e-16 m over
# h = 1 ms), the rows factored within 1e-25
EXCLUDED_TOL = 1e-11


@kernel
def excluded_rows_hold(ws, n):
    """True if no row was left out of the sparse factors (sparse_factor.order_rows), or the
    answer in ws.v_new meets each left-out row's equation, b + J (v_new - v*) = 0, within
    EXCLUDED_TOL (|b| + 1): the rows it keeps hold the others, as where they were dropped
    as dependent."""
    if ws.factor_kind[0] != SPARSE or ws.sp_factored[0] >= n:
        return True
    big_b = 0.0
    for r in range(n):
        big_b = max(big_b, abs(ws.row_b[r]))
    limit = EXCLUDED_TOL * (big_b + 1.0)
    for k in range(ws.sp_factored[0], n):
        r = ws.sp_perm[k]
        w = (ws.row_b[r] + row_dot(ws, r, ws.row_J, ws.v_new)
             - row_dot(ws, r, ws.row_J, ws.v_pred))
        if abs(w) > limit:
            return False
    return True


@kernel
def remember_dependent(s, ws, n):
    """State.contact_dependent: after a sparse factorisation, for each contact row of the
    solve, its bit set if the row was dropped as dependent (or left out and held), cleared
    if not (the next step leaves the set ones out: sparse_factor.order_rows)."""
    if ws.factor_kind[0] != SPARSE:
        return
    for r in range(n):
        bit = dependent_bit(ws.row_kind[r])
        if bit == 0:
            continue
        o = ws.row_owner[r]
        if ws.sp_pivot[ws.sp_iperm[r]] == 0.0:
            s.contact_dependent[o] |= bit
        else:
            s.contact_dependent[o] &= ~bit
