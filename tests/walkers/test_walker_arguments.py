"""Walker arguments that failed deep inside (numpy, enum, a filter's design) or ran silently
now raise a ValueError naming the argument: SIMBICON's push, Ranger's dt, max_steps, seed and
suspended, a gait of None, a quadruped speed beyond its parameter's bounds."""
import pytest

import walkers
from walkers.simbicon.rollout import _push_array


@pytest.mark.parametrize("push, said", [
    ((100.0, 0.1), "a sequence is \\(fx, start, duration\\)"),          # was: not enough values
    ({"forc": 100.0}, "the keys are \\['force', 'start', 'duration'\\]"),  # was: KeyError 'force'
    ({"force": 100.0, "strat": 5.0}, "keys \\['force', 'strat'\\]"),      # was: pushed at t = 0
    ({"force": (1.0, 2.0, 3.0)}, "force is fx or \\(fx, fy\\)"),           # was: fz dropped
    ({"force": "abc"}, "could not convert"),
    ("abc", "a sequence is"),
])
def test_simbicon_push_of_another_form_is_named(push, said):
    with pytest.raises(ValueError, match=f"push=.*{said}"):
        _push_array(push)


def test_simbicon_push_forms_that_stand():
    assert _push_array((100.0, 0.5, 0.2)).tolist() == [100.0, 0.0, 0.5, 0.2]
    assert _push_array({"force": (10.0, -5.0), "start": 1.0}).tolist() == [10.0, -5.0, 1.0, 0.2]
    assert _push_array(None).tolist() == [0.0, 0.0, -1.0, 0.0]


@pytest.mark.parametrize("kw, said", [
    (dict(dt=0.05), r"ranger: dt=0.05 s is too large"),    # was: the estimator's Nyquist cutoff
    (dict(max_steps=-1), r"ranger: max_steps=-1 must be a whole number >= 1"),   # was: negative dimensions
    (dict(seed=-1), r"ranger: seed=-1 must be a whole number >= 0"),
])
def test_ranger_arguments_are_named(kw, said):
    with pytest.raises(ValueError, match=said):
        walkers.load("ranger").Run(**kw)


def test_ranger_suspended_takes_true_or_false():
    with pytest.raises(TypeError, match=r"ranger: suspended='no' must be True or False"):
        walkers.load("ranger").Run(suspended="no")


@pytest.mark.parametrize("name", ["simple-biped", "quadruped"])
@pytest.mark.parametrize("gait", [None, "fly", 7, True])
def test_unknown_gait_is_named_with_the_gaits(name, gait):
    """gait=None raised enum's "None is not a valid Gait"."""
    module = walkers.load(name)
    with pytest.raises(ValueError, match=f"unknown {name} gait {gait!r}; use one of "
                                         f"\\{list(module.GAITS)}"):
        module.Run(gait=gait)


@pytest.mark.parametrize("name, speed", [("quadruped", 100.0), ("quadruped", -1.5),
                                         ("simple-biped", 5.0), ("simple-biped", -0.1)])
def test_speed_beyond_the_params_bounds_is_refused(name, speed):
    """quadruped.simulate(speed=100) ran (QuadrupedParams(speed=100) was refused)."""
    with pytest.raises(ValueError, match=f"{name}: speed={speed} m/s must be a finite number within"):
        walkers.load(name).Run(speed=speed)


def test_load_takes_a_name():
    with pytest.raises(KeyError, match=r"unknown walker \['ranger'\]"):
        walkers.load(["ranger"])
