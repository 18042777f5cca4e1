"""The envelope solves: L D L^T of a symmetric system against the LU that serves the general
one, on random constraint rows (each touching at most two bodies, as in the engine), some of
them exactly dependent (closed loops)."""
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from numba import njit

from planarsim.compile import options as compile_options
from planarsim.kernels.solver.envelope import (NULL_DIAGONAL, compute_envelope, factor,
                                               factor_symmetric, substitute,
                                               substitute_symmetric)
from strategies import body_rows, dense_jacobian, vectors

TOL = 1e-11
# not cached: numba checks a cached function against its own file only, and these wrappers
# must follow the kernels they call
jit = njit(**dict(compile_options(), cache=False))


def _start(first):
    """Where each row's envelope begins in the envelope storage (envelope.compute_envelope)."""
    n = len(first)
    return np.concatenate([[0], np.cumsum(np.arange(n) - np.asarray(first) + 1)]).astype(np.int64)


def _pack(A, first):
    """(low, up, start): dense A in the envelope storage (lower triangle and diagonal by row;
    the upper triangle by column, in the same places)."""
    n = A.shape[0]
    start = _start(first)
    low = np.zeros(max(1, start[n]))
    up = np.zeros(max(1, start[n]))
    for i in range(n):
        for j in range(first[i], i + 1):
            low[start[i] + j - first[i]] = A[i, j]
            up[start[i] + j - first[i]] = A[j, i]
    return low, up, start


def _unpack(low, up, start, first, n, symmetric):
    """The dense matrix of the envelope storage (zeros outside the envelope)."""
    A = np.zeros((n, n))
    for i in range(n):
        for j in range(first[i], i + 1):
            A[i, j] = low[start[i] + j - first[i]]
            if j < i and not symmetric:
                A[j, i] = up[start[i] + j - first[i]]
    return A


@jit
def _lu_packed(low, up, start, first, reach, rhs, x, scale, tol, rows):
    n = rhs.shape[0]
    dropped = factor(low, up, start, first, reach, n, tol, scale, rows)
    substitute(low, up, start, first, reach, rhs, x, n)
    return dropped


@jit
def _ldl_packed(low, start, first, reach, rhs, x, scale, tol, rows):
    n = rhs.shape[0]
    dropped = factor_symmetric(low, start, first, reach, n, tol, scale, rows)
    substitute_symmetric(low, start, first, reach, rhs, x, n)
    return dropped


def _lu(A, first, reach, rhs, x, scale, tol, rows):
    low, up, start = _pack(A, first)
    return _lu_packed(low, up, start, np.asarray(first, np.int64), np.asarray(reach, np.int64),
                      rhs, x, scale, tol, rows)


def _ldl(A, first, reach, rhs, x, scale, tol, rows):
    """(The upper triangle is not packed: the symmetric factorisation must not need it.)"""
    low, _, start = _pack(np.tril(A), first)
    return _ldl_packed(low, start, np.asarray(first, np.int64), np.asarray(reach, np.int64),
                       rhs, x, scale, tol, rows)


def _envelope(row_body, n_body):
    """first[r]: first row sharing a body with r; reach[k]: last row whose envelope holds k
    (the definition of kernels.solver.envelope.compute_envelope)."""
    n = len(row_body)
    seen = [-1] * n_body
    first = np.arange(n)
    for r, bodies in enumerate(row_body):
        for b in bodies:
            if b < 0:
                continue
            if seen[b] < 0:
                seen[b] = r
            first[r] = min(first[r], seen[b])
    reach = np.arange(n)
    for i in range(n):
        reach[first[i]:i] = i
    return first, reach


@st.composite
def systems(draw):
    """Rows on a chain of bodies (a row joins body a to a + 1 or to the world; a fifth of them
    exact multiples of earlier ones), in body order as build_rows emits them; inverse masses
    [1/kg] drawn in [0.2, 5] (inverse inertias 3 times those, 1/(kg m^2)); a right-hand side
    A y, y drawn in [-3, 3], in the range of A (consistent, as the engine's)."""
    n_body = draw(st.integers(1, 6))
    n_row = draw(st.integers(1, 3 * n_body + 3))
    rows = draw(body_rows(n_body, n_row, dependent=0.2, chain=True))
    rows.sort(key=lambda row: max(row[0], row[1]))
    row_body = [(a, b) for a, b, _, _ in rows]
    J = dense_jacobian(rows, n_body)
    w = np.repeat(draw(vectors(n_body, 0.2, 5.0)), 3) * np.tile([1.0, 1.0, 3.0], n_body)
    A = (J * w) @ J.T
    A = 0.5 * (A + A.T)
    rhs = A @ draw(vectors(n_row, -3.0, 3.0))
    return A, rhs, row_body, n_body, J, w


@settings(max_examples=200, deadline=None)
@given(systems())
def test_symmetric_factor_gives_the_velocity_change_of_lu_and_reads_only_the_lower_triangle(system):
    """Impulses x of a system with dependent rows are not unique (rows near the pivot
    threshold may be kept by one and dropped by the other), but the velocity change they make,
    W J^T x, is: both must give it, and both must solve A x = rhs."""
    A, rhs, row_body, n_body, J, w = system
    n = len(rhs)
    first, reach = _envelope(row_body, n_body)
    x_lu = np.zeros(n)
    _lu(A.copy(), first, reach, rhs.copy(), x_lu, np.zeros(n), TOL, np.zeros(n, np.int64))
    x_ldl = np.zeros(n)
    _ldl(A.copy(), first, reach, rhs.copy(), x_ldl, np.zeros(n), TOL, np.zeros(n, np.int64))
    assert np.all(np.isfinite(x_ldl))
    dv_lu = w * (J.T @ x_lu)
    dv_ldl = w * (J.T @ x_ldl)
    assert np.abs(dv_ldl - dv_lu).max() <= 1e-6 * (1.0 + np.abs(dv_lu).max())
    for x in (x_lu, x_ldl):
        assert np.abs(A @ x - rhs).max() <= 1e-6 * (1.0 + np.abs(rhs).max())


@pytest.mark.parametrize("lever", [7.1e-156, 1e-150, 1e-146])
def test_a_row_of_vanishing_jacobian_is_dropped_not_divided_by(lever):
    """A row whose Jacobian entries are of order 1e-155 (hypothesis found it) has a diagonal of
    1e-310, whose reciprocal overflows: both factorisations gave NaN impulses. It acts on
    nothing and must be dropped, the other row solved."""
    J = np.array([[0.0, 0.0, lever], [0.0, 0.0, 1.0]])
    w = np.array([1.0, 1.0, 3.0])
    A = (J * w) @ J.T
    rhs = A @ np.array([1.0, 1.0])
    first, reach = _envelope([(0, -1), (0, -1)], 1)
    for solve in (_lu, _ldl):
        x = np.zeros(2)
        solve(A.copy(), first, reach, rhs.copy(), x, np.zeros(2), TOL, np.zeros(2, np.int64))
        assert np.all(np.isfinite(x)), (solve.__name__, x)
        assert abs((w * (J.T @ x))[2] - (w * (J.T @ np.ones(2)))[2]) <= 1e-12


def test_dependent_rows_are_dropped_by_both():
    """Two copies of one row and a third row: rank 2; both factorisations drop the copy."""
    A = np.array([[2.0, 4.0, 1.0], [4.0, 8.0, 2.0], [1.0, 2.0, 3.0]])
    rhs = A @ np.array([1.0, 0.0, 1.0])
    first = np.zeros(3, np.int64)
    reach = np.full(3, 2, np.int64)
    for solve in (_lu, _ldl):
        x = np.zeros(3)
        assert solve(A.copy(), first, reach, rhs.copy(), x, np.zeros(3), TOL,
                     np.zeros(3, np.int64)) == 1
        assert x[1] == 0.0
        assert np.allclose(A @ x, rhs)


def _reference_elimination(A, first, reach, n, tol, symmetric):
    """The envelope LU (L D L^T where symmetric) as first written, each row tested against
    the column (first[i] <= k) in every loop: the operations, and their order, that the
    kernels must keep bit for bit. Returns #dropped."""
    dropped = 0
    scale = [abs(A[k, k]) for k in range(n)]
    for k in range(n):
        piv = A[k, k]
        below = [i for i in range(k + 1, reach[k] + 1) if first[i] <= k]
        if abs(piv) <= tol * scale[k] or scale[k] <= NULL_DIAGONAL:
            dropped += 1
            for j in below:
                A[j, k] = 0.0
                if not symmetric:
                    A[k, j] = 0.0
            A[k, k] = 0.0
            continue
        inv = 1.0 / piv
        if symmetric:       # rows from the last up, each row's update up to its diagonal
            for i in reversed(below):
                if A[i, k] == 0.0:
                    continue
                fct = A[i, k] * inv
                for j in below:
                    if j <= i:
                        A[i, j] -= fct * A[j, k]
                A[i, k] = fct
            continue
        for i in below:
            fct = A[i, k] * inv
            A[i, k] = fct
            if fct == 0.0:
                continue
            for j in below:
                A[i, j] -= fct * A[k, j]
    return dropped


@jit
def _factor_packed(low, up, start, first, reach, n, tol, symmetric, scale, rows):
    if symmetric:
        return factor_symmetric(low, start, first, reach, n, tol, scale, rows)
    return factor(low, up, start, first, reach, n, tol, scale, rows)


def _factor_only(A, first, reach, tol, symmetric, scale, rows):
    """Factor A in the envelope storage; A (n x n) gets the factors back inside the envelope."""
    n = A.shape[0]
    first = np.asarray(first, np.int64)
    low, up, start = _pack(A, first)
    dropped = _factor_packed(low, up, start, first, np.asarray(reach, np.int64), n, tol,
                             symmetric, scale, rows)
    A[...] = _unpack(low, up, start, first, n, symmetric)
    return dropped


@settings(max_examples=200, deadline=None)
@given(systems(), st.sampled_from([TOL, 1e-3, 0.0]), st.data())
def test_the_factorisations_keep_the_operations_of_the_envelope_elimination_bit_for_bit(
        system, tol, data):
    """Each column's rows are listed once (envelope.rows_below) instead of tested in every loop:
    the factors, dropped rows and all, must be those of the elimination as first written, to
    the bit (signed zeros included), for rows in build order and out of it; a non-symmetric
    matrix (the position correction's) goes through the LU."""
    A, rhs, row_body, n_body, J, w = system
    n = len(rhs)
    if data.draw(st.booleans(), label="out of build order"):
        order = data.draw(st.permutations(range(n)), label="order")
        A, row_body = A[np.ix_(order, order)], [row_body[r] for r in order]
    first, reach = _envelope(row_body, n_body)
    skew = A + 1e-3 * np.tril(np.ones((n, n)), -1) * A        # as J(q+) W J(q)^T: not symmetric
    for matrix, symmetric in ((A, True), (skew, False)):
        mine, theirs = matrix.copy(), matrix.copy()
        dropped = _factor_only(mine, first, reach, tol, symmetric, np.zeros(n),
                               np.zeros(n, np.int64))
        assert dropped == _reference_elimination(theirs, first, reach, n, tol, symmetric)
        keep = np.zeros((n, n), bool)
        for i in range(n):
            keep[i, first[i]:i + 1] = True
        if not symmetric:
            keep |= keep.T
        assert mine[keep].tobytes() == theirs[keep].tobytes()


@jit
def _compute_envelope(ws, n, n_body):
    compute_envelope(ws, n, n_body)


@settings(max_examples=100, deadline=None)
@given(st.data())
def test_the_envelope_kernel_gives_each_rows_first_row_and_each_columns_reach(data):
    """compute_envelope's first rows and reaches (what the factorisations and substitutions
    loop within) against their definitions (_envelope), for drawn rows (each a body or the
    world, and a body) in the order build_rows makes (body by body) and out of it, up to the
    workspace's room for rows."""
    import planarsim as ps
    from planarsim.state import make_workspace
    builder = ps.ModelBuilder(dt=1e-3)
    prev = None
    for i in range(6):       # a chain of 6 pinned links
        link = builder.add_body(f"link{i}", mass=1.0, inertia=0.1, pos=(i + 0.5, 0.0))
        builder.add_pin(f"pin{i}", prev, link, anchor_world=(float(i), 0.0))
        prev = link
    model = builder.compile()
    ws = make_workspace(model)
    pairs = st.tuples(st.integers(-1, model.n_body - 1), st.integers(0, model.n_body - 1))
    bodies = np.array(data.draw(st.lists(pairs, max_size=ws.row_first.shape[0]), label="rows"),
                      np.int64).reshape(-1, 2)
    n = len(bodies)
    if data.draw(st.booleans(), label="in build order"):
        bodies = bodies[np.argsort(bodies.max(axis=1), kind="stable")]
    ws.row_body[:n] = bodies
    _compute_envelope(ws, n, model.n_body)
    first, reach = _envelope([tuple(b) for b in bodies], model.n_body)
    assert list(ws.row_first[:n]) == list(first)
    assert list(ws.row_reach[:n]) == list(reach)
