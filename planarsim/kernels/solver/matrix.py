"""The step's linear algebra on J W F^T, one interface over three factorisations: the
envelope elimination (envelope.py; chains, trees) below SPARSE_MIN_ROWS rows, the same
elimination in a dense square (dense.py; a few rows that fill most of their envelope: a
walker's, a cheetah's), the sparse one in nested-dissection order (sparse_factor.py; piles,
walls, worlds of many bodies) from SPARSE_MIN_ROWS rows on. All are exact elimination without
pivoting that drops dependent rows by the same test (the dense one gives the envelope's
factors to the last bit); ws.factor_kind[0] says which one holds the current rows (arrange).

Order of use: arrange (the rows' structure), assemble, then add_to_diagonal /
scale_diagonal, factor_ws, diagonal_and_pivot, substitute_ws (as often as needed).
"""
from ...compile import kernel
from .dense import (assemble_dense, factor_dense, substitute_dense,
                    substitute_dense_pair, substitute_dense_symmetric)
from .envelope import (assemble_rows, compute_envelope, factor, factor_symmetric, substitute,
                       substitute_symmetric)
from .sparse_factor import (SPARSE_MIN_ROWS, analyse, assemble_sparse, factor_sparse,
                            order_rows, substitute_sparse)

ENVELOPE = 0
SPARSE = 1
DENSE = 2
# the dense square is taken where the rows' envelope fills at least this share of the lower
# triangle (a walker's rows: 0.58; a chain's of 10 links: 0.3), or the rows are at most
# DENSE_ALWAYS: there the square's vectorised loops beat the envelope's indexed ones
DENSE_FILL = 0.4
DENSE_ALWAYS = 12


@kernel
def arrange(q, ws, n, n_body, dependent, exclude):
    """The structure of rows 0..n-1 (bodies at q): their envelope, or their sparse order and
    elimination tree; there, if `exclude`, without the contact rows the last step dropped as
    dependent (dependent: State.contact_dependent; sparse_factor.order_rows). Returns False
    (ws.room set) if it does not fit the workspace's storage: the step begins again with
    more (kernels/step.py, GUARD_ROOM). Factors kept for reuse (solve.same_rows_factored)
    are forgotten."""
    ws.sp_kept[0] = 0
    ws.sp_factored[0] = n
    if n >= SPARSE_MIN_ROWS:
        ws.factor_kind[0] = SPARSE
        order_rows(q, ws, n, dependent, exclude)
        return analyse(ws, n, n_body)
    ws.factor_kind[0] = ENVELOPE
    if not compute_envelope(ws, n, n_body):
        return False
    if n <= ws.A_dense.shape[0] and (n <= DENSE_ALWAYS or ws.row_start[n]
                                     >= DENSE_FILL * (n * (n + 1) // 2)):
        ws.factor_kind[0] = DENSE
    return True


@kernel(inline="always")
def _diag(ws, r):
    """Where row r's diagonal entry lies (envelope: in ws.A_low; sparse: in ws.sp_diag)."""
    if ws.factor_kind[0] == SPARSE:
        return ws.sp_iperm[r]
    return ws.row_start[r] + r - ws.row_first[r]


@kernel
def assemble(m, ws, JL, JR, n, symmetric):
    """A = JL W JR^T on the rows' structure (symmetric: JL = JR, the lower half only)."""
    if ws.factor_kind[0] == SPARSE:
        assemble_sparse(JL, JR, ws.row_body, m.body_inv_mass, m.body_inv_inertia, ws, n,
                        symmetric)
    elif ws.factor_kind[0] == DENSE:
        assemble_dense(JL, JR, ws.row_body, m.body_inv_mass, m.body_inv_inertia, ws.row_first,
                       ws.A_dense, n, symmetric)
    else:
        assemble_rows(JL, JR, ws.row_body, m.body_inv_mass, m.body_inv_inertia, ws.row_first,
                      ws.row_start, ws.A_low, ws.A_up, n, symmetric)


@kernel
def add_to_diagonal(ws, r, value):
    """A[r, r] += value (before factor_ws)."""
    if ws.factor_kind[0] == SPARSE:
        ws.sp_diag[_diag(ws, r)] += value
    elif ws.factor_kind[0] == DENSE:
        ws.A_dense[r, r] += value
    else:
        ws.A_low[_diag(ws, r)] += value


@kernel
def scale_diagonal(ws, r, factor):
    """A[r, r] *= factor (before factor_ws)."""
    if ws.factor_kind[0] == SPARSE:
        ws.sp_diag[_diag(ws, r)] *= factor
    elif ws.factor_kind[0] == DENSE:
        ws.A_dense[r, r] *= factor
    else:
        ws.A_low[_diag(ws, r)] *= factor


@kernel
def diagonal_and_pivot(ws, r):
    """After factor_ws: (row r's diagonal before elimination, its pivot; 0 if dropped)."""
    if ws.factor_kind[0] == SPARSE:
        return ws.lam[r], ws.sp_pivot[ws.sp_iperm[r]]
    if ws.factor_kind[0] == DENSE:
        return ws.lam[r], ws.A_dense[r, r]
    return ws.lam[r], ws.A_low[_diag(ws, r)]


@kernel(inline="always")
def factor_ws(ws, n, tol, symmetric):
    """Factor the assembled matrix (ws.lam holds each row's diagonal before elimination
    afterwards); returns #dropped rows. Factors kept for reuse (solve.same_rows_factored) are
    replaced, so forgotten."""
    ws.sp_kept[0] = 0
    if ws.factor_kind[0] == SPARSE:
        return factor_sparse(ws, n, tol, symmetric, ws.lam)
    if ws.factor_kind[0] == DENSE:
        return factor_dense(ws.A_dense, n, tol, ws.lam, ws.sp_y, symmetric)
    if symmetric:
        return factor_symmetric(ws.A_low, ws.row_start, ws.row_first, ws.row_reach, n, tol,
                                ws.lam, ws.row_list)
    return factor(ws.A_low, ws.A_up, ws.row_start, ws.row_first, ws.row_reach, n, tol, ws.lam,
                  ws.row_list)


@kernel(inline="always")
def substitute_ws(ws, rhs, x, n, symmetric):
    """x = A^-1 rhs from the factors of factor_ws (rhs destroyed); dropped rows get 0."""
    if ws.factor_kind[0] == SPARSE:
        substitute_sparse(ws, rhs, x, n, symmetric)
    elif ws.factor_kind[0] == DENSE:
        if symmetric:
            substitute_dense_symmetric(ws.A_dense, rhs, x, n)
        else:
            substitute_dense(ws.A_dense, rhs, x, n)
    elif symmetric:
        substitute_symmetric(ws.A_low, ws.row_start, ws.row_first, ws.row_reach, rhs, x, n)
    else:
        substitute(ws.A_low, ws.A_up, ws.row_start, ws.row_first, ws.row_reach, rhs, x, n)


@kernel(inline="always")
def solves_pairs(ws):
    """The factors are the dense square's: substitute_pair_ws may be called (ws.sp_x and
    ws.sp_y, the sparse factorisation's scratch, are free for its second answer)."""
    return ws.factor_kind[0] == DENSE


@kernel(inline="always")
def substitute_pair_ws(ws, rhs, x, rhs2, x2, n):
    """Where solves_pairs: x = A^-1 rhs and x2 = A^-1 rhs2 from the factors of factor_ws (not
    symmetric; both right-hand sides destroyed), the answers of two substitute_ws calls bit
    for bit, in one pass."""
    substitute_dense_pair(ws.A_dense, rhs, x, rhs2, x2, n)


@kernel(inline="always")
def factor_solve(ws, rhs, x, n, tol):
    """Factor the assembled (not symmetric) matrix and solve A x = rhs; returns #dropped."""
    dropped = factor_ws(ws, n, tol, False)
    substitute_ws(ws, rhs, x, n, False)
    return dropped
