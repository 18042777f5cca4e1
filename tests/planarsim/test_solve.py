"""The envelope solves: L D L^T of a symmetric system against the LU that serves the general
one, on random constraint rows (each touching at most two bodies, as in the engine), some of
them exactly dependent (closed loops)."""
import numpy as np
from hypothesis import given, settings, strategies as st

from numba import njit

from planarsim.compile import options as compile_options
from planarsim.kernels.solve import (compute_envelope, factor, factor_symmetric, substitute,
                                     substitute_symmetric)

TOL = 1e-11
# not cached: numba checks a cached function against its own file only, and these wrappers
# must follow the kernels they call
jit = njit(**dict(compile_options(), cache=False))


@jit
def _lu(A, start, below, rhs, x, scale, tol):
    dropped = factor(A, start, below, A.shape[0], tol, scale)
    substitute(A, start, below, rhs, x, A.shape[0])
    return dropped


@jit
def _ldl(A, start, below, rhs, x, scale, tol):
    dropped = factor_symmetric(A, start, below, A.shape[0], tol, scale)
    substitute_symmetric(A, start, below, rhs, x, A.shape[0])
    return dropped


def _rows_below(first):
    """(start, below): column k's rows below the diagonal whose envelope reaches it, ascending,
    at below[start[k]:start[k + 1]] (the definition of kernels.solve.compute_envelope)."""
    n = len(first)
    columns = [[i for i in range(k + 1, n) if first[i] <= k] for k in range(n)]
    start = np.zeros(n + 2, np.int64)
    start[1:n + 1] = np.cumsum([len(c) for c in columns])
    below = np.array([i for c in columns for i in c] or [0], np.int64)
    return start, below


def _envelope(row_body, n_body):
    """first[r]: first row sharing a body with r, and the rows below each column (_rows_below)
    (the definition of kernels.solve.compute_envelope)."""
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
    return _rows_below(first)


@st.composite
def systems(draw):
    """Rows on a chain of bodies (a row joins body a to a + 1 or to the world), an inverse
    mass matrix, and a right-hand side in the range of A (consistent, as the engine's)."""
    n_body = draw(st.integers(1, 6))
    n_row = draw(st.integers(1, 3 * n_body + 3))
    seed = draw(st.integers(0, 2 ** 32 - 1))
    rng = np.random.default_rng(seed)
    J = np.zeros((n_row, 3 * n_body))
    row_body = []
    for r in range(n_row):
        if r > 0 and rng.random() < 0.2:
            # an exact copy of an earlier row, scaled: a dependent row (a closed loop)
            k = int(rng.integers(0, r))
            J[r] = rng.uniform(0.5, 2.0) * J[k]
            row_body.append(row_body[k])
            continue
        a = int(rng.integers(0, n_body))
        b = a + 1 if (a + 1 < n_body and rng.random() < 0.7) else -1
        for body in (a, b):
            if body >= 0:
                J[r, 3 * body:3 * body + 3] = rng.normal(size=3)
        row_body.append((a, b))
    # rows in body order, as build_rows emits them
    order = sorted(range(n_row), key=lambda r: max(row_body[r]))
    J = J[order]
    row_body = [row_body[r] for r in order]
    w = np.repeat(rng.uniform(0.2, 5.0, n_body), 3) * np.tile([1.0, 1.0, 3.0], n_body)
    A = (J * w) @ J.T
    A = 0.5 * (A + A.T)
    rhs = A @ rng.normal(size=n_row)
    return A, rhs, row_body, n_body, J, w


@settings(max_examples=200, deadline=None)
@given(systems())
def test_symmetric_factor_gives_the_velocity_change_of_lu_and_reads_only_the_lower_triangle(system):
    """Impulses x of a system with dependent rows are not unique (rows near the pivot
    threshold may be kept by one and dropped by the other), but the velocity change they make,
    W J^T x, is: both must give it, and both must solve A x = rhs."""
    A, rhs, row_body, n_body, J, w = system
    n = len(rhs)
    start, below = _envelope(row_body, n_body)
    x_lu = np.zeros(n)
    _lu(A.copy(), start, below, rhs.copy(), x_lu, np.zeros(n), TOL)
    A_ldl = A.copy()
    A_ldl[np.triu_indices(n, 1)] = np.nan      # must never be read
    x_ldl = np.zeros(n)
    _ldl(A_ldl, start, below, rhs.copy(), x_ldl, np.zeros(n), TOL)
    assert np.all(np.isfinite(x_ldl))
    dv_lu = w * (J.T @ x_lu)
    dv_ldl = w * (J.T @ x_ldl)
    assert np.abs(dv_ldl - dv_lu).max() <= 1e-6 * (1.0 + np.abs(dv_lu).max())
    for x in (x_lu, x_ldl):
        assert np.abs(A @ x - rhs).max() <= 1e-6 * (1.0 + np.abs(rhs).max())


def test_dependent_rows_are_dropped_by_both():
    """Two copies of one row and a third row: rank 2; both factorisations drop the copy."""
    A = np.array([[2.0, 4.0, 1.0], [4.0, 8.0, 2.0], [1.0, 2.0, 3.0]])
    rhs = A @ np.array([1.0, 0.0, 1.0])
    start, below = _rows_below(np.zeros(3, np.int64))
    for solve in (_lu, _ldl):
        x = np.zeros(3)
        assert solve(A.copy(), start, below, rhs.copy(), x, np.zeros(3), TOL) == 1
        assert x[1] == 0.0
        assert np.allclose(A @ x, rhs)


@jit
def _compute_envelope(ws, n, n_body):
    compute_envelope(ws, n, n_body)


@settings(max_examples=100, deadline=None)
@given(st.integers(0, 2 ** 32 - 1))
def test_the_envelope_kernel_lists_each_columns_rows_below_it(seed):
    """compute_envelope's first rows and each column's rows below it (what the factorisations
    and substitutions loop over) against their definitions, for rows in the order build_rows
    makes (body by body) and out of it, up to the workspace's room for rows."""
    import planarsim as ps
    from planarsim.state import make_workspace
    builder = ps.ModelBuilder(dt=1e-3)
    prev = None
    for i in range(6):       # a chain of 6 pinned links: room for 12 rows
        link = builder.add_body(f"link{i}", mass=1.0, inertia=0.1, pos=(i + 0.5, 0.0))
        builder.add_pin(f"pin{i}", prev, link, anchor_world=(float(i), 0.0))
        prev = link
    model = builder.compile()
    ws = make_workspace(model)
    rng = np.random.default_rng(seed)
    capacity = ws.row_first.shape[0]
    n = int(rng.integers(0, capacity + 1))
    a = rng.integers(-1, model.n_body, n)
    b = rng.integers(0, model.n_body, n)
    bodies = np.stack([a, b], 1)
    if rng.random() < 0.5:
        bodies = bodies[np.argsort(bodies.max(axis=1), kind="stable")]
    ws.row_body[:n] = bodies
    _compute_envelope(ws, n, model.n_body)
    touched = [set(b[b >= 0]) for b in bodies]
    first = [min([k for k in range(r) if touched[k] & touched[r]] + [r]) for r in range(n)]
    assert list(ws.row_first[:n]) == first
    start, below = _rows_below(np.array(first, np.int64))
    assert list(ws.row_below_start[:n + 1]) == list(start[:n + 1])
    assert list(ws.row_below[:start[n]]) == list(below[:start[n]])
