"""A flat body on a gentle hill crest rocks like a stiff spring (stiffness m g R: turned by phi,
its edge's deepest point moves R phi along the edge); the step bounds its length by that
rocking (geometry/rocking.py). benchmarks/crest_rest.py measures the family: flat shapes
landing on their side on crests of radius 1 to 300 m.
"""
import numpy as np
import pytest

import planarsim as ps
from planarsim import terrain
from planarsim.kernels.checks.audit import AUDIT_NAMES
from planarsim.kernels.info import step_info


def board_on_a_crest(dt=0.003):
    """benchmarks/crest_rest.py's seed 7: a board (0.28 m x 5 mm, 0.28 kg) dropped flat onto a
    sine hill's crest of radius 175 m (its rocking: w = 508 rad/s)."""
    lam, amp = 25.378723197582012, 0.09322777058932208
    b = ps.ModelBuilder(dt=dt, terrain=terrain.hills([amp], [lam], [0.0]))
    b.add_body("board", 0.2821073361044683, 0.001871766637581941,
               pos=(6.386585866170069, 0.09624954734525892), angle=3.138386148874165,
               vel=(-0.2451304123458754, -0.12962559554657344), omega=0.054579107495439594,
               shapes=[("box", (0.0, 0.0), 0.2821230508343068, 0.005091490009518625,
                        {"mu": 1.0212284183827662})])
    return b.compile()


@pytest.mark.parametrize("dt", [0.003, 0.01])
def test_a_board_settled_on_a_gentle_crest_rocks_as_its_velocities_say_unaudited(dt):
    """Before the step was bounded by the rocking, at h w 1.5 (dt 3 ms) the board settled into
    a two-step cycle: each step the velocity solve turned it by 2.7e-4 rad about the contact of
    the step's start, the edge ended 6e-6 m in the hill, the projection lifted it, and the
    energy bound took the whole motion to pay for the lift and counted the rest: it flipped
    by +-2.4e-4 rad every step with v = 0 at the end, and every step drew a correction_work
    audit. Now it is taken in sub-steps of h w <= 1: no audit, and each step's turn is the
    one its velocities explain (twice their larger, plus 1e-6 rad: the rocking turns faster
    between the sub-steps than at the step's ends)."""
    model = board_on_a_crest(dt)
    sim = ps.Simulator(model)
    sim.steps(int(round(0.4 / dt)))         # landed, settled onto the crest
    substeps = []
    for _ in range(40):
        before = sim.state.copy()
        sim.step()
        substeps.append(step_info(sim.ws)["turn_substeps"])
        turn = abs(float(sim.state.q[0, 2] - before.q[0, 2]))
        # (the rocking may turn faster between the sub-steps than at the step's ends)
        explained = 2.0 * dt * max(abs(float(before.v[0, 2])), abs(float(sim.state.v[0, 2])))
        assert turn <= explained + 1e-6, (turn, explained)
    audits = {k: int(v) for k, v in zip(AUDIT_NAMES, sim.ws.audit) if v}
    assert not audits, audits
    assert min(substeps) >= 2       # (h w of 1.5 and 5: the rocking cuts the step)


def test_a_board_on_flat_ground_and_a_body_on_a_crest_with_joints_take_whole_steps():
    """The rocking bound counts only a body free of joints on a convex hill: on flat ground a
    board rests on its corners (no rocking spring), and a body held by joints rocks the bodies
    it is joined to too (its own inertia would understate theirs)."""
    flat = ps.ModelBuilder(dt=0.003)
    flat.add_body("board", 0.28, 0.0019, pos=(0.0, 0.0026), shapes=[("box", (0.0, 0.0), 0.28, 0.005)])
    sim = ps.Simulator(flat.compile())
    for _ in range(200):
        sim.step()
        assert step_info(sim.ws)["turn_substeps"] == 1
    b = ps.ModelBuilder(dt=0.003, terrain=terrain.hills([0.09322777058932208], [25.378723197582012],
                                                         [0.0]))
    board = b.add_body("board", 0.2821073361044683, 0.001871766637581941,
                       pos=(6.344680799395503, 0.0983), shapes=[("box", (0.0, 0.0), 0.28, 0.005)])
    arm = b.add_body("arm", 1.0, 0.01, pos=(6.344680799395503, 0.3))
    b.add_pin("hinge", board, arm, anchor_world=(6.344680799395503, 0.1))
    sim = ps.Simulator(b.compile())
    sim.steps(100)
    assert step_info(sim.ws)["turn_substeps"] == 1


def test_the_rocking_bound_follows_the_physics():
    """The same board at dt 2 ms (h w = 1.0) needed no sub-step and was never audited, before
    the bound too: the bound cuts a step only where its rocking needs it."""
    model = board_on_a_crest(0.002)
    sim = ps.Simulator(model)
    sim.steps(300)
    counts = []
    for _ in range(40):
        sim.step()
        counts.append(step_info(sim.ws)["turn_substeps"])
    assert max(counts) <= 2 and not np.any(sim.ws.audit)
