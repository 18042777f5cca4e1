"""Inputs that were accepted silently now raise an error naming the culprit: ModelError for
model-building mistakes, ValueError for data files and states."""
import math
import re

import numpy as np
import pytest

import planarsim as ps
from planarsim import ModelError

NAN = float("nan")


def base():
    b = ps.ModelBuilder(dt=1e-3)
    b.add_body("torso", mass=10.0, inertia=1.0, pos=(0.0, 1.0))
    return b


def resting_rod():
    """A 1 m rod lying on flat ground on two end contacts, with an arm pinned to it (a lower
    limit, no upper one) and a point mass held by a rod on the arm: the State has contacts,
    a pin and a rod."""
    b = ps.ModelBuilder(dt=1e-3)
    rod = b.add_body("rod", 1.0, 1.0 / 12, pos=(0.0, 0.0))
    b.add_point_contact("left", rod, (-0.5, 0.0))
    b.add_point_contact("right", rod, (0.5, 0.0))
    arm = b.add_body("arm", 0.1, 0.01, pos=(0.0, 0.3))
    b.add_pin("hinge", rod, arm, anchor_world=(0.0, 0.1), limit=(-1.0, math.inf))
    bob = b.add_point_mass("bob", 0.1, pos=(0.0, 0.6))
    b.add_rod("link", arm, bob, anchor_a=(0.0, 0.2))
    return b.compile()


# 1. point-mass and shape radii ----------------------------------------------------------------
@pytest.mark.parametrize("radius", [-0.05, NAN])
@pytest.mark.parametrize("where", ["point_mass", "circle", "capsule"])
def test_negative_or_nan_radius(where, radius):
    b = base()
    with pytest.raises(ModelError, match=r"radius=(-0\.05|nan) must be") as e:
        if where == "point_mass":
            b.add_point_mass("foot", 1.0, radius=radius)
        elif where == "circle":
            b.add_shape("torso", "circle", (0.0, 0.0), radius)
        else:
            b.add_shape(0, "capsule", (0.0, 0.0), (0.0, -0.5), radius)
    assert ("'foot'" if where == "point_mass" else f"{where} shape") in str(e.value)


# 2. box sizes ---------------------------------------------------------------------------------
@pytest.mark.parametrize("width, height, bad", [(0.0, 0.2, "width=0.0"), (-0.4, 0.2, "width=-0.4"),
                                                (0.4, 0.0, "height=0.0"), (0.4, NAN, "height=nan")])
@pytest.mark.parametrize("where", ["contacts", "shape"])
def test_box_of_zero_negative_or_nan_size(where, width, height, bad):
    b = base()
    if where == "contacts":
        with pytest.raises(ModelError, match=rf"box 'feet' \(0\): {bad} must be"):
            b.add_box_contacts("feet", "torso", (0.0, -0.5), width, height)
        assert b._contacts == [], "no corner contact may be left behind"
    else:
        with pytest.raises(ModelError, match=rf"box shape .*: {bad} must be"):
            b.add_body("leg", 1.0, 0.1, shapes=[("box", (0.0, 0.0), width, height)])


# 3. shapes on missing bodies ------------------------------------------------------------------
@pytest.mark.parametrize("body, pattern", [(7, r"body=7 is not a body id \(0\.\.0\)"),
                                           (-1, r"body=-1 is not a body id"),
                                           ("shin", r"body='shin' names no body")])
def test_shape_on_a_missing_body(body, pattern):
    b = base()
    with pytest.raises(ModelError, match=r"circle shape \(0\): " + pattern):
        b.add_shape(body, "circle", (0.0, 0.0), 0.1)
    assert b.compile().shapes == ()


# 4. trajectory files --------------------------------------------------------------------------
@pytest.mark.parametrize("damage, pattern", [
    (lambda d: d.update(q=d["q"][:, :, 0]), r"trajectory\.q has shape \(\d+, 2\); it must be \(K=\d+, n_body, 3\)"),
    (lambda d: d.update(q=d["q"].reshape(-1)), r"trajectory\.q has shape \(\d+,\); it must be"),
    (lambda d: d.update(v=d["v"][:-1]), r"trajectory\.v has shape \((\d+), 2, 3\); it must be \(K=(?!\1)\d+, n_body=2, 3\)"),
    (lambda d: d.update(t=d["t"][:-2]), r"trajectory\.q has shape .*; it must be \(K=\d+, n_body, 3\)"),
    (lambda d: d.update(act_u=d["act_u"][:3]), r"trajectory\.act_u has shape \(3, 1\)"),
])
def test_trajectory_file_with_bad_shapes(tmp_path, damage, pattern):
    b = base()
    b.add_body("leg", 1.0, 0.1, pos=(0.0, 0.5))
    b.add_pin("hip", "torso", "leg", anchor_world=(0.0, 0.75))
    b.add_pin_motor("hip_motor", "hip")
    traj = ps.Simulator(b.compile()).run(0.01, u=[0.0])
    path = traj.save(tmp_path / "t.npz")
    data = dict(np.load(path))
    damage(data)
    np.savez(path, **data)
    with pytest.raises(ValueError, match=r"t\.npz: " + pattern):
        ps.Trajectory.load(path)


# 5. states handed in by a user ----------------------------------------------------------------
def _reshape(a):
    return np.zeros((a.shape[0] + 1,) + a.shape[1:], a.dtype)


BAD_VALUES = [  # (field, change, the words of the error)
    ("contact_mode", lambda a: a.__setitem__(1, 7), r"contact_mode\[1\]=7 .*must be 0 \(free\), 1 \(pinned\) or 2"),
    ("contact_mode", lambda a: a.__setitem__(0, -1), r"contact_mode\[0\]=-1 "),
    ("contact_enabled", lambda a: a.__setitem__(0, 2), r"contact_enabled\[0\]=2 .*must be 0 or 1"),
    ("limit_active", lambda a: a.__setitem__((0, 1), 5), r"limit_active\[0, 1\]=5 .*must be 0 or 1"),
    ("limit_active", lambda a: a.__setitem__((0, 1), 1),
     r"limit_active\[0, 1\]=1 \(pin 'hinge'\) must be 0: the pin has no limit on that side"),
    ("contact_slip", lambda a: a.__setitem__(1, 0.5), r"contact_slip\[1\]=0.5 .*must be -1 or \+1"),
    ("mode_cursor", lambda a: a.__setitem__(0, 2), r"mode_cursor\[0\]=2 must be in 0\.\.1"),
    ("mode_cursor", lambda a: a.__setitem__(0, -1), r"mode_cursor\[0\]=-1 must be in 0\.\.1"),
    ("step", lambda a: a.__setitem__(0, -3), r"step\[0\]=-3 must be an integer >= 0"),
    ("q", lambda a: a.__setitem__((1, 2), np.nan), r"q\[1, 2\]=nan .*must be finite"),
    ("v", lambda a: a.__setitem__((0, 0), np.inf), r"v\[0, 0\]=inf .*must be finite"),
    ("time", lambda a: a.__setitem__(0, np.nan), r"time\[0\]=nan must be finite"),
    ("ext_force", lambda a: a.__setitem__((2, 1), -np.inf), r"ext_force\[2, 1\]=-inf .*must be finite"),
    ("last_contact_impulse", lambda a: a.__setitem__((0, 0), np.nan), r"last_contact_impulse\[0, 0\]=nan"),
    ("last_pin_impulse", lambda a: a.__setitem__((0, 3), np.inf), r"last_pin_impulse\[0, 3\]=inf"),
    ("last_rod_impulse", lambda a: a.__setitem__(0, np.nan), r"last_rod_impulse\[0\]=nan"),
]
# Simulator(state=) and the setter checked shapes already; restore and snapshots did not
BAD_SHAPES = [
    ("q", _reshape, r"q has shape \(4, 3\)"),
    ("contact_mode", lambda a: a[:1], r"contact_mode has shape \(1,\)"),
    ("last_contact_impulse", lambda a: a[:, :1], r"last_contact_impulse has shape \(2, 1\)"),
    ("last_pin_impulse", lambda a: a[:, :2], r"last_pin_impulse has shape \(1, 2\)"),
    ("last_rod_impulse", _reshape, r"last_rod_impulse has shape \(2,\)"),
]


def _bad_state(model, field, change):
    sim = ps.Simulator(model)
    sim.run(0.05)
    state = sim.snapshot()
    arr = getattr(state, field)
    out = change(arr)
    return state._replace(**{field: out}) if out is not None else state


CASES = ([(entry, *case) for entry in ("init", "setter", "restore", "load_snapshot")
          for case in BAD_VALUES]
         + [(entry, *case) for entry in ("restore", "load_snapshot") for case in BAD_SHAPES])


@pytest.mark.parametrize("entry, field, change, pattern", CASES,
                         ids=[f"{e}-{f}-{i}" for i, (e, f, _, _) in enumerate(CASES)])
def test_bad_state_is_refused(tmp_path, entry, field, change, pattern):
    model = resting_rod()
    bad = _bad_state(model, field, change)
    sim = ps.Simulator(model)
    before = sim.snapshot()
    with pytest.raises(ValueError, match=r"state\." + pattern):
        if entry == "init":
            ps.Simulator(model, state=bad)
        elif entry == "setter":
            sim.state = bad
        elif entry == "restore":
            sim.restore(bad)
        else:
            ps.load_snapshot(ps.save_snapshot(tmp_path / "s.npz", bad), model)
    for a, b in zip(sim.state, before):   # a refused state leaves the simulator unchanged
        assert np.array_equal(a, b)


@pytest.mark.parametrize("field, change, pattern", [
    ("contact_mode", lambda a: a.__setitem__(1, 7), r"s\.npz: snapshot state\.contact_mode\[1\]=7 must be"),
    ("mode_cursor", lambda a: a.__setitem__(0, 2), r"s\.npz: snapshot state\.mode_cursor\[0\]=2 must be in 0\.\.1"),
    ("contact_slip", lambda a: a[:1], r"s\.npz: snapshot state\.contact_slip has shape \(1,\); it must be \(n_contact=2,\)"),
])
def test_snapshot_without_a_model_checks_itself(tmp_path, field, change, pattern):
    """Without a model, a snapshot's arrays must agree with each other (sizes from the first
    array that has them: q, contact_mode, limit_active, last_rod_impulse)."""
    bad = _bad_state(resting_rod(), field, change)
    with pytest.raises(ValueError, match=pattern):
        ps.load_snapshot(ps.save_snapshot(tmp_path / "s.npz", bad))


def test_bad_state_names_the_contact():
    model = resting_rod()
    bad = _bad_state(model, "contact_mode", lambda a: a.__setitem__(1, 7))
    with pytest.raises(ValueError, match=r"state\.contact_mode\[1\]=7 \(contact 'right'\)"):
        ps.Simulator(model).state = bad


def test_valid_states_still_pass(tmp_path):
    """Legal states (every mode, disabled contacts, active limits, slip 0 of the frictionless
    rule, a cursor on the last contact) are taken as before, from a file too."""
    model = resting_rod()
    sim = ps.Simulator(model)
    sim.run(0.05)
    state = sim.snapshot()
    state.contact_mode[:] = (2, 0)
    state.contact_slip[:] = (0.0, -1.0)
    state.contact_enabled[:] = (0, 1)
    state.limit_active[0] = (1, 0)
    state.mode_cursor[0] = 1
    loaded, _ = ps.load_snapshot(ps.save_snapshot(tmp_path / "s.npz", state))
    sim.restore(loaded)
    sim.state = state
    ps.Simulator(model, state=state).steps(10)
    free = ps.ModelBuilder()
    free.add_point_mass("ball", 1.0, radius=0.0)   # a radius of 0 only draws nothing
    assert ps.Simulator(free.compile()).state.mode_cursor[0] == 0


def two_bodies():
    b = ps.ModelBuilder(dt=1e-3)
    b.add_body("a", 1.0, 0.1, pos=(0.0, 1.0))
    b.add_body("b", 1.0, 0.1, pos=(0.6, 1.0), angle=0.2)
    return b.compile()


@pytest.mark.parametrize("shape", ["transposed", "flat", "short"])
def test_poses_of_the_wrong_shape_are_refused(shape):
    """A (3, n_body) or flat q was reshaped into other bodies' numbers (a transposed pose of
    two bodies read as [[0, 0, 0.2], [0.6, 0, 0]])."""
    m = two_bodies()
    q = np.array(m.q0, float)
    bad = {"transposed": q.T.copy(), "flat": q.ravel(), "short": q.ravel()[:5]}[shape]
    sim = ps.Simulator(m)
    with pytest.raises(ValueError, match=r"q has shape .* must be \(2, 3\)"):
        sim.start_over(q=bad)
    with pytest.raises(ValueError, match=r"v has shape .* must be \(2, 3\)"):
        ps.make_state(m, v=bad)
    assert np.array_equal(sim.state.q, q)          # nothing was put in


@pytest.mark.parametrize("index, pattern", [(-1, "not a contact"), (2, "not a contact"),
                                            (1.7, "whole number"), (NAN, "whole number")])
def test_contact_switch_names_a_contact(index, pattern):
    """set_contact_enabled(-1) turned off the last contact and 1.7 the second."""
    sim = ps.Simulator(resting_rod())
    before = sim.state.contact_enabled.copy()
    with pytest.raises((IndexError, ValueError), match=pattern):
        sim.set_contact_enabled(index, False)
    assert np.array_equal(sim.state.contact_enabled, before)


@pytest.mark.parametrize("flag", ["off", None, 2, 0.5])
def test_contact_switch_takes_true_or_false(flag):
    """set_contact_enabled(0, "off") switched the contact on (a non-empty string is true)."""
    sim = ps.Simulator(resting_rod())
    sim.set_contact_enabled(0, False)
    with pytest.raises(TypeError, match=rf"enabled={flag!r} must be True or False"):
        sim.set_contact_enabled(0, flag)
    assert sim.state.contact_enabled[0] == 0
    sim.set_contact_enabled(0, 1)
    assert sim.state.contact_enabled[0] == 1


@pytest.mark.parametrize("call, pattern", [
    (lambda sim: sim.steps(2.7), r"n=2.7 must be a whole number"),
    (lambda sim: sim.steps(NAN), "whole number"),
    (lambda sim: sim.run(n_steps=2.5), r"n_steps=2.5 must be a whole number"),
    (lambda sim: sim.run(0.01, record_every=2.5), "record_every=2.5"),
    (lambda sim: sim.run(1e-5), r"less than half a step"),
])
def test_step_counts_that_are_not_whole_are_refused(call, pattern):
    """Fractional counts were truncated, and a run shorter than half a step took none."""
    sim = ps.Simulator(two_bodies())
    with pytest.raises(ValueError, match=pattern):
        call(sim)
    assert sim.state.step[0] == 0
    sim.run(0.0)                                   # (an empty run is asked for: fine)


@pytest.mark.parametrize("call, error, pattern", [
    (lambda sim: sim.steps(10 ** 30), ValueError,
     r"n=1000000000000000000000000000000 must be a whole number from 0 to 1,000,000,000 "
     r"\(steps in one call; take more in several calls\)"),
    (lambda sim: sim.steps(2 ** 63), ValueError, r"n=9223372036854775808 must be a whole number from 0 to"),
    (lambda sim: sim.steps(1e30), ValueError, r"n=1e\+30 must be a whole number from 0 to 1,000,000,000"),
    (lambda sim: sim.steps(-1), ValueError, r"n=-1 must be a whole number from 0 to 1,000,000,000$"),
    (lambda sim: sim.steps(True), ValueError, r"n=True must be a whole number \(not True or False\)"),
    (lambda sim: sim.run(n_steps=10 ** 12, record_every=10 ** 9), ValueError,
     r"n_steps=1000000000000 must be a whole number from 0 to 1,000,000,000"),
    (lambda sim: sim.run(1e7, record_every=10 ** 9), ValueError,
     r"duration=1e\+07 s at dt=0.001 s is 10,000,000,000 steps, more than 1,000,000,000 in one call"),
    (lambda sim: sim.run(True), ValueError, r"duration=True must be a number of seconds"),
    (lambda sim: sim.run(0.01, record_every=True), ValueError, r"record_every=True must be a whole number"),
])
def test_step_counts_beyond_the_compiled_loop_are_refused(call, error, pattern):
    """steps(10**30) failed inside numba ("int too big to convert"), steps(True) took a step
    and steps(10**18) would run for ever."""
    sim = ps.Simulator(two_bodies())
    with pytest.raises(error, match=pattern):
        call(sim)
    assert sim.state.step[0] == 0


@pytest.mark.parametrize("kw, pattern", [
    (dict(controller=5), r"controller=5 must be a function controller\(sim\) -> u, or None"),
    (dict(controller="pd"), r"controller='pd' must be a function controller\(sim\) -> u"),
    (dict(controller=lambda s: np.zeros(0), labels=5),
     r"labels=5 must be a function labels\(sim\) -> dict of scalars"),
])
def test_run_controllers_and_labels_must_be_functions(kw, pattern):
    """run(controller=5) failed at its first call with "'int' object is not callable"."""
    sim = ps.Simulator(two_bodies())
    with pytest.raises(TypeError, match=pattern):
        sim.run(0.01, **kw)
    assert sim.state.step[0] == 0


def actuated_pendulum():
    b = ps.ModelBuilder(dt=1e-3)
    arm = b.add_body("arm", 1.0, 0.1, pos=(0.5, 1.0))
    b.add_pin("shoulder", None, arm, anchor_world=(0.0, 1.0))
    b.add_pin_motor("motor", "shoulder")
    return b.compile()


@pytest.mark.parametrize("call, pattern", [
    (lambda sim: sim.step("a"), r"commands u='a' must be numbers, shape \(1,\) \(one per "
                                r"actuator: \['motor'\]\)"),
    (lambda sim: sim.steps(3, [[1.0], [2.0, 3.0]]), r"commands u=.* must be numbers"),
    (lambda sim: sim.run("abc"), r"duration='abc' must be a number of seconds"),
    (lambda sim: sim.start_over(q="abc"), r"q='abc' must be numbers: one row \(x, y, theta\) "
                                          r"per body of the model, shape \(1, 3\)"),
    (lambda sim: sim.start_over(v=[[0.0, 0.0, "fast"]]), r"v=.* must be numbers"),
])
def test_arguments_that_are_not_numbers_are_named(call, pattern):
    """Commands, a duration or poses that are not numbers raised numpy's or Python's "could
    not convert string to float: 'abc'", naming no argument."""
    sim = ps.Simulator(actuated_pendulum())
    with pytest.raises(ValueError, match=pattern):
        call(sim)
    assert sim.state.step[0] == 0


@pytest.mark.parametrize("frame_skip", [0, -3, 2.5])
def test_env_frame_skip_must_be_a_positive_whole_number(frame_skip):
    """frame_skip=0 divided by zero in the env's render rate; -3 failed at the first step."""
    gym = pytest.importorskip("gymnasium")
    import planarsim.envs  # noqa: F401
    with pytest.raises(ValueError, match="frame_skip"):
        gym.make("planarsim/InvertedPendulum-v0", frame_skip=frame_skip)


def test_run_refuses_arguments_it_would_ignore():
    """run(u=..., controller=...) dropped u, and labels without a controller were ignored."""
    sim = ps.Simulator(two_bodies())
    with pytest.raises(ValueError, match="not both"):
        sim.run(0.01, u=np.zeros(0), controller=lambda s: np.zeros(0))
    with pytest.raises(ValueError, match="only with a controller"):
        sim.run(0.01, labels=lambda s: {"t": s.t})
    assert sim.state.step[0] == 0


@pytest.mark.parametrize("kw, text", [(dict(reset_noise_scale=-1.0), "reset_noise_scale"),
                                      (dict(reset_noise_scale=NAN), "reset_noise_scale"),
                                      (dict(render_mode="rgb_array", width=0), "width=0")])
def test_env_settings_that_fail_late_are_refused_when_made(kw, text):
    """A negative or NaN reset noise failed in numpy at reset; width 0 in the renderer."""
    gym = pytest.importorskip("gymnasium")
    import planarsim.envs  # noqa: F401
    with pytest.raises(ValueError, match=text):
        gym.make("planarsim/Hopper-v0", **kw)


MJCF_PENDULUM = ('<mujoco><worldbody><body name="b"><joint name="j" type="hinge" axis="{axis}" '
                 '{joint}/><geom name="foot" type="sphere" size="0.1" {geom}/></body></worldbody>'
                 '<actuator>{motor}</actuator></mujoco>')


@pytest.mark.parametrize("kw, error, words", [
    (dict(source=None), TypeError, r"load_mjcf: source=None must be a path .* or its XML text"),
    (dict(source=5), TypeError, r"load_mjcf: source=5 must be a path"),
    (dict(collide="foot"), TypeError, r"load_mjcf: collide='foot' must be None or a list of geom names"),
    (dict(axis="0 0 0"), ps.ModelError, r"<joint name='j'> \(line 1\): axis=\(0.0, 0.0, 0.0\) must be non-zero"),
    (dict(joint='range="1 -1"'), ps.ModelError, r"range=\(1.0, -1.0\) has lower > upper"),
    (dict(geom='friction="-1"'), ps.ModelError, r"friction=\(-1.0,\) must be >= 0"),
    (dict(motor='<motor joint="j" ctrlrange="1 -1"/>'), ps.ModelError, r"ctrlrange=\(1.0, -1.0\) has lower"),
    (dict(motor='<motor joint="j" gear="1 2"/>'), ps.ModelError, r"gear='1 2' must have 1 or 6 number"),
])
def test_mjcf_source_and_messages(kw, error, words):
    """load_mjcf(None) and load_mjcf(5) read str(source) as XML ("malformed XML: syntax error");
    collide='foot' named geoms 'f', 'o' and 't'; messages printed
    axis=(np.float64(0.0), np.float64(0.0), np.float64(0.0))."""
    from planarsim.mjcf import load_mjcf
    parts = dict(axis="0 1 0", joint="", geom="", motor="")
    parts.update({k: v for k, v in kw.items() if k in parts})
    source = kw.get("source", MJCF_PENDULUM.format(**parts))
    with pytest.raises(error, match=words) as err:
        load_mjcf(source, collide=kw.get("collide"))
    assert "np.float64" not in str(err.value)


@pytest.mark.parametrize("shape", [(3,), (2, 5), (3, 1), (2,)])
def test_vector_env_action_of_the_wrong_shape(shape):
    """(3, 1) failed with "zip() argument 2 is shorter than argument 1", and (3,) or (2, 5) with
    a copy's "action has shape ()": neither said the shape the vector env takes, (2, 1)."""
    gym = pytest.importorskip("gymnasium")
    import planarsim.envs  # noqa: F401
    envs = gym.make_vec("planarsim/InvertedPendulum-v0", num_envs=2,
                        vectorization_mode="vector_entry_point")
    try:
        envs.reset(seed=0)
        with pytest.raises(ValueError, match=rf"actions have shape {re.escape(str(shape))}; 2 copies "
                                             r"of planarsim/InvertedPendulum-v0 take shape \(2, 1\)"):
            envs.step(np.zeros(shape))
        envs.step(np.zeros((2, 1)))
    finally:
        envs.close()


@pytest.mark.parametrize("kw, words", [
    (dict(refine_iters=NAN), r"StepOptions\.refine_iters=nan must be an integer >= 0"),
    (dict(refine_iters=math.inf), r"StepOptions\.refine_iters=inf must be an integer >= 0"),
    (dict(max_substeps=np.float64(NAN)), r"StepOptions\.max_substeps=nan must be an integer >= 1"),
    (dict(integrator=NAN), r"StepOptions\.integrator=nan must be one of 0\.\.3"),
    (dict(refine_tol=NAN), r"StepOptions\.refine_tol=nan must be finite"),
    (dict(refine_iters="4"), r"StepOptions\.refine_iters='4' must be an integer"),
])
def test_step_options_nan_or_wrong_type(kw, words):
    """A NaN or infinite integer field failed in int() with "cannot convert float NaN to
    integer", naming no field; make_options returned the bad options unchecked."""
    model = two_bodies()
    with pytest.raises(ValueError, match=words) as err:
        ps.Simulator(model, options=ps.StepOptions(**kw))
    assert "np.float64" not in str(err.value)
    with pytest.raises(ValueError, match=words):
        ps.make_options(**kw)


@pytest.mark.parametrize("model", ["abc", 5, ps.ModelBuilder])
def test_load_snapshot_takes_a_model_or_none(tmp_path, model):
    """load_snapshot(path, model="abc") failed with "'str' object has no attribute 'n_body'"."""
    sim = ps.Simulator(two_bodies())
    path = ps.save_snapshot(tmp_path / "s.npz", sim.state)
    with pytest.raises(TypeError, match=rf"load_snapshot: model={re.escape(repr(model))} must be a "
                                        r"planarsim Model \(from ModelBuilder.compile\(\)\)"):
        ps.load_snapshot(path, model=model)
    ps.load_snapshot(path, model=sim.model)


def test_files_of_the_wrong_kind(tmp_path):
    """to_csv("out.npz") wrote CSV text into a .npz file; save_snapshot(path, 5) and
    save_snapshot(path, sim) failed with AttributeError ... 'as_dict'."""
    sim = ps.Simulator(two_bodies())
    traj = sim.run(0.01)
    with pytest.raises(ValueError, match=r"CSV file '.*out\.npz' must end in \.csv"):
        traj.to_csv(tmp_path / "out.npz")
    with pytest.raises(TypeError, match=r"save_snapshot: state must be a planarsim State, got int"):
        ps.save_snapshot(tmp_path / "s.npz", 5)
    with pytest.raises(TypeError, match=r"must be a planarsim State \(a Simulator's is sim\.state\), "
                                        r"got Simulator"):
        ps.save_snapshot(tmp_path / "s.npz", sim)
    with pytest.raises(TypeError, match=r"memory must be a dict"):
        ps.save_snapshot(tmp_path / "s.npz", sim.state, memory=5)
    # a memory value that is no number was pickled into a file that load_snapshot then called
    # "truncated or corrupted" (allow_pickle=False)
    with pytest.raises(TypeError, match=r"save_snapshot: memory\['gains'\] = dict must be numbers"):
        ps.save_snapshot(tmp_path / "s.npz", sim.state, memory={"gains": {"kp": 1.0}})
    with pytest.raises(TypeError, match=r"memory\[3\] = float must be numbers .* under a string name"):
        ps.save_snapshot(tmp_path / "s.npz", sim.state, memory={3: 1.0})
    assert list(tmp_path.iterdir()) == []
    ps.save_snapshot(tmp_path / "s.npz", sim.state, memory={"gains": [1.0, 2.0], "mode": 3})
    assert ps.load_snapshot(tmp_path / "s.npz")[1]["gains"].tolist() == [1.0, 2.0]


def test_mjcf_file_that_is_not_utf8_names_the_file(tmp_path):
    """A file of other bytes raised UnicodeDecodeError from read_text, naming no file."""
    from planarsim.mjcf import load_mjcf
    path = tmp_path / "latin.xml"
    path.write_bytes(b"\xff\xfe <mujoco/>")
    with pytest.raises(ModelError, match=r"cannot read MJCF file '.*latin.xml': not UTF-8 text"):
        load_mjcf(path)


@pytest.mark.parametrize("kw", [dict(allow_below_ground="no"), dict(allow_overlap=1)])
def test_simulator_switches_take_true_or_false(kw):
    """The string "no" is truthy: allow_below_ground="no" allowed what it said not to."""
    with pytest.raises(TypeError, match=f"Simulator: {next(iter(kw))}=.* must be True or False"):
        ps.Simulator(base().compile(), **kw)


@pytest.mark.parametrize("mode", [7, -1])
def test_contact_mode_edited_in_place_is_refused(mode):
    """A mode that is none of free, pinned, sliding written into the State in place (which the
    state setter's check never sees) was stepped as some mode, silently."""
    sim = ps.Simulator(resting_rod())
    sim.step()
    sim.state.contact_mode[1] = mode
    q = sim.state.q.copy()
    with pytest.raises(ValueError, match=rf"state.contact_mode\[1\] = {mode} \(contact "
                                         r"'right'\) must be 0 \(free\), 1 \(pinned\) or 2"):
        sim.step()
    assert np.array_equal(sim.state.q, q)       # nothing was stepped
    sim.state.contact_mode[1] = 1
    sim.step()
