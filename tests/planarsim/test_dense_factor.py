"""The dense elimination (kernels/solver/dense.py) of a walker's few rows must give the
envelope elimination's (envelope.py) factors and answers to the last bit: on random rows
between bodies (each row on one body or two, as the engine's), some exact multiples of
earlier ones (closed loops: dropped rows), J W J^T (L D L^T) and J W F^T with F != J (LU,
sliding contacts and the position correction), the same rows dropped, the same pivots and
the same solution, compared with ==; two right-hand sides solved in one pass as each alone."""
import numpy as np
from hypothesis import given, settings, strategies as st
from hypothesis.extra.numpy import arrays
from numba import njit

import planarsim as ps
from planarsim import state as state_module
from planarsim.compile import options as compile_options
from planarsim.kernels.codes import DENSE_MAX_ROWS
from planarsim.kernels.solver import matrix
from strategies import INERTIA, MASS, body_rows, reals, vectors

jit = njit(**dict(compile_options(), cache=False))
TOL = 1e-11


@jit
def _solve(m, q, ws, n, n_body, rhs, x, pivots, symmetric, kind):
    """Rows 0..n-1 arranged, then assembled, factored and solved by factorisation `kind`
    (matrix.ENVELOPE or matrix.DENSE); pivots: each row's pivot; returns #dropped."""
    matrix.arrange(q, ws, n, n_body, ws.start.contact_dependent, False)
    ws.factor_kind[0] = kind
    matrix.assemble(m, ws, ws.row_J, ws.row_F, n, symmetric)
    dropped = matrix.factor_ws(ws, n, TOL, symmetric)
    for r in range(n):
        pivots[r] = matrix.diagonal_and_pivot(ws, r)[1]
    matrix.substitute_ws(ws, rhs, x, n, symmetric)
    return dropped


@jit
def _pair(m, q, ws, n, n_body, rhs, x, rhs2, x2):
    """Rows 0..n-1 (not symmetric) factored dense, both right-hand sides solved in one pass
    (matrix.substitute_pair_ws)."""
    matrix.arrange(q, ws, n, n_body, ws.start.contact_dependent, False)
    ws.factor_kind[0] = matrix.DENSE
    matrix.assemble(m, ws, ws.row_J, ws.row_F, n, False)
    matrix.factor_ws(ws, n, TOL, False)
    matrix.substitute_pair_ws(ws, rhs, x, rhs2, x2, n)


@st.composite
def systems(draw):
    """(model, rows, F's entries moved from J's or None): 1 to 12 free bodies and 1 to
    DENSE_MAX_ROWS rows between them, up to half of them dependent."""
    n_body = draw(st.integers(1, 12))
    n_row = draw(st.integers(1, DENSE_MAX_ROWS))
    b = ps.ModelBuilder(dt=1e-3)
    for i in range(n_body):
        b.add_body(f"b{i}", mass=draw(reals(*MASS)), inertia=draw(reals(*INERTIA)),
                   pos=tuple(draw(vectors(2, -3.0, 3.0))))
    rows = draw(body_rows(n_body, n_row, draw(reals(0.0, 0.5)), chain=draw(st.booleans())))
    move = None
    if draw(st.booleans()):
        move = draw(arrays(np.float64, (n_row, 2, 3), elements=reals(-0.15, 0.15),
                           fill=st.nothing()))
    return b.compile(), rows, move


def _workspace(model, rows, move):
    n_row = len(rows)
    ws = state_module.make_workspace(model)
    ws = ws._replace(**state_module._solve_arrays(model, n_row, n_row * (n_row + 1) // 2 + 1, 1))
    ws.row_body[:n_row] = [(b, a) for a, b, _, _ in rows]
    ws.row_J[:n_row] = [(jb, ja) for _, _, ja, jb in rows]
    ws.row_F[:n_row] = ws.row_J[:n_row]
    if move is not None:
        ws.row_F[:n_row] += move * (ws.row_J[:n_row] != 0.0)
    # the square's storage as a step leaves it, stale: NaN, so that an entry read before it is
    # written shows in the answer
    ws.A_dense[:] = np.nan
    return ws


@settings(max_examples=150, deadline=None)
@given(systems(), st.data())
def test_the_dense_elimination_is_the_envelope_elimination_bit_for_bit(system, data):
    model, rows, move = system
    n_row = len(rows)
    rhs = np.array(data.draw(vectors(n_row, -3.0, 3.0), label="rhs"))
    q = np.array(model.q0, dtype=float)
    out = []
    for kind in (matrix.ENVELOPE, matrix.DENSE):
        ws = _workspace(model, rows, move)
        assert ws.A_dense.shape[0] >= n_row
        x, pivots = np.zeros(n_row), np.zeros(n_row)
        dropped = _solve(model.arrays, q, ws, n_row, model.n_body, rhs.copy(), x, pivots,
                         move is None, kind)
        assert ws.factor_kind[0] == kind
        out.append((dropped, pivots, x))
    (de, pe, xe), (dd, pd, xd) = out
    assert de == dd
    assert np.array_equal(pe, pd)
    assert np.array_equal(xe, xd, equal_nan=True)
    if move is not None:
        # two right-hand sides in one pass (the position correction's move and velocity):
        # each the answer of its own substitution
        rhs2 = np.array(data.draw(vectors(n_row, -3.0, 3.0), label="rhs2"))
        ws = _workspace(model, rows, move)
        x, x2 = np.zeros(n_row), np.zeros(n_row)
        _pair(model.arrays, q, ws, n_row, model.n_body, rhs.copy(), x, rhs2.copy(), x2)
        assert np.array_equal(x, xd, equal_nan=True)
        ws = _workspace(model, rows, move)
        alone = np.zeros(n_row)
        _solve(model.arrays, q, ws, n_row, model.n_body, rhs2.copy(), alone, np.zeros(n_row),
               False, matrix.DENSE)
        assert np.array_equal(x2, alone, equal_nan=True)


def test_a_walkers_rows_are_eliminated_dense():
    """dm_control's walker (seven bodies on six hinges with rotors, its feet on the ground):
    its 18 to 22 rows fill most of their envelope, so matrix.arrange takes the dense square
    for its solves and corrections."""
    gymnasium = __import__("pytest").importorskip("gymnasium")
    import planarsim.envs  # noqa: F401  (registers the environments)
    env = gymnasium.make("planarsim/dmc-walker-walk-v0").unwrapped
    env.reset(seed=0)
    for _ in range(20):
        env.step(np.zeros(env.action_space.shape))
    ws = env.sim.ws
    assert 18 <= ws.n_row[0] <= DENSE_MAX_ROWS
    assert ws.factor_kind[0] == matrix.DENSE
