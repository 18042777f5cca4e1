"""The sparse factorisation (kernels/solver/sparse_factor.py) that serves piles and walls: on random
rows between bodies scattered in the plane (each row touching one or two bodies, as the
engine's), some exactly dependent (closed loops, redundant contacts), its answers must solve
A x = rhs and give the velocity change W J^T x of the envelope elimination; on
independent rows, the one answer. The order it finds must be a permutation, and its
factors must fit the room analyse asked for."""
import numpy as np
from hypothesis import given, settings, strategies as st
from hypothesis.extra.numpy import arrays
from numba import njit

import planarsim as ps
from planarsim import state as state_module
from planarsim.compile import options as compile_options
from planarsim.kernels.solver import matrix
from planarsim.kernels.solver import sparse_factor as sf
from planarsim.kernels.codes import ROW_CONTACT_N
from strategies import INERTIA, MASS, body_rows, dense_jacobian, reals, vectors

TOL = 1e-11
jit = njit(**dict(compile_options(), cache=False))


@jit
def _sparse_solve_marked(m, q, ws, n, n_body, rhs, x, symmetric, dependent, exclude):
    """Order (with the rows marked in `dependent` left out if `exclude`: order_rows), analyse,
    assemble, factor and solve rows 0..n-1 sparse; returns #dropped (-1: no room)."""
    sf.order_rows(q, ws, n, dependent, exclude)
    if not sf.analyse(ws, n, n_body):
        return -1
    ws.factor_kind[0] = matrix.SPARSE
    matrix.assemble(m, ws, ws.row_J, ws.row_F, n, symmetric)
    dropped = matrix.factor_ws(ws, n, TOL, symmetric)
    matrix.substitute_ws(ws, rhs, x, n, symmetric)
    return dropped


def _sparse_solve(m, q, ws, n, n_body, rhs, x, symmetric):
    return _sparse_solve_marked(m, q, ws, n, n_body, rhs, x, symmetric, np.zeros(1, np.int64),
                                False)


@jit
def _envelope_solve(m, q, ws, n, n_body, rhs, x, symmetric):
    ws.factor_kind[0] = matrix.ENVELOPE
    matrix.arrange(q, ws, n, n_body, ws.start.contact_dependent, False)  # (< SPARSE_MIN_ROWS)
    matrix.assemble(m, ws, ws.row_J, ws.row_F, n, symmetric)
    dropped = matrix.factor_ws(ws, n, TOL, symmetric)
    matrix.substitute_ws(ws, rhs, x, n, symmetric)
    return dropped


def _bodies(n_body, rng):
    """A model of n_body free bodies of random masses and inertias, scattered in the plane
    (the seeded pile of test_a_pile_too_large_for_the_storage_asks_for_room)."""
    b = ps.ModelBuilder(dt=1e-3)
    for i in range(n_body):
        b.add_body(f"b{i}", mass=float(rng.uniform(0.2, 5.0)), inertia=float(rng.uniform(0.01, 2.0)),
                   pos=(float(rng.uniform(-3, 3)), float(rng.uniform(-3, 3))))
    return b.compile()


@st.composite
def piles(draw, dependent):
    """(model, rows): 1 to 40 free bodies (masses [kg] in MASS, inertias [kg m^2] in INERTIA,
    positions [m] in [-3, 3]^2) and up to SPARSE_MIN_ROWS - 1 rows between them (body_rows:
    on one body or two, a share `dependent` of them exact multiples of earlier ones)."""
    n_body = draw(st.integers(1, 40))
    n_row = draw(st.integers(1, min(4 * n_body + 4, sf.SPARSE_MIN_ROWS - 1)))
    b = ps.ModelBuilder(dt=1e-3)
    for i in range(n_body):
        b.add_body(f"b{i}", mass=draw(reals(*MASS)), inertia=draw(reals(*INERTIA)),
                   pos=tuple(draw(vectors(2, -3.0, 3.0))))
    return b.compile(), draw(body_rows(n_body, n_row, draw(dependent), chain=False))


def _stack(rows, n_body):
    """row_body (n, 2), row_J (n, 2, 3) and the dense J (n, 3 n_body) of body_rows' rows (the
    second body first, -1 where a row has one)."""
    row_body = np.array([(b, a) for a, b, _, _ in rows], np.int64)
    row_J = np.array([(jb, ja) for _, _, ja, jb in rows])
    return row_body, row_J, dense_jacobian(rows, n_body)


def _workspace(model, n_row):
    """A workspace with room for n_row rows and every entry their factors could need."""
    ws = state_module.make_workspace(model)
    arrays = state_module._solve_arrays(model, n_row, n_row * (n_row + 1) // 2 + 1, 1)
    return ws._replace(**arrays)


def _rows(model, n_row, dependent, rng):
    """row_body (n, 2), row_J (n, 2, 3) and the dense J (n, 3 n_body): rows on one body (the
    other -1) or two, a share of them exact multiples of earlier ones."""
    n_body = model.n_body
    row_body = np.full((n_row, 2), -1, np.int64)
    row_J = np.zeros((n_row, 2, 3))
    for r in range(n_row):
        if r > 0 and rng.random() < dependent:
            k = int(rng.integers(0, r))
            row_body[r] = row_body[k]
            row_J[r] = rng.uniform(0.5, 2.0) * row_J[k]
            continue
        a = int(rng.integers(0, n_body))
        b = int(rng.integers(0, n_body)) if rng.random() < 0.7 else -1
        if b == a:
            b = -1
        row_body[r] = (b, a)
        row_J[r, 1] = rng.normal(size=3)
        if b >= 0:
            row_J[r, 0] = rng.normal(size=3)
    J = np.zeros((n_row, 3 * n_body))
    for r in range(n_row):
        for e in range(2):
            body = row_body[r, e]
            if body >= 0:
                J[r, 3 * body:3 * body + 3] += row_J[r, e]
    return row_body, row_J, J


def _weights(model):
    a = model.arrays
    return np.repeat(np.stack([a.body_inv_mass, a.body_inv_mass, a.body_inv_inertia], 1).ravel()
                     .reshape(-1, 3), 1, 0).ravel()


def _consistent_system(model, rows, data):
    """(J, the weights W, A = J W J^T, a consistent right-hand side A y with y drawn in
    [-3, 3], the bodies' positions) of body_rows' rows."""
    _, _, J = _stack(rows, model.n_body)
    w = _weights(model)
    A = (J * w) @ J.T
    rhs = A @ data.draw(vectors(len(rows), -3.0, 3.0), label="y")
    return J, w, A, rhs, np.array(model.q0, dtype=float)


def _filled_workspace(model, rows):
    """_workspace for the rows, their bodies and Jacobians (F = J) filled in."""
    n_row = len(rows)
    row_body, row_J, _ = _stack(rows, model.n_body)
    ws = _workspace(model, n_row)
    ws.row_body[:n_row] = row_body
    ws.row_J[:n_row] = row_J
    ws.row_F[:n_row] = row_J
    return ws


@settings(max_examples=100, deadline=None)        # 150 with a seed: drawing the rows is slower
@given(piles(dependent=reals(0.0, 0.5)), st.data())
def test_the_sparse_factorisation_solves_what_the_envelope_solves(pile, data):
    """Rows some of which are dependent, a consistent right-hand side A y (y drawn in
    [-3, 3], as the engine's)."""
    model, rows = pile
    n_body, n_row = model.n_body, len(rows)
    J, w, A, rhs, q = _consistent_system(model, rows, data)
    answers = []
    for solve in (_sparse_solve, _envelope_solve):
        ws = _filled_workspace(model, rows)
        x = np.zeros(n_row)
        dropped = solve(model.arrays, q, ws, n_row, n_body, rhs.copy(), x, True)
        assert dropped >= 0
        assert np.all(np.isfinite(x))
        assert np.abs(A @ x - rhs).max() <= 1e-7 * (1.0 + np.abs(rhs).max())
        answers.append((x, dropped, ws))
    (xs, ds, ws), (xe, de, _) = answers
    perm = ws.sp_perm[:n_row]
    assert sorted(perm) == list(range(n_row))
    assert np.array_equal(ws.sp_iperm[perm], np.arange(n_row))
    # impulses of dependent rows are not unique (a row whose pivot is rounding near the
    # threshold may be kept by one order and dropped by the other); the velocity change is
    dv_s, dv_e = w * (J.T @ xs), w * (J.T @ xe)
    assert np.abs(dv_s - dv_e).max() <= 1e-6 * (1.0 + np.abs(dv_e).max())


@settings(max_examples=60, deadline=None)         # 100 with a seed: drawing the rows is slower
@given(piles(dependent=st.just(0.0)), st.data())
def test_the_sparse_lu_of_a_matrix_that_is_not_symmetric_gives_its_one_answer(pile, data):
    """J W F^T with F != J (sliding contacts, the position correction's J(q+) W J(q)^T; F's
    nonzero entries J's moved by up to 0.15, drawn): independent rows, the answer of a dense
    solve of a drawn right-hand side (entries in [-3, 3])."""
    model, rows = pile
    n_body, n_row = model.n_body, len(rows)
    row_body, row_J, J = _stack(rows, n_body)
    if np.linalg.matrix_rank(J) < n_row:
        return
    move = data.draw(arrays(np.float64, row_J.shape, elements=reals(-0.15, 0.15), fill=st.nothing()),
                     label="F - J")
    row_F = row_J + move * (row_J != 0.0)
    F = np.zeros_like(J)
    for r in range(n_row):
        for e in range(2):
            body = row_body[r, e]
            if body >= 0:
                F[r, 3 * body:3 * body + 3] += row_F[r, e]
    w = _weights(model)
    A = (J * w) @ F.T
    if np.linalg.cond(A) > 1e8:
        return
    rhs = data.draw(vectors(n_row, -3.0, 3.0), label="rhs")
    ws = _workspace(model, n_row)
    ws.row_body[:n_row] = row_body
    ws.row_J[:n_row] = row_J
    ws.row_F[:n_row] = row_F
    x = np.zeros(n_row)
    assert _sparse_solve(model.arrays, np.array(model.q0, float), ws, n_row, n_body, rhs.copy(),
                         x, False) == 0
    assert np.allclose(x, np.linalg.solve(A, rhs), rtol=1e-8, atol=1e-8 * np.abs(x).max())


def test_a_pile_too_large_for_the_storage_asks_for_room():
    """analyse finds the entries the factors need before writing any: a workspace with too
    few asks for them (ws.room) and returns False."""
    rng = np.random.default_rng(3)
    model = _bodies(30, rng)
    row_body, row_J, J = _rows(model, 100, 0.2, rng)
    ws = state_module.make_workspace(model)._replace(
        **state_module._solve_arrays(model, 100, 10, 1))
    ws.row_body[:100] = row_body
    ws.row_J[:100] = row_J
    x = np.zeros(100)
    assert _sparse_solve(model.arrays, np.array(model.q0, float), ws, 100, 30, np.ones(100), x,
                         True) == -1
    assert ws.room[0] == 1 and ws.room[2] > 10


@settings(max_examples=60, deadline=None)
@given(piles(dependent=reals(0.0, 0.5)), st.data())
def test_rows_left_out_as_dependent_come_last_and_the_others_solve_as_alone(pile, data):
    """Rows marked as dropped by the last step (State.contact_dependent: here the rows the
    full factorisation drops, and some drawn others) are ordered after all the rest, in
    their own order, are dropped without elimination, and the remaining rows' answer solves
    their own equations; where only truly dependent rows are left out, it solves them all
    (a consistent right-hand side A y)."""
    model, rows = pile
    n_body, n_row = model.n_body, len(rows)
    J, w, A, rhs, q = _consistent_system(model, rows, data)
    ws = _filled_workspace(model, rows)
    ws.row_kind[:n_row] = ROW_CONTACT_N
    ws.row_owner[:n_row] = np.arange(n_row)
    x = np.zeros(n_row)
    assert _sparse_solve(model.arrays, q, ws, n_row, n_body, rhs.copy(), x, True) >= 0
    dropped_rows = ws.sp_pivot[ws.sp_iperm[:n_row]] == 0.0
    extra = data.draw(arrays(np.bool_, n_row), label="also left out") & data.draw(st.booleans())
    out = dropped_rows | extra
    dependent = out.astype(np.int64)          # bit 1: a normal row
    dropped = _sparse_solve_marked(model.arrays, q, ws, n_row, n_body, rhs.copy(), x, True,
                                   dependent, True)
    factored = int(ws.sp_factored[0])
    assert factored == n_row - out.sum()
    perm = ws.sp_perm[:n_row]
    assert sorted(perm) == list(range(n_row))
    assert list(perm[factored:]) == list(np.flatnonzero(out))
    assert np.all(ws.sp_pivot[factored:n_row] == 0.0) and dropped >= out.sum()
    assert np.all(x[out] == 0.0)
    keep = ~out
    scale = 1e-7 * (1.0 + np.abs(rhs).max())
    assert np.abs(A[np.ix_(keep, keep)] @ x[keep] - rhs[keep]).max(initial=0.0) <= scale
    if not extra.any():
        assert np.abs(A @ x - rhs).max() <= scale
