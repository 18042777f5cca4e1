"""A free body's coordinates (ModelBuilder.add_free_coordinate: no constraint, the joint's
limits, spring-damper and armature act on it) and the fluid drag (ModelBuilder.add_fluid_box,
MuJoCo's inertia-box model) against closed forms."""
import math

import numpy as np
import pytest

import planarsim as ps
from planarsim import ModelError
from planarsim.energy import kinetic_energy

M, I = 2.0, 0.3


def free_body(dt=1e-3, **kw):
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0))
    body = b.add_body("box", mass=M, inertia=I, pos=(0.0, 0.0), **kw)
    return b, body


def test_free_slide_spring_with_armature_has_the_closed_form_period():
    """A spring k on a free slide along x with armature a: x'' = -k x / (M + a), so the
    period is 2 pi sqrt((M + a) / k); y and the angle are untouched (no constraint)."""
    k, a = 50.0, 0.5
    b, body = free_body(vel=(0.0, 0.3), omega=0.2)
    b.add_free_coordinate("x", body, kind="slide", axis=(1.0, 0.0), stiffness=k, armature=a)
    model = b.compile()
    sim = ps.Simulator(model, state=ps.make_state(model, model.q0 + [[0.1, 0.0, 0.0]], model.v0))
    period = 2 * math.pi * math.sqrt((M + a) / k)
    n = round(period / model.dt)
    xs = []
    for _ in range(n):
        sim.step()
        xs.append(sim.state.q[0, 0])
    xs = np.array(xs)
    assert xs.min() == pytest.approx(-0.1, abs=2e-3)               # half a period: the far side
    assert abs(np.argmin(xs) * model.dt - period / 2) < 0.01 * period
    assert xs[-1] == pytest.approx(0.1, abs=2e-3)                  # back after one period
    T = n * model.dt
    assert sim.state.q[0, 1] == pytest.approx(0.3 * T, abs=1e-9)   # free in y
    assert sim.state.q[0, 2] == pytest.approx(0.2 * T, abs=1e-9)   # and in angle


def test_free_hinge_limit_stops_the_turn():
    b, body = free_body(omega=2.0)
    b.add_free_coordinate("turn", body, kind="hinge", limit=(-0.5, 0.5))
    model = b.compile()
    sim = ps.Simulator(model)
    sim.run(1.0)
    assert sim.state.q[0, 2] == pytest.approx(0.5, abs=1e-6)
    assert abs(sim.state.v[0, 2]) < 1e-9
    assert sim.ws.audit.sum() == 0


def test_slide_motor_on_a_free_coordinate_pushes_at_its_anchor():
    """A force along x at a point above the COM also turns the body: torque -h F."""
    b, body = free_body()
    b.add_free_coordinate("x", body, kind="slide", axis=(1.0, 0.0), anchor_world=(0.0, 0.2))
    b.add_slider_motor("push", "x")
    model = b.compile()
    sim = ps.Simulator(model)
    F, T = 3.0, 0.1
    sim.steps(round(T / model.dt), np.array([F]))
    assert sim.state.v[0, 0] == pytest.approx(F * T / M, rel=1e-6)
    assert sim.state.v[0, 2] == pytest.approx(-0.2 * F * T / I, rel=1e-3)


def drag_body(viscosity, density, v0, omega0=0.0, dt=1e-4):
    b, body = free_body(dt=dt, vel=v0, omega=omega0)
    b.add_fluid_box(body, (1.0, 0.2, 0.1), viscosity=viscosity, density=density)
    return b.compile()


def test_viscous_drag_decays_as_the_exponential():
    """Linear drag c = 3 pi d mu (d the sides' mean): v(t) = v0 exp(-c t / M); turning:
    w(t) = w0 exp(-pi d^3 mu t / I)."""
    mu = 0.5
    model = drag_body(mu, 0.0, (1.0, -0.5), omega0=1.0)
    sim = ps.Simulator(model)
    T = 1.0
    sim.run(T)
    d = (1.0 + 0.2 + 0.1) / 3
    decay = math.exp(-3 * math.pi * d * mu * T / M)
    np.testing.assert_allclose(sim.state.v[0, :2], np.array([1.0, -0.5]) * decay, rtol=1e-3)
    assert sim.state.v[0, 2] == pytest.approx(math.exp(-math.pi * d ** 3 * mu * T / I), rel=1e-3)


def test_quadratic_drag_along_an_axis_has_the_closed_form():
    """Along the box's long axis (l1 = 1) the cross-section is l2 ln: v' = -(rho l2 ln / 2M) v^2,
    so v(t) = v0 / (1 + beta v0 t); across it (l1 ln) the drag is 5 times stronger."""
    rho = 100.0
    T = 0.5
    for v0, area in (((2.0, 0.0), 0.2 * 0.1), ((0.0, 2.0), 1.0 * 0.1)):
        sim = ps.Simulator(drag_body(0.0, rho, v0))
        sim.run(T)
        beta = 0.5 * rho * area / M
        assert np.hypot(*sim.state.v[0, :2]) == pytest.approx(2.0 / (1 + beta * 2.0 * T), rel=1e-3)


def test_drag_only_takes_energy_out():
    model = drag_body(0.1, 50.0, (1.0, 0.7), omega0=-3.0, dt=1e-3)
    sim = ps.Simulator(model)
    ke = [kinetic_energy(model, sim.state.q, sim.state.v)]
    for _ in range(200):
        sim.step()
        ke.append(kinetic_energy(model, sim.state.q, sim.state.v))
    assert np.all(np.diff(ke) < 0)


@pytest.mark.parametrize("call, match", [
    (lambda b: b.add_fluid_box(0, (1.0, 0.0, 1.0), viscosity=1.0), r"size\[1\]=0.0 must be > 0"),
    (lambda b: b.add_fluid_box(0, (1.0, 1.0, 1.0), density=-1.0), r"density=-1.0 must be >= 0"),
    (lambda b: b.add_fluid_box(5, (1.0, 1.0, 1.0)), r"body=5 is not a body id"),
    (lambda b: b.add_free_coordinate("x", 0, kind="ball"), r"kind='ball' must be 'slide' or 'hinge'"),
    (lambda b: b.add_free_coordinate("x", 0, axis=(0.0, 0.0)), r"axis=\(0.0, 0.0\) must not be zero"),
    (lambda b: b.add_free_coordinate("x", 0, armature=-1.0), r"armature=-1.0 must be >= 0"),
])
def test_bad_fluid_and_free_coordinate_arguments_name_the_culprit(call, match):
    b, _ = free_body()
    with pytest.raises(ModelError, match=match):
        call(b)
