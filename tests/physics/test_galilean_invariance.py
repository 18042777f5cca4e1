"""Galilean invariance of free systems: a model that touches the world nowhere (no ground, no
joint to the world, no static shape) moves the same seen from a frame drifting at any
constant speed. Seeded corpora of hard cases (two bodies in an impact: circles and squares,
mass ratio 1e-2..1e2, restitution 0..1, friction 0..2, spins up to 50 rad/s, 0.1..30 m/s,
dt 1e-4..1e-2; chains of two to four bodies pinned together with armature and springs,
spinning, mass ratio 1e-2..1e2), each run at rest and drifting at 1..1000 m/s: the velocities
less the drift agree to 1e-8 of the largest. Before the step's checks measured a free model
about its centre of mass (kernels/checks/frame.py) and pairs' sweeps and speculative margins
used the shapes' relative speeds, 189 of 2,000 such impacts differed (up to half the
velocity), and 18 of 500 such chains (benchmarks/galilean_corpus.py runs them all)."""
import numpy as np
import pytest

import planarsim as ps
from planarsim.compiled import audit_counts

R = 0.1


def _shape(kind, e, mu):
    if kind == "circle":
        return [("circle", (0.0, 0.0), R, {"restitution": e, "mu": mu})]
    return [("box", (0.0, 0.0), 2 * R, 2 * R, {"restitution": e, "mu": mu})]


def _impact(case, drift):
    """Two bodies in zero gravity, the first at u m/s toward the second, seen drifting at
    `drift` (m/s, m/s); returns the velocities less the drift after the impact and the audit's
    count."""
    kind_a, kind_b, e, mu, m1, m2, u, dt, off, w0, angle = case
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    gap = 0.3 + 3.7 * u * dt
    b.add_body("a", m1, 0.5 * m1 * R * R, pos=(-R - gap / 2, 0.0), vel=(u + drift[0], drift[1]),
               omega=w0, shapes=_shape(kind_a, e, mu))
    b.add_body("b", m2, 0.5 * m2 * R * R, pos=(R + gap / 2, off), vel=drift, angle=angle,
               shapes=_shape(kind_b, e, mu))
    sim = ps.Simulator(b.compile())
    sim.steps(int(gap / (u * dt)) + 40)
    v = sim.state.v.copy()
    v[:, :2] -= drift
    return v, sum(audit_counts(sim.ws).values())


def _impact_cases(seed, n):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        case = (str(rng.choice(["circle", "box"])), str(rng.choice(["circle", "box"])),
                float(rng.choice([0.0, 0.5, 1.0])), float(rng.choice([0.0, 0.3, 1.0, 2.0])),
                10 ** rng.uniform(-2, 2), 10 ** rng.uniform(-2, 2), 10 ** rng.uniform(-1, 1.5),
                float(rng.choice([1e-4, 1e-3, 1e-2])), rng.uniform(-0.18, 0.18),
                rng.uniform(-50, 50), rng.uniform(0, 1.5))
        drift = tuple(rng.uniform(-1, 1, 2) * 10 ** rng.uniform(0, 3))
        yield case, drift


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_an_impact_of_two_free_bodies_is_the_same_in_a_drifting_frame(seed):
    """100 seeded impacts per seed (module docstring), at rest and drifting."""
    for case, drift in _impact_cases(seed, 100):
        v0, audits0 = _impact(case, (0.0, 0.0))
        v1, audits1 = _impact(case, drift)
        assert audits0 == 0 and audits1 == 0, (case, drift)
        diff = np.abs(v1 - v0).max() / max(1.0, np.abs(v0).max())
        assert diff <= 1e-8, (case, drift, diff)


def _chain(case, drift):
    """n bodies (mass ratio r end to end) pinned in a row with armature a and a spring k on
    each pin, spinning at w rad/s about the origin, neighbours' spins 2 rel apart, drifting at
    `drift`; returns the velocities less the drift after 100 steps and the audit's count."""
    n, a, k, dt, w, rel, ratio = case
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    bodies = []
    for i in range(n):
        m = ratio ** (i / (n - 1))
        bodies.append(b.add_body(f"link{i}", m, 0.02 * m, pos=(0.5 * i, 0.0),
                                 vel=(drift[0], w * 0.5 * i + drift[1]),
                                 omega=w + rel * (-1) ** i, angle=0.1 * i))
    for i in range(n - 1):
        b.add_pin(f"pin{i}", bodies[i], bodies[i + 1], anchor_world=(0.5 * i + 0.25, 0.0),
                  stiffness=k, armature=a, ref_angle=0.0)
    sim = ps.Simulator(b.compile())
    sim.steps(100)
    v = sim.state.v.copy()
    v[:, :2] -= drift
    return v, sum(audit_counts(sim.ws).values())


def _chain_cases(seed, n):
    rng = np.random.default_rng(100 + seed)
    for _ in range(n):
        case = (int(rng.integers(2, 5)), float(rng.choice([0.0, 0.01, 0.1])),
                float(rng.choice([0.0, 10.0, 1e3])), float(rng.choice([1e-3, 1e-2])),
                rng.uniform(-5, 5), rng.uniform(-15, 15), 10 ** rng.uniform(-2, 2))
        drift = tuple(rng.uniform(-1, 1, 2) * 10 ** rng.uniform(0, 2.5))
        yield case, drift


@pytest.mark.parametrize("seed", [0, 1])
def test_a_free_spinning_chain_is_the_same_in_a_drifting_frame(seed):
    """25 seeded chains per seed (_chain; armature 0..0.1, springs 0..1e3, dt 1e-3..1e-2,
    up to 20 rad/s), at rest and drifting at 1..300 m/s."""
    for case, drift in _chain_cases(seed, 25):
        v0, audits0 = _chain(case, (0.0, 0.0))
        v1, audits1 = _chain(case, drift)
        assert audits0 == 0 and audits1 == 0, (case, drift)
        diff = np.abs(v1 - v0).max() / max(1.0, np.abs(v0).max())
        assert diff <= 1e-8, (case, drift, diff)
