import numpy as np
import pytest

import planarsim as ps


def _pendulum():
    b = ps.ModelBuilder(dt=1e-3)
    rod = b.add_body("rod", mass=1.0, inertia=1.0 / 12, pos=(0.5, 0.0))
    b.add_pin("pivot", None, rod, anchor_world=(0.0, 0.0))
    return b.compile()


def test_pendulum_swings_and_keeps_its_pin():
    b = ps.ModelBuilder(dt=1e-3)
    rod = b.add_body("rod", mass=1.0, inertia=1.0 / 12, pos=(0.5, 0.0))
    b.add_pin("pivot", None, rod, anchor_world=(0.0, 0.0))
    sim = ps.Simulator(b.compile())
    sim.steps(300)
    x, y, th = sim.state.q[0]
    assert y < -0.1  # it fell
    assert abs(np.hypot(x, y) - 0.5) < 1e-9  # the pin held


@pytest.mark.parametrize("field, value, rule", [
    ("refine_iters", -1, ">= 0"), ("refine_iters", 1.5, "integer"),
    ("refine_tol", float("nan"), "finite"), ("pivot_tol", 0.0, r"\(0, 1\)"),
    ("guard_limit", float("inf"), "finite"), ("mode_strategy", 7, "alternating"),
    ("audit_raise", 2, "0 or 1"), ("max_ccd_splits", "4", "integer"),
])
def test_bad_step_options_are_named(field, value, rule):
    model = _pendulum()
    with pytest.raises(ValueError, match=f"StepOptions.{field}=.*{rule}"):
        ps.Simulator(model, ps.StepOptions(**{field: value}))


def test_options_are_normalised_and_python_steps_match_compiled_steps():
    model = _pendulum()
    a = ps.Simulator(model, ps.StepOptions(refine_iters=np.int32(2), refine_tol=0))
    assert type(a.options.refine_iters) is int and type(a.options.refine_tol) is float
    b = ps.Simulator(model, ps.StepOptions(refine_iters=2, refine_tol=0.0))
    for _ in range(500):
        a.step()
    b.steps(500)
    assert np.array_equal(a.state.q, b.state.q) and np.array_equal(a.state.v, b.state.v)


def test_state_assignment_copies_into_the_simulators_arrays():
    model = _pendulum()
    sim = ps.Simulator(model)
    own = sim.state
    other = ps.make_state(model)
    other.q[0, 2] = 0.3
    sim.state = other
    assert sim.state is own and sim.state.q[0, 2] == 0.3
    other.q[0, 2] = 0.5                      # no aliasing
    assert sim.state.q[0, 2] == 0.3
    bad = ps.State(*(np.zeros((7,) + a.shape[1:], a.dtype) if k == 0 else a
                     for k, a in enumerate(other)))
    with pytest.raises(ValueError, match="state.q has shape"):
        sim.state = bad
    with pytest.raises(TypeError, match="State"):
        sim.state = {"q": 1}


def test_changing_options_reaches_the_python_step():
    model = _pendulum()
    a = ps.Simulator(model)
    a.options = ps.StepOptions(refine_iters=0)
    b = ps.Simulator(model, ps.StepOptions(refine_iters=0))
    c = ps.Simulator(model)
    for _ in range(300):
        a.step()
        b.step()
        c.step()
    assert np.array_equal(a.state.q, b.state.q)
    assert not np.array_equal(a.state.q, c.state.q)   # refinement on moves the result
    with pytest.raises(ValueError, match="refine_iters"):
        a.options = ps.StepOptions(refine_iters=-2)


def test_commands_of_any_layout_and_type_give_the_same_step():
    b = ps.ModelBuilder(dt=1e-3)
    upper = b.add_body("upper", mass=1.0, inertia=1.0 / 12, pos=(0.5, 0.0))
    lower = b.add_body("lower", mass=1.0, inertia=1.0 / 12, pos=(1.5, 0.0))
    b.add_pin("shoulder", None, upper, anchor_world=(0.0, 0.0))
    b.add_pin("elbow", upper, lower, anchor_world=(1.0, 0.0))
    b.add_pin_motor("m0", "shoulder")
    b.add_pin_motor("m1", "elbow")
    model = b.compile()
    strided = np.array([0.5, 9.0, -0.25, 9.0])[::2]        # a non-contiguous view
    assert not strided.flags.c_contiguous
    runs = []
    # 0.5 and -0.25 are exact in float32 too
    for u in (np.array([0.5, -0.25]), [0.5, -0.25], np.array([0.5, -0.25], np.float32), strided):
        sim = ps.Simulator(model)
        for _ in range(200):
            sim.step(u)
        sim.steps(100, u)
        sim.run(n_steps=50, u=u)
        runs.append(sim.state.q.copy())
    for q in runs[1:]:
        assert np.array_equal(q, runs[0])
    with pytest.raises(ValueError, match="shape"):
        ps.Simulator(model).step(np.zeros(3))


def test_a_controller_that_returns_nothing_is_named():
    """A Python controller that forgets `return` would run with zero commands: an error."""
    b = ps.ModelBuilder(dt=1e-3)
    body = b.add_body("arm", 1.0, 0.1, pos=(0.0, -0.5))
    b.add_pin("shoulder", None, body, anchor_world=(0.0, 0.0))
    b.add_pin_motor("motor", "shoulder")
    sim = ps.Simulator(b.compile())

    def hold(sim):
        0.0 * sim.t
    with pytest.raises(TypeError, match="'hold' returned None.*forget `return`"):
        sim.run(0.01, controller=hold)


def test_a_nan_command_is_named_as_a_command_and_nothing_steps():
    b = ps.ModelBuilder(dt=1e-3)
    body = b.add_body("arm", 1.0, 0.1, pos=(0.0, -0.5))
    b.add_pin("shoulder", None, body, anchor_world=(0.0, 0.0))
    b.add_pin_motor("motor", "shoulder")
    sim = ps.Simulator(b.compile())
    before = sim.snapshot()
    for call in (lambda: sim.step([np.nan]), lambda: sim.steps(3, [np.inf]),
                 lambda: sim.run(0.01, controller=lambda s: [np.nan])):
        with pytest.raises(ValueError, match=r"command u\[0\] for actuator 'motor' is (nan|inf)"):
            call()
        assert np.array_equal(sim.state.q, before.q) and sim.state.step[0] == before.step[0]


def test_a_step_of_another_length_needs_no_new_model():
    """StepOptions.dt: a step of tau with the model as it is equals a step of a model built
    with dt = tau, bit for bit; time advances by tau; 0 means the model's dt."""
    from benchmarks.scenes import biped_collapse
    tau = 3.7e-4
    a = ps.Simulator(biped_collapse(dt=1e-3), ps.make_options(dt=tau))
    b = ps.Simulator(biped_collapse(dt=tau))
    for _ in range(300):
        a.step()
        b.step()
    assert np.array_equal(a.state.q, b.state.q) and np.array_equal(a.state.v, b.state.v)
    assert a.state.time[0] == b.state.time[0] and abs(a.state.time[0] - 300 * tau) < 1e-12
    c = ps.Simulator(biped_collapse(dt=1e-3), ps.make_options(dt=0.0))
    c.step()
    assert c.state.time[0] == 1e-3
    with pytest.raises(ValueError, match="StepOptions.dt"):
        ps.Simulator(biped_collapse(), ps.make_options(dt=-1e-3))


def test_a_simulator_runs_its_duration_with_the_options_step_length():
    from benchmarks.scenes import chain
    sim = ps.Simulator(chain(2), ps.make_options(dt=5e-4))
    assert sim.dt == 5e-4
    traj = sim.run(1.0, record_every=1)
    assert abs(sim.state.time[0] - 1.0) < 1e-9 and len(traj.t) == 2001   # frame 0: t = 0
    assert traj.t[0] == 0.0 and traj.t[1] == 5e-4
    assert traj.info["dt"] == 5e-4


def test_a_run_records_its_start_then_the_same_states_as_stepping(tmp_path):
    """Frame 0 is the state the run starts from; frame k the state after k * record_every
    steps, bit for bit the state of plain stepping; the CSV's first row is t = 0."""
    from benchmarks.scenes import chain
    model = chain(3)
    sim = ps.Simulator(model)
    start = sim.snapshot()
    traj = sim.run(n_steps=40, record_every=4)
    assert len(traj) == 11 and traj.t[0] == 0.0
    assert np.array_equal(traj.q[0], start.q) and np.array_equal(traj.v[0], start.v)
    plain = ps.Simulator(model)
    for k in range(1, 11):
        plain.steps(4)
        assert np.array_equal(traj.q[k], plain.state.q) and traj.t[k] == plain.t, k
    again = sim.run(n_steps=8, record_every=4)   # a second run starts where the first ended
    assert again.t[0] == traj.t[-1] and np.array_equal(again.q[0], traj.q[-1]) and len(again) == 3
    rows = np.loadtxt(traj.to_csv(tmp_path / "run.csv", model), delimiter=",", skiprows=1)
    assert rows.shape[0] == 11 and rows[0, 0] == 0.0 and rows[0, 1] == start.q[0, 0]


def test_a_controlled_run_labels_its_start():
    from benchmarks.scenes import chain
    sim = ps.Simulator(chain(2))
    calls = []

    def controller(s):
        calls.append(s.t)
        return np.zeros(s.model.n_act)

    traj = sim.run(n_steps=6, controller=controller, control_every=2,
                   labels=lambda s: {"calls": len(calls)})
    assert traj.t[0] == 0.0 and len(traj) == 7
    assert traj.labels["calls"].tolist() == [0, 1, 1, 2, 2, 3, 3]
