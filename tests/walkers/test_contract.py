"""Every shipped walker meets the walker contract (walkers/base.py): the same module attributes,
a run class on WalkerRun, the same simulate() keywords, a summary the common summary can read,
and chunked runs that end bit for bit where one run of the same length does."""
import math

import numpy as np
import pytest

import walkers
from walkers.base import WalkerRun, contract_problems
from walkers.common.summary import REPLACED, walker_summary

# the keys `planarsim run W --json` prints for every walker W
COMMON_KEYS = {"walker", "gait", "terrain", "duration_s", "params_changed", "time_s", "fell",
               "distance_m", "mean_speed_m_per_s", "steps", "whole_steps", "step_period_s",
               "step_length_m", "step_speed_m_per_s", "audit", "wall_time_s", "extras"}
# run keywords for the chunk test: SIMBICON pushed across the chunk boundary
CHUNK_KEYWORDS = {"simbicon": {"push": dict(force=60.0, start=0.8, duration=0.3)}}


@pytest.mark.parametrize("name", sorted(walkers.WALKERS))
def test_every_walker_meets_the_contract(name):
    mod = walkers.load(name)
    assert contract_problems(name, mod) == []
    traj, summary, model = mod.simulate(0.2)
    assert "fell" in summary and "audit" in summary and ("time" in summary or "duration" in summary)
    undeclared = [k for k in summary if k not in REPLACED and k not in mod.SUMMARY_EXTRAS]
    assert not undeclared
    assert len(traj.t) > 0 and model.n_body > 0
    common = walker_summary(mod, traj, model, summary, walker=name, gait=mod.GAITS[0],
                            terrain="flat", duration=0.2)
    assert set(common) == COMMON_KEYS


@pytest.mark.parametrize("name", sorted(walkers.WALKERS))
def test_chunked_run_ends_where_one_run_does(name):
    """Run(...).run(a); .run(b) ends bit for bit in the state of Run(...).run(a + b)."""
    mod = walkers.load(name)
    kw = CHUNK_KEYWORDS.get(name, {})
    whole = mod.Run(**kw)
    whole.run(2.5)
    chunked = mod.Run(**kw)
    first = chunked.run(1.0)
    second = chunked.run(1.5)
    for field in ("q", "v", "time", "step", "contact_mode", "contact_enabled"):
        assert np.array_equal(getattr(chunked.state, field), getattr(whole.state, field)), field
    assert np.array_equal(chunked.memory, whole.memory)
    joined = chunked.trajectory()
    assert len(joined) == len(first) + len(second)
    assert np.array_equal(joined.q, whole.trajectory().q)
    assert chunked.summary()["fell"] == whole.summary()["fell"]


@pytest.mark.parametrize("name", sorted(walkers.WALKERS))
def test_frame_0_is_the_initial_state_at_t_0(name):
    """The first chunk's frame 0 is the state the walker starts from, at t = 0; frame 1 is the
    state after the first record_every steps, bit for bit that of a run recording nothing."""
    mod = walkers.load(name)
    run = mod.Run(record_every=5)
    start = run.state.copy()
    first = run.run(0.3)
    assert first.t[0] == 0.0 and start.time[0] == 0.0
    assert np.array_equal(first.q[0], start.q) and np.array_equal(first.v[0], start.v)
    assert np.array_equal(first.contact_mode[0],
                          np.where(start.contact_enabled != 0, start.contact_mode, -1))
    assert first.t[1] == pytest.approx(5 * run.dt, rel=1e-12)
    assert set(first.labels) == set(mod.Run.LABELS) and all(len(v) == len(first) for v in first.labels.values())
    blind = mod.Run(record_every=0)
    blind.run(5 * run.dt)
    assert np.array_equal(first.q[1], blind.state.q) and np.array_equal(first.v[1], blind.state.v)
    second = run.run(0.1)   # a later chunk starts after the first one's last frame
    assert second.t[0] > first.t[-1]
    traj, _, _ = mod.simulate(0.05)
    assert traj.t[0] == 0.0 and np.array_equal(traj.q[0], mod.Run().state.q)


# a start or terrain each walker falls on within 6 s
FALLS = {"simple-biped": dict(terrain="hills:0.15,1.0"), "simbicon": dict(terrain="hills:0.1,1.5"),
         "compass-gait": dict(terrain="slope:-8")}


@pytest.mark.parametrize("name", sorted(FALLS))
def test_a_walker_that_fell_stays_where_it_fell(name):
    """A chunk after the fall adds nothing: chunked runs end where one run does after a fall too."""
    mod = walkers.load(name)
    whole = mod.Run(**FALLS[name])
    whole.run(6.0)
    assert whole.fell
    chunked = mod.Run(**FALLS[name])
    chunked.run(whole.time + 0.5)
    assert len(chunked.run(1.0)) == 0
    assert chunked.time == whole.time and np.array_equal(chunked.state.q, whole.state.q)
    assert len(chunked.trajectory()) == len(whole.trajectory())


def test_options_with_another_step_length_are_refused():
    """The controllers integrate with the model's dt: options.dt must be 0 or that dt."""
    import planarsim as ps
    with pytest.raises(ValueError, match="options.dt"):
        walkers.load("simple-biped").Run(options=ps.StepOptions(dt=2e-3))
    with pytest.raises(ValueError, match="dt"):
        walkers.load("simple-biped").Run(options=ps.StepOptions(dt=math.nan))


@pytest.mark.parametrize("name", sorted(walkers.WALKERS))
def test_feet_and_extras_names(name):
    """FEET (where given) names real contacts, each once; SUMMARY_EXTRAS names are unique."""
    mod = walkers.load(name)
    model = mod.Run().model
    feet = getattr(mod, "FEET", None)
    if feet is not None:
        flat = [c for group in feet for c in group]
        assert set(flat) <= set(model.contact_names), set(flat) - set(model.contact_names)
        assert len(flat) == len(set(flat))
    names = [spec[0] for spec in mod.SUMMARY_EXTRAS.values() if spec is not None]
    assert len(names) == len(set(names)), names


@pytest.mark.parametrize("seconds", [-1.0, math.nan, math.inf, "long", True])
def test_run_rejects_bad_seconds(seconds):
    run = walkers.load("simple-biped").Run()
    with pytest.raises(ValueError, match="seconds"):
        run.run(seconds)


def test_run_of_less_than_half_a_step_is_refused():
    """run(1e-6) took no step and returned as if it had run (simulate(1e-6) the summary of a
    walker that never moved), where Simulator.run refuses it; run(0.0) stays a run of none."""
    run = walkers.load("simple-biped").Run()
    with pytest.raises(ValueError, match=r"run\(1e-06 s\) is less than half a step \(dt=0.001 s\)"):
        run.run(1e-6)
    with pytest.raises(ValueError, match="less than half a step"):
        walkers.load("simple-biped").simulate(4e-4)
    assert len(run.run(0.0).t) == 1


@pytest.mark.parametrize("name", ["simple-biped", "simplest-walker"])
def test_a_run_of_too_many_steps_is_refused_naming_dt_and_duration(name, monkeypatch):
    """A run at dt=1e-9 whose recording fits (none, or a frame every 10**6 steps) ran
    practically forever (1e10 steps for 10 s)."""
    mod = walkers.load(name)
    monkeypatch.setattr(mod.Run, "advance", lambda *args: pytest.fail("the run started"))
    run = mod.Run(dt=1e-9, record_every=0)
    said = (rf"{name}: run\(10 s\) at dt=1e-09 s would take 10,000,000,000 steps, more than "
            r"100,000,000 \(a run that long would take practically forever\)$")
    with pytest.raises(ValueError, match=said):
        run.run(10.0)
    with pytest.raises(ValueError, match=said):
        mod.simulate(10.0, dt=1e-9, record_every=10 ** 6)
    assert run.time == 0.0


@pytest.mark.parametrize("name, kw, error, said", [
    # terrain=5: "'int' object has no attribute 'height'" from inside the model builder
    ("simple-biped", dict(terrain=5), TypeError, r"terrain=5 must be a planarsim.terrain.Terrain"),
    ("simplest-walker", dict(terrain=5.0), TypeError, r"terrain=5.0 must be a planarsim.terrain.Terrain"),
    # numpy's "expected non-negative integer" and "SeedSequence expects int ..."
    ("simple-biped", dict(seed=-1), ValueError, r"simple-biped: seed=-1 must be a whole number >= 0"),
    ("quadruped", dict(seed=1.5), ValueError, r"quadruped: seed=1.5 must be a whole number >= 0"),
    # a longer section state was cut to its first numbers silently; a NaN one diverged at
    # step 0 naming the hip
    ("simplest-walker", dict(x0=np.zeros(7)), ValueError,
     r"simplest-walker: x0=\[0.0, .*\] must be 4 number\(s\), the section state \(theta, theta_dot"),
    ("compass-gait", dict(x0=[0.1, float("nan"), -0.1, 0.0]), ValueError,
     r"compass-gait: x0 theta_dot=nan must be finite"),
    ("rimless-wheel", dict(x0="fast"), ValueError, r"rimless-wheel: x0='fast' must be 1 number"),
    # a NaN speed stopped the run at its first step naming actuator 'leg0''s command; 'fast'
    # failed in float(); 5 m/s (set_speed's bound: [0, 3]) was taken by the constructor
    ("simple-biped", dict(speed=float("nan")), ValueError,
     r"simple-biped: speed=nan m/s must be a finite number within \[0, 3\]"),
    ("simple-biped", dict(speed=5.0), ValueError, r"simple-biped: speed=5.0 m/s must be a finite"),
    ("quadruped", dict(speed="fast"), ValueError, r"quadruped: speed='fast' m/s must be a finite number"),
    # the passive walkers' dt: "fast" failed in float(), True was taken for a 1 s step
    ("simplest-walker", dict(dt="fast"), ValueError,
     r"simplest-walker: dt='fast' s must be a finite step size > 0 \[s\]"),
    ("rimless-wheel", dict(dt=True), ValueError, r"rimless-wheel: dt=True s must be a finite step"),
    ("compass-gait", dict(dt=-1e-3), ValueError, r"compass-gait: dt=-0.001 s must be a finite step"),
])
def test_bad_run_keywords_are_named(name, kw, error, said):
    with pytest.raises(error, match=said):
        walkers.load(name).Run(**kw)


def test_a_speed_set_while_running_is_checked_too():
    with pytest.raises(ValueError, match=r"simple-biped: speed=inf m/s"):
        walkers.load("simple-biped").Run().set_speed(float("inf"))
    with pytest.raises(ValueError, match=r"quadruped: speed=nan m/s"):
        walkers.load("quadruped").Run().set_gait("walk", float("nan"))


def test_run_rejects_bad_record_every():
    with pytest.raises(ValueError, match="record_every"):
        walkers.load("quadruped").Run(record_every=-1)


def test_the_contract_check_names_what_is_missing():
    import types
    fake = types.SimpleNamespace(NAME="other", GAITS=("walk",), Params=object, SUMMARY_EXTRAS={"x": ("x_m",)},
                                 Run=object, simulate=lambda duration, gait="run": None)
    problems = contract_problems("fake", fake)
    assert any("registered as 'fake'" in p for p in problems)
    assert any("lacks the keywords" in p for p in problems)
    assert any("WalkerParams" in p for p in problems)
    assert any("WalkerRun" in p for p in problems)
    assert any("SUMMARY_EXTRAS['x']" in p for p in problems)
    assert issubclass(walkers.load("ranger").Run, WalkerRun)


@pytest.mark.parametrize("name", ["simple-biped", "rimless-wheel"])
def test_params_as_a_dict_or_of_another_walker(name):
    """simulate(params={...}) raised AttributeError ('dict' object has no attribute ...), as did
    another walker's Params; a dict of fields now means those fields over the defaults."""
    mod = walkers.load(name)
    field, value = next(iter(mod.Params().as_dict().items()))
    as_dict = mod.simulate(0.02, params={field: value})
    as_params = mod.simulate(0.02, params=mod.Params())
    np.testing.assert_array_equal(as_dict[0].q, as_params[0].q)
    other = walkers.load("ranger" if name != "ranger" else "simple-biped").Params()
    with pytest.raises(TypeError, match=f"params must be a {type(mod.Params()).__name__}"):
        mod.simulate(0.02, params=other)
    with pytest.raises(TypeError, match="not fields of"):
        mod.simulate(0.02, params={"no_such_field": 1.0})


@pytest.mark.parametrize("name", ["simple-biped", "ranger", "simbicon", "quadruped"])
def test_an_actuated_walker_refuses_a_step_its_controller_is_not_tuned_for(name):
    """As the command line refuses --dt above 0.01 s, so does the Python API for a walker with
    motors (at 0.2 s the Simple Biped was thrown 1 m up in 3 steps, at 0.05 s it shuffled
    0.12 m in 2 s, with no error). The passive walkers take any step."""
    from walkers.base import MAX_DT
    said = rf"{name}: dt=0.05 s is too large; use a step of at most {MAX_DT:g} s"
    with pytest.raises(ValueError, match=said):     # (Ranger's estimator said its cutoff first)
        walkers.load(name).Run(dt=0.05)
    walkers.load(name).Run(dt=MAX_DT)
    walkers.load("rimless-wheel").Run(dt=0.05)
