"""The recorded fields (planarsim/trajectory.py RECORDED): one table that the Recorder, frame
sizes, the Python recording and the Trajectory follow, and the compiled recording agrees."""
import numpy as np

import planarsim as ps
from planarsim.compiled import jit, record_frame
from planarsim.trajectory import (FRAME_DIMS, RECORDED, Recorder, Trajectory, frame_bytes,
                                  make_recorder, record_state)


def _box_on_ground():
    b = ps.ModelBuilder(dt=1e-3)
    box = b.add_body("box", mass=2.0, inertia=0.1, pos=(0.0, 0.1), vel=(1.0, 0.0))
    b.add_box_contacts("corner", box, (0.0, 0.0), 0.8, 0.2, mu=0.3)
    b.add_body_force("push", box)
    return b.compile()


@jit
def _record_compiled(s, ws, rec, k):
    record_frame(s, ws, rec, k)


def test_recorder_frame_sizes_and_trajectory_follow_the_one_table():
    model = _box_on_ground()
    rec = make_recorder(model, 3)
    assert Recorder._fields == tuple(FRAME_DIMS) == Trajectory._ARRAYS == tuple(r[0] for r in RECORDED)
    sizes = dict(K=3, n_body=model.n_body, n_contact=model.n_contact, n_act=model.n_act)
    for name, dims, dtype, _ in RECORDED:
        array = getattr(rec, name)
        assert array.dtype == dtype and array.shape == tuple(sizes.get(d, d) for d in dims), name
    assert frame_bytes(model) == sum(array[0].nbytes for array in rec)


def test_python_and_compiled_recordings_of_a_state_are_the_same():
    model = _box_on_ground()
    sim = ps.Simulator(model)
    sim.steps(150, u=np.array([3.0]))          # sliding, corners on the ground, a force acting
    rec = make_recorder(model, 2)
    record_state(rec, 0, sim.state, sim.ws)
    _record_compiled(sim.state, sim.ws, rec, 1)
    for name in Recorder._fields:
        frames = getattr(rec, name)
        assert np.array_equal(frames[0], frames[1]), name
    assert np.any(rec.contact_impulse[0] != 0) and np.any(rec.act_power[0] != 0)
