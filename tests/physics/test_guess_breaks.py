"""step_info's guess_* counts: the rules the step's guess (its first answer, under the modes
the last step left) broke, by rule (modes.rule_breaks into ws.broken_rules). They say why a
step needed more than one linear solve, or the complementarity solve
(benchmarks/step_times.py reports them for those steps)."""
import numpy as np

import planarsim as ps
from planarsim.compiled import step_info

GUESS = ("guess_equations", "guess_pulls", "guess_reversals", "guess_cones", "guess_limits")


def box_on_ground(speed=0.0, mu=0.5):
    """A 1 kg, 0.2 m box resting on flat ground on its two lower corners, moving at `speed`
    [m/s] along it."""
    b = ps.ModelBuilder(dt=1e-3, ground=True)
    box = b.add_body("box", 1.0, 1.0 * (0.2 ** 2 + 0.2 ** 2) / 12, pos=(0.0, 0.1))
    b.add_box_contacts("box", box, (0.0, 0.0), 0.2, 0.2, mu=mu)
    model = b.compile()
    sim = ps.Simulator(model)
    sim.state.v[0, 0] = speed
    return sim


def guess_counts(sim):
    info = step_info(sim.ws)
    return np.array([info[name] for name in GUESS])


def test_a_box_at_rest_keeps_its_guess_and_pulls_when_lifted():
    """At rest every step's guess (both corners pinned) holds; lifted by twice its weight
    the guess of that step pulls at the corners it still pins, and the box leaves the ground."""
    sim = box_on_ground()
    for _ in range(200):
        sim.step()
    for _ in range(50):
        sim.step()
        assert guess_counts(sim).sum() == 0
        assert step_info(sim.ws)["solves"] == 1
    sim.state.ext_force[0, 1] = 2 * 9.81
    sim.step()
    counts = guess_counts(sim)
    assert counts[1] >= 1                       # the pinned corners pull
    assert counts[0] == counts[2] == counts[4] == 0
    assert sim.state.v[0, 1] > 0.0


def test_a_box_sliding_to_a_stop_reverses_its_slip_in_the_guess():
    """Sliding at 0.5 m/s on mu 0.5 the box stops within about 0.1 s: at the step it would
    slide back, its guess (still sliding) reverses the slip; it rests afterwards."""
    sim = box_on_ground(speed=0.5)
    total = np.zeros(len(GUESS), int)
    for _ in range(400):
        sim.step()
        total += guess_counts(sim)
    assert total[2] >= 1
    assert total[4] == 0                        # (no joint, no limit)
    assert abs(sim.state.v[0, 0]) < 1e-9


def test_a_model_without_contacts_counts_nothing():
    b = ps.ModelBuilder(dt=1e-3)
    b.add_body("link", 1.0, 0.02, pos=(0.25, 0.0))
    b.add_pin("hinge", None, "link", anchor_world=(0.0, 0.0))
    sim = ps.Simulator(b.compile())
    for _ in range(100):
        sim.step()
        assert guess_counts(sim).sum() == 0
