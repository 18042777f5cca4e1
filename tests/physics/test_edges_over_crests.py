"""A straight side longer than the ground's crests are apart (a plank, a capsule lying across
sine hills): held in pieces of at most half the shortest wavelength (builder.edge_pieces),
each piece's contact holding the crest under it in the velocity solve. With one contact for
the whole side, a plank resting on three crests had one of them in the solve: it fell about
that crest while the position correction held it up, its velocity grew to 2.3 m/s and its
energy by 3 J in 0.25 s with no audit, then the correction_work audit counted every step;
sliding over crests it gained up to 8 % of its kinetic energy."""
import math

import numpy as np
import pytest

import planarsim as ps
from planarsim import terrain
from planarsim.builder import edge_pieces
from planarsim.compiled import audit_counts

G = 9.81


def _plank(shape, lam, dt, mu=1.0, pos=(0.1, 0.2), angle=0.03, vel=(0.0, 0.0), amp=0.05):
    """A 1 kg plank (a 1.04 x 0.04 m box, or a 1 m capsule of radius 2 cm) over hills of
    wavelength lam [m]."""
    b = ps.ModelBuilder(dt=dt, terrain=terrain.hills([amp], [lam]))
    side = (("box", (0, 0), 1.04, 0.04, {"mu": mu}) if shape == "box"
            else ("capsule", (-0.5, 0), (0.5, 0), 0.02, {"mu": mu}))
    b.add_body("plank", 1.0, 1.0 / 12, pos=pos, angle=angle, vel=vel, shapes=[side])
    return ps.Simulator(b.compile())


def _energy(sim):
    """Symplectic Euler's modified energy [J] of the 1 kg plank: E - (h / 2) m g v_y."""
    q, v = sim.state.q[0], sim.state.v[0]
    return (0.5 * (v[0] ** 2 + v[1] ** 2) + 0.5 / 12 * v[2] ** 2 + G * q[1]
            - 0.5 * sim.dt * G * v[1])


@pytest.mark.parametrize("shape", ["box", "capsule"])
@pytest.mark.parametrize("lam, dt", [(0.3, 1e-3), (0.45, 1e-2), (0.7, 2e-3), (0.3, 1e-2)])
def test_a_plank_dropped_across_crests_comes_to_rest_on_them(shape, lam, dt):
    """Dropped 0.1 m onto 2 or 3 crests: it lands (losing energy), rests on them with no
    velocity, never gains energy, and draws no audit."""
    sim = _plank(shape, lam, dt)
    start = _energy(sim)
    highest = -math.inf
    for _ in range(int(round(0.5 / dt))):
        sim.step()
        highest = max(highest, _energy(sim) - start)
    assert highest <= 1e-9, highest
    assert np.abs(sim.state.v).max() <= 1e-9, sim.state.v
    assert sum(audit_counts(sim.ws).values()) == 0, audit_counts(sim.ws)


@pytest.mark.parametrize("shape", ["box", "capsule"])
@pytest.mark.parametrize("lam, dt, share", [(0.3, 1e-3, 1e-6), (0.45, 1e-2, 1e-3),
                                           (0.3, 1e-2, 1e-3)])
@pytest.mark.parametrize("mu, speed", [(0.0, 1.0), (0.3, 2.0)])
def test_a_plank_sliding_over_crests_gains_no_energy_beyond_the_steps_order(
        shape, lam, dt, share, mu, speed):
    """Thrown along hills of 2 cm, frictionless or sliding to a stop on mu 0.3: its energy
    only falls, but for rises of the step's first order (a share of 1e-6 of its kinetic
    energy at 1 ms, 1e-3 at 10 ms; measured 1.3e-7 and 1.1e-4 at most; 5e-2 and 8e-2 with
    one contact for the whole side), and no audit."""
    sim = _plank(shape, lam, dt, mu=mu, pos=(0.1, 0.05), angle=0.0, vel=(speed, 0.0), amp=0.02)
    energies = []
    for _ in range(int(round(1.0 / dt))):
        sim.step()
        energies.append(_energy(sim))
    e = np.array(energies)
    rise = float(np.max(e - np.minimum.accumulate(e)))
    assert rise <= share * 0.5 * speed ** 2, rise
    assert sum(audit_counts(sim.ws).values()) == 0, audit_counts(sim.ws)


def test_a_side_is_cut_only_where_it_may_span_two_crests():
    """One piece (the whole side, own part (0, 0)) up to half the shortest wavelength, as
    every foot of the walkers on their hills; beyond, equal pieces that overlap by a quarter
    of a piece at each cut and own consecutive parts of the side."""
    a, b = np.array([-0.5, 0.0]), np.array([0.5, 0.0])
    assert len(edge_pieces(a, b, terrain.flat())) == 1
    assert len(edge_pieces(a, b, terrain.hills([0.05], [2.0]))) == 1
    pieces = edge_pieces(a, b, terrain.hills([0.05, 0.01], [3.0, 0.3]))
    assert len(pieces) == 7
    owned = []
    for start, end, (lo, hi) in pieces:
        owned.append((start + lo * (end - start), start + hi * (end - start)))
        assert np.hypot(*(end - start)) <= 1.5 * 0.15 + 1e-12
    assert np.allclose(owned[0][0], a) and np.allclose(owned[-1][1], b)
    for (_, e0), (s1, _) in zip(owned, owned[1:]):
        assert np.allclose(e0, s1)
    names = ps.ModelBuilder(terrain=terrain.hills([0.05], [0.3]))
    names.add_body("plank", 1.0, 0.1, pos=(0.0, 1.0), shapes=[("box", (0, 0), 1.0, 0.04)])
    assert "plank.box0/edge0.3" in names.compile().contact_names
