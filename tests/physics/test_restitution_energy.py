"""Restitution with friction adds no energy (the energetic bound, kernels/solver/rebound.py).

Newton's law of restitution with Coulomb friction can return more energy than an impact
brought (Kane's paradox): a spinning triangle dropped with e = 1 and mu = 1 gained 25 % of its
energy in one impact, unaudited. The step now scales the rebounds of an answer that adds
energy down to the largest that adds none. Energy here is symplectic Euler's modified energy
E - (h/2) sum m g v_y, which the scheme keeps in free flight (E itself swings by h m g v_y / 2
with the vertical velocity, and an impact reverses it)."""
import math

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st

import planarsim as ps
from benchmarks.bounce_energy import G, modified_energy, shape_of
from planarsim.compiled import audit_counts
from planarsim.kernels.info import INFO_TURN_SUBSTEPS


def triangle(mu, e, dt=1e-3):
    """A 0.3 m triangle of 1 kg dropped from 1 m at 0.3 rad, spinning at 10 rad/s."""
    s = 0.3
    b = ps.ModelBuilder(dt=dt)
    b.add_body("triangle", mass=1.0, inertia=s * s / 18, pos=(0, 1.0), angle=0.3, omega=10.0,
               shapes=[("polygon", [(-s / 2, -s / 3), (s / 2, -s / 3), (0, s / 2)],
                        {"mu": mu, "restitution": e})])
    return ps.Simulator(b.compile())


def energies(sim, dt, steps):
    """The modified energy after each of `steps` steps."""
    out = []
    for _ in range(steps):
        sim.steps(1)
        out.append(modified_energy(sim, dt))
    return np.array(out)


def test_an_elastic_bounce_with_friction_adds_no_energy():
    """e = 1, mu = 1: the corner sticks at its first impact; Newton's rebound on top of the
    sticking friction's turn added 25 % of the energy (10.04 J -> 12.58 J). Now no step adds
    more than 1e-6 of it, and the first impact, which sticks (its friction does no work),
    keeps it: the bound takes the largest rebound that adds none, not a plastic impact."""
    sim = triangle(1.0, 1.0)
    start = modified_energy(sim, 1e-3)
    e = energies(sim, 1e-3, 2000)
    assert e.max() <= start * (1 + 1e-6), (e.max(), start)
    # the first impact is at step 421 (the corner reaches the ground): energy kept
    assert abs(e[430] - start) <= 1e-5 * start, (e[430], start)
    assert sum(audit_counts(sim.ws).values()) == 0


def test_a_frictionless_elastic_bounce_keeps_its_energy_exactly():
    """mu = 0, e = 1: Newton's law conserves energy; the bound never acts."""
    sim = triangle(0.0, 1.0)
    start = modified_energy(sim, 1e-3)
    e = energies(sim, 1e-3, 2000)
    assert np.abs(e - start).max() <= 1e-9 * start


def gain_of_steps(sim, dt, steps):
    """The greatest rise [J] over `steps` steps of the modified energy each step keeps,
    summed step by step: a step taken in n turn sub-steps (step.turn_substeps: a spinning
    corner near the ground) is symplectic Euler at dt / n, which keeps E - (dt / 2n) sum m g
    v_y, not the whole step's. (Measured against the whole step's, such a step moves it by
    (dt / 2)(1 - 1/n) m g dv_y, its own step length's term: + m (g dt)^2 / 3 in free fall
    at n = 3, the other way where the step stops a fall.)"""
    a = sim.model.arrays
    m, inertia = float(a.body_mass[0]), float(a.body_inertia[0])
    info = sim.ws.info
    q, v = sim.state.q, sim.state.v

    def energy_and_vy():
        return (0.5 * m * (v[0, 0] ** 2 + v[0, 1] ** 2) + 0.5 * inertia * v[0, 2] ** 2
                + m * G * q[0, 1], v[0, 1])

    total = 0.0
    top = 0.0
    for _ in range(steps):
        e0, vy0 = energy_and_vy()
        sim.steps(1)
        e1, vy1 = energy_and_vy()
        h = dt / max(int(info[INFO_TURN_SUBSTEPS]), 1)
        total += (e1 - e0) - 0.5 * h * G * m * (vy1 - vy0)
        top = max(top, total)
    return top


@settings(max_examples=25, deadline=None)
@given(kind=st.sampled_from(["triangle", "box", "circle", "capsule"]),
       size=st.floats(0.05, 0.5), log_mass=st.floats(-2.0, 2.0), log_inertia=st.floats(-1.0, 1.0),
       mu=st.sampled_from([0.0, 0.3, 1.0, 2.0]), e=st.sampled_from([0.3, 0.7, 1.0]),
       dt=st.sampled_from([1e-4, 1e-3, 5e-3]), angle=st.floats(-3.0, 3.0),
       omega=st.floats(-30.0, 30.0), vx=st.floats(-3.0, 3.0), vy=st.floats(-5.0, 2.0))
@example(kind="triangle", size=0.5, log_mass=0.0, log_inertia=0.0, mu=0.0, e=0.3, dt=0.005,
         angle=0.453125, omega=26.5, vx=0.0, vy=0.5)
def test_dropped_shapes_bounce_without_gaining_energy(kind, size, log_mass, log_inertia, mu, e,
                                                      dt, angle, omega, vx, vy):
    """Any shape, mass, inertia, spin, friction and restitution, dropped on the ground for
    1.5 s: the modified energy of the steps taken (gain_of_steps) never rises above its start
    by more than 1e-6 of it, and the audit stays silent. (Measured over 300 random drops:
    largest rise 6.5e-7. The example: a triangle spinning at 26.5 rad/s at dt 5 ms, whose
    corner's approach is taken in 3 sub-steps twice before it strikes.)"""
    mass = 10.0 ** log_mass
    shape, inertia = shape_of(kind, size, 0.6, {"mu": mu, "restitution": e})
    b = ps.ModelBuilder(dt=dt)
    b.add_body("body", mass=mass, inertia=mass * inertia * 10.0 ** log_inertia, pos=(0.0, 1.0),
               angle=angle, omega=omega, vel=(vx, vy), shapes=[shape])
    sim = ps.Simulator(b.compile())
    start = modified_energy(sim, dt)
    top = gain_of_steps(sim, dt, int(1.5 / dt))
    assert top <= 1e-6 * abs(start), (top, start)
    assert sum(audit_counts(sim.ws).values()) == 0


def test_kanes_double_pendulum_striking_rough_ground_gains_nothing():
    """Kane's example: a double pendulum whose tip strikes rough ground, e = 1. Over 3 s of
    strikes the modified energy never rises beyond SHAKE's swing of it before any impact
    (6e-6), at mu 0.3 and 1 alike."""
    for mu in (0.3, 1.0):
        dt = 1e-3
        L = 0.6
        b = ps.ModelBuilder(dt=dt)
        a1, a2 = -0.3, -1.2
        u = b.add_body("upper", mass=1.0, inertia=L * L / 12, angle=a1,
                       pos=(0.5 * L * math.cos(a1), 1.0 + 0.5 * L * math.sin(a1)))
        knee = (L * math.cos(a1), 1.0 + L * math.sin(a1))
        low = b.add_body("lower", mass=1.0, inertia=L * L / 12, angle=a2,
                         pos=(knee[0] + 0.5 * L * math.cos(a2), knee[1] + 0.5 * L * math.sin(a2)),
                         shapes=[("circle", (0.5 * L, 0.0), 0.03, {"mu": mu, "restitution": 1.0})])
        b.add_pin("hip", None, u, anchor_world=(0.0, 1.0))
        b.add_pin("knee", u, low, anchor_world=knee)
        sim = ps.Simulator(b.compile())
        start = modified_energy(sim, dt)
        e = energies(sim, dt, 3000)
        assert e.max() <= start * (1 + 2e-5), (mu, e.max(), start)
        assert e[-1] < start * (1 - 1e-3)       # (it struck: friction took some)
        assert sum(audit_counts(sim.ws).values()) == 0
