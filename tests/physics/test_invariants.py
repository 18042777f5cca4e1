"""Conservation, invariance and determinism on random free-floating assemblies."""
import math

import numpy as np
from hypothesis import HealthCheck, given, settings, strategies as st

import planarsim as ps


@st.composite
def assemblies(draw):
    """1-8 rigid bodies in a random tree of pins (body i pinned to an earlier body), no
    gravity, random poses and velocities. Returns a description the builder can mirror."""
    n = draw(st.integers(1, 8))
    bodies = []
    for i in range(n):
        bodies.append(dict(mass=draw(st.floats(0.2, 5.0)), inertia=draw(st.floats(0.01, 1.0)),
                           angle=draw(st.floats(-math.pi, math.pi)),
                           vel=(draw(st.floats(-2, 2)), draw(st.floats(-2, 2))),
                           omega=draw(st.floats(-3, 3))))
    # place bodies: body 0 at the origin, each next one at an arm from a pin on its parent
    pins = []
    pos = [np.zeros(2)]
    for i in range(1, n):
        parent = draw(st.integers(0, i - 1))
        pin_at = pos[parent] + np.array([draw(st.floats(-0.5, 0.5)), draw(st.floats(-0.5, 0.5))])
        arm = np.array([draw(st.floats(-0.5, 0.5)), draw(st.floats(-0.5, 0.5))])
        pos.append(pin_at + arm)
        pins.append((parent, i, pin_at))
    for b, p in zip(bodies, pos):
        b["pos"] = tuple(p)
    return bodies, pins


def build(desc, mirror=False, shift=(0.0, 0.0)):
    bodies, pins = desc
    sx = -1.0 if mirror else 1.0
    b = ps.ModelBuilder(dt=1e-3, gravity=(0.0, 0.0))
    for i, d in enumerate(bodies):
        b.add_body(f"b{i}", d["mass"], d["inertia"],
                   pos=(sx * d["pos"][0] + shift[0], d["pos"][1] + shift[1]),
                   angle=sx * d["angle"], vel=(sx * d["vel"][0], d["vel"][1]), omega=sx * d["omega"])
    for j, (a, c, at) in enumerate(pins):
        b.add_pin(f"p{j}", a, c, anchor_world=(sx * at[0] + shift[0], at[1] + shift[1]))
    return b.compile()


def momenta(model, q, v):
    a = model.arrays
    m = a.body_mass
    p = np.array([np.sum(m * v[:, 0]), np.sum(m * v[:, 1])])
    L = np.sum(m * (q[:, 0] * v[:, 1] - q[:, 1] * v[:, 0]) + a.body_inertia * v[:, 2])
    return p, L


SETTINGS = settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@SETTINGS
@given(assemblies())
def test_momentum_conserved(desc):
    model = build(desc)
    sim = ps.Simulator(model)
    sim.step()  # the first step projects the random velocities onto the constraints
    p0, L0 = momenta(model, sim.state.q, sim.state.v)
    sim.steps(1000)
    p1, L1 = momenta(model, sim.state.q, sim.state.v)
    scale_p = np.sum(model.arrays.body_mass) * (np.max(np.abs(sim.state.v[:, :2])) + 1e-3)
    r = np.max(np.hypot(sim.state.q[:, 0], sim.state.q[:, 1])) + 1.0
    scale_L = scale_p * r + np.sum(model.arrays.body_inertia * np.abs(sim.state.v[:, 2]))
    assert np.max(np.abs(p1 - p0)) <= 1e-9 * scale_p
    assert abs(L1 - L0) <= 1e-9 * scale_L


@SETTINGS
@given(assemblies(), st.floats(-5, 5), st.floats(-5, 5))
def test_translation_and_mirror_invariance(desc, dx, dy):
    ref = ps.Simulator(build(desc))
    moved = ps.Simulator(build(desc, shift=(dx, dy)))
    mirrored = ps.Simulator(build(desc, mirror=True))
    for sim in (ref, moved, mirrored):
        sim.steps(1000)
    q, qm, qr = ref.state.q, moved.state.q, mirrored.state.q
    assert np.max(np.abs(qm[:, 0] - dx - q[:, 0])) < 1e-9
    assert np.max(np.abs(qm[:, 1] - dy - q[:, 1])) < 1e-9
    assert np.max(np.abs(np.angle(np.exp(1j * (qm[:, 2] - q[:, 2]))))) < 1e-9
    assert np.max(np.abs(qr[:, 0] + q[:, 0])) < 1e-9
    assert np.max(np.abs(qr[:, 1] - q[:, 1])) < 1e-9
    assert np.max(np.abs(np.angle(np.exp(1j * (qr[:, 2] + q[:, 2]))))) < 1e-9


@SETTINGS
@given(assemblies())
def test_same_input_gives_identical_bits(desc):
    model = build(desc)
    a, b = ps.Simulator(model), ps.Simulator(model)
    a.steps(500)
    for _ in range(500):
        b.step()
    assert a.state.q.tobytes() == b.state.q.tobytes()
    assert a.state.v.tobytes() == b.state.v.tobytes()
