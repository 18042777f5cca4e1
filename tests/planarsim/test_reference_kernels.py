"""The compiled kernels against their plain numpy references (tests/reference.py) on random
inputs: constraint rows and their Jacobians, the effective-mass matrix, and the mixed
complementarity solve against every combination of Coulomb contact modes."""
import math

import numpy as np
from hypothesis import given, settings, strategies as st
from numba import njit

import planarsim as ps
from planarsim.compile import options as compile_options
from planarsim.kernels.geometry.contacts import find_contacts
from planarsim.kernels.solver.lcp import LCP_SOLVED
from planarsim.kernels.math2d import update_trig
from planarsim.kernels.solver.mixed_lcp import assemble_dense, solve_mixed_lcp
from planarsim.kernels.constraints.rows import build_rows
from planarsim.state import make_workspace

import reference as ref

# not cached: numba checks a cached function against its own file only, and these wrappers
# must follow the kernels they call
jit = njit(**dict(compile_options(), cache=False))


@jit
def _rows_at(m, s, ws):
    """Stages 2-3 at s.q with every contact pinned: the contacts, the rows, their errors and
    Jacobians."""
    update_trig(s.q, ws.body_cs)
    for i in range(s.q.shape[0]):
        for k in range(3):
            ws.q_pred[i, k] = s.q[i, k]
    update_trig(ws.q_pred, ws.cs_pred)
    find_contacts(m, s, ws, m.dt)
    build_rows(m, s, ws, m.dt)
    n = ws.n_row[0]
    for r in range(n):
        ws.island_rows[r] = r
    assemble_dense(m, ws, ws.island_rows, 0, n)
    return n


@jit
def _solve(m, ws, n):
    status, pivots, scale = solve_mixed_lcp(m, ws, ws.island_rows, 0, n, 40 * (4 * n + 10), 0.0)
    return status, pivots


@st.composite
def mechanisms(draw, max_bodies):
    """What _mechanism builds, drawn (so a failing case shrinks to fewer bodies, equal
    masses, no rod, ...): a chain of 1..max_bodies boxes (pins with limits; perhaps the first
    pinned to the world, a rod across three or more) with point contacts at some bodies'
    lower corners (always the first's), on a slope: some independent rows, others closed
    loops with redundant ones."""
    n_body = draw(st.integers(1, max_bodies))

    def each(strategy, n=n_body):
        return draw(st.lists(strategy, min_size=n, max_size=n))
    return dict(slope_deg=draw(st.floats(-20.0, 20.0)), world_pin=draw(st.booleans()),
                mass=each(st.floats(0.1, 10.0)), inertia=each(st.floats(0.01, 1.0)),
                contact=[True] + each(st.booleans(), n_body - 1), mu=each(st.floats(0.2, 1.2)),
                rod=n_body >= 3 and draw(st.booleans()))


def offsets(n_body, scale):
    """(n_body, 3) draws in [-scale, scale] (a pose's or a velocity's)."""
    return st.lists(st.floats(-scale, scale), min_size=3 * n_body, max_size=3 * n_body).map(
        lambda x: np.reshape(x, (n_body, 3)))


def _mechanism(slope_deg, world_pin, mass, inertia, contact, mu, rod):
    b = ps.ModelBuilder(terrain=ps.terrain.slope(slope_deg))
    n_body = len(mass)
    prev = None
    for k in range(n_body):
        body = b.add_body(f"b{k}", mass=mass[k], inertia=inertia[k], pos=(0.4 * k, 0.3))
        if prev is not None or world_pin:
            b.add_pin(f"p{k}", prev, body, anchor_world=(0.4 * k - 0.2, 0.3),
                      limit=(-0.5, 0.5) if prev is not None else None)
        if contact[k]:
            b.add_point_contact(f"c{k}", body, local=(0.1, -0.15), mu=mu[k])
        prev = body
    if rod:
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
@given(data=st.data(), mechanism=mechanisms(4))
def test_rows_and_jacobians_match_the_constraint_functions(data, mechanism):
    model = _mechanism(**mechanism)
    a = model.arrays
    q = model.q0 + data.draw(offsets(model.n_body, 0.15), label="pose offset")
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
@given(data=st.data(), mechanism=mechanisms(3))
def test_mixed_complementarity_solve_meets_coulomb_and_matches_the_enumeration(data, mechanism):
    """Problems of the engine's own rows (drawn mechanisms: pins, limits, a rod, a pinned
    contact per body, so closed loops and redundant rows), b from drawn velocities."""
    model = _mechanism(**mechanism)
    a = model.arrays
    state = ps.make_state(model, q=model.q0 + data.draw(offsets(model.n_body, 0.15), label="pose offset"))
    state.contact_mode[:] = 1
    active = data.draw(st.lists(st.booleans(), min_size=a.pin_limit.size, max_size=a.pin_limit.size),
                       label="limit rows active")
    state.limit_active[:] = np.isfinite(a.pin_limit) & np.reshape(active, a.pin_limit.shape).astype(bool)
    ws = make_workspace(model)
    n = _rows_at(a, state, ws)
    J = _dense(ws, n, model.n_body)
    b = J @ data.draw(offsets(model.n_body, 3.0), label="velocity").ravel()
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
        assert not (full_rank and len(solutions) == 1), status
        return
    x = ws.lam[:n].copy()
    assert ref.coulomb_violations(A, b, kinds, mu_of_row, x, scale) <= 1e-7 * scale * (1 + np.abs(x).max())
    if full_rank:
        # without redundant rows Coulomb's problem here has this one answer
        assert len(solutions) >= 1
        assert any(np.allclose(x, s_, rtol=1e-7, atol=1e-9 * scale) for s_ in solutions), (x, solutions)
