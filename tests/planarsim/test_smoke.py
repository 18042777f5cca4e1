import numpy as np

import planarsim as ps


def test_pendulum_swings_and_keeps_its_pin():
    b = ps.ModelBuilder(dt=1e-3)
    rod = b.add_body("rod", mass=1.0, inertia=1.0 / 12, pos=(0.5, 0.0))
    b.add_pin("pivot", None, rod, anchor_world=(0.0, 0.0))
    sim = ps.Simulator(b.compile())
    sim.steps(300)
    x, y, th = sim.state.q[0]
    assert y < -0.1  # it fell
    assert abs(np.hypot(x, y) - 0.5) < 1e-9  # the pin held
