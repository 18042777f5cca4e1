"""The complementarity solve's joint block (kernels/solver/mixed_lcp._factor_joints): A = J W J^T of
joint rows that may be exactly dependent (a closed loop), with bodies whose masses and
inertias differ by up to 1e8. Its factorization must leave out exactly the dependent rows,
whatever their order and scale, and solve consistent right-hand sides with impulses bounded
in each row's own scale."""
import numpy as np
from hypothesis import given, settings, strategies as st
from numba import njit

from planarsim.compile import options as compile_options
from planarsim.kernels.solver.mixed_lcp import _factor_joints, _solve_joints
from strategies import full_rank, vectors

jit = njit(**dict(compile_options(), cache=False))


@jit
def _factor_solve(A, b, rows, B, G, x, local):
    n = b.shape[0]
    _factor_joints(A, local, B, n, rows, G)
    for i in range(n):
        G[i, 0] = b[rows[i]]
    _solve_joints(B, n, G, 0)
    dropped = 0
    for i in range(n):
        x[rows[i]] = G[i, 0]
        if B[i, i] == 0.0:
            dropped += 1
    return dropped


def _solve(A, b, rows):
    """(impulses x, rows left out) of A x = b."""
    n = len(b)
    x = np.zeros(n)
    dropped = _factor_solve(A, b, rows, np.zeros((n, n)), np.zeros((n, 2)), x, np.arange(n))
    return x, dropped


@st.composite
def dependent_joints(draw):
    """(A, b, d): n joint rows on d < n degrees of freedom whose inverse masses and inertias
    are 10^U(-4, 4) apart (A = J W J^T, singular by n - d; J of full rank d, its entries lever
    arms of order 1 drawn in [-3, 3]), each row in units of its own (scaled by 10^U(-2, 2));
    b = A y for drawn impulses y in [-3, 3] (a consistent drift)."""
    n = draw(st.integers(2, 10))
    d = draw(st.integers(max(1, n - 3), n - 1))
    row_scale = 10.0 ** draw(vectors(n, -2.0, 2.0))
    J = draw(full_rank(n, d)) * row_scale[:, None]
    W = 10.0 ** draw(vectors(d, -4.0, 4.0))
    A = (J * W) @ J.T
    return A, A @ draw(vectors(n, -3.0, 3.0)), d


def _scaled_least(A, b):
    """The least impulses solving A x = b in each row's own scale (x_i sqrt(A_ii)): that
    scale, and those impulses so scaled."""
    scale = np.sqrt(np.diag(A))
    return scale, np.linalg.lstsq(A / np.outer(scale, scale), b / scale, rcond=None)[0]


@settings(max_examples=300, deadline=None)
@given(dependent_joints())
def test_the_joint_block_leaves_out_exactly_the_dependent_rows(problem):
    """The rows left out are as many as the dependencies; the others solve a consistent
    drift to rounding, with impulses within a small factor of the least (in each row's own
    scale)."""
    A, b, d = problem
    n = len(b)
    x, dropped = _solve(A, b, np.arange(n))
    assert dropped == n - d
    assert np.abs(A @ x - b).max() <= 1e-8 * np.abs(b).max()
    scale, least = _scaled_least(A, b)
    assert np.abs(x * scale).max() <= 1e2 * np.abs(least).max()
