"""The compiled kernels against their plain numpy references (tests/reference.py) on random
inputs: constraint rows and their Jacobians, the effective-mass matrix, and the mixed
complementarity solve against every combination of Coulomb contact modes."""
import math

import numpy as np
from hypothesis import given, settings, strategies as st
from numba import njit

import planarsim as ps
from planarsim.compile import options as compile_options
from planarsim.kernels.contacts import find_contacts
from planarsim.kernels.lcp import LCP_SOLVED
from planarsim.kernels.math2d import update_trig
from planarsim.kernels.mixed_lcp import assemble_dense, solve_mixed_lcp
from planarsim.kernels.rows import build_rows
from planarsim.state import make_workspace

import reference as ref

# not cached: numba checks a cached function against its own file only, and these wrappers
# must follow the kernels they call
jit = njit(**dict(compile_options(), cache=False))


@jit
def _rows_at(m, s, ws):
    """Stages 3-4 at s.q with every contact pinned: the rows, their errors and Jacobians."""
    update_trig(s.q, ws.body_cs)
    for i in range(s.q.shape[0]):
        for k in range(3):
            ws.q_pred[i, k] = s.q[i, k]
    update_trig(ws.q_pred, ws.cs_pred)
    find_contacts(m, s, ws, m.dt)
    build_rows(m, s, ws)
    n = ws.n_row[0]
    for r in range(n):
        ws.island_rows[r] = r
    assemble_dense(m, ws, ws.island_rows, 0, n)
    return n


@jit
def _solve(m, ws, n):
    status, pivots, scale = solve_mixed_lcp(m, ws, ws.island_rows, 0, n, 40 * (4 * n + 10), 0.0)
    return status, pivots


def _mechanism(n_body, slope_deg, seed):
    """A chain of n_body boxes (pins with limits; per seed the first pinned to the world, a rod
    across three or more) with point contacts at some bodies' lower corners, on a slope: some
    seeds give independent rows, others closed loops with redundant ones."""
    rng = np.random.default_rng(seed)
    b = ps.ModelBuilder(terrain=ps.terrain.slope(slope_deg))
    world_pin = rng.uniform() < 0.5
    prev = None
    for k in range(n_body):
        body = b.add_body(f"b{k}", mass=float(rng.uniform(0.1, 10.0)), inertia=float(rng.uniform(0.01, 1.0)),
                          pos=(0.4 * k, 0.3))
        if prev is not None or world_pin:
            b.add_pin(f"p{k}", prev, body, anchor_world=(0.4 * k - 0.2, 0.3),
                      limit=(-0.5, 0.5) if prev is not None else None)
        if k == 0 or rng.uniform() < 0.6:
            b.add_point_contact(f"c{k}", body, local=(0.1, -0.15), mu=float(rng.uniform(0.2, 1.2)))
        prev = body
    if n_body >= 3 and rng.uniform() < 0.5:
        b.add_rod("r", 0, n_body - 1, anchor_a=(0.0, 0.1), anchor_b=(0.0, 0.1))
    return b.compile()


def _dense(ws, n, n_body):
    """The rows' Jacobians as one (n, 3 n_body) matrix."""
    J = np.zeros((n, 3 * n_body))
    for r in range(n):
        for e in range(2):
            body = ws.row_body[r, e]
            if body >= 0:
                J[r, 3 * body:3 * body + 3] += ws.row_J[r, e]
    return J


@settings(max_examples=40, deadline=None)
@given(n_body=st.integers(1, 4), slope=st.floats(-20.0, 20.0), seed=st.integers(0, 10_000))
def test_rows_and_jacobians_match_the_constraint_functions(n_body, slope, seed):
    model = _mechanism(n_body, slope, seed)
    a = model.arrays
    rng = np.random.default_rng(seed + 1)
    q = model.q0 + rng.normal(0.0, 0.05, model.q0.shape)
    state = ps.make_state(model, q=q)
    state.contact_mode[:] = 1          # pinned: a normal and a tangent row each
    state.limit_active[:] = np.isfinite(a.pin_limit)   # both limit rows of every limited pin
    ws = make_workspace(model)
    n = _rows_at(a, state, ws)
    J = _dense(ws, n, model.n_body)
    th = math.atan(a.terrain_coef[1])
    normal = np.array([-math.sin(th), math.cos(th)])
    ground = np.array([0.0, a.terrain_coef[0]])
    for r in range(n):
        kind, o = ws.row_kind[r], ws.row_owner[r]
        if kind in (ref.PIN_X, ref.PIN_Y):
            f = lambda x, j=o, k=kind: ref.pin_error(a, x, j)[k - ref.PIN_X]
        elif kind == ref.ROD:
            f = lambda x, j=o: ref.rod_error(a, x, j)
        elif kind in (ref.LIMIT_LO, ref.LIMIT_HI):
            f = lambda x, j=o, k=kind: ref.limit_errors(a, x, j)[k - ref.LIMIT_LO]
        elif kind == ref.CONTACT_N:
            f = lambda x, i=o: ref.point_gap(a, x, i, normal, ground)
        else:   # the tangent row holds the point where it touched: t . (p - g0)
            g0 = ws.contact_ground[o].copy()
            t = np.array([normal[1], -normal[0]])
            f = lambda x, i=o, g0=g0, t=t: float(t @ (ref.world_point(x, a.contact_body[i], a.contact_local[i]) - g0))
        assert abs(ws.row_c[r] - f(q)) < 1e-12, (kind, o)
        assert np.allclose(J[r], ref.jacobian(f, q)[0], atol=1e-8), (kind, o)
    # the effective-mass matrix
    A = ref.delassus(J, ref.inverse_mass(a))
    assert np.allclose(ws.lcp_A[:n, :n], A, rtol=1e-12, atol=1e-12 * np.abs(A).max())


@settings(max_examples=300, deadline=None)
@given(n_body=st.integers(1, 3), slope=st.floats(-20.0, 20.0), seed=st.integers(0, 1_000_000))
def test_mixed_complementarity_solve_meets_coulomb_and_matches_the_enumeration(n_body, slope, seed):
    """Problems of the engine's own rows (random mechanisms: pins, limits, a rod, a pinned
    contact per body, so closed loops and redundant rows), b from random velocities."""
    model = _mechanism(n_body, slope, seed)
    a = model.arrays
    rng = np.random.default_rng(seed + 2)
    state = ps.make_state(model, q=model.q0 + rng.normal(0.0, 0.05, model.q0.shape))
    state.contact_mode[:] = 1
    state.limit_active[:] = np.isfinite(a.pin_limit) & (rng.uniform(size=a.pin_limit.shape) < 0.3)
    ws = make_workspace(model)
    n = _rows_at(a, state, ws)
    J = _dense(ws, n, model.n_body)
    b = J @ rng.normal(0.0, 1.0, J.shape[1])
    ws.row_b[:n] = b
    A = ws.lcp_A[:n, :n].copy()
    kinds = [int(k) for k in ws.row_kind[:n]]
    mu_of_row = np.array([a.contact_mu[o] if k >= ref.CONTACT_N else 0.0 for k, o in zip(kinds, ws.row_owner[:n])])
    status, pivots = _solve(a, ws, n)
    solutions = ref.coulomb_solutions(A, b, kinds, mu_of_row)
    full_rank = np.linalg.matrix_rank(J) == n
    scale = 1.0 + np.abs(b).max()
    if status != LCP_SOLVED:
        # the engine then uses its frictionless rule; Lemke's path must not miss the one
        # answer of a problem without redundant rows
        assert not (full_rank and len(solutions) == 1), (seed, status)
        return
    x = ws.lam[:n].copy()
    assert ref.coulomb_violations(A, b, kinds, mu_of_row, x, scale) <= 1e-7 * scale * (1 + np.abs(x).max())
    if full_rank:
        # without redundant rows Coulomb's problem here has this one answer
        assert len(solutions) >= 1
        assert any(np.allclose(x, s_, rtol=1e-7, atol=1e-9 * scale) for s_ in solutions), seed
