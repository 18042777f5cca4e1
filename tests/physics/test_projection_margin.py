"""The position projection's rows reach as far as its last move: a thin polygon rocking on its
edge contact on a hill, a ball rolling on it; and the projection's trust in its linearisation:
a capsule rocking on its side on a hill, whose whole Newton moves swung it back and forth.

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
import pytest

import planarsim as ps
from planarsim.kernels.checks.audit import AUDIT_NAMES, DEPTH_TOL
from planarsim.kernels.info import INFO_PROJECTIONS

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from benchmarks.contact_stress import build, shape_clearance  # noqa: E402


def _saved_state(seed, name):
    model, _, _, _ = build("shape_hills", seed)
    data = np.load(Path(__file__).parents[1] / "data" / name)
    state = ps.make_state(model)
    for k in data.files:
        getattr(state, k)[...] = data[k]
    return model, state


def test_a_thin_polygon_rocking_on_a_hill_under_a_rolling_ball_is_projected_out():
    model, state = _saved_state(39, "shape_hills_39_step80_state.npz")
    sim = ps.Simulator(model, ps.make_options("all"), state)
    sim.step()      # raised SimulationDiverged: s5.polygon5/edge0 0.000313 m below the ground
    assert sim.ws.info[INFO_PROJECTIONS] > 0, "the saved state no longer needs the projection"
    assert sum(sim.ws.audit) == 0, dict(zip(AUDIT_NAMES, sim.ws.audit))
    assert -float(np.min(shape_clearance(model, sim.state.q[None]))) <= DEPTH_TOL


@pytest.mark.parametrize("strategy", ["alternating", "all"])
def test_a_capsule_rocking_on_its_side_on_a_hill_is_projected_out(strategy):
    """State: contact_stress shape_hills seed 13 (dt 3e-3 s, strategy 'alternating') at the
    start of step 355, as a trial form of held contacts' second-order target reached it. A
    capsule (core 0.31 m, radius 0.032 m) lies on its side on a hill of radius about 30 m,
    its edge contact 7.4e-5 m deep after the correction. Lifting the edge's deepest point by
    turning the capsule moves that point along the side by R phi (a straight edge pivoting on
    a hill dips R phi^2 / 2): each whole Newton move of the projection dipped the edge as far
    as it lifted it, and the next swung it back (phi +1.9e-3, -2.1e-3, +2.1e-3 rad...); its
    20 iterations ended 2.7e-6 m deep and the step raised SimulationDiverged. The projection
    now trusts its linearisation only as far as the last move bore it out (a trust region on
    the move's length, complementarity.TRUST_LOW): the cycle is damped and Newton's
    quadratic end reached within the iterations."""
    model, state = _saved_state(13, "shape_hills_13_step355_state.npz")
    sim = ps.Simulator(model, ps.make_options(strategy), state)
    sim.step()
    assert sim.ws.info[INFO_PROJECTIONS] > 0, "the saved state no longer needs the projection"
    assert sum(sim.ws.audit) == 0, dict(zip(AUDIT_NAMES, sim.ws.audit))
    assert -float(np.min(shape_clearance(model, sim.state.q[None]))) <= DEPTH_TOL
