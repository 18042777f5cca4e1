"""Statically indeterminate piles from rest: a box on two others touches them at four corners
for three degrees of freedom, so the contact rows are dependent and the split of the load
among them is not fixed by the equations. The elimination's split once hung a box from one
corner (a pulling contact), which sent the first step of a 21-box pyramid to the
complementarity solve (445 Lemke pivots; 5 s for 55 boxes). The least change of impulses
(kernels/solve.py least_change_impulses) spreads the load as the geometry does, and the
first step ends with linear solves only."""
import numpy as np
import pytest

import planarsim as ps
from benchmarks.worlds import pyramid   # 0.2 m boxes of 4 kg, each on two below
from planarsim.compiled import audit_counts, step_info
from planarsim.kernels.codes import CONTACT_PAIR

G = 9.81


@pytest.mark.parametrize("rows", [6, 8])
def test_a_pyramid_from_rest_takes_its_first_step_with_linear_solves_and_stands(rows):
    model = pyramid(rows)
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
