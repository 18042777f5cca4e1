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
up). So in exact arithmetic it ends at a solution for our problems; in floating point
rounding can spoil a long path, so lemke refines and checks its final basis (_refine_basis)
and reports LCP_INACCURATE when that fails, and rounding can bring a path back to a basis it
has visited, which ends it (LCP_CAP: the caller's next path runs).

The tableau holds B^-1 [I, -M, -d, q] for the basis B (columns: w 0..m-1, z m..2m-1, the
artificial z0 at 2m, the right-hand side at 2m+1); basis[i] is the variable of row i.
A pivot costs m (2m + 2) multiply-adds.
"""
import math

from ...compile import kernel

LCP_SOLVED = 0
LCP_RAY = 1     # no blocking row for the entering variable: no solution on this path
LCP_CAP = 2     # more pivots than the cap (only by rounding: the path is finite)
LCP_INACCURATE = 3   # the path ended, but its basis gives no answer within ANSWER_TOL

# a basic variable (some z or w) may be this far below zero, relative to max -q, in an answer:
# the rounding of a basis of condition up to 1e9 (a 16-box chain resting on its 32 corners has
# 3e9: its fresh solve misses by 2e-9 max -q)
ANSWER_TOL = 1e-7
# the answer check's scale is at least this share of the problem's largest |q|: its basic
# values carry rounding of every q (ANSWER_TOL times this, 1e-13 of max |q|, is ~500 eps)
ROUNDING_SHARE = 1e-6
GOLDEN = 0.6180339887498949
# refinements of the final basis against M and q (rounding of the pivots, not the path): at
# most this many, until the residual is rounding (REFINE_TARGET of max -q) or stops shrinking
REFINE_PASSES = 6
REFINE_TARGET = 1e-14

# a column entry below this share of the column's largest is treated as zero in the ratio test
RATIO_PIVOT_TOL = 1e-11
# ratios this close (relative) are ties, broken lexicographically
TIE_TOL = 1e-12
# _min_change's damping, relative to the largest diagonal of B B^T: far below the squared
# smallest non-zero singular value of a basis (measured 1e-5 of the largest on a 16-box
# chain's), far above rounding
MIN_CHANGE_DAMPING = 1e-12


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


@kernel
def covering(i, m, cover):
    """Entry i of the covering vector d > 0 (the artificial variable's column is -d).
    Any d > 0 gives Lemke's method its guarantees; the all-ones vector meets the exact ties
    of our problems (friction's beta+ and beta- rows have q of equal size and opposite sign,
    symmetric contacts equal rows), which rounding then breaks at random. A ramp (cover 0)
    or a golden-ratio sequence (cover 1, a second path when the first fails) has no ties.
    Measured on the 24 problems of the stress corpus where the engine's all-ones paths all
    failed, replayed in Python: all-ones 17 solved, the ramp 24, the golden sequence 24."""
    if cover == 0:
        return 1.0 + 0.5 * i / m
    return 1.0 + 0.5 * ((i * GOLDEN) % 1.0)


@kernel
def _first_leaving(q, m, cover):
    """The row where the artificial variable enters: the most negative q_i / d_i, d the
    covering vector; -1 where q >= 0 (z = 0 is the answer) or m == 0."""
    if m == 0:
        return -1
    lowest = 0
    for i in range(m):
        if q[i] / covering(i, m, cover) < q[lowest] / covering(lowest, m, cover):
            lowest = i
    return lowest if q[lowest] < 0.0 else -1


@kernel(inline="never")
def lemke(M, q, m, T, basis, z, max_pivots, cover, floor):
    """Solve LCP(M[:m, :m], q[:m]) into z[:m] along the path of covering vector `cover`
    (see covering); T (>= m, >= 2m + 2) and basis (>= m) are scratch. floor: a lower bound
    of the answer check's scale (_is_answer; 0: this problem's own). A path that comes back
    to one of its last m bases (rounding: the exact path never does) ends as the cap would
    (LCP_CAP): a 36-box pyramid set sliding cycled from pivot 1,882 to the cap of 29,160,
    nine tenths of its step. Returns (status LCP_*, pivots)."""
    for i in range(m):
        z[i] = 0.0
    lowest = _first_leaving(q, m, cover)
    if lowest < 0:
        return LCP_SOLVED, 0
    z0 = 2 * m
    for i in range(m):
        for j in range(2 * m + 2):
            T[i, j] = 0.0
        T[i, i] = 1.0
        for j in range(m):
            T[i, m + j] = -M[i, j]
        T[i, z0] = -covering(i, m, cover)
        T[i, z0 + 1] = q[i]
        basis[i] = i
    # z0 enters at the value that makes every w non-negative; the most negative q leaves
    _pivot(T, m, lowest, z0)
    leaving = basis[lowest]
    basis[lowest] = z0
    pivots = 1
    key = 0
    for i in range(m):
        key ^= _basis_key(basis[i])
    _seen_lately(z, m, key, 0)
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
        key ^= _basis_key(leaving) ^ _basis_key(entering)
        if _seen_lately(z, m, key, pivots - 1):
            break
    for i in range(m):
        z[i] = 0.0
    if status == LCP_SOLVED:
        status = _refine_basis(M, q, m, T, basis, z, floor)
    if status == LCP_SOLVED:
        _answer(T, m, basis, z)
    return status, pivots


# problems of at least this many variables take lemke_revised: the tableau's m (2m + 2)
# multiply-adds a pivot, on a path of 2-3 m pivots, grow as m^3 (a pile of 50 shapes poured
# into a box: 260 variables, 600 pivots, 100 ms a step); smaller problems keep lemke's tableau
REVISED_SIZE = 96


@kernel
def _eta_pivot(T, m, r, col, row):
    """_pivot in revised form: the entering column B^-1 a in T's column col; only B^-1 (T's
    first m columns) and the basic values (column 2m + 1) are updated. row (>= m) is scratch:
    the pivot row copied out of T, so that the compiler sees it apart from the rows it
    updates (vectorised: twice as fast)."""
    rhs = 2 * m + 1
    inv = 1.0 / T[r, col]
    for j in range(m):
        row[j] = T[r, j] * inv
        T[r, j] = row[j]
    T[r, rhs] *= inv
    xr = T[r, rhs]
    for i in range(m):
        if i == r:
            continue
        f = T[i, col]
        if f == 0.0:
            continue
        Ti = T[i]
        for j in range(m):
            Ti[j] -= f * row[j]
        T[i, rhs] -= f * xr


@kernel
def _entering_column(M, m, T, nz, var):
    """T[:, 2m] = B^-1 a for variable var's column a of [I, -M] (w_j: e_j; z_j: -M[:, j]),
    B^-1 read from T's first m columns; nz (>= m, int) is scratch (M's column's non-zero
    rows: a contact's column couples only the contacts on its two bodies)."""
    col = 2 * m
    if var < m:
        for i in range(m):
            T[i, col] = T[i, var]
        return
    j = var - m
    count = 0
    for k in range(m):
        if M[k, j] != 0.0:
            nz[count] = k
            count += 1
    for i in range(m):
        acc = 0.0
        for c in range(count):
            k = nz[c]
            acc -= T[i, k] * M[k, j]
        T[i, col] = acc


@kernel
def _mix31(x, k1, k2):
    """A 31-bit integer hash of x >= 0 (multiply-xorshift; every product below 2^62, so the
    same in Python as compiled)."""
    x = (x * k1 + 0x3C6EF372) & 0x7FFFFFFF
    x = ((x ^ (x >> 15)) * k2) & 0x7FFFFFFF
    x = ((x ^ (x >> 13)) * 0x297A2D39) & 0x7FFFFFFF
    return x ^ (x >> 16)


@kernel
def _basis_key(var):
    """A 52-bit key of variable var (exact as a float); a basis's key is the XOR of its
    variables'."""
    return (_mix31(var, 0x2545F491, 0x2C1B3C6D) << 21) ^ _mix31(var, 0x1B873593, 0x27D4EB2F)


@kernel
def _seen_lately(keys, m, key, count):
    """Record basis key `key` as the path's basis number `count` in keys[:m] (a ring of the
    last m bases' keys, as floats; lemke's z, free while the path runs) and return True if one
    of the last m bases had it: a cycle of up to m pivots, which rounding alone can make."""
    mark = float(key)
    for p in range(min(count, m)):
        if keys[p] == mark:
            return True
    keys[count % m] = mark
    return False


@kernel
def _seen_before(T, m, key, count):
    """Record basis key `key` as the path's basis number `count` (as a float, in T's columns
    m..2m-1, which the revised form leaves free) and return True if an earlier basis of the
    path had it."""
    mark = float(key)
    for p in range(min(count, m * m)):
        if T[p % m, m + p // m] == mark:
            return True
    if count < m * m:
        T[count % m, m + count // m] = mark
    return False


@kernel(inline="never")
def lemke_revised(M, q, m, T, basis, z, nz, max_pivots, cover, floor):
    """lemke's path (the same pivots in exact arithmetic) in revised form: T keeps only B^-1
    (its first m columns) and the basic values (column 2m + 1); each entering column is made
    from M (_entering_column, into column 2m, the artificial's), so a pivot costs m (m + 1)
    multiply-adds plus m per non-zero of M's column, not m (2m + 2), and the early pivots,
    while B^-1 is sparse, far less. The lexicographic tie-break, the final refinement and
    check, and polish read B^-1 and the basic values where lemke's tableau keeps them.
    Lemke's path never visits a basis twice; rounding can send it back to one (a pile's
    degenerate problem, nearly regularised, measured cycling to the cap of 14,000 pivots
    where paths take about 1.2 m), so a basis seen before ends the path as the cap would
    (LCP_CAP: the caller's next path then runs). Same arguments and return as lemke, plus nz
    (>= m, int scratch)."""
    for i in range(m):
        z[i] = 0.0
    lowest = _first_leaving(q, m, cover)
    if lowest < 0:
        return LCP_SOLVED, 0
    rhs = 2 * m + 1
    z0 = 2 * m
    for i in range(m):
        for j in range(m):
            T[i, j] = 0.0
        T[i, i] = 1.0
        T[i, z0] = -covering(i, m, cover)
        T[i, rhs] = q[i]
        basis[i] = i
    _eta_pivot(T, m, lowest, z0, z)
    leaving = basis[lowest]
    basis[lowest] = z0
    pivots = 1
    key = 0
    for i in range(m):
        key ^= _basis_key(basis[i])
    _seen_before(T, m, key, 0)
    status = LCP_CAP
    while pivots < max_pivots:
        entering = leaving + m if leaving < m else leaving - m
        _entering_column(M, m, T, nz, entering)
        r = _leaving_row(T, m, basis, z0)
        if r < 0:
            status = LCP_RAY
            break
        _eta_pivot(T, m, r, z0, z)
        leaving = basis[r]
        basis[r] = entering
        if leaving == z0:
            pivots += 1
            status = LCP_SOLVED
            break
        key ^= _basis_key(leaving) ^ _basis_key(entering)
        if _seen_before(T, m, key, pivots):
            pivots += 1
            break
        pivots += 1
    if status == LCP_SOLVED:
        status = _refine_basis(M, q, m, T, basis, z, floor)
    if status == LCP_SOLVED:
        _answer(T, m, basis, z)
    else:
        for i in range(m):
            z[i] = 0.0
    return status, pivots


@kernel(inline="never")
def lemke_large(M, q, m, T, basis, z, nz, max_pivots, cover, floor):
    """A large problem's path: lemke_revised, and where it came back to a basis, met the cap
    or ended at a basis whose answer fails the check, lemke's tableau on the same covering
    vector (which ends too where it comes back to a recent basis). Measured on seeded
    singular frictionless problems (100-160 contacts on 40-60
    degrees of freedom; tests/planarsim/test_lcp_revised.py): the revised path's rounding
    failed 11 of 40 (4 back to a basis, 7 at a basis whose answer fails), of which the
    tableau solved 10; on Stewart and Trinkle's frictional problems of the same sizes both
    solve all 40. A ray is the tableau's too (the same path). Same arguments and return as
    lemke_revised; the pivots of both are counted."""
    status, pivots = lemke_revised(M, q, m, T, basis, z, nz, max_pivots, cover, floor)
    if status == LCP_SOLVED or status == LCP_RAY:
        return status, pivots
    status, more = lemke(M, q, m, T, basis, z, max_pivots, cover, floor)
    return status, pivots + more


@kernel
def _answer(T, m, basis, z):
    """z from the basic values (T's rhs column): z_j where z_j is basic, else 0."""
    for i in range(m):
        z[i] = 0.0
    for i in range(m):
        b = basis[i]
        if m <= b < 2 * m:
            z[b - m] = max(T[i, 2 * m + 1], 0.0)


@kernel
def _min_change(M, q, m, T, basis, res):
    """Basic values x (T's rhs column) moved by the smallest change dx that makes B x = q
    hold, B the basis's matrix for M (column i: e_b for w_b, -M[:, j] for z_j), when B is
    singular: a basis of redundant contacts sharing a load, whose impulses are not unique.
    dx = B^T y with (B B^T + delta I) y = q - B x, twice (iterated Tikhonov: dx stays
    orthogonal to B's null space, so x does not drift along it). B goes into T's z columns,
    B B^T and its Cholesky factor into the w columns; the path is over."""
    rhs = 2 * m + 1
    for i in range(m):
        for k in range(m):
            T[k, m + i] = 0.0
        b = basis[i]
        if b < m:
            T[b, m + i] = 1.0
        else:
            for k in range(m):
                T[k, m + i] = -M[k, b - m]
    # B B^T's lower triangle, column by column of B over its non-zero rows (a contact's
    # column couples only the contacts on its two bodies; each entry's sum runs in the same
    # order as the dense product's, without its zero terms); res holds the rows meanwhile
    for i in range(m):
        for k in range(i + 1):
            T[i, k] = 0.0
    for c in range(m):
        count = 0
        for i in range(m):
            if T[i, m + c] != 0.0:
                res[count] = i
                count += 1
        for a in range(count):
            i = int(res[a])
            bi = T[i, m + c]
            for b in range(a + 1):
                k = int(res[b])
                T[i, k] += bi * T[k, m + c]
    big = 0.0
    for i in range(m):
        big = max(big, T[i, i])
    delta = MIN_CHANGE_DAMPING * big
    for i in range(m):              # Cholesky of B B^T + delta I, lower triangle
        for k in range(i + 1):
            acc = T[i, k] + (delta if i == k else 0.0)
            for j in range(k):
                acc -= T[i, j] * T[k, j]
            if i == k:
                if acc <= 0.0:
                    return False
                T[i, i] = acc ** 0.5
            else:
                T[i, k] = acc / T[k, k]
    for _ in range(2):
        for i in range(m):
            acc = q[i]
            for j in range(m):
                acc -= T[i, m + j] * T[j, rhs]
            res[i] = acc
        for i in range(m):          # y = (L L^T)^-1 res, in res
            acc = res[i]
            for j in range(i):
                acc -= T[i, j] * res[j]
            res[i] = acc / T[i, i]
        for i in range(m - 1, -1, -1):
            acc = res[i]
            for j in range(i + 1, m):
                acc -= T[j, i] * res[j]
            res[i] = acc / T[i, i]
        for j in range(m):          # x += B^T y
            acc = 0.0
            for i in range(m):
                acc += T[i, m + j] * res[i]
            T[j, rhs] += acc
    return True


@kernel
def _swap_to_answer(M, q, m, T, basis, res, floor):
    """Principal pivots from the nearby problem's basis to one of M's own: while the basis's
    exact answer (a fresh elimination) has a negative basic value, that variable leaves and
    its complement enters (a row loaded at a hair below zero is let go, a row whose w is a
    hair below zero is loaded: the nearby problem's eps can put a row whose share is nearly
    zero on the wrong side), at most m times. True with T's rhs column and basis holding the
    answer; False with basis as it was (T's rhs column overwritten). T's z columns keep the
    basis meanwhile (the path is over)."""
    rhs = 2 * m + 1
    for i in range(m):
        T[i, m] = basis[i]
    for _ in range(m):
        if not _solve_basis(M, q, m, T, basis, res):
            break
        if _is_answer(M, q, m, T, basis, res, floor):
            return True
        worst = 0.0
        at = -1
        for i in range(m):
            if T[i, rhs] < worst:
                worst = T[i, rhs]
                at = i
        if at < 0:
            break                   # B x = q fails, not a sign: no swap mends that
        b = basis[at]
        basis[at] = b + m if b < m else b - m
    for i in range(m):
        basis[i] = int(T[i, m])
    return False


@kernel(inline="never")
def polish(M, q, m, T, basis, z, floor):
    """After lemke solved a nearby problem (M + eps I, say) into z on `basis`: the same
    basis's answer for M and q themselves, checked as lemke checks its own. First refined and
    re-solved (_refine_basis); where the basis is singular for M (redundant contacts), the
    smallest change of the nearby answer that solves it (_min_change); where the nearby
    problem put a row with a nearly zero share on the wrong side, principal pivots to M's
    own basis (_swap_to_answer). Returns LCP_SOLVED with z replaced by that answer, or
    LCP_INACCURATE with z, the basis and T's basic values left as they were. T's
    artificial column keeps the nearby answer meanwhile."""
    rhs = 2 * m + 1
    for i in range(m):
        T[i, 2 * m] = T[i, rhs]
    status = _refine_basis(M, q, m, T, basis, z, floor)
    if status != LCP_SOLVED:
        for i in range(m):
            T[i, rhs] = T[i, 2 * m]
        if _min_change(M, q, m, T, basis, z) and _is_answer(M, q, m, T, basis, z, floor):
            status = LCP_SOLVED
        elif _swap_to_answer(M, q, m, T, basis, z, floor):
            status = LCP_SOLVED
        else:
            for i in range(m):
                T[i, rhs] = T[i, 2 * m]
    _answer(T, m, basis, z)
    return status


@kernel
def _basic_residual(M, q, m, T, basis, res):
    """res = q - B x for the basic values x (T's rhs column) of the basis; returns the
    largest -q_i (the fastest approach: rows with a large positive q, say a contact far
    above the ground, must not loosen the tolerance of the others), at least ROUNDING_SHARE
    of the largest |q_i|."""
    rhs = 2 * m + 1
    scale = 0.0
    size = 0.0
    for i in range(m):
        res[i] = q[i]
        scale = max(scale, -q[i])
        size = max(size, abs(q[i]))
    for i in range(m):
        b = basis[i]
        x = T[i, rhs]
        if b < m:
            res[b] -= x                 # column of w_b: e_b
        else:
            j = b - m                   # column of z_j: -M[:, j]
            for k in range(m):
                res[k] += M[k, j] * x
    # ... but the basic values are computed from every q: where the only approaches are
    # rounding (touching bodies at rest beside an impact, -q ~ 1e-14) their rounding is that
    # of the largest |q|, far below what an approach could be (ROUNDING_SHARE of it)
    return max(scale, ROUNDING_SHARE * size)


@kernel
def _is_answer(M, q, m, T, basis, res, floor):
    """The basic values (T's rhs column) solve B x = q to ANSWER_TOL max(-q) and are all >=
    -ANSWER_TOL max(-q) (the non-basic ones are 0, so z . w = 0); res is scratch. max(-q) is
    taken at least `floor`: an island's problem is checked at the scale of the step's largest
    approach (kernels/solver/islands.py), as it would be inside one problem of every island."""
    scale = max(_basic_residual(M, q, m, T, basis, res), floor)
    for i in range(m):
        if abs(res[i]) > ANSWER_TOL * scale or T[i, 2 * m + 1] < -ANSWER_TOL * scale:
            return False
    return True


@kernel
def _solve_basis(M, q, m, T, basis, x):
    """Basic values x of the final basis by a fresh Gaussian elimination with partial
    pivoting of B x = q (B's column i: e_b for w_b, -M[:, j] for z_j), into T's rhs column.
    T's first m columns (B^-1) are overwritten; the path is over."""
    rhs = 2 * m + 1
    for i in range(m):
        for k in range(m):
            T[k, i] = 0.0
        b = basis[i]
        if b < m:
            T[b, i] = 1.0
        else:
            for k in range(m):
                T[k, i] = -M[k, b - m]
    for k in range(m):
        x[k] = q[k]
    for c in range(m):
        p = c
        for i in range(c + 1, m):
            if abs(T[i, c]) > abs(T[p, c]):
                p = i
        if T[p, c] == 0.0:
            return False
        if p != c:
            for j in range(c, m):
                T[c, j], T[p, j] = T[p, j], T[c, j]
            x[c], x[p] = x[p], x[c]
        for i in range(c + 1, m):
            f = T[i, c] / T[c, c]
            if f != 0.0:
                for j in range(c + 1, m):
                    T[i, j] -= f * T[c, j]
                x[i] -= f * x[c]
    for i in range(m - 1, -1, -1):
        acc = x[i]
        for j in range(i + 1, m):
            acc -= T[i, j] * x[j]
        x[i] = acc / T[i, i]
    for i in range(m):
        T[i, rhs] = x[i]
    return True


@kernel
def _refine_basis(M, q, m, T, basis, res, floor):
    """The basic values x (rhs column of T) of the final basis B, made accurate and checked.
    Every pivot rounds the tableau, and a path of hundreds of pivots can leave x far from
    B^-1 q (measured: a resting 16-box chain kicked to 7 m/s by such an answer). First
    iterative refinement, x += B^-1 (q - B x) with B^-1 read from the tableau's w columns
    (they started as I); if the answer still fails the check, x from a fresh elimination of
    B. A refinement that stalls inside the tolerance is kept, not replaced by the fresh
    elimination: on a nearly singular B (loaded rows' M with an eigenvalue below the path's
    eps) B^-1 q can carry large impulses along the near-null direction (measured: a folded
    four-bar on the ground, the corpus's loop_inertia seed 42, then gained 0.04 J in one
    step). The check (_is_answer): B x = q holds, and every basic variable (z of a row in the
    problem, w of a row out of it) is >= 0, both to ANSWER_TOL max(-q). Returns LCP_SOLVED
    or LCP_INACCURATE; res (>= m) is scratch."""
    rhs = 2 * m + 1
    last = math.inf
    for _ in range(REFINE_PASSES):
        scale = max(_basic_residual(M, q, m, T, basis, res), floor)
        size = 0.0
        for i in range(m):
            size = max(size, abs(res[i]))
        # refined as far as the arithmetic allows (not just to the acceptance tolerance: the
        # audit sees every contact's velocity, the check only the largest approach's share)
        if size <= REFINE_TARGET * scale or size >= last:
            break
        last = size
        for i in range(m):
            acc = 0.0
            for k in range(m):
                acc += T[i, k] * res[k]
            T[i, rhs] += acc
    if _is_answer(M, q, m, T, basis, res, floor):
        return LCP_SOLVED
    if _solve_basis(M, q, m, T, basis, res) and _is_answer(M, q, m, T, basis, res, floor):
        return LCP_SOLVED
    return LCP_INACCURATE
