"""The position projection's rows reach as far as its last move: a thin polygon rocking on its
edge contact on a hill, a ball rolling on it.

State: contact_stress shape_hills seed 39 (dt 1e-2 s, strategy 'all') at the start of step 80,
as the engine at 9581216 reached it (saved by the engine of that commit). s5, a polygon about
1 cm thin, lies on its long edge on a gentle hill (the edge contact pinned at its deepest
point) while s4, a circle rolling at 2 m/s and 34 rad/s, presses on it; the step turns s5 by
0.008 rad about the held point, which leaves the edge 0.3 mm in the ground (a straight edge
pivoting on a hill of radius R dips R phi^2 / 2). The projection that follows took in only the
contacts within rounding (1e-6 m) of the ground: lifting the edge by turning the light polygon
brought a corner 1.4 mm down, lifting the corner brought the edge down again, and so on
through its 20 iterations; the step raised SimulationDiverged (0.313 mm below the ground).
"""
import sys
from pathlib import Path

import numpy as np

import planarsim as ps
from planarsim.kernels.checks.audit import AUDIT_NAMES, DEPTH_TOL
from planarsim.kernels.info import INFO_PROJECTIONS

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from benchmarks.contact_stress import build, shape_clearance  # noqa: E402


def _state_at_step_80():
    model, _, _, _ = build("shape_hills", 39)
    data = np.load(Path(__file__).parents[1] / "data" / "shape_hills_39_step80_state.npz")
    state = ps.make_state(model)
    for k in data.files:
        getattr(state, k)[...] = data[k]
    return model, state


def test_a_thin_polygon_rocking_on_a_hill_under_a_rolling_ball_is_projected_out():
    model, state = _state_at_step_80()
    sim = ps.Simulator(model, ps.make_options("all"), state)
    sim.step()      # raised SimulationDiverged: s5.polygon5/edge0 0.000313 m below the ground
    assert sim.ws.info[INFO_PROJECTIONS] > 0, "the saved state no longer needs the projection"
    assert sum(sim.ws.audit) == 0, dict(zip(AUDIT_NAMES, sim.ws.audit))
    assert -float(np.min(shape_clearance(model, sim.state.q[None]))) <= DEPTH_TOL
