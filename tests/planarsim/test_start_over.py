"""Simulator.start_over: starting again in place is starting a new Simulator (bit for bit),
after any history; a non-finite start names the body."""
import numpy as np
import pytest

import planarsim as ps


def tumbling_boxes():
    b = ps.ModelBuilder(dt=2e-3)
    for i in range(3):
        b.add_body(f"box{i}", mass=1.0 + i, inertia=0.05, pos=(0.3 * i, 0.3 + 0.35 * i),
                   angle=0.3 * i, shapes=[("box", (0.0, 0.0), 0.3, 0.2, {"mu": 0.6})])
    b.add_pin("hinge", 0, 1, anchor_world=(0.15, 0.45), limit=(-0.5, 0.5), damping=0.1)
    return b.compile()


def test_start_over_is_a_new_simulator():
    model = tumbling_boxes()
    rng = np.random.default_rng(0)
    q = model.q0 + rng.normal(0, 0.01, model.q0.shape)
    v = rng.normal(0, 0.5, model.v0.shape)
    fresh = ps.Simulator(model)
    fresh.start_over(q, v)
    fresh.steps(400)
    used = ps.Simulator(model, options=fresh.options)
    used.steps(700, None)                       # a history: landings, contact modes, limits
    assert used.state.contact_mode.any()
    used.start_over(q, v)
    assert used.t == 0.0
    used.steps(400)
    for a, b in zip(fresh.state, used.state):
        assert np.array_equal(a, b)


def test_start_over_names_a_non_finite_body():
    model = tumbling_boxes()
    sim = ps.Simulator(model)
    q = model.q0.copy()
    q[2, 1] = np.nan
    with pytest.raises(ValueError, match=r"start_over: q of body 'box2' \(2\)"):
        sim.start_over(q, model.v0)
