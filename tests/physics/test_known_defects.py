"""Known defects, found by an adversarial search at the extremes and not mended yet: each test
states what the physics requires and is marked xfail(strict=True), so it fails the suite the
day the defect is mended (then remove the mark) and cannot pass by accident meanwhile. The
engine neither raises nor audits in any of them: these are silent errors."""
import pytest

import planarsim as ps
from planarsim import compiled
from planarsim.energy import total_energy


DEFECTS = {
    "bounce": ("Newton restitution with Coulomb friction can add energy at an impact; the "
               "energy audit leaves bouncing contacts out"),
}


def audits(sim):
    return sum(compiled.audit_counts(sim.ws).values())


@pytest.mark.xfail(strict=True, raises=AssertionError, reason=DEFECTS["bounce"])
def test_an_elastic_bounce_with_friction_adds_no_energy_unaudited():
    s = 0.3
    b = ps.ModelBuilder(dt=1e-3)
    b.add_body("triangle", mass=1.0, inertia=s * s / 18, pos=(0, 1.0), angle=0.3, omega=10.0,
               shapes=[("polygon", [(-s / 2, -s / 3), (s / 2, -s / 3), (0, s / 2)],
                        {"mu": 1.0, "restitution": 1.0})])
    m = b.compile()
    sim = ps.Simulator(m)
    start = total_energy(m, sim.state.q, sim.state.v)
    most = start
    for _ in range(20):
        sim.steps(100)
        most = max(most, total_energy(m, sim.state.q, sim.state.v))
    assert audits(sim) > 0 or most <= start * (1 + 1e-3)
