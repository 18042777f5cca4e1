"""Stage 4's factorisation for large systems: a sparse L U in an order of little fill.

The envelope elimination (solve.py) is linear for chains and trees, but a pile or a wall
couples every row of a level with the level above: its envelope is as wide as a level, and
the work grows as rows x width^2 (a 1,035-box pyramid: a second a step). Here the rows are
put in a nested-dissection order of their bodies, found from the bodies' positions: the
bodies are split at the median of their longer extent, again and again (quickselect, in
place), down to LEAF_BODIES; a row between two bodies belongs to the smallest part holding
both, and a part's rows come after those of its two halves. The rows of a half then never
meet those of the other half during elimination, so fill stays within the separators
(a planar pile: work ~ rows^1.5, fill ~ rows log rows).

The factors follow the elimination tree (Liu; the up-looking scheme of Davis's LDL): row k
of L and column k of U come from sparse triangular solves whose pattern is the rows reached
from row k's neighbours up the tree. The matrix's pattern is symmetric (rows meet where they
share a body), so L's columns and U's rows share one index list. Where J W F^T is symmetric,
U = D L^T and only L is computed (half the work). A row whose pivot falls below tol times its
own diagonal depends on earlier rows and is dropped, as in the envelope elimination: its
pivot and multipliers are zero, its impulse 0.

A pile at rest drops most of its rows as dependent (a 1,035-box pyramid: 4,710 of 7,816),
and those rows make most of the work: they sit in the separators, and every row after them
reaches through them. So the rows the last step dropped (State.contact_dependent) are left
out: they come last in the order (ws.sp_factored: the places factored), take no part in the
pattern, the elimination tree or the factors, and count as dropped (pivot 0). The solve then
checks their equations (solve.excluded_rows_hold) and factors every row where one fails.

Storage (the workspace's): the order (sp_perm: place -> row, sp_iperm: row -> place), the
matrix's lower pattern by place (sp_start, sp_index; values sp_low = A[k, i], sp_up =
A[i, k], i < k; diagonal sp_diag), and the factors' columns (sp_lstart, ws.L_index; values
ws.A_low = L, ws.A_up = U; pivots sp_pivot).
"""
from ...compile import kernel
from ..codes import SPARSE_MAX_DEPTH as MAX_DEPTH
from .envelope import _entry, is_dependent
from ..constraints.rows import dependent_bit

# a system of at least this many rows is factored sparse (fewer: the envelope elimination,
# which is exact as well and has no ordering to find)
SPARSE_MIN_ROWS = 1024
# bodies in a part that is not split further
LEAF_BODIES = 4


@kernel
def _select(bodies, key, lo, hi, nth):
    """Reorder bodies[lo:hi] so that bodies[nth] has the key it would have sorted by key,
    none before it a larger key and none after it a smaller (quickselect, Hoare's partition
    around the median of three; deterministic)."""
    while hi - lo > 1:
        mid = (lo + hi - 1) // 2
        a = key[bodies[lo]]
        b = key[bodies[mid]]
        c = key[bodies[hi - 1]]
        pivot = max(min(a, b), min(max(a, b), c))
        i = lo
        j = hi - 1
        while i <= j:
            while key[bodies[i]] < pivot:
                i += 1
            while key[bodies[j]] > pivot:
                j -= 1
            if i <= j:
                t = bodies[i]
                bodies[i] = bodies[j]
                bodies[j] = t
                i += 1
                j -= 1
        if nth <= j:
            hi = j + 1
        elif nth >= i:
            lo = i
        else:
            return


@kernel
def _bisect(q, ws, count):
    """ws.sp_bodies[:count] arranged as nested halves: each part [lo, hi) of more than
    LEAF_BODIES bodies split at mid = (lo + hi) // 2 by the coordinate along which its bodies
    spread most (x or y of q), each half again; ws.sp_body_place[b] = body b's place."""
    stack = ws.sp_stack
    top = 0
    stack[0, 0] = 0
    stack[0, 1] = count
    top = 1
    while top > 0:
        top -= 1
        lo = stack[top, 0]
        hi = stack[top, 1]
        if hi - lo <= LEAF_BODIES:
            continue
        x0 = 1e300
        x1 = -1e300
        y0 = 1e300
        y1 = -1e300
        for p in range(lo, hi):
            b = ws.sp_bodies[p]
            x0 = min(x0, q[b, 0])
            x1 = max(x1, q[b, 0])
            y0 = min(y0, q[b, 1])
            y1 = max(y1, q[b, 1])
        axis = 0 if x1 - x0 >= y1 - y0 else 1
        for p in range(lo, hi):
            b = ws.sp_bodies[p]
            ws.sp_key[b] = q[b, axis]
        mid = (lo + hi) // 2
        _select(ws.sp_bodies, ws.sp_key, lo, hi, mid)
        stack[top, 0] = lo
        stack[top, 1] = mid
        stack[top + 1, 0] = mid
        stack[top + 1, 1] = hi
        top += 2
    for p in range(count):
        ws.sp_body_place[ws.sp_bodies[p]] = p


@kernel
def _part_key(count, p0, p1):
    """The place of the smallest part holding body places p0 and p1 (p1 < 0: p0's leaf) in
    the order: parts by their end, and of parts ending alike the deeper first."""
    lo = 0
    hi = count
    depth = 0
    if p1 < 0:
        p1 = p0
    while hi - lo > LEAF_BODIES:
        mid = (lo + hi) // 2
        if p0 < mid and p1 < mid:
            hi = mid
        elif p0 >= mid and p1 >= mid:
            lo = mid
        else:
            break
        depth += 1
    return hi * MAX_DEPTH + (MAX_DEPTH - 1 - min(depth, MAX_DEPTH - 1))


@kernel(inline="always")
def is_excluded(ws, r, dependent):
    """Row r is a contact's row that the last step dropped as dependent (dependent:
    State.contact_dependent)."""
    bit = dependent_bit(ws.row_kind[r])
    return bit != 0 and (dependent[ws.row_owner[r]] & bit) != 0


@kernel
def order_rows(q, ws, n, dependent, exclude):
    """ws.sp_perm / sp_iperm: rows 0..n-1 in nested-dissection order of their bodies
    (positions q). Rows of one part keep their own order (a counting sort, stable). exclude:
    the rows the last step dropped as dependent (is_excluded) come after all others, in
    their own order; ws.sp_factored[0] = the places before them."""
    count = 0
    for r in range(n):
        for e in range(2):
            b = ws.row_body[r, e]
            if b >= 0:
                ws.sp_body_place[b] = -1
    for r in range(n):
        for e in range(2):
            b = ws.row_body[r, e]
            if b >= 0 and ws.sp_body_place[b] == -1:
                ws.sp_body_place[b] = -2
                ws.sp_bodies[count] = b
                count += 1
    _bisect(q, ws, count)
    n_key = (count + 1) * MAX_DEPTH
    for k in range(n_key + 1):
        ws.sp_count[k] = 0
    for r in range(n):
        if exclude and is_excluded(ws, r, dependent):
            ws.sp_row_key[r] = -1
            continue
        b0 = ws.row_body[r, 0]
        b1 = ws.row_body[r, 1]
        p0 = ws.sp_body_place[b1] if b1 >= 0 else ws.sp_body_place[b0]
        p1 = ws.sp_body_place[b0] if (b0 >= 0 and b1 >= 0) else -1
        key = _part_key(count, p0, p1)
        ws.sp_row_key[r] = key
        ws.sp_count[key + 1] += 1
    for k in range(n_key):
        ws.sp_count[k + 1] += ws.sp_count[k]
    factored = ws.sp_count[n_key]
    last = factored
    for r in range(n):
        key = ws.sp_row_key[r]
        if key < 0:
            k = last
            last += 1
        else:
            k = ws.sp_count[key]
            ws.sp_count[key] += 1
        ws.sp_perm[k] = r
        ws.sp_iperm[r] = k
    ws.sp_factored[0] = factored


@kernel
def analyse(ws, n, n_body):
    """The matrix's lower pattern by place (rows meet where they share a body; the places
    from ws.sp_factored[0] on have none), the elimination tree (sp_parent) and the factors'
    column starts (sp_lstart). Returns False
    (ws.room set, with the entries needed) if the pattern or the factors do not fit the
    workspace's storage."""
    # each body's rows, by place (ascending)
    for b in range(n_body + 1):
        ws.sp_body_start[b] = 0
    for r in range(n):
        for e in range(2):
            b = ws.row_body[r, e]
            if b >= 0:
                ws.sp_body_start[b + 1] += 1
    for b in range(n_body):
        ws.sp_body_start[b + 1] += ws.sp_body_start[b]
    for b in range(n_body):
        ws.sp_body_fill[b] = ws.sp_body_start[b]
    for k in range(n):
        r = ws.sp_perm[k]
        for e in range(2):
            b = ws.row_body[r, e]
            if b >= 0:
                ws.sp_body_rows[ws.sp_body_fill[b]] = k
                ws.sp_body_fill[b] += 1
    # the lower pattern: column k's neighbours i < k
    cap = ws.sp_index.shape[0]
    fill = 0
    factored = ws.sp_factored[0]
    for k in range(n):
        ws.sp_flag[k] = -1
    for k in range(n):
        ws.sp_start[k] = fill
        ws.sp_flag[k] = k
        if k >= factored:
            continue
        r = ws.sp_perm[k]
        for e in range(2):
            b = ws.row_body[r, e]
            if b < 0:
                continue
            for t in range(ws.sp_body_start[b], ws.sp_body_start[b + 1]):
                i = ws.sp_body_rows[t]
                if i >= k:
                    break
                if ws.sp_flag[i] == k:
                    continue
                ws.sp_flag[i] = k
                if fill < cap:
                    ws.sp_index[fill] = i
                fill += 1
    ws.sp_start[n] = fill
    # the elimination tree and each column's count (Liu: each neighbour i < k walks up the
    # tree to k, every row on the way gaining an entry in row k)
    for k in range(n):
        ws.sp_parent[k] = -1
        ws.sp_flag[k] = k
        ws.sp_lcount[k] = 0
        if fill > cap:
            continue
        for p in range(ws.sp_start[k], ws.sp_start[k + 1]):
            i = ws.sp_index[p]
            while ws.sp_flag[i] != k:
                if ws.sp_parent[i] == -1:
                    ws.sp_parent[i] = k
                ws.sp_lcount[i] += 1
                ws.sp_flag[i] = k
                i = ws.sp_parent[i]
    ws.sp_lstart[0] = 0
    for k in range(n):
        ws.sp_lstart[k + 1] = ws.sp_lstart[k] + ws.sp_lcount[k]
    need = max(fill, ws.sp_lstart[n])
    if need > cap or need > ws.A_low.shape[0]:
        ws.room[0] = 1
        ws.room[2] = max(ws.room[2], need)
        return False
    return True


@kernel
def assemble_sparse(JL, JR, row_body, inv_mass, inv_inertia, ws, n, symmetric):
    """The matrix JL W JR^T on its pattern by place: sp_diag[k] = A[k, k], sp_low[p] =
    A[k, i] and (not symmetric) sp_up[p] = A[i, k] for i = sp_index[p] < k."""
    perm = ws.sp_perm
    for k in range(n):
        rk = perm[k]
        ws.sp_diag[k] = _entry(JL, JR, row_body, inv_mass, inv_inertia, rk, rk)
        for p in range(ws.sp_start[k], ws.sp_start[k + 1]):
            ri = perm[ws.sp_index[p]]
            ws.sp_low[p] = _entry(JL, JR, row_body, inv_mass, inv_inertia, rk, ri)
            if not symmetric:
                ws.sp_up[p] = _entry(JL, JR, row_body, inv_mass, inv_inertia, ri, rk)


@kernel
def _row_pattern(ws, k, symmetric):
    """Scatter row k's lower entries A[k, i] into sp_y (and column k's upper ones A[i, k]
    into sp_x unless symmetric), and put into sp_pattern[top:n] the rows i < k its row of L
    reaches, each before its parent in the elimination tree (Davis's ereach). Returns top."""
    n = ws.sp_pattern.shape[0]
    flag = ws.sp_flag
    pattern = ws.sp_pattern
    parent = ws.sp_parent
    flag[k] = k
    top = n
    for p in range(ws.sp_start[k], ws.sp_start[k + 1]):
        i = ws.sp_index[p]
        ws.sp_y[i] += ws.sp_low[p]
        if not symmetric:
            ws.sp_x[i] += ws.sp_up[p]
        length = 0
        while flag[i] != k:
            pattern[length] = i
            length += 1
            flag[i] = k
            i = parent[i]
        while length > 0:
            top -= 1
            length -= 1
            pattern[top] = pattern[length]
    return top


@kernel
def _eliminate_symmetric(y, L, Li, lstart, count, pivot, pattern, top, k, d):
    """Row k of L (L D L^T): each i of its pattern in turn, L[k, i] = y_i / d_i, then
    y_j -= L[j, i] y_i for the entries j of column i so far; returns the pivot d_k."""
    for t in range(top, pattern.shape[0]):
        i = pattern[t]
        yi = y[i]
        y[i] = 0.0
        end = lstart[i] + count[i]
        lki = 0.0
        if pivot[i] != 0.0:
            lki = yi / pivot[i]
            for p in range(lstart[i], end):
                y[Li[p]] -= L[p] * yi
            d -= lki * yi
        Li[end] = k
        L[end] = lki
        count[i] += 1
    return d


@kernel
def _eliminate(x, y, L, U, Li, lstart, count, pivot, pattern, top, k, d):
    """Row k of L and column k of U (L U): for each i of the pattern in turn,
    L[k, i] = y_i / U[i, i] and U[i, k] = x_i, then y_j -= U[i, j] L[k, i] and
    x_j -= L[j, i] U[i, k] over the entries j of column i so far; returns U[k, k]."""
    for t in range(top, pattern.shape[0]):
        i = pattern[t]
        yi = y[i]
        xi = x[i]
        y[i] = 0.0
        x[i] = 0.0
        end = lstart[i] + count[i]
        lki = 0.0
        uik = 0.0
        if pivot[i] != 0.0:
            lki = yi / pivot[i]
            uik = xi
            for p in range(lstart[i], end):
                j = Li[p]
                y[j] -= U[p] * lki
                x[j] -= L[p] * uik
            d -= lki * uik
        Li[end] = k
        L[end] = lki
        U[end] = uik
        count[i] += 1
    return d


@kernel(inline="never")
def factor_sparse(ws, n, tol, symmetric, scale):
    """L U (symmetric: L D L^T) of the matrix assemble_sparse filled, up-looking along the
    elimination tree; scale[r] (by row) the diagonal before elimination. Dropped rows (pivot
    below tol times their diagonal) get zero pivots and multipliers, as do the places from
    ws.sp_factored[0] on (left out by order_rows). Returns #dropped."""
    dropped = 0
    for k in range(n):
        ws.sp_y[k] = 0.0
        ws.sp_x[k] = 0.0
        ws.sp_lcount[k] = 0
    pattern = ws.sp_pattern
    factored = ws.sp_factored[0]
    for k in range(n):
        d = ws.sp_diag[k]
        scale[ws.sp_perm[k]] = abs(d)
        if k >= factored:           # left out (order_rows): dropped
            ws.sp_pivot[k] = 0.0
            dropped += 1
            continue
        top = _row_pattern(ws, k, symmetric)
        if symmetric:
            d = _eliminate_symmetric(ws.sp_y, ws.A_low, ws.L_index, ws.sp_lstart, ws.sp_lcount,
                                     ws.sp_pivot, pattern, top, k, d)
        else:
            d = _eliminate(ws.sp_x, ws.sp_y, ws.A_low, ws.A_up, ws.L_index, ws.sp_lstart,
                           ws.sp_lcount, ws.sp_pivot, pattern, top, k, d)
        if is_dependent(d, abs(ws.sp_diag[k]), tol):
            ws.sp_pivot[k] = 0.0
            dropped += 1
        else:
            ws.sp_pivot[k] = d
    return dropped


@kernel(inline="never")
def substitute_sparse(ws, rhs, out, n, symmetric):
    """out = A^-1 rhs (both by row) from the factors of factor_sparse (rhs destroyed);
    dropped rows get 0."""
    z = ws.sp_y
    L = ws.A_low
    U = ws.A_up
    Li = ws.L_index
    lstart = ws.sp_lstart
    pivot = ws.sp_pivot
    for k in range(n):
        z[k] = rhs[ws.sp_perm[k]]
    for k in range(n):
        if pivot[k] == 0.0:
            z[k] = 0.0
            continue
        zk = z[k]
        for p in range(lstart[k], lstart[k + 1]):
            z[Li[p]] -= L[p] * zk
    for k in range(n - 1, -1, -1):
        if pivot[k] == 0.0:
            z[k] = 0.0
            continue
        if symmetric:
            acc = z[k] / pivot[k]
            for p in range(lstart[k], lstart[k + 1]):
                acc -= L[p] * z[Li[p]]
            z[k] = acc
        else:
            acc = z[k]
            for p in range(lstart[k], lstart[k + 1]):
                acc -= U[p] * z[Li[p]]
            z[k] = acc / pivot[k]
    for k in range(n):
        out[ws.sp_perm[k]] = z[k]
        z[k] = 0.0
