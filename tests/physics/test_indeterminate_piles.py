"""Statically indeterminate piles from rest: a box on two others touches them at four corners
for three degrees of freedom, so the contact rows are dependent and the split of the load
among them is not fixed by the equations. The elimination's split once hung a box from one
corner (a pulling contact), which sent the first step of a 21-box pyramid to the
complementarity solve (445 Lemke pivots; 5 s for 55 boxes). The least change of impulses
(kernels/solver/solve.py least_change_impulses) spreads the load as the geometry does; where its
answer still pulls at a corner, or loads a corner with 1e-5 of a box's weight and friction
beyond its cone (a staggered wall), that contact is released and the least change solved
again (kernels/step.py least_change_answer). The first step ends with linear solves only."""
import numpy as np
import pytest

import planarsim as ps
from benchmarks.worlds import pyramid, wall   # 0.2 m boxes of 4 kg, each on two below
from planarsim.compiled import audit_counts, step_info
from planarsim.kernels.codes import CONTACT_PAIR, ROW_CONTACT_N, ROW_CONTACT_T
from planarsim.kernels.solver.matrix import SPARSE
from planarsim.kernels.solver.sparse_factor import SPARSE_MIN_ROWS

G = 9.81


@pytest.mark.parametrize("pile", ["pyramid6", "pyramid8", "pyramid10", "pyramid20", "wall2x8",
                                  "wall8x8"])
def test_a_pile_from_rest_takes_its_first_step_with_linear_solves_and_stands(pile):
    """Pyramids of 21 to 210 boxes and staggered walls of 16 and 64 bricks (half a brick
    over each joint below; 8 rows once sent the first step to Lemke: 634 pivots for 16
    bricks, 3,869 and 94 s for 160). The 210-box pyramid's 1,568 rows go through the sparse
    factorisation (kernels/solver/sparse_factor.py), the others' through the envelope."""
    if pile.startswith("pyramid"):
        rows = int(pile[len("pyramid"):])
        model = pyramid(rows)
    else:
        columns, rows = (int(k) for k in pile[len("wall"):].split("x"))
        model = wall(columns, rows)
    sim = ps.Simulator(model)
    q0 = sim.state.q.copy()
    sim.step()
    info = step_info(sim.ws)
    assert info["lcp_solves"] == 0, info
    assert info["solves"] <= 2 * rows, info
    # the ground carries the pile's weight over the step: M g h
    a = model.arrays
    ground = np.flatnonzero(a.contact_kind != CONTACT_PAIR)
    weight = float(np.sum(a.body_mass)) * G * model.dt
    assert abs(np.sum(sim.state.last_contact_impulse[ground, 0]) - weight) <= 1e-9 * weight
    assert np.all(sim.state.last_contact_impulse[:, 0] >= -1e-12 * weight)
    sim.steps(200)
    assert np.max(np.abs(sim.state.q - q0)) <= 1e-9
    assert sum(audit_counts(sim.ws).values()) == 0
    sparse = sim.ws.n_row[0] >= SPARSE_MIN_ROWS
    assert sparse == (pile == "pyramid20")
    assert (sim.ws.factor_kind[0] == SPARSE) == sparse


def _run(model, state, steps, forget_dependent=False):
    """A Simulator from a copy of `state` after `steps` single steps (forget_dependent: no
    row known dependent before each, so every step factors all its rows)."""
    sim = ps.Simulator(model, None, state.copy())
    for _ in range(steps):
        if forget_dependent:
            sim.state.contact_dependent[:] = 0
        sim.step()
    return sim


@pytest.fixture(scope="module")
def settled_pyramid():
    """The 210-box pyramid (1,568 rows: the sparse factorisation) after 5 steps from rest,
    and its model."""
    model = pyramid(20)
    sim = ps.Simulator(model)
    sim.steps(5)
    return model, sim.state.copy()


def test_a_pile_at_rest_factors_only_the_rows_the_last_step_kept(settled_pyramid):
    """The rows the last step dropped as dependent (State.contact_dependent) are left out of
    the factors (ws.sp_factored of ws.n_row places), and their equations hold: the pile
    moves as one whose every step factors every row, to rounding, and stands."""
    model, state = settled_pyramid
    sim = _run(model, state, 20)
    ws = sim.ws
    n, factored = int(ws.n_row[0]), int(ws.sp_factored[0])
    kind, owner = ws.row_kind[:n], ws.row_owner[:n]
    bit = np.where(kind == ROW_CONTACT_N, 1, np.where(kind == ROW_CONTACT_T, 2, 0))
    marked = (sim.state.contact_dependent[owner] & bit) != 0
    assert ws.factor_kind[0] == SPARSE
    assert factored < n / 2 and n - factored == marked.sum(), (n, factored, marked.sum())
    assert set(ws.sp_perm[factored:n]) == set(np.flatnonzero(marked))
    full = _run(model, state, 20, forget_dependent=True)
    assert np.abs(sim.state.q - full.state.q).max() <= 1e-12
    assert np.abs(sim.state.v - full.state.v).max() <= 1e-9
    weight = float(np.sum(model.arrays.body_mass)) * G * model.dt
    ground = np.flatnonzero(model.arrays.contact_kind != CONTACT_PAIR)
    for s in (sim.state, full.state):
        assert abs(np.sum(s.last_contact_impulse[ground, 0]) - weight) <= 1e-9 * weight
    assert np.abs(sim.state.q - state.q).max() <= 1e-9
    assert sum(audit_counts(sim.ws).values()) == 0


def test_rows_wrongly_marked_dependent_are_caught_and_every_row_factored(settled_pyramid):
    """Every contact row of the pile marked dropped, in a state put in from outside without
    the last impulses the left-out rows would keep: their equations fail the check
    (solve.excluded_rows_hold), the step factors every row, and it ends where a step with
    none marked ends, to rounding."""
    model, state = settled_pyramid
    clean_state = state.copy()
    clean_state.last_contact_impulse[:] = 0.0
    marked = clean_state.copy()
    marked.contact_dependent[:] = 3
    sim = _run(model, marked, 1)
    clean = _run(model, clean_state, 1, forget_dependent=True)
    assert np.abs(sim.state.q - clean.state.q).max() <= 1e-12
    assert np.abs(sim.state.v - clean.state.v).max() <= 1e-9
    assert sum(audit_counts(sim.ws).values()) == 0
    assert 0 < np.count_nonzero(sim.state.contact_dependent) < model.n_contact


def test_a_pile_restored_mid_run_continues_bit_for_bit(settled_pyramid):
    """The rows left out live in the State: a run restored from its state after 10 steps
    takes the next 10 exactly as the run that went on."""
    model, state = settled_pyramid
    sim = _run(model, state, 10)
    middle = sim.state.copy()
    sim.steps(10)
    again = _run(model, middle, 10)
    for a, b in zip(sim.state, again.state):
        assert np.array_equal(a, b)


def _pyramid_and_falling_box(rows, drop):
    """benchmarks.worlds.pyramid(rows) and one more box beside it, its bottom `drop` [m]
    above the ground."""
    b = ps.ModelBuilder(dt=1e-3)
    for level in range(rows):
        n = rows - level
        for j in range(n):
            b.add_body(f"box{level}_{j}", pos=((j - (n - 1) / 2) * 0.2, 0.1 + level * 0.2),
                       shapes=[("box", (0.0, 0.0), 0.2, 0.2, {"mu": 0.6})], density=100.0)
    b.add_body("falling", pos=(0.3 * rows, 0.1 + drop),
               shapes=[("box", (0.0, 0.0), 0.2, 0.2, {"mu": 0.6})], density=100.0)
    return b.compile()


def test_a_box_landing_beside_a_pile_at_rest_moves_as_where_every_row_is_factored():
    """A box dropped 5 cm beside the 210-box pyramid: its contacts join the rows when it
    lands (about 100 ms in), while the pile's rows left out as dependent stay left out; over
    130 steps both move as where every step factors every row, to 1e-9 m, nothing audited.
    (A box of the pyramid itself thrown or pushed sends its first step to the
    complementarity solve for minutes, with or without rows left out.)"""
    model = _pyramid_and_falling_box(20, 0.05)
    sim = ps.Simulator(model)
    sim.steps(5)
    state = sim.state.copy()
    sim = _run(model, state, 130)
    full = _run(model, state, 130, forget_dependent=True)
    assert sim.ws.sp_factored[0] < sim.ws.n_row[0] / 2
    assert np.abs(sim.state.q - full.state.q).max() <= 1e-9
    assert np.abs(sim.state.v - full.state.v).max() <= 1e-6
    falling = model.body_names.index("falling")
    assert abs(sim.state.q[falling, 1] - 0.1) <= 1e-8 and abs(sim.state.v[falling, 1]) <= 1e-6
    assert sum(audit_counts(sim.ws).values()) == 0
    assert sum(audit_counts(full.ws).values()) == 0
