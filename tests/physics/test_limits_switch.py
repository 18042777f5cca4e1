"""Joint limits in the mode rounds (kernels/solver/modes.py switch_broken): an engaged limit whose
impulse pulls is released in the rounds, as a contact that pulls is, so a step where a joint
leaves its limit is answered by linear solves, not by the complementarity solve. On the arm
below (a unique answer) it is the complementarity solve's (mode_strategy 'all') to rounding;
where friction leaves the answer not unique (a foot sliding or sticking with equal right), the
rounds may stand on another answer that keeps every rule. Before, the rounds
re-examined contacts only: every step that released a limit ended in Lemke's method (under
random torques dm_control's cheetah took it at 88 % of its steps, now 3 %)."""
import numpy as np
import pytest

import planarsim as ps
from planarsim.compiled import audit_counts, step_info


def arm(with_floor, dt=1e-3):
    """A 0.4 m, 1 kg link hinged to the world at (0, 1) with limits (-0.3, 0.3) rad and a
    motor of +-20 N m; a second link hinged to its tip, limits (-0.5, 0.5); with_floor: a 1 kg
    box resting on the ground beside them (a contact, so the alternating rounds run)."""
    b = ps.ModelBuilder(dt=dt, ground=True if with_floor else None)
    b.add_body("upper", 1.0, 1.0 * 0.4 ** 2 / 12, pos=(0.2, 1.0))
    b.add_pin("shoulder", None, "upper", anchor_world=(0.0, 1.0), limit=(-0.3, 0.3))
    b.add_body("lower", 0.5, 0.5 * 0.4 ** 2 / 12, pos=(0.6, 1.0))
    b.add_pin("elbow", "upper", "lower", anchor_world=(0.4, 1.0), limit=(-0.5, 0.5))
    b.add_pin_motor("shoulder_motor", "shoulder", limit=(-20.0, 20.0))
    b.add_pin_motor("elbow_motor", "elbow", limit=(-20.0, 20.0))
    if with_floor:
        box = b.add_body("box", 1.0, 1.0 * (0.2 ** 2 + 0.2 ** 2) / 12, pos=(2.0, 0.1))
        b.add_box_contacts("box", box, (0.0, 0.0), 0.2, 0.2, mu=0.8)
    return b.compile()


def drive(model, strategy, pattern):
    """Steps of the arm under motor commands `pattern` (a list of (steps, (u0, u1))); returns
    (q and v after each step, how many steps ended in the complementarity solve, how many
    steps released a limit)."""
    sim = ps.Simulator(model, ps.make_options(strategy))
    out, lemke, released = [], 0, 0
    for n, u in pattern:
        for _ in range(n):
            before = sim.state.limit_active.copy()
            sim.step(np.array(u, float))
            lemke += step_info(sim.ws)["lcp_solves"] > 0
            released += int((before > sim.state.limit_active).any())
            out.append(np.concatenate([sim.state.q.ravel(), sim.state.v.ravel()]))
    return np.array(out), lemke, released


# down onto the limits, up off them, down again, a wiggle
PATTERN = [(300, (-20.0, -20.0)), (200, (20.0, 20.0)), (200, (-20.0, 20.0)),
           (300, (20.0, -20.0)), (200, (-5.0, 5.0))]


@pytest.mark.parametrize("with_floor", [True, False])
def test_a_joint_leaving_its_limit_is_answered_by_the_rounds(with_floor):
    model = arm(with_floor)
    rounds, lemke, released = drive(model, "alternating", PATTERN)
    reference, _, released_all = drive(model, "all", PATTERN)
    assert released >= 4 and released_all >= 4      # limits engaged and left several times
    assert lemke == 0
    scale = 1.0 + np.abs(reference).max()
    assert np.abs(rounds - reference).max() <= 1e-9 * scale


def test_the_rounds_hand_a_cycling_step_to_the_complementarity_solve():
    """dm_control's cheetah under random full torques, a foot on the floor and joints on their
    limits: where the rounds have stalled (the least-index rule) and the solve dropped rows
    as dependent, the problem's matrix is singular, the rule has no end to promise, and the
    rounds stop there: the complementarity solve takes the step. Before, such steps cycled
    through least-change answers for all SWITCH_ROUNDS rounds (116-133 linear solves, then
    Lemke's method anyway): here no physics step runs the rounds to their last. No step's
    answer draws an audit."""
    gym = pytest.importorskip("gymnasium")
    pytest.importorskip("dm_control", reason="dm_control ships the cheetah's file")
    import planarsim.envs  # noqa: F401
    from planarsim.kernels.step import SWITCH_ROUNDS
    env = gym.make("planarsim/dmc-cheetah-run-v0").unwrapped
    env.reset(seed=0)
    rng = np.random.default_rng(0)
    most, solves, lemke, n = 0, 0, 0, 600
    before = audit_counts(env.sim.ws)         # (the reset's settling has its own)
    for _ in range(n):
        env.load_commands(rng.uniform(env.action_space.low, env.action_space.high))
        for _ in range(env.frame_skip):       # (each physics step's counts)
            env.sim.steps(1, env._u)
            info = step_info(env.sim.ws)
            most = max(most, info["switch_rounds"])
            solves = max(solves, info["solves"])
            lemke += info["lcp_solves"] > 0
        env._sync()
    print(f"cheetah: most switch rounds in a step {most} (most solves {solves}), "
          f"steps to Lemke {lemke} of {n * env.frame_skip}")
    assert lemke >= 1             # (the case arises in this run)
    assert most < SWITCH_ROUNDS, most
    assert audit_counts(env.sim.ws) == before, (before, audit_counts(env.sim.ws))


def test_limits_are_engaged_by_answers_not_by_the_free_motion():
    """The step's guess engages a joint limit only once an answer's velocity carries the joint
    past it (step.solve_modes). The free motion v* turns each body alone, without the pins and
    rotors (armature) that share a joint's torque: under random full torques it carried
    dm_control's cheetah's joints past limits in most steps, the answer then pulled on them,
    and the rounds released them again (3.9 linear solves a physics step). Now at most 2.6 a
    step on average, every limit still held: no answer draws an audit, and no joint ends a
    step past its limit by more than 1e-9 rad."""
    gym = pytest.importorskip("gymnasium")
    pytest.importorskip("dm_control", reason="dm_control ships the cheetah's file")
    import planarsim.envs  # noqa: F401
    env = gym.make("planarsim/dmc-cheetah-run-v0").unwrapped
    env.reset(seed=0)
    rng = np.random.default_rng(1)
    a = env.sim_model.arrays
    limited = np.flatnonzero(np.isfinite(a.pin_limit).any(axis=1))
    assert limited.size == 6
    before = audit_counts(env.sim.ws)
    solves, steps, worst = 0, 0, 0.0
    for _ in range(500):
        env.load_commands(rng.uniform(env.action_space.low, env.action_space.high))
        for _ in range(env.frame_skip):
            env.sim.steps(1, env._u)
            solves += step_info(env.sim.ws)["solves"]
            steps += 1
            q = env.sim.state.q
            for j in limited:
                parent, child = a.pin_body[j]
                angle = q[child, 2] - a.pin_ref[j] - (q[parent, 2] if parent >= 0 else 0.0)
                worst = max(worst, a.pin_limit[j, 0] - angle, angle - a.pin_limit[j, 1])
    print(f"cheetah: {solves / steps:.2f} linear solves a physics step, "
          f"worst limit overshoot {worst:.2e} rad")
    assert solves / steps <= 2.6
    assert worst <= 1e-9
    assert audit_counts(env.sim.ws) == before
