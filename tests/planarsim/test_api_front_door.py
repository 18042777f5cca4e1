"""What a new user meets first in the Python API: a run that cannot be recorded is refused
with a clear error before anything is allocated."""
import numpy as np
import pytest

import planarsim as ps


def point_mass_model():
    b = ps.ModelBuilder(dt=1e-3)
    b.add_point_mass("ball", 1.0, pos=(0.0, 1.0))
    return b.compile()


# a duration that cannot fit in memory ----------------------------------------------------------
def test_a_run_too_long_to_record_is_a_value_error_naming_the_memory():
    sim = ps.Simulator(point_mass_model())
    with pytest.raises(ValueError, match="GiB of memory") as err:
        sim.run(1e12)
    from planarsim.errors import RecordingTooLarge
    assert isinstance(err.value, RecordingTooLarge)
    assert err.value.frames > 10 ** 14 and err.value.nbytes > err.value.available > 0
    assert "steps of 0.001 s" in str(err.value)


def test_a_walker_run_too_long_to_record_is_refused_before_it_runs():
    import walkers
    mod = walkers.load("simple-biped")
    with pytest.raises(ValueError, match="simple-biped: run\\(1e\\+09 s\\).*GiB of memory"):
        mod.simulate(1e9)
    from planarsim.errors import RecordingTooLarge
    run = mod.Run()
    with pytest.raises(RecordingTooLarge):
        run.run(1e9)
    assert run.time == 0.0


# progress goes to a terminal only ---------------------------------------------------------------
def test_export_animation_draws_no_bar_into_a_pipe(tmp_path, capsys):
    """pytest's captured stderr is no terminal, as a pipe or a log is not."""
    from planarsim.render import export_animation
    sim = ps.Simulator(point_mass_model())
    traj = sim.run(0.2, record_every=10)
    capsys.readouterr()
    export_animation(traj, sim.model, tmp_path / "drop.gif", fps=20, workers=1)
    err = capsys.readouterr().err
    assert "\r" not in err and "frames" not in err
    assert (tmp_path / "drop.gif").stat().st_size > 0


def test_the_text_bar_draws_on_stderr_only_when_it_is_a_terminal(capsys, monkeypatch):
    import planarsim.progress as progress
    progress.TextProgress(3, "points")(3)
    assert capsys.readouterr().err == ""
    monkeypatch.setattr(progress, "stderr_is_terminal", lambda: True)
    progress.TextProgress(3, "points")(3)
    assert capsys.readouterr().err.endswith("3/3 points\n")


# the terrain's parameters are recorded ------------------------------------------------------------
def test_a_saved_trajectory_reproduces_its_terrain(tmp_path):
    from planarsim import terrain
    for ground in (terrain.hills([0.04, 0.01], [2.0, 0.7], [0.5, 0.0], grade=0.02, height=0.1),
                   terrain.slope(-4.25), terrain.flat(0.3)):
        b = ps.ModelBuilder(dt=1e-3, terrain=ground)
        b.add_point_mass("ball", 1.0, pos=(0.0, 2.0))
        traj = ps.Simulator(b.compile()).run(0.01)
        traj.save(tmp_path / "run.npz")
        again = ps.Trajectory.load(tmp_path / "run.npz").terrain()
        assert again.coef.tolist() == ground.coef.tolist()
        assert again.name == ground.name
    custom = terrain.hills([0.05], [2.5], [0.3])
    assert custom.name != "hills" and terrain.parse(custom.name).coef.tolist() == custom.coef.tolist()


# whole steps only for a model that steps ----------------------------------------------------------
def rocking_stand(seconds=4.0):
    """A frame standing on two point feet 0.4 m apart, rocked from foot to foot by a PD torque
    (+-0.12 rad every 0.5 s): each foot lifts for about 0.5 s and lands where it was."""
    b = ps.ModelBuilder(dt=1e-3)
    body = b.add_body("frame", mass=10.0, inertia=0.4, pos=(0.0, 0.3))
    b.add_point_contact("left_foot", body, (-0.2, -0.3))
    b.add_point_contact("right_foot", body, (0.2, -0.3))
    b.add_body_torque("rock", body)
    model = b.compile()

    def rock(sim):
        target = 0.12 if int(sim.t / 0.5) % 2 else -0.12
        return np.array([300.0 * (target - sim.state.q[0, 2]) - 30.0 * sim.state.v[0, 2]])
    return model, ps.Simulator(model).run(seconds, controller=rock, record_every=10)


def test_a_model_that_only_stands_makes_no_whole_steps():
    from planarsim import measure
    model, traj = rocking_stand()
    on = np.isin(traj.contact_mode, (1, 2))
    lifts = (~on[1:] & on[:-1]).sum(axis=0)
    assert (lifts >= 3).all()                     # both feet lift again and again ...
    s = measure.summary(traj, model)
    assert s["whole_steps"] == 0                  # ... and land where they were: no steps
    assert np.isnan(s["step_length"]) and np.isnan(s["step_period"])
    assert abs(s["distance"]) < 0.02


def test_a_foot_that_lands_elsewhere_is_a_step():
    """The same frame walked forward: a foot that lifts and lands 5 cm ahead is a step."""
    from planarsim import measure
    from planarsim.analysis import step_events
    model, traj = rocking_stand()
    moved = traj.q.copy()
    moved[:, 0, 0] += 0.05 * np.floor(traj.t / 0.5)       # 5 cm further every half second
    walked = ps.Trajectory(**{**traj.__dict__, "q": moved})
    assert measure.summary(walked, model)["whole_steps"] >= 5
    assert len(step_events(traj, feet=[[0], [1]], min_air=0.05)) >= 5   # landings, wherever


# a body that starts below the ground ------------------------------------------------------------
def shin_model(y, terrain=None):
    """A shin whose arc foot (radius 0.05 m) has its lowest point 0.3 m below its centre of
    mass: built with the centre at height y."""
    b = ps.ModelBuilder(dt=1e-3, terrain=terrain)
    shin = b.add_body("shin", mass=2.0, inertia=0.05, pos=(0.4, y))
    b.add_arc_contact("heel", shin, center=(0.0, -0.25), radius=0.05)
    return b.compile()


def test_a_body_built_below_the_ground_is_a_model_error_naming_it():
    from planarsim.errors import ModelError
    with pytest.raises(ModelError, match=r"contact 'heel' \(0\) of body 'shin' \(0\) starts 1 m "
                                         r"below the ground at x=0.4 m") as err:
        ps.Simulator(shin_model(-0.7))
    assert "allow_below_ground=True" in str(err.value)
    # on hills, against the normal of the ground
    from planarsim import terrain
    with pytest.raises(ModelError, match="'heel'"):
        ps.Simulator(shin_model(0.25, terrain.hills([0.1], [2.0])))


def test_a_start_on_the_ground_or_allowed_below_it_runs():
    sim = ps.Simulator(shin_model(0.3 - 5e-4))        # half a millimetre: rounding, allowed
    sim.steps(10)
    deep = ps.Simulator(shin_model(-0.7), allow_below_ground=True)
    deep.steps(1)
    assert deep.state.q[0, 1] == pytest.approx(0.3, abs=1e-6)   # lifted onto the ground, as asked


def test_simbicon_starts_with_its_soles_on_the_ground_on_hills():
    """SIMBICON's soles start on the highest ground under them: on the default hills no
    corner starts inside (standing at the heel's height, the toe began 3 cm inside, and the
    steps lifting it out moved the legs 2-3 cm farther than their velocities explain), and
    nothing is said."""
    import warnings

    import walkers
    mod = walkers.load("simbicon")
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        _, raw, _ = mod.simulate(0.05, terrain="hills")
    assert raw["audit"]["start_below_ground"] == 0
    assert not any("below the ground" in str(w.message) for w in said)
    _, raw, _ = mod.simulate(0.05, terrain="flat")
    assert raw["audit"]["start_below_ground"] == 0


def _ball_at(pos, gravity=-9.81):
    b = ps.ModelBuilder(dt=1e-3, gravity=(0.0, gravity), ground=None)
    b.add_body("ball", mass=1.0, inertia=0.01, pos=pos, shapes=[("circle", (0, 0), 0.1)])
    return b.compile()


def test_a_simulator_built_beyond_the_guard_limit_is_refused_naming_the_body():
    from planarsim.errors import ModelError
    with pytest.raises(ModelError, match=r"body 'ball' has x = 1e\+11 m, beyond "
                                         r"StepOptions.guard_limit 1e\+10 \(the step stops any "
                                         r"state beyond it: move the scene nearer the origin"):
        ps.Simulator(_ball_at((1e11, 0.0)))
    start = ps.make_state(_ball_at((0.0, 0.0)))
    start.v[0, 1] = -2e10
    with pytest.raises(ModelError, match=r"body 'ball' has vy = -2e\+10 m/s, .*: start it slower"):
        ps.Simulator(_ball_at((0.0, 0.0)), state=start)
    # a state put in later is the step's to judge (as MuJoCo's set_state takes any numbers):
    # SimulationDiverged names it at the next step
    sim = ps.Simulator(_ball_at((0.0, 0.0)))
    sim.start_over(v=np.array([[0.0, -2e10, 0.0]]))
    with pytest.raises(ps.SimulationDiverged):
        sim.step()
    sim.start_over()
    near = sim.state.copy()
    near.q[0, 0] = 20.0
    sim.state = near
    with pytest.raises(ModelError, match=r"has x = 20 m, beyond StepOptions.guard_limit 10"):
        sim.options = ps.StepOptions(guard_limit=10.0)


def test_a_model_swapped_in_bounds_the_speeds_by_its_own_gravity():
    """A speed limit resolved from the model (the default) is resolved again from a model
    swapped in: a ball falling under 100 g is not stopped by the bound of 1e-3 g."""
    sim = ps.Simulator(_ball_at((0.0, 100.0), gravity=-0.01))
    sim.model = _ball_at((0.0, 100.0), gravity=-981.0)
    assert sim.options.speed_limit == ps.Simulator(_ball_at((0.0, 100.0), -981.0)).options.speed_limit
    sim.run(0.4)                                  # 392 m/s: within the new bound
    assert sim.state.v[0, 1] == pytest.approx(-981.0 * 0.4, rel=1e-9)
