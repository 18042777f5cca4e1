"""Continuous collision on sine hills: a fast point skimming tight crests hits the first one
its path dips below (conservative advancement; sampling the path missed most of them)."""
import numpy as np
import pytest

import planarsim as ps
from planarsim import terrain

A, L = 0.05, 0.2        # crest height [m], wavelength [m]


@pytest.mark.parametrize("x0", np.linspace(0.0, 0.65, 25))
def test_a_point_skimming_crests_at_200_m_s_hits_one(x0):
    """Thrown level at 200 m/s, 0.2 mm above the crests, dt = 10 ms: its path falls 0.49 mm
    within the step, below the crests' tops over its last 0.7 m (three and more crests), so
    it must hit one; it ends the step deflected (slowed, or turned upward) and not below the
    ground."""
    ground = terrain.hills([A], [L], [0.0])
    b = ps.ModelBuilder(dt=1e-2, terrain=ground)
    b.add_point_mass("p", 1.0, pos=(float(x0), A + 2e-4), vel=(200.0, 0.0))
    b.add_point_contact("c", "p", mu=0.5)
    sim = ps.Simulator(b.compile())
    sim.steps(1)
    vx, vy = sim.state.v[0, 0], sim.state.v[0, 1]
    assert vx < 199.0 or vy > 0.0, (vx, vy)
    x, y = sim.state.q[0, 0], sim.state.q[0, 1]
    assert y >= ground.height(x) - 1e-8
