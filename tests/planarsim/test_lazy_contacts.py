"""On hills, free point contacts surely clear of the ground are not queried every step
(kernels/geometry/contacts.py): the step's numbers must be those of querying every contact, and a
skipped contact's kept gap must be a lower bound of its real gap."""
import numpy as np
import pytest

from numba import njit

import planarsim as ps
from planarsim import terrain
from planarsim.compile import options as compile_options
from planarsim.kernels.math2d import update_trig
from planarsim.kernels.solver.modes import engage_contacts
from planarsim.kernels.geometry.terrain import closest_point


def _boxes(ter, spin, dt=1e-3, n=4):
    """Boxes dropped from different heights and angles, spinning (up to `spin` rad/s), so
    contacts go clear, come back and touch down on different steps: a spinning box's corner
    moves fast while its centre does not, which is where a skipped contact's kept gap (a lower
    bound) is not enough and it must be queried when it may touch down."""
    b = ps.ModelBuilder(dt=dt, terrain=ter)
    for i in range(n):
        x = 1.1 * i
        box = b.add_body(f"box{i}", mass=1.0 + i, inertia=(1.0 + i) * 0.05 / 12,
                         pos=(x, float(ter.height(x)) + 0.2 + 0.15 * i), angle=0.3 * i - 0.4,
                         vel=(0.5 - 0.3 * i, 0.0), omega=spin * (1.0 - 0.5 * i))
        b.add_box_contacts(f"box{i}", box, (0.0, 0.0), 0.4, 0.1, mu=0.6)
    return b.compile()


@pytest.mark.parametrize("spin, dt", [(2.0, 1e-3), (30.0, 1e-3), (30.0, 4e-3)])
def test_unqueried_contacts_change_no_number(spin, dt):
    """Hills of zero amplitude are flat ground through the hills code path (where contacts
    are left unqueried); every state must equal flat ground's (every contact queried), bit for
    bit, while contacts were in fact left unqueried."""
    flat = ps.Simulator(_boxes(terrain.flat(), spin, dt))
    hills = ps.Simulator(_boxes(terrain.hills([0.0], [3.0]), spin, dt))
    assert hills.model.arrays.terrain_coef[2] != 0.0
    skipped = 0
    for _ in range(int(1.5 / dt)):
        flat.steps(1)
        hills.steps(1)
        skipped += int(hills.ws.contact_stale.sum())
        assert np.array_equal(flat.state.q, hills.state.q)
        assert np.array_equal(flat.state.v, hills.state.v)
        assert np.array_equal(flat.state.contact_mode, hills.state.contact_mode)
        assert np.array_equal(flat.ws.contact_point, hills.ws.contact_point)
    assert skipped > 100


def test_kept_gap_is_a_lower_bound_on_hills():
    ter = terrain.hills([0.08, 0.03], [2.5, 0.9], [0.3, 1.0])
    sim = ps.Simulator(_boxes(ter, 30.0))
    model = sim.model.arrays
    coef = np.asarray(model.terrain_coef)
    checked = 0
    for _ in range(1500):
        q0 = sim.state.q.copy()
        sim.steps(1)
        ws = sim.ws
        for i in np.flatnonzero(ws.contact_stale):
            # the kept gap is of the step's start configuration
            b = model.contact_body[i]
            c, s = np.cos(q0[b, 2]), np.sin(q0[b, 2])
            lx, ly = model.contact_local[i]
            px, py = q0[b, 0] + c * lx - s * ly, q0[b, 1] + s * lx + c * ly
            gap = closest_point.py_func(coef, px, py)[4]
            assert ws.contact_gap[i] <= gap + 1e-12
            assert ws.contact_gap[i] > 0.0
            checked += 1
    assert checked > 1000


_jit = njit(**dict(compile_options(), cache=False))   # not cached: it must follow the kernels it calls


@_jit
def _engage(m, s, ws, h):
    update_trig(s.q, ws.body_cs)
    return engage_contacts(m, s, ws, h, True, s.v)


def test_engage_queries_a_skipped_contact_before_judging_it():
    """A skipped contact's kept gap is only a lower bound: where that bound says the motion
    may push it into the ground, its real gap decides. A box corner 5 cm up, moving down at
    20 mm a step, with a kept bound of 1 mm: it must stay free (and be queried), where the
    bound alone would engage it."""
    ter = terrain.hills([0.0], [3.0])
    b = ps.ModelBuilder(dt=1e-3, terrain=ter)
    box = b.add_body("box", mass=1.0, inertia=0.01, pos=(0.0, 0.05 + 0.05), vel=(0.0, -20.0))
    b.add_box_contacts("box", box, (0.0, 0.0), 0.4, 0.1, mu=0.6)
    sim = ps.Simulator(b.compile())
    sim.steps(1)                        # every contact queried at 5 cm or more; now 2 cm lower
    state, ws, m = sim.state, sim.ws, sim.model.arrays
    low = [i for i in range(4) if m.contact_local[i, 1] < 0.0]
    real = ws.contact_gap.copy()
    for i in low:
        ws.contact_stale[i] = 1
        ws.contact_gap[i] = 1e-3
    h = 1e-3
    assert all(real[i] > h * 20.0 + 0.02 for i in low)   # clear of this step's 20 mm
    assert _engage(m, state, ws, h) == 0
    for i in low:
        assert state.contact_mode[i] == 0
        assert ws.contact_stale[i] == 0
        assert ws.contact_gap[i] > h * 20.0        # its real gap, queried at s.q


def test_a_new_model_forgets_the_ground_queries_of_the_old():
    """Simulator.model = another terrain: the kept gaps were of the old ground, so the next
    step queries every contact again. Hills raised 1 m under falling boxes bury every corner,
    which the old bounds call clear; kept, the corners stay unqueried and sink unseen."""
    ter = terrain.hills([0.08], [2.5])
    sim = ps.Simulator(_boxes(ter, 2.0))
    sim.steps(30)          # every box in the air, every contact clear and unqueried
    assert sim.ws.contact_stale.all() and (sim.state.contact_mode == 0).all()
    sim.model = _boxes(terrain.hills([0.08], [2.5], height=1.0), 2.0)
    sim.steps(1)
    assert sim.ws.contact_stale.sum() == 0
    # every corner the raised ground buried was found and lifted onto it in that step
    m = sim.model.arrays
    coef = np.asarray(m.terrain_coef)
    q = sim.state.q
    gaps = []
    for i in range(m.contact_body.shape[0]):
        b = m.contact_body[i]
        c, s = np.cos(q[b, 2]), np.sin(q[b, 2])
        lx, ly = m.contact_local[i]
        gaps.append(closest_point.py_func(coef, q[b, 0] + c * lx - s * ly, q[b, 1] + s * lx + c * ly)[4])
    assert min(gaps) >= -1e-8


def test_step_from_python_forgets_the_ground_queries_of_another_model():
    """The same Workspace stepped by step_from_python with another model's arrays: the next
    step queries every contact again (the kept gaps were of the other ground)."""
    from planarsim.compiled import step_from_python
    low = _boxes(terrain.hills([0.08], [2.5]), 2.0)
    high = _boxes(terrain.hills([0.08], [2.5], height=1.0), 2.0)
    sim = ps.Simulator(low)
    state, ws, opt = sim.state, sim.ws, sim.options
    u = np.zeros(0)
    for _ in range(30):
        assert step_from_python(low.arrays, state, ws, opt, u) == 0
    assert ws.contact_stale.all()
    step_from_python(high.arrays, state, ws, opt, u)
    assert ws.contact_stale.sum() == 0
