"""The elimination of small systems in a dense square: L U (L D L^T where symmetric) of
J W F^T in ws.A_dense, row by row.

A walker's or a cheetah's rows (18 to 30: its pins, rotors, limits and contacts) fill most of
their envelope (envelope.py): a foot's contact rows share bodies with the leg's pins, and the
envelope's bookkeeping (an index per entry, a list of rows per column) then costs more than
the arithmetic it saves. Here the same elimination runs over the whole square, whose rows are
contiguous: its inner loops are runs of one multiply and subtract the compiler vectorises.

Every entry sees the same operations in the same order as in envelope.py (the eliminations
run over columns in ascending order, each entry's updates in that order, the substitutions'
sums in the same order): entries outside the envelope are zero at the start and stay zero
(rows touch at most two bodies, so the envelope holds every fill), and subtracting a product
with a zero factor leaves an entry as it was. The factors and the solutions are therefore the
envelope's to the last bit where every entry and right-hand side is finite (a NaN or inf
right-hand side entry spreads to rows the envelope leaves alone, as 0 * inf is NaN: a step
with one ends at the non-finite guard either way); only the time differs (matrix.py chooses).
"""
from ...compile import kernel
from .envelope import is_dependent


@kernel
def assemble_dense(JL, JR, row_body, inv_mass, inv_inertia, first, A, n, symmetric):
    """A[:n, :n] = JL W JR^T: the entries inside the rows' envelope (first: envelope.py),
    zero elsewhere; symmetric (JL = JR): the lower triangle and diagonal only (all that
    factor_dense reads where symmetric)."""
    for i in range(n):
        # (outside the envelope: row i left of it and, for LU, column i above it)
        for j in range(first[i]):
            A[i, j] = 0.0
            if not symmetric:
                A[j, i] = 0.0
        # row i's bodies and numbers, read once for its whole row (and, LU, column): the
        # loads _entry would repeat for every entry, as A's stores may alias them
        b0 = row_body[i, 0]
        b1 = row_body[i, 1]
        m0 = inv_mass[b0] if b0 >= 0 else 0.0
        i0 = inv_inertia[b0] if b0 >= 0 else 0.0
        m1 = inv_mass[b1] if b1 >= 0 else 0.0
        i1 = inv_inertia[b1] if b1 >= 0 else 0.0
        l00, l01, l02 = JL[i, 0, 0], JL[i, 0, 1], JL[i, 0, 2]
        l10, l11, l12 = JL[i, 1, 0], JL[i, 1, 1], JL[i, 1, 2]
        r00, r01, r02 = JR[i, 0, 0], JR[i, 0, 1], JR[i, 0, 2]
        r10, r11, r12 = JR[i, 1, 0], JR[i, 1, 1], JR[i, 1, 2]
        for j in range(first[i], i + 1):
            c0 = row_body[j, 0]
            c1 = row_body[j, 1]
            # (JL W JR^T)[i, j], as _entry sums it: over row i's sides, each against row j's
            acc = 0.0
            if b0 >= 0:
                if c0 == b0:
                    acc = _pair(acc, l00, l01, l02, JR[j, 0, 0], JR[j, 0, 1], JR[j, 0, 2], m0, i0)
                if c1 == b0:
                    acc = _pair(acc, l00, l01, l02, JR[j, 1, 0], JR[j, 1, 1], JR[j, 1, 2], m0, i0)
            if b1 >= 0:
                if c0 == b1:
                    acc = _pair(acc, l10, l11, l12, JR[j, 0, 0], JR[j, 0, 1], JR[j, 0, 2], m1, i1)
                if c1 == b1:
                    acc = _pair(acc, l10, l11, l12, JR[j, 1, 0], JR[j, 1, 1], JR[j, 1, 2], m1, i1)
            A[i, j] = acc
            if j != i and not symmetric:
                # (JL W JR^T)[j, i]: over row j's sides, each against row i's
                acc = 0.0
                for e in range(2):
                    c = c0 if e == 0 else c1
                    if c < 0:
                        continue
                    mj = inv_mass[c]
                    ij = inv_inertia[c]
                    if b0 == c:
                        acc = _pair(acc, JL[j, e, 0], JL[j, e, 1], JL[j, e, 2], r00, r01, r02, mj, ij)
                    if b1 == c:
                        acc = _pair(acc, JL[j, e, 0], JL[j, e, 1], JL[j, e, 2], r10, r11, r12, mj, ij)
                A[j, i] = acc


@kernel(inline="always")
def _pair(acc, a0, a1, a2, b0, b1, b2, inv_mass, inv_inertia):
    """acc plus one shared body's part of an entry, a side (a0, a1, a2) of one row against a
    side (b0, b1, b2) of the other: the translation's over the mass, then the turn's over the
    inertia, in _entry's order."""
    acc += (a0 * b0 + a1 * b1) * inv_mass
    return acc + a2 * b2 * inv_inertia


@kernel(inline="always")
def _dropped(A, n, k, tol, scale, upper):
    """Row k's pivot test (envelope.is_dependent against scale[k], its diagonal before
    elimination): a dependent row is dropped, its pivot and multipliers (and, upper, its row
    of U) zeroed. Returns whether it was."""
    if not is_dependent(A[k, k], scale[k], tol):
        return False
    for i in range(k + 1, n):
        A[i, k] = 0.0
        if upper:
            A[k, i] = 0.0
    A[k, k] = 0.0
    return True


@kernel
def factor_dense(A, n, tol, scale, column, symmetric):
    """LU factorisation of A[:n, :n] in place without pivoting: U on and above the diagonal,
    the multipliers L below it; symmetric: A = L D L^T in half the work, the multipliers L
    below the diagonal and D on it, the upper triangle neither read nor written (column (n,)
    is scratch: column k before its division by the pivot). A row whose pivot falls below
    tol times its own diagonal (scale: the diagonal before elimination, written here)
    depends on earlier rows: it is dropped (zero pivot, zero multipliers and, LU, zero U
    row). Returns #dropped."""
    dropped = 0
    for k in range(n):
        scale[k] = abs(A[k, k])
    for k in range(n):
        if _dropped(A, n, k, tol, scale, not symmetric):
            dropped += 1
            continue
        inv = 1.0 / A[k, k]
        if symmetric:
            _eliminate_symmetric(A, n, k, inv, column)
        else:
            _eliminate(A, n, k, inv)
    return dropped


@kernel(inline="always")
def _eliminate(A, n, k, inv):
    """LU: column k's multipliers, and the rows below it less their multiple of row k."""
    for i in range(k + 1, n):
        fct = A[i, k] * inv
        A[i, k] = fct
        if fct == 0.0:
            continue
        for j in range(k + 1, n):
            A[i, j] -= fct * A[k, j]


@kernel(inline="always")
def _eliminate_symmetric(A, n, k, inv, column):
    """L D L^T: the lower triangle below row k less column k's outer product over its pivot,
    then column k's multipliers."""
    for j in range(k + 1, n):
        column[j] = A[j, k]
    for i in range(k + 1, n):
        a_ik = column[i]
        if a_ik == 0.0:
            continue
        fct = a_ik * inv
        for j in range(k + 1, i + 1):
            A[i, j] -= fct * column[j]
        A[i, k] = fct


@kernel(inline="always")
def _forward(A, rhs, n):
    """rhs <- L^-1 rhs with the unit lower factor below the diagonal (both factorisations);
    dropped rows (zero pivot) get 0."""
    for k in range(n):
        if A[k, k] == 0.0:
            rhs[k] = 0.0
            continue
        rk = rhs[k]
        # (column by column, as envelope.py's: each entry's updates in the same order, and
        # independent of each other, where a row's sum would wait on each of its terms)
        for i in range(k + 1, n):
            rhs[i] -= A[i, k] * rk


@kernel
def substitute_dense(A, rhs, x, n):
    """x = A^-1 rhs from the factors of factor_dense (rhs destroyed); dropped rows get 0."""
    _forward(A, rhs, n)
    for k in range(n - 1, -1, -1):
        d = A[k, k]
        if d == 0.0:
            x[k] = 0.0
            continue
        acc = rhs[k]
        for j in range(k + 1, n):
            acc -= A[k, j] * x[j]
        x[k] = acc / d


@kernel
def substitute_dense_symmetric(A, rhs, x, n):
    """x = A^-1 rhs from the symmetric factors of factor_dense (rhs destroyed); dropped rows
    get 0. Back substitution uses U = D L^T: x_k = y_k / d_k - sum_j L_jk x_j."""
    _forward(A, rhs, n)
    for k in range(n - 1, -1, -1):
        d = A[k, k]
        if d == 0.0:
            x[k] = 0.0
            continue
        acc = rhs[k] / d
        for j in range(k + 1, n):
            acc -= A[j, k] * x[j]
        x[k] = acc


@kernel
def substitute_dense_pair(A, rhs, x, rhs2, x2, n):
    """substitute_dense for two right-hand sides at once (both destroyed): each answer's
    arithmetic is substitute_dense's, in the same order; the two sums of the back
    substitution, each waiting on its own last term, run side by side (the forward ones'
    updates are independent already)."""
    _forward(A, rhs, n)
    _forward(A, rhs2, n)
    for k in range(n - 1, -1, -1):
        d = A[k, k]
        if d == 0.0:
            x[k] = 0.0
            x2[k] = 0.0
            continue
        acc = rhs[k]
        acc2 = rhs2[k]
        for j in range(k + 1, n):
            u = A[k, j]
            acc -= u * x[j]
            acc2 -= u * x2[j]
        x[k] = acc / d
        x2[k] = acc2 / d
