"""SIMBICON biped: walks 100 steps with the shipped parameters (only the feet touch the ground),
recovers from the applet's 60 N / 0.2 s push both ways, never stalls, and the compiled and
Python controller paths agree bit for bit."""
import numpy as np
import pytest

import planarsim as ps
import walkers.simbicon as simbicon
from walkers import WALKERS
from walkers.simbicon.controller import Controller, Phase
from walkers.simbicon.model import build, non_foot_clearance, start_state
from walkers.simbicon.params import THESIS, SimbiconParams
from walkers.simbicon.rollout import STRATEGY, run


@pytest.fixture(scope="module")
def long_walk():
    return run(SimbiconParams(), 75.0, record_every=20)


def test_registered_and_uniform_interface():
    assert WALKERS["simbicon"] == "walkers.simbicon"
    assert simbicon.NAME == "simbicon" and "walk" in simbicon.GAITS
    traj, summary, model = simbicon.simulate(0.5)
    assert len(traj.t) == 51 and traj.t[0] == 0.0 and model.n_act == 6   # start + 50 frames
    assert {"distance", "speed", "steps", "fell"} <= set(summary)
    with pytest.raises(ValueError, match="gait 'run' unknown"):
        simbicon.simulate(0.5, gait="run")


def test_walks_100_steps_on_flat_ground_feet_only(long_walk):
    traj, s, model = long_walk
    assert not s["glitch"], s
    assert not s["fell"], s
    assert s["steps"] >= 100, s
    assert s["timeouts"] == 0, s          # every swing ended at a real foot strike
    assert s["distance"] > 10.0 and s["speed"] > 0.2, s
    # only the feet touched the ground: every other part stayed above it in every frame
    assert non_foot_clearance(model, traj.q).min() > 0.0
    torso = model.meta["torso"]
    assert np.abs(traj.q[:, torso, 2]).max() < 0.5      # torso upright within ~30 deg


@pytest.mark.parametrize("force", [60.0, -60.0])
def test_recovers_from_the_applet_push(force):
    """60 N for 0.2 s at the torso while walking (the SIMBICON applet's push), both ways."""
    traj, s, model = run(SimbiconParams(), 20.0, push=dict(force=force, start=8.0, duration=0.2))
    assert not s["fell"], s
    # the push really acted: the torso speed changed compared with the unpushed walk
    _, s0, _ = run(SimbiconParams(), 20.0, record=False)
    assert abs(s["distance"] - s0["distance"]) > 1e-3


def test_fsm_never_stalls_without_contact():
    """With every foot contact disabled the character falls through the ground; the contact
    states still end by their timeout, so the machine cycles through all four states."""
    p = SimbiconParams(contact_timeout=0.2)
    model = build(p)
    sim = ps.Simulator(model, ps.make_options(STRATEGY))
    for name in model.contact_names:
        sim.set_contact_enabled(name, False)
    ctrl = Controller(p, model)
    seen = []
    for _ in range(1200):
        sim.step(ctrl(sim))
        if not seen or seen[-1] != ctrl.phase:
            seen.append(ctrl.phase)
    assert seen[:5] == [Phase.RIGHT_SWING_UP, Phase.RIGHT_SWING_DOWN, Phase.LEFT_SWING_UP,
                        Phase.LEFT_SWING_DOWN, Phase.RIGHT_SWING_UP]


def _paths(duration):
    p = SimbiconParams()
    traj, _, model = run(p, duration, record_every=1)
    sim = ps.Simulator(model, ps.make_options(STRATEGY),
                       state=start_state(model, p.start_lean, p.start_speed))
    ctrl = Controller(p, model)
    for k in range(len(traj.t) - 1):   # frame 0 is the start: one step per later frame
        sim.step(ctrl(sim))
    return sim.state.q, traj.q[-1]


def test_compiled_and_python_paths_agree():
    """The Python controller path and the compiled rollout step the same physics, bit for bit
    over 0.6 s (600 steps, several FSM transitions and contact-mode switches)."""
    q_python, q_compiled = _paths(0.6)
    assert np.array_equal(q_python, q_compiled)


def test_left_right_symmetry_is_data():
    """Mirroring: the left swing (state 2) uses the same target row as the right (state 0)."""
    p = SimbiconParams()
    model = build(p)
    tab = Controller(p, model).tables
    assert tab.target.shape == (2, 5)
    assert tab.pin.shape == (2, 3) and set(tab.pin.ravel()) == set(range(6))


def test_thesis_parameters_are_tables_3_and_4():
    assert (THESIS.swing_hip_0, THESIS.swing_knee_0, THESIS.swing_hip_1) == (0.7, -1.3, -0.7)
    assert (THESIS.cd_0, THESIS.cv_0, THESIS.cd_1, THESIS.cv_1) == (0.0, 0.2, 2.2, 0.0)
    assert THESIS.kp_hip == 800.0 and THESIS.kd_hip == 80.0
