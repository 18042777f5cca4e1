"""ModelBuilder(ground=None): a world without the analytic ground; shapes touch only shapes."""
import math

import numpy as np
import pytest

import planarsim as ps
from planarsim import ModelError
from planarsim.half_step import to_step_velocity

G = 9.81


def test_a_box_falls_forever():
    """From rest at y = 0 (where the default ground would hold it) for 2 s: y_n = -g h^2 n(n+1)/2
    (symplectic Euler from a state velocity 0); from the velocity 0 at the instant t = 0
    (half_step.to_step_velocity) y = -g t^2 / 2, both to rounding."""
    h, n = 1e-3, 2000
    b = ps.ModelBuilder(dt=h, ground=None)
    b.add_body("box", 1.0, 1.0 / 6, shapes=[("box", (0.0, 0.0), 1.0, 1.0)])
    model = b.compile()
    assert model.terrain is None and model.n_contact == 0
    sim = ps.Simulator(model)
    sim.steps(n)
    assert sim.state.q[0, 1] == pytest.approx(-G * h * h * n * (n + 1) / 2, abs=1e-9)
    sim = ps.Simulator(model)
    to_step_velocity(model, sim.state, sim.ws, h)
    sim.steps(n)
    assert sim.state.q[0, 1] == pytest.approx(-G * (n * h) ** 2 / 2, abs=1e-9)
    assert sim.state.q[0, 0] == 0.0 and sim.state.q[0, 2] == 0.0


def test_shapes_still_touch_each_other():
    """A box on a static floor whose top is y = 0 (no analytic ground): it rests on the floor,
    and a second box dropped onto it comes to rest on it."""
    b = ps.ModelBuilder(dt=1e-3, ground=None)
    b.add_shape(None, "box", (0.0, -0.5), 4.0, 1.0, name="floor")
    b.add_body("lower", 1.0, 0.05 / 12, pos=(0.0, 0.05), shapes=[("box", (0, 0), 0.2, 0.1)])
    b.add_body("upper", 1.0, 0.05 / 12, pos=(0.02, 0.4), shapes=[("box", (0, 0), 0.2, 0.1)])
    sim = ps.Simulator(b.compile())
    sim.steps(2000)
    assert sim.state.q[0, 1] == pytest.approx(0.05, abs=1e-6)
    assert sim.state.q[1, 1] == pytest.approx(0.15, abs=1e-6)
    assert np.abs(sim.state.v).max() < 1e-6


def incline(angle, mu, ground):
    """A static box (6 m x 0.5 m) tilted by `angle` [rad] whose top face passes through the
    origin, and a box 'block' (0.2 m x 0.1 m, 2 kg) resting on that face at the origin."""
    t = np.array([math.cos(angle), math.sin(angle)])
    n = np.array([-math.sin(angle), math.cos(angle)])
    b = ps.ModelBuilder(dt=1e-3, ground=ground)
    b.add_shape(None, "box", tuple(-0.25 * n), 6.0, 0.5, angle, mu=mu, name="ramp")
    b.add_body("block", 2.0, 2.0 * (0.2 ** 2 + 0.1 ** 2) / 12, pos=tuple(0.05 * n), angle=angle,
               shapes=[("box", (0.0, 0.0), 0.2, 0.1, {"mu": mu})])
    return b.compile(), t


@pytest.mark.parametrize("angle_deg, mu", [(20.0, 0.2), (35.0, 0.5), (15.0, 0.0)])
def test_a_box_slides_down_a_static_incline_through_the_origin(angle_deg, mu):
    a = math.radians(angle_deg)
    model, t = incline(a, mu, ground=None)
    sim = ps.Simulator(model)
    h, n = 1e-3, 1000
    sim.steps(n)
    accel = G * (math.sin(a) - mu * math.cos(a))     # down the slope
    v = sim.state.v[0, :2] @ t
    s = (sim.state.q[0, :2] - model.q0[0, :2]) @ t
    assert v == pytest.approx(-accel * n * h, rel=1e-9)
    assert s == pytest.approx(-accel * h * h * n * (n + 1) / 2, rel=1e-9)
    assert sim.state.v[0, 2] == pytest.approx(0.0, abs=1e-9)    # it slides, it does not tip


def test_the_default_ground_refuses_that_incline():
    with pytest.raises(ModelError, match="below the ground"):
        ps.Simulator(incline(math.radians(20.0), 0.2, ground=True)[0])


@pytest.mark.parametrize("add", [
    lambda b: b.add_point_contact("toe", "shin"),
    lambda b: b.add_arc_contact("toe", "shin", (0.0, 0.0), 0.05),
    lambda b: b.add_box_contacts("toe", "shin", (0.0, 0.0), 0.1, 0.05),
])
def test_ground_contacts_are_refused_without_ground(add):
    b = ps.ModelBuilder(ground=None)
    b.add_body("shin", 1.0, 0.1)
    with pytest.raises(ModelError, match=r"contact 'toe' \(0\): add_(point|arc|box)_contacts? "
                                         r"touches only the ground, and this model has none"):
        add(b)
    assert b._contacts == [] and b._shapes == []


def test_ground_none_takes_no_terrain():
    with pytest.raises(ModelError, match="ground=None"):
        ps.ModelBuilder(ground=None, terrain=ps.terrain.slope(10.0))
    with pytest.raises(ModelError, match="must be True"):
        ps.ModelBuilder(ground=False)


def test_a_run_without_ground_records_and_draws_none():
    model, _ = incline(0.3, 0.2, ground=None)
    traj = ps.Simulator(model).run(n_steps=10)
    assert traj.info["terrain"] == "none" and traj.terrain() is None
    pytest.importorskip("matplotlib")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from planarsim.render.draw import Scene
    fig, ax = plt.subplots()
    scene = Scene(model, ax)
    scene.draw_frame(traj, len(traj) - 1)
    assert len(scene.terrain_line.get_xdata()) == 0 and not scene.ground_fill.get_visible()
    plt.close(fig)
