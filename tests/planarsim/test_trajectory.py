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


def _bodies(n):
    b = ps.ModelBuilder(dt=1e-3)
    for i in range(n):
        b.add_body(f"b{i}", mass=1.0, inertia=0.01, pos=(float(i), 1.0))
    return b.compile()


def test_another_models_numbers_are_refused_not_computed(tmp_path):
    """A 2-body recording's energy, centre of mass and CSV with a 1-body model were computed
    silently (numpy broadcast the one body's mass over both); kinetic_energy of a 1-body v with
    a 2-body model likewise; concatenating two models' recordings raised numpy's "all the
    input array dimensions ... must match exactly"."""
    import pytest
    one, two = _bodies(1), _bodies(2)
    traj = ps.Simulator(two).run(0.01)
    for who in ("energy", "com", "com_velocity"):
        with pytest.raises(ValueError, match=rf"Trajectory\.{who}: the trajectory has 2 bodies "
                                             r"per frame but the model has 1"):
            getattr(traj, who)(one)
    with pytest.raises(ValueError, match=r"Trajectory\.to_csv: the trajectory has 2 bodies"):
        traj.to_csv(tmp_path / "t.csv", one)
    with pytest.raises(ValueError, match=r"kinetic_energy: v has shape \(1, 3\); it must be "
                                         r"\(\.\.\., 2, 3\)"):
        ps.kinetic_energy(two, two.q0, np.zeros((1, 3)))
    with pytest.raises(ValueError, match=r"potential_energy: q has shape \(3,\)"):
        ps.potential_energy(one, np.zeros(3))
    with pytest.raises(ValueError, match=r"Trajectory\.concatenate: chunk 1 has body_names "
                                         r"\['b0'\] but chunk 0 has \['b0', 'b1'\]"):
        Trajectory.concatenate([traj, ps.Simulator(one).run(0.01)])
    assert list(tmp_path.iterdir()) == []
    assert ps.total_energy(two, traj.q, traj.v).shape == (len(traj.t),)   # frames still fine
