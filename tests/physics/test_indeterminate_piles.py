"""Statically indeterminate piles from rest: a box on two others touches them at four corners
for three degrees of freedom, so the contact rows are dependent and the split of the load
among them is not fixed by the equations. The elimination's split once hung a box from one
corner (a pulling contact), which sent the first step of a 21-box pyramid to the
complementarity solve (445 Lemke pivots; 5 s for 55 boxes). The least change of impulses
(kernels/solve.py least_change_impulses) spreads the load as the geometry does; where its
answer still pulls at a corner, or loads a corner with 1e-5 of a box's weight and friction
beyond its cone (a staggered wall), that contact is released and the least change solved
again (kernels/step.py least_change_answer). The first step ends with linear solves only."""
import numpy as np
import pytest

import planarsim as ps
from benchmarks.worlds import pyramid, wall   # 0.2 m boxes of 4 kg, each on two below
from planarsim.compiled import audit_counts, step_info
from planarsim.kernels.codes import CONTACT_PAIR
from planarsim.kernels.matrix import ENVELOPE, SPARSE
from planarsim.kernels.sparse_factor import SPARSE_MIN_ROWS

G = 9.81


@pytest.mark.parametrize("pile", ["pyramid6", "pyramid8", "pyramid10", "pyramid20", "wall2x8",
                                  "wall8x8"])
def test_a_pile_from_rest_takes_its_first_step_with_linear_solves_and_stands(pile):
    """Pyramids of 21 to 210 boxes and staggered walls of 16 and 64 bricks (half a brick
    over each joint below; 8 rows once sent the first step to Lemke: 634 pivots for 16
    bricks, 3,869 and 94 s for 160). The 210-box pyramid's 1,568 rows go through the sparse
    factorisation (kernels/sparse_factor.py), the others' through the envelope."""
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
    assert sim.ws.factor_kind[0] == (SPARSE if sparse else ENVELOPE)
