"""Lemke's complementary pivoting for the linear complementarity problem LCP(M, q).

Find z >= 0 with w = M z + q >= 0 and z . w = 0 (m unknowns, M dense, any sign pattern).

Why Lemke: it changes one variable of the complementary set per pivot (one contact's mode,
or the friction state of one contact), and its path through the bases is unique, so it cannot
cycle (degenerate ties are broken lexicographically). It ends after finitely many pivots,
either at a solution or on a ray. For the contact problems of the step (a positive
semidefinite J W J^T with dependent rows, plus Coulomb friction in the form of Stewart and
Trinkle, 1996, where the 2D friction cone is exactly two edges) Stewart-Trinkle and
Anitescu-Potra (1997) show the ray cannot happen when some motion lifts every contact off the
ground while keeping every joint, which a height-field ground always allows (move everything
up). So for our problems it ends at a solution; the caller still verifies the answer.

The tableau holds B^-1 [I, -M, -d, q] for the basis B (columns: w 0..m-1, z m..2m-1, the
artificial z0 at 2m, the right-hand side at 2m+1); basis[i] is the variable of row i.
A pivot costs m (2m + 2) multiply-adds.
"""
from ._jit import kernel, kernel_call

LCP_SOLVED = 0
LCP_RAY = 1     # no blocking row for the entering variable: no solution on this path
LCP_CAP = 2     # more pivots than the cap (only by rounding: the path is finite)

# a column entry below this share of the column's largest is treated as zero in the ratio test
RATIO_PIVOT_TOL = 1e-11
# ratios this close (relative) are ties, broken lexicographically
TIE_TOL = 1e-12


@kernel
def _pivot(T, m, r, col):
    """Make column col the unit vector e_r by row operations on the first m rows of T."""
    width = 2 * m + 2
    p = T[r, col]
    inv = 1.0 / p
    for j in range(width):
        T[r, j] *= inv
    T[r, col] = 1.0
    for i in range(m):
        if i == r:
            continue
        f = T[i, col]
        if f == 0.0:
            continue
        for j in range(width):
            T[i, j] -= f * T[r, j]
        T[i, col] = 0.0


@kernel
def _lexico_less(T, m, i, ai, r, ar):
    """Row i (divided by ai) lexicographically below row r (divided by ar) over the columns of
    B^-1 (the w columns): the tie-break that keeps Lemke's path from cycling."""
    for k in range(m):
        x = T[i, k] / ai
        y = T[r, k] / ar
        d = x - y
        if abs(d) > TIE_TOL * (abs(x) + abs(y)):
            return d < 0.0
    return i < r


@kernel
def _leaving_row(T, m, basis, col):
    """Ratio test for entering column col: the row whose basic variable reaches zero first
    (the artificial variable wins a tie, so the path ends as soon as it can); -1: a ray."""
    rhs = 2 * m + 1
    big = 0.0
    for i in range(m):
        if abs(T[i, col]) > big:
            big = abs(T[i, col])
    tol = RATIO_PIVOT_TOL * big
    r = -1
    best = 0.0
    for i in range(m):
        a = T[i, col]
        if a <= tol:
            continue
        ratio = max(T[i, rhs], 0.0) / a
        if r < 0 or ratio < best - TIE_TOL * (best + ratio):
            r = i
            best = ratio
            continue
        if ratio <= best + TIE_TOL * (best + ratio):
            if basis[r] == 2 * m:
                continue
            if basis[i] == 2 * m or _lexico_less(T, m, i, a, r, T[r, col]):
                r = i
                best = min(best, ratio)
    return r


@kernel_call
def lemke(M, q, m, T, basis, z, max_pivots):
    """Solve LCP(M[:m, :m], q[:m]) into z[:m]; T (>= m, >= 2m + 2) and basis (>= m) are
    scratch. Returns (status LCP_*, pivots)."""
    for i in range(m):
        z[i] = 0.0
    lowest = 0
    for i in range(m):
        if q[i] < q[lowest]:
            lowest = i
    if m == 0 or q[lowest] >= 0.0:
        return LCP_SOLVED, 0
    z0 = 2 * m
    for i in range(m):
        for j in range(2 * m + 2):
            T[i, j] = 0.0
        T[i, i] = 1.0
        for j in range(m):
            T[i, m + j] = -M[i, j]
        T[i, z0] = -1.0
        T[i, z0 + 1] = q[i]
        basis[i] = i
    # z0 enters at the value that makes every w non-negative; the most negative q leaves
    _pivot(T, m, lowest, z0)
    leaving = basis[lowest]
    basis[lowest] = z0
    pivots = 1
    status = LCP_CAP
    while pivots < max_pivots:
        entering = leaving + m if leaving < m else leaving - m
        r = _leaving_row(T, m, basis, entering)
        if r < 0:
            status = LCP_RAY
            break
        _pivot(T, m, r, entering)
        leaving = basis[r]
        basis[r] = entering
        pivots += 1
        if leaving == z0:
            status = LCP_SOLVED
            break
    if status == LCP_SOLVED:
        for i in range(m):
            b = basis[i]
            if m <= b < 2 * m:
                z[b - m] = max(T[i, 2 * m + 1], 0.0)
    return status, pivots
