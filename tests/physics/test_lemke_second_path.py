"""A complementarity problem whose first covering vector's paths all go astray is solved on the
second's before the frictionless rule is taken.

State: contact_stress shape_hills seed 21 (dt 3e-4 s, strategy 'all') at the start of step 2269,
as the engine reached it with Newton-SHAKE's extra last substitution left out after a chord
pass. Eleven shapes rest on sine hills; the step's velocity stage goes to the complementarity
problem, one island of 16 rows (32 variables), highly degenerate: 12 of its 32 complementary
pairs have both members at zero in the answer. Lemke's method in exact rational arithmetic
solves it in 28 pivots on the ramp covering vector; in floating point the path chose the wrong
row at pivot 23, where two ratios were 1.7e-6 apart (7.6166842e-7 against 7.6166968e-7), and
ended on a ray. The regularised paths (M + eps I) ended astray too up to eps = 1e-6, whose
answer polish could not make exact and which missed M's rules by eps z = 6e-4, beyond
SOFT_ANSWER_TOL: the island took the frictionless rule (a 'fallback' audit). The second
covering vector's paths are other paths through the same problem; the joint problem of every
island solves on them.
"""
import sys
from pathlib import Path

import numpy as np

import planarsim as ps
from planarsim.kernels.checks.audit import AUDIT_NAMES
from planarsim.kernels.info import INFO_LCP_SOLVES

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from benchmarks.contact_stress import build  # noqa: E402


def test_a_degenerate_pile_on_hills_keeps_its_friction():
    model, _, _, _ = build("shape_hills", 21)
    data = np.load(Path(__file__).parents[1] / "data" / "shape_hills_21_step2269_state.npz")
    state = ps.make_state(model)
    for k in data.files:
        getattr(state, k)[...] = data[k]
    sim = ps.Simulator(model, ps.make_options("all"), state)
    sim.step()
    assert sim.ws.info[INFO_LCP_SOLVES] > 0, "the saved state no longer needs the complementarity solve"
    assert sum(sim.ws.audit) == 0, dict(zip(AUDIT_NAMES, sim.ws.audit))
    assert np.all(np.isfinite(sim.state.q)) and np.all(np.isfinite(sim.state.v))
