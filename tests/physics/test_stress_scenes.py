"""Box2D's classic stress scenes and the contact-rich scenes (benchmarks/stress_scenes.py) held
exactly: every pin's anchors within 1e-9 m of each other, no two shapes (nor a shape and the
ground) overlapping by more than 1e-8 m at any step, and the resting piles (the stack, the
pyramid, the 100:1 boxes, the card house) standing: no body moves more than 1e-6 m. Each
scene runs its `test_seconds` (0.3-0.5 s), every step recorded. Box2D's own taut bridge is not
held yet (FAILS)."""
import numpy as np
import pytest

import planarsim as ps
from benchmarks.stress_scenes import STRESS_SCENES, accuracy, build_model

PIN_TOL = 1e-9       # [m]
OVERLAP_TOL = 1e-8   # [m]
REST_TOL = 1e-6      # [m]

#: scenes the engine does not hold yet, each with what it does instead
FAILS = {
    "bridge160_taut": pytest.mark.xfail(
        raises=ps.SimulationDiverged, strict=True,
        reason="Box2D's own bridge, 160 planks 0.25 m spanning their gap exactly (taut): the step "
               "stops at step 37 (t = 0.037 s) with SimulationDiverged, pin 108 open by 4.94e-6 m "
               "(its pins' rows are dependent along the bridge; the sagging bridge160 holds)"),
}


def run_scene(name):
    """(scene, model, recorded frames q (K, n_body, 3)) of the scene's test run."""
    scene = STRESS_SCENES[name]
    model = build_model(scene)
    sim = ps.Simulator(model)
    traj = sim.run(n_steps=int(round(scene.test_seconds / scene.dt)), record_every=1)
    assert np.all(np.isfinite(traj.q)), name
    return scene, model, traj.q


@pytest.mark.parametrize("name", [pytest.param(n, marks=FAILS.get(n, ())) for n in STRESS_SCENES])
def test_scene_is_held_exactly(name):
    scene, model, q = run_scene(name)
    figures = accuracy(scene, model, q)
    if model.n_pin:
        assert figures["pin_gap_m"] <= PIN_TOL, figures
    assert figures["overlap_m"] <= OVERLAP_TOL, figures
    if scene.resting:
        assert figures["rest_drift_m"] <= REST_TOL, figures


def test_chain_ball_falls_and_swings_on_its_pins():
    """The 50 kg ball, released level with the world pin 10 m from it, falls and swings in."""
    _, _, q = run_scene("chain_ball")
    ball = q[:, -1]
    assert ball[-1, 1] < ball[0, 1] - 0.5 and ball[-1, 0] < ball[0, 0]


def test_bridge_sags_from_its_arc_toward_hanging():
    """The bridge's middle plank falls from the arc it starts on (its ends stay pinned)."""
    _, model, q = run_scene("bridge160")
    middle = model.n_body // 2
    assert q[-1, middle, 1] < q[0, middle, 1] - 1e-3


def test_first_domino_knocks_over_the_next():
    _, _, q = run_scene("dominoes20")
    assert q[-1, 0, 2] < -0.3 and q[-1, 1, 2] < -0.05, q[-1, :3, 2]


def test_poured_shapes_stay_inside_the_u():
    """Every circle and capsule stays between the walls and above the floor of the static U."""
    scene, _, q = run_scene("pour50")
    (_, w_floor, _), (left, wall, _), (right, _, _) = scene.statics
    assert np.all(q[..., 0] > left[0] + wall / 2) and np.all(q[..., 0] < right[0] - wall / 2)
    assert np.all(q[..., 1] > 0.0)
