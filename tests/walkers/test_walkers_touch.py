"""The walkers' shapes that collide: a fallen SIMBICON lies on the ground, not in it; the
MJCF loader's collide names."""
import pytest

import planarsim as ps
from planarsim.compiled import audit_counts
from planarsim.errors import ModelError
from walkers.simbicon.model import XML, build, non_foot_clearance


@pytest.mark.parametrize("vx", [1.5, -1.5])
def test_a_fallen_simbicon_lies_on_the_ground_not_in_it(vx):
    """No controller: thrown forward or backward at vx [m/s], the character collapses. Its
    torso, hip and knee spheres and leg capsules collide, so nothing ends inside the ground
    (they used to sink through it: only the feet had contacts)."""
    model = build()
    state = ps.make_state(model)
    state.v[:, 0] = vx
    sim = ps.Simulator(model, state=state)
    traj = sim.run(4.0, record_every=5)
    low = non_foot_clearance(model, traj.q)
    assert low.min() > -1e-8
    assert low[-1] < 0.01                      # it did fall: a part other than a foot touches
    assert all(v == 0 for v in audit_counts(sim.ws).values())


def test_mjcf_collide_names_unknown_geoms():
    with pytest.raises(ModelError, match="no_such_geom"):
        ps.mjcf.load_mjcf(XML, collide=("no_such_geom",))
