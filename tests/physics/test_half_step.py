"""planarsim.half_step: velocities at an instant and over a step. With a state's velocity
converted to the step's on the way in and back on the way out, the step's symplectic Euler is
the leapfrog (Stoermer-Verlet / SHAKE): exact for a constant force, second order for a rod
pendulum, where the velocities taken as they are give first order."""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import planarsim as ps
from planarsim.half_step import kick, project_velocities, to_instant_velocity, to_step_velocity

G = 9.81


def _falling(h):
    b = ps.ModelBuilder(dt=h, gravity=(0.0, -G))
    b.add_point_mass("ball", 2.0, pos=(0.0, 100.0), vel=(1.5, 4.0))
    b.add_body("box", 1.0, 0.1, pos=(5.0, 100.0), vel=(0.0, 0.0))
    return b.compile()


@pytest.mark.parametrize("convert", [False, True])
def test_free_fall_is_exact_with_conversions_and_first_order_without(convert):
    h, n = 1e-3, 500
    model = _falling(h)
    sim = ps.Simulator(model)
    v0 = sim.state.v.copy()
    if convert:
        to_step_velocity(model, sim.state, sim.ws, h)
    sim.steps(n)
    if convert:
        to_instant_velocity(model, sim.state, sim.ws, h)
    t = n * h
    y = 100.0 + v0[0, 1] * t - 0.5 * G * t * t
    dy = sim.state.q[0, 1] - y
    assert abs(sim.state.v[0, 1] - (v0[0, 1] - G * t)) < 1e-9     # velocities exact either way
    if convert:
        assert abs(dy) < 1e-9 and abs(sim.state.q[1, 1] - (100.0 - 0.5 * G * t * t)) < 1e-9
    else:
        # symplectic Euler taken as it is: y falls n h^2 g / 2 too far
        assert dy == pytest.approx(-0.5 * n * h * h * G, rel=1e-6)


def _pendulum_error(h, convert, theta0=1.0, duration=1.0):
    """|angle error| [rad] of a 1 m rod pendulum released from rest at theta0 after `duration`."""
    b = ps.ModelBuilder(dt=h, gravity=(0.0, -G))
    bob = b.add_point_mass("bob", 1.0, pos=(math.sin(theta0), 100.0 - math.cos(theta0)))
    b.add_rod("rod", None, bob, anchor_a=(0.0, 100.0))
    model = b.compile()
    sim = ps.Simulator(model)
    if convert:
        to_step_velocity(model, sim.state, sim.ws, h)
    sim.steps(int(round(duration / h)))
    if convert:
        to_instant_velocity(model, sim.state, sim.ws, h)
    x, y = sim.state.q[0, :2]
    ref = solve_ivp(lambda t, s: [s[1], -G * math.sin(s[0])], (0.0, duration), [theta0, 0.0],
                    rtol=1e-12, atol=1e-12).y[0, -1]
    return abs(math.atan2(x, 100.0 - y) - ref)


def test_rod_pendulum_second_order_with_conversions():
    # measured: 2.2e-6, 5.4e-7, 1.4e-7 with; 5.7e-4, 2.9e-4, 1.4e-4 without
    hs = (2e-3, 1e-3, 5e-4)
    with_ = [_pendulum_error(h, True) for h in hs]
    without = [_pendulum_error(h, False) for h in hs]
    print("pendulum angle errors with / without conversions:", with_, without)
    for big, small in zip(with_, with_[1:]):
        assert 3.5 < big / small < 4.5
    for big, small in zip(without, without[1:]):
        assert 1.8 < big / small < 2.2
    assert with_[1] < 2e-3 * without[1]
    # docs/engine.md: "5.4e-7 rad after 1 s at dt 1e-3 s instead of 2.9e-4"
    assert (f"{with_[1]:.1e}", f"{without[1]:.1e}") == ("5.4e-07", "2.9e-04"), (with_[1], without[1])


def test_instant_velocity_is_consistent_with_the_rods_and_pinned_contacts():
    b = ps.ModelBuilder(dt=1e-3, gravity=(0.0, -G))
    hip = b.add_point_mass("hip", 1.0, pos=(0.3, 0.9))
    foot = b.add_point_mass("foot", 0.01, pos=(0.0, 0.0))
    b.add_rod("leg", hip, foot)
    b.add_point_contact("foot", foot)
    model = b.compile()
    s = ps.make_state(model)
    rng = np.random.default_rng(3)
    s.v[:, :2] = rng.normal(size=(2, 2))
    sim = ps.Simulator(model)
    to_instant_velocity(model, s, sim.ws, 1e-3, pinned=[model.contact("foot")])
    assert np.allclose(s.v[1, :2], 0.0, atol=1e-12)
    e = s.q[0, :2] - s.q[1, :2]
    assert abs(e @ (s.v[0, :2] - s.v[1, :2])) < 1e-12
    assert np.allclose(project_velocities(model, s.q, s.v, [model.contact("foot")]), s.v, atol=1e-12)


def test_kick_applies_actuator_commands_saturated():
    b = ps.ModelBuilder(dt=1e-3, gravity=(0.0, 0.0))
    body = b.add_body("wheel", 2.0, 0.5)
    b.add_pin("axle", None, body, anchor_world=(0.0, 0.0))
    b.add_pin_motor("motor", "axle", limit=(-1.0, 1.0))
    model = b.compile()
    sim = ps.Simulator(model)
    kick(model.arrays, sim.state, sim.ws, np.array([5.0]), 0.1, 0.1)  # saturated to 1 N m
    assert sim.state.v[0, 2] == pytest.approx(0.1 * 1.0 / 0.5)


def test_bad_input_names_the_culprit():
    b = ps.ModelBuilder(dt=1e-3)
    base = b.add_body("base", 1.0, 0.1)
    cart = b.add_body("cart", 1.0, 0.1, pos=(1.0, 0.0))
    b.add_slider("rail", base, cart)
    model = b.compile()
    sim = ps.Simulator(model)
    with pytest.raises(ps.ModelError, match="slider joint 0 .'rail'."):
        to_instant_velocity(model, sim.state, sim.ws, 1e-3)
    with pytest.raises(ValueError, match="u has shape"):
        to_step_velocity(model, sim.state, sim.ws, 1e-3, u=[1.0])


def test_free_coordinates_hold_nothing_in_the_projection():
    """A body on free coordinates (an MJCF free root's slides and hinge) moves as it likes:
    the projection leaves its velocity as it is, while a pin next to it still holds."""
    b = ps.ModelBuilder(dt=1e-3)
    b.add_body("float", 1.0, 0.1, pos=(0.0, 1.0))
    b.add_free_coordinate("float_x", "float", kind="slide", axis=(1.0, 0.0))
    b.add_free_coordinate("float_a", "float", kind="hinge")
    b.add_body("arm", 1.0, 0.1, pos=(0.5, 0.0))
    b.add_pin("shoulder", None, "arm", anchor_world=(0.0, 0.0))
    model = b.compile()
    v = np.array([[1.0, -2.0, 3.0], [0.4, 0.3, 0.0]])
    out = project_velocities(model, model.q0, v)
    np.testing.assert_array_equal(out[0], v[0])
    # the arm's pin point at the origin is at rest after the projection
    assert abs(out[1, 0] - 0.0 * out[1, 2]) < 1e-12 and abs(out[1, 1] - 0.5 * out[1, 2]) < 1e-12
