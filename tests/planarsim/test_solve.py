"""The envelope solves: L D L^T of a symmetric system against the LU that serves the general
one, on random constraint rows (each touching at most two bodies, as in the engine), some of
them exactly dependent (closed loops)."""
import numpy as np
from hypothesis import given, settings, strategies as st

from numba import njit

from planarsim.compile import options as compile_options
from planarsim.kernels.solve import factor, factor_symmetric, substitute, substitute_symmetric

TOL = 1e-11
# not cached: numba checks a cached function against its own file only, and these wrappers
# must follow the kernels they call
jit = njit(**dict(compile_options(), cache=False))


@jit
def _lu(A, first, reach, rhs, x, scale, tol):
    dropped = factor(A, first, reach, A.shape[0], tol, scale)
    substitute(A, first, reach, rhs, x, A.shape[0])
    return dropped


@jit
def _ldl(A, first, reach, rhs, x, scale, tol):
    dropped = factor_symmetric(A, first, reach, A.shape[0], tol, scale)
    substitute_symmetric(A, first, reach, rhs, x, A.shape[0])
    return dropped


def _envelope(row_body, n_body):
    """first[r]: first row sharing a body with r; reach[k]: last row whose envelope holds k
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
    reach = np.arange(n)
    for i in range(n):
        reach[first[i]:i] = i
    return first, reach


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
    first, reach = _envelope(row_body, n_body)
    x_lu = np.zeros(n)
    _lu(A.copy(), first, reach, rhs.copy(), x_lu, np.zeros(n), TOL)
    A_ldl = A.copy()
    A_ldl[np.triu_indices(n, 1)] = np.nan      # must never be read
    x_ldl = np.zeros(n)
    _ldl(A_ldl, first, reach, rhs.copy(), x_ldl, np.zeros(n), TOL)
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
    first = np.zeros(3, np.int64)
    reach = np.full(3, 2, np.int64)
    for solve in (_lu, _ldl):
        x = np.zeros(3)
        assert solve(A.copy(), first, reach, rhs.copy(), x, np.zeros(3), TOL) == 1
        assert x[1] == 0.0
        assert np.allclose(A @ x, rhs)
