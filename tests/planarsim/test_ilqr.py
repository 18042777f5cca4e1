"""planarsim.ilqr: iterative LQR on the exact step derivatives, on a pendulum driven by a
motor at its pin (the cart-pole swing-up is tests/examples' cartpole_swingup)."""
import numpy as np
import pytest

import planarsim as ps
from planarsim.ilqr import QuadraticCost, follow, ilqr, state_vector


def pendulum(dt=0.01, damping=0.05):
    """A 1 kg rod of 0.5 m hinged at one end to the world, hanging, a motor at the hinge
    (+-20 N m) and a damper."""
    b = ps.ModelBuilder(dt=dt)
    rod = b.add_body("rod", mass=1.0, inertia=0.25 / 12, pos=(0.0, -0.25), angle=-np.pi / 2)
    b.add_pin("hinge", None, rod, anchor_world=(0.0, 0.0), damping=damping)
    b.add_pin_motor("motor", "hinge", limit=(-20.0, 20.0))
    return b.compile()


def turn_cost(model, angle):
    """Reach the rod's angle `angle` [rad] at rest at the end (and stay near it), small
    torques."""
    h = model.dt
    goal = np.zeros(6)
    goal[0:2] = 0.25 * np.array([np.cos(angle), np.sin(angle)])
    goal[2] = angle
    Q = np.zeros((6, 6))
    Q[2, 2] = 1.0 * h
    Qf = np.zeros((6, 6))
    Qf[2, 2], Qf[5, 5] = 100.0, 10.0
    return QuadraticCost(goal, Q, 1e-3 * h * np.eye(1), Qf)


def test_a_pendulum_is_turned_to_a_target_and_held():
    """From hanging (-pi/2) to horizontal (0) in 1.5 s: the cost falls at every iteration, the
    run ends within 0.01 rad and 0.05 rad/s of the target, the feedback run follows the plan,
    and the simulator is left where it started."""
    model = pendulum()
    sim = ps.Simulator(model)
    start = sim.snapshot()
    result = ilqr(sim, np.zeros((150, 1)), turn_cost(model, 0.0), iterations=50)
    assert np.array_equal(sim.state.q, start.q) and np.array_equal(sim.state.v, start.v)
    assert all(b < a for a, b in zip(result.costs, result.costs[1:]))
    assert result.converged
    end = result.xs[-1]
    assert abs(end[2]) < 0.01 and abs(end[5]) < 0.05, end
    run = follow(sim, result)
    assert np.abs(run - result.xs).max() < 1e-9        # (no disturbance: the plan itself)
    assert np.array_equal(run[-1], state_vector(sim))


def test_the_feedback_rejects_a_push():
    """The gains close the loop: pushed by 0.1 rad/s at the start, the feedback run still ends
    within 0.05 rad of the target, where the plan's commands alone miss it by radians."""
    model = pendulum()
    sim = ps.Simulator(model)
    result = ilqr(sim, np.zeros((150, 1)), turn_cost(model, 0.0), iterations=50)
    pushed = sim.snapshot()
    pushed.v[0] = [0.25 * 0.1, 0.0, 0.1]                # turning at 0.1 rad/s about the pin
    sim.state = pushed
    closed = follow(sim, result)
    sim.state = pushed
    for u in result.us:
        sim.step(u)
    open_loop = state_vector(sim)
    assert abs(closed[-1, 2]) < 0.05
    assert abs(open_loop[2]) > 0.05


def test_bad_commands_are_refused_by_name():
    sim = ps.Simulator(pendulum())
    cost = turn_cost(sim.model, 0.0)
    with pytest.raises(ValueError, match="us must have shape"):
        ilqr(sim, np.zeros((10, 2)), cost)
    with pytest.raises(ValueError, match="us must be finite"):
        ilqr(sim, np.full((10, 1), np.nan), cost)


def test_a_box_is_pushed_to_a_mark_through_friction():
    """Through contact: a 2 kg box on the floor (mu 0.4, four corner contacts), a horizontal
    push of at most 30 N, to be at rest 1 m on after 1.5 s. From a first guess that slides it
    (12 N for 0.4 s: where it sticks, no small push moves it and the derivative says so), the
    cost falls at every iteration and the box ends within 1 mm of the mark, at rest; the
    plan's steps slide and stick (the derivatives through both modes)."""
    b = ps.ModelBuilder(dt=0.01)
    box = b.add_body("box", mass=2.0, inertia=2.0 * (0.3 ** 2 + 0.2 ** 2) / 12, pos=(0.0, 0.1))
    b.add_box_contacts("box", box, (0.0, 0.0), 0.3, 0.2, mu=0.4)
    b.add_body_force("push", box, direction=(1.0, 0.0), limit=(-30.0, 30.0))
    model = b.compile()
    sim = ps.Simulator(model)
    sim.steps(5)
    h = model.dt
    goal = state_vector(sim).copy()
    goal[0] = 1.0
    Q = np.zeros((6, 6))
    Q[0, 0] = h
    Qf = np.zeros((6, 6))
    Qf[0, 0], Qf[3, 3] = 100.0, 10.0
    first = np.zeros((150, 1))
    first[:40] = 12.0
    result = ilqr(sim, first, QuadraticCost(goal, Q, 1e-3 * h * np.eye(1), Qf), iterations=40)
    assert all(b < a for a, b in zip(result.costs, result.costs[1:]))
    end = result.xs[-1]
    assert abs(end[0] - 1.0) < 1e-3 and np.abs(end[3:]).max() < 1e-3, end
    modes = set()                       # (ilqr left sim where it started)
    for u in result.us:
        sim.step(u)
        modes.update(sim.state.contact_mode.tolist())
    assert {1, 2} <= modes, modes
