"""The viewer's hook of every walker that has gaits to switch (planarsim view WALKER): the
Python-path controller it returns moves the walker as the compiled rollout does, its gait keys
and sliders act on the run."""
import numpy as np
import pytest

import walkers
from walkers import simbicon, simple_biped


@pytest.mark.parametrize("name", ["simple-biped", "ranger", "quadruped", "simbicon"])
def test_every_actuated_walker_has_a_viewer_hook(name):
    spec = walkers.load(name).live()
    assert {"sim", "controller"} <= set(spec)


def test_simple_biped_hook_walks_like_its_rollout():
    spec = simple_biped.live(gait="walk")
    sim = spec["sim"]
    sim.run(4.0, controller=spec["controller"])
    traj, summary, model = simple_biped.simulate(4.0, gait="walk")
    # the same controller and engine, stepped from Python or compiled: the same motion
    assert np.allclose(sim.state.q, traj.q[-1], atol=1e-9)
    spec["on_gait"](spec["gait_keys"]["j"])
    assert spec["labels"](sim)["gait"] == int(simple_biped.Gait.JUMP)


def test_simbicon_hook_walks_like_its_rollout_and_the_push_slider_pushes():
    spec = simbicon.live()
    sim = spec["sim"]
    sim.run(3.0, controller=spec["controller"])
    traj, summary, model = simbicon.simulate(3.0)
    assert np.allclose(sim.state.q, traj.q[-1], atol=1e-9)
    push = spec["gains"]["push [N]"]
    push[3](100.0)
    sim.run(0.2, controller=spec["controller"])
    assert push[2]() == 100.0 and sim.state.ext_force[:, 0].max() == 100.0
