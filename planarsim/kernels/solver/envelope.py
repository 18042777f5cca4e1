"""The envelope elimination: L U (L D L^T where symmetric) of J W F^T inside its rows' envelope.

Rows touch at most two bodies, so for rows ordered along a chain or tree the matrix is banded:
row r's entries lie between the first row sharing a body with it (row_first[r]) and its
diagonal, and elimination inside that envelope fills nothing outside it and costs O(n) for a
chain. The envelope is stored row by row in one array (ws.A_low: the lower triangle and the
diagonal; ws.A_up: the upper triangle, column by column, in the same places), sized by the
rows' envelope, never by rows squared. A row whose pivot falls below tol times its own
diagonal depends on earlier rows (a closed loop, a box on two corners): it is dropped
(impulse 0), marked by a zero pivot. Large systems of piles and walls are factored sparse
instead (sparse_factor.py); matrix.py chooses.
"""
from ...compile import kernel


@kernel
def compute_envelope(ws, n, n_body):
    """row_first[r]: the first row sharing a body with row r; row_reach[k]: the last row whose
    envelope reaches column k; row_start[r]: where row r's envelope (columns row_first[r]..r)
    begins in ws.A_low / ws.A_up. Rows touch at most two bodies, so for rows ordered along a
    chain or tree the envelope is narrow and elimination inside it costs O(n), not O(n^3).
    Returns False (ws.room set, with the entries needed) if the envelope does not fit the
    workspace's storage: the step begins again with more (kernels/step.py, GUARD_ROOM)."""
    for b in range(n_body):
        ws.body_first_row[b] = -1
    ws.row_start[0] = 0
    for r in range(n):
        f = r
        for e in range(2):
            b = ws.row_body[r, e]
            if b < 0:
                continue
            if ws.body_first_row[b] < 0:
                ws.body_first_row[b] = r
            elif ws.body_first_row[b] < f:
                f = ws.body_first_row[b]
        ws.row_first[r] = f
        ws.row_reach[r] = r
        ws.row_start[r + 1] = ws.row_start[r] + r - f + 1
    for i in range(n):
        for k in range(ws.row_first[i], i):
            ws.row_reach[k] = i
    if ws.row_start[n] > ws.A_low.shape[0]:
        ws.room[0] = 1
        ws.room[2] = max(ws.room[2], ws.row_start[n])
        return False
    return True


@kernel(inline="always")
def at(start, first, i, j):
    """Where entry (i, j), first[i] <= j <= i, of a lower envelope lies (and entry (j, i) of
    the upper one)."""
    return start[i] + j - first[i]


@kernel
def _entry(JL, JR, row_body, inv_mass, inv_inertia, i, j):
    """(JL W JR^T)[i, j] over the bodies rows i and j share (each row touches at most two)."""
    acc = 0.0
    bj0 = row_body[j, 0]
    bj1 = row_body[j, 1]
    for ei in range(2):
        bi = row_body[i, ei]
        if bi < 0:
            continue
        im = inv_mass[bi]
        ii = inv_inertia[bi]
        if bj0 == bi:
            acc += (JL[i, ei, 0] * JR[j, 0, 0] + JL[i, ei, 1] * JR[j, 0, 1]) * im
            acc += JL[i, ei, 2] * JR[j, 0, 2] * ii
        if bj1 == bi:
            acc += (JL[i, ei, 0] * JR[j, 1, 0] + JL[i, ei, 1] * JR[j, 1, 1]) * im
            acc += JL[i, ei, 2] * JR[j, 1, 2] * ii
    return acc


@kernel
def assemble_rows(JL, JR, row_body, inv_mass, inv_inertia, first, start, low, up, n,
                  symmetric):
    """A = JL W JR^T inside the envelope (entries outside it are structurally zero): its
    lower triangle and diagonal into `low`, the upper triangle into `up` (see
    compute_envelope); symmetric (JL = JR): the lower one only (all that factor_symmetric
    reads). Takes the arrays it needs as arguments, so the loops index them directly."""
    for i in range(n):
        for j in range(first[i], i + 1):
            p = at(start, first, i, j)
            low[p] = _entry(JL, JR, row_body, inv_mass, inv_inertia, i, j)
            if j != i and not symmetric:
                up[p] = _entry(JL, JR, row_body, inv_mass, inv_inertia, j, i)


@kernel
def assemble(m, ws, JL, JR, n, symmetric):
    """ws.A_low / A_up = JL W JR^T inside the envelope (symmetric: JL = JR, lower triangle
    only)."""
    assemble_rows(JL, JR, ws.row_body, m.body_inv_mass, m.body_inv_inertia, ws.row_first,
                  ws.row_start, ws.A_low, ws.A_up, n, symmetric)


@kernel
def diagonal_scale(low, start, first, n, scale):
    """scale[k] = |A[k, k]| before elimination: the yardstick of the pivot test."""
    for k in range(n):
        scale[k] = abs(low[at(start, first, k, k)])


# A diagonal below this is a row of no effect (its Jacobian entries below 1e-145): its pivot's
# reciprocal would overflow (1 / 5e-309 is inf), so it is dropped as a dependent row is.
NULL_DIAGONAL = 1e-290


@kernel
def is_dependent(piv, scale, tol):
    """A row whose pivot fell below tol times its own diagonal depends on earlier rows; a row
    whose diagonal is below NULL_DIAGONAL acts on nothing."""
    return abs(piv) <= tol * scale or scale <= NULL_DIAGONAL


@kernel
def rows_below(first, reach, k, rows):
    """rows[:count] = the rows below column k whose envelope reaches it (first[i] <= k),
    ascending; returns count. Listed once per column, the elimination's double loop over them
    tests nothing (in a tree the rows up to reach[k] include whole branches that do not)."""
    count = 0
    for i in range(k + 1, reach[k] + 1):
        if first[i] <= k:
            rows[count] = i
            count += 1
    return count


@kernel
def factor(low, up, start, first, reach, n, tol, scale, rows):
    """LU factorisation in place, inside the envelope given by first / reach / start (see
    compute_envelope): U on and above the diagonal (its diagonal in `low`, the rest in `up`),
    the multipliers L below it (in `low`). `scale` (n,) and `rows` (n,) int are scratch.

    A row whose pivot falls below tol times its own diagonal depends on earlier rows (a
    closed loop, a box on two corners): it is dropped (impulse 0), marked by a zero pivot.
    Returns #dropped.
    """
    dropped = 0
    diagonal_scale(low, start, first, n, scale)
    for k in range(n):
        dk = at(start, first, k, k)
        piv = low[dk]
        count = rows_below(first, reach, k, rows)
        if is_dependent(piv, scale[k], tol):
            dropped += 1
            for a in range(count):
                p = at(start, first, rows[a], k)
                up[p] = 0.0
                low[p] = 0.0
            low[dk] = 0.0
            continue
        inv = 1.0 / piv
        for a in range(count):
            i = rows[a]
            pik = at(start, first, i, k)
            fct = low[pik] * inv
            low[pik] = fct
            if fct == 0.0:
                continue
            for b in range(count):
                j = rows[b]
                ukj = up[at(start, first, j, k)]
                if j <= i:
                    low[at(start, first, i, j)] -= fct * ukj
                else:
                    up[at(start, first, j, i)] -= fct * ukj
    return dropped


@kernel
def forward_substitute(low, start, first, reach, rhs, n):
    """rhs <- L^-1 rhs with the unit lower factor below the diagonal (both factorisations
    store it in `low`); dropped rows (zero pivot) get 0."""
    for k in range(n):
        if low[at(start, first, k, k)] == 0.0:
            rhs[k] = 0.0
            continue
        rk = rhs[k]
        for i in range(k + 1, reach[k] + 1):
            if first[i] <= k:
                rhs[i] -= low[at(start, first, i, k)] * rk


@kernel
def substitute(low, up, start, first, reach, rhs, x, n):
    """x = A^-1 rhs from the factors of `factor` (rhs destroyed); dropped rows get x = 0."""
    forward_substitute(low, start, first, reach, rhs, n)
    for k in range(n - 1, -1, -1):
        d = low[at(start, first, k, k)]
        if d == 0.0:
            x[k] = 0.0
            continue
        acc = rhs[k]
        for j in range(k + 1, reach[k] + 1):
            if first[j] <= k:
                acc -= up[at(start, first, j, k)] * x[j]
        x[k] = acc / d


@kernel
def factor_symmetric(low, start, first, reach, n, tol, scale, rows):
    """As `factor` for a symmetric A, in half the work: A = L D L^T with the multipliers L
    below the diagonal and D on it (all in `low`); the upper triangle is neither read nor
    written. The same pivot test drops dependent rows (zero pivot and multipliers).
    Returns #dropped."""
    dropped = 0
    diagonal_scale(low, start, first, n, scale)
    for k in range(n):
        dk = at(start, first, k, k)
        piv = low[dk]
        count = rows_below(first, reach, k, rows)
        if is_dependent(piv, scale[k], tol):
            dropped += 1
            for a in range(count):
                low[at(start, first, rows[a], k)] = 0.0
            low[dk] = 0.0
            continue
        inv = 1.0 / piv
        # rows from the last up: the update of row i reads column k of the rows j <= i, which
        # must still hold A[j, k] (not yet divided by the pivot)
        for a in range(count - 1, -1, -1):
            i = rows[a]
            pik = at(start, first, i, k)
            a_ik = low[pik]
            if a_ik == 0.0:
                continue
            fct = a_ik * inv
            base = start[i] - first[i]
            for b in range(a + 1):
                j = rows[b]
                low[base + j] -= fct * low[at(start, first, j, k)]
            low[pik] = fct
    return dropped


@kernel
def substitute_symmetric(low, start, first, reach, rhs, x, n):
    """x = A^-1 rhs from the factors of `factor_symmetric` (rhs destroyed); dropped rows get
    x = 0. Back substitution uses U = D L^T: x_k = y_k / d_k - sum_j L_jk x_j."""
    forward_substitute(low, start, first, reach, rhs, n)
    for k in range(n - 1, -1, -1):
        d = low[at(start, first, k, k)]
        if d == 0.0:
            x[k] = 0.0
            continue
        acc = rhs[k] / d
        for j in range(k + 1, reach[k] + 1):
            if first[j] <= k:
                acc -= low[at(start, first, j, k)] * x[j]
        x[k] = acc
