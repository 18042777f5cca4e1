"""Stage 5: position-level impulses, one dense solve.

Impulses lambda make every active row hold at the END of the step (symplectic Euler inside):
    c + h J (v* + W F^T lambda) = 0   =>   (J W F^T) lambda = -(c / h + J v*)
with W = M^-1 (diagonal: 1/m, 1/m, 1/I per body) and F = J except for sliding contacts.
Closed loops (Ranger in double stance, a box on two corners) make J W F^T singular: Gaussian
elimination drops a row whose pivot falls below pivot_tol times its own diagonal, i.e. a row
that is a combination of earlier ones; its impulse is zero and the rows it depends on carry
the load. For consistent constraints this is exact, not a regularisation.
"""
from ._jit import jit
from .rows import ROW_CONTACT_T, ROW_LIMIT_LO


@jit
def assemble(m, ws, JL, JR, n):
    """ws.A[:n, :n] = JL W JR^T over shared bodies (rows touch at most two bodies)."""
    A = ws.A
    for i in range(n):
        for j in range(n):
            acc = 0.0
            for ei in range(2):
                bi = ws.row_body[i, ei]
                if bi < 0:
                    continue
                for ej in range(2):
                    if ws.row_body[j, ej] != bi:
                        continue
                    acc += (JL[i, ei, 0] * JR[j, ej, 0] + JL[i, ei, 1] * JR[j, ej, 1]) * m.body_inv_mass[bi]
                    acc += JL[i, ei, 2] * JR[j, ej, 2] * m.body_inv_inertia[bi]
            A[i, j] = acc


@jit
def factor_solve(A, rhs, x, n, tol):
    """Solve A x = rhs in place (A, rhs destroyed), dropping dependent rows; returns #dropped."""
    dropped = 0
    for k in range(n):
        diag = abs(A[k, k])
        # diagonal before elimination is kept in x[k] as the scale for the pivot test
        x[k] = diag
    for k in range(n):
        piv = A[k, k]
        if abs(piv) <= tol * x[k] or x[k] == 0.0:
            dropped += 1
            for j in range(k, n):
                A[k, j] = 0.0
            for i in range(k + 1, n):
                A[i, k] = 0.0
            A[k, k] = 1.0
            rhs[k] = 0.0
            continue
        inv = 1.0 / piv
        for i in range(k + 1, n):
            fct = A[i, k] * inv
            if fct == 0.0:
                continue
            for j in range(k + 1, n):
                A[i, j] -= fct * A[k, j]
            A[i, k] = 0.0
            rhs[i] -= fct * rhs[k]
    for k in range(n - 1, -1, -1):
        acc = rhs[k]
        for j in range(k + 1, n):
            acc -= A[k, j] * x[j]
        x[k] = acc / A[k, k]
    return dropped


@jit
def apply_impulses(m, ws, F, lam, n, vel, scale):
    """vel += scale * W F^T lam (rows 0..n-1)."""
    for r in range(n):
        l = lam[r] * scale
        if l == 0.0:
            continue
        for e in range(2):
            b = ws.row_body[r, e]
            if b < 0:
                continue
            vel[b, 0] += m.body_inv_mass[b] * F[r, e, 0] * l
            vel[b, 1] += m.body_inv_mass[b] * F[r, e, 1] * l
            vel[b, 2] += m.body_inv_inertia[b] * F[r, e, 2] * l


@jit
def row_dot(ws, r, J, vel):
    """J_r . vel."""
    acc = 0.0
    for e in range(2):
        b = ws.row_body[r, e]
        if b < 0:
            continue
        acc += J[r, e, 0] * vel[b, 0] + J[r, e, 1] * vel[b, 1] + J[r, e, 2] * vel[b, 2]
    return acc


@jit
def solve_impulses(m, ws, h, tol):
    """lambda for the active rows and v_new = v* + W F^T lambda; returns #dropped rows."""
    n = ws.n_row[0]
    for i in range(ws.v_new.shape[0]):
        for k in range(3):
            ws.v_new[i, k] = ws.v_pred[i, k]
    if n == 0:
        return 0
    assemble(m, ws, ws.row_J, ws.row_F, n)
    for r in range(n):
        c = ws.row_c[r]
        if c < 0.0 and ws.row_kind[r] >= ROW_LIMIT_LO and ws.row_kind[r] != ROW_CONTACT_T:
            # a unilateral row that starts violated only stops approaching; the position
            # correction removes the overlap without turning it into velocity (energy)
            c = 0.0
        ws.rhs[r] = -(c / h + row_dot(ws, r, ws.row_J, ws.v_pred))
    dropped = factor_solve(ws.A, ws.rhs, ws.lam, n, tol)
    apply_impulses(m, ws, ws.row_F, ws.lam, n, ws.v_new, 1.0)
    return dropped
