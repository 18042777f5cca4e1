"""The motor turn check (StepOptions.turn_limit, kernels/checks/guards.py turn_gain): a torque
actuator whose command alone would turn its hinge by more than turn_limit in one step from
rest stops the run before that step. The turn is h^2 |u| kappa, kappa the hinge angle's
inverse inertia with the hinge's own pin holding its two bodies: a link hinged to the world
turns about its hinge (1 / (I + m d^2)), not about its centre of mass (1 / I, the bound
before, which stopped pendulums and arms that a step resolves)."""
import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import planarsim as ps
import reference as ref


def guard_kappa(model, state, torque):
    """The kappa [1/(kg m^2)] the guard measured for actuator 0 (a turn_limit no command
    passes), from `state`."""
    sim = ps.Simulator(model, ps.make_options(turn_limit=1e-300), state=state)
    with pytest.raises(ps.SimulationDiverged, match="acts faster than the step"):
        sim.step(np.array([torque]))
    return float(sim.ws.guard_value[1])


def hanging_link(m, inertia, d, dt, torque, damping=0.0, armature=0.0):
    """A link (mass m [kg], inertia [kg m^2] about its centre) whose centre lies d [m] from a
    world hinge at (0, 1), with a motor of +-torque [N m] at the hinge (its damping [N m s/rad]
    and armature [kg m^2]); no gravity."""
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0))
    b.add_body("link", m, inertia, pos=(d, 1.0))
    b.add_pin("hinge", None, "link", anchor_world=(0.0, 1.0), damping=damping, armature=armature)
    b.add_pin_motor("motor", "hinge", limit=(-torque, torque))
    return b.compile()


def test_a_link_hinged_to_the_world_turns_about_its_hinge():
    """kappa = 1 / (I + m d^2) (parallel axes) to rounding; a limit just above the turn
    h^2 u kappa runs the step and one just below stops it; the step then turns the link by
    that turn to within its second-order correction."""
    m, inertia, d, dt, u = 0.5, 2e-3, 0.3, 1e-3, 1.0
    model = hanging_link(m, inertia, d, dt, u)
    kappa = 1.0 / (inertia + m * d * d)
    assert guard_kappa(model, ps.make_state(model), u) == pytest.approx(kappa, rel=1e-12)
    turn = dt * dt * u * kappa
    stopped = ps.Simulator(model, ps.make_options(turn_limit=0.99 * turn))
    with pytest.raises(ps.SimulationDiverged):
        stopped.step(np.array([u]))
    sim = ps.Simulator(model, ps.make_options(turn_limit=1.01 * turn))
    sim.step(np.array([u]))
    assert sim.state.q[0, 2] == pytest.approx(turn, rel=1e-3)
    # the bound before (1 / I about the centre) was 1 + m d^2 / I = 23.5 times this one
    assert (1.0 / inertia) / kappa == pytest.approx(23.5)


@settings(max_examples=60, deadline=None)
@given(mass=st.tuples(*[st.floats(0.01, 100.0)] * 2), inertia=st.tuples(*[st.floats(1e-4, 10.0)] * 2),
       arm=st.tuples(*[st.floats(-1.0, 1.0)] * 4), angle=st.tuples(*[st.floats(-math.pi, math.pi)] * 2),
       shoulder=st.one_of(st.none(), st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0))))
def test_a_hinges_turn_gain_is_the_pins_schur_complement(mass, inertia, arm, angle, shoulder):
    """Two bodies joined by a motor's hinge, drawn masses [kg], inertias [kg m^2], anchors
    [m] and angles [rad], body a hinged to the world at a drawn point of its own or not (an
    arm at its shoulder): the guard's kappa equals the reference Schur complement of those
    pins' rows (tests/reference.py hinge_turn_gain) and never exceeds 1/I_a + 1/I_b."""
    b = ps.ModelBuilder(dt=1e-3, gravity=(0.0, 0.0))
    la, lb = np.array(arm[:2]), np.array(arm[2:])
    hinge = np.array([0.0, 1.0])
    # body centres placed so that their anchors la, lb (in the bodies' frames) meet at the hinge
    for name, mk, ik, local, th in (("a", mass[0], inertia[0], la, angle[0]),
                                    ("b", mass[1], inertia[1], lb, angle[1])):
        c, s = math.cos(th), math.sin(th)
        centre = hinge - np.array([c * local[0] - s * local[1], s * local[0] + c * local[1]])
        b.add_body(name, mk, ik, pos=tuple(centre), angle=th)
    b.add_pin("hinge", "a", "b", anchor_world=tuple(hinge))
    if shoulder is not None:       # a point of body a, (x, y) [m] from its centre in its frame
        c, s = math.cos(angle[0]), math.sin(angle[0])
        centre = hinge - np.array([c * la[0] - s * la[1], s * la[0] + c * la[1]])
        point = centre + np.array([c * shoulder[0] - s * shoulder[1], s * shoulder[0] + c * shoulder[1]])
        b.add_pin("shoulder", None, "a", anchor_world=tuple(point))
    b.add_pin_motor("motor", "hinge", limit=(-1.0, 1.0))
    model = b.compile()
    state = ps.make_state(model)
    kappa = guard_kappa(model, state, 1.0)
    expected = ref.hinge_turn_gain(model.arrays, np.array(state.q[:model.n_body]), 0)
    if shoulder is not None:       # the shoulder holds a: never more than the pair alone
        pair = ref.hinge_turn_gain(model.arrays._replace(pin_kind=model.arrays.pin_kind * 0 + [0, 99]),
                                   np.array(state.q[:model.n_body]), 0)
        assert expected <= pair * (1 + 1e-9) + 1e-12
    assert kappa == pytest.approx(expected, rel=1e-6, abs=1e-6 * (1.0 / min(inertia)))
    assert kappa <= (1.0 / inertia[0] + 1.0 / inertia[1]) * (1 + 1e-12)


@pytest.mark.parametrize("damping, armature", [(0.01, 0.0), (2.5, 0.0), (0.3, 1e-3), (1e-6, 0.0)])
def test_a_damped_hinge_is_judged_by_the_turn_its_step_takes(damping, armature):
    """The damper is implicit (constraints/soft.py), so a step of h from rest turns the hinge
    by h^2 u / (I_h + a + h c), I_h the link's inertia about the hinge: the guard's kappa is
    1 / (I_h + a + h c), and the step's turn is the guard's turn. The link of dm_control's
    reacher (its wrist: 8.33e-5 kg m^2, 0.01 N m s/rad, 0.05 N m at dt 0.02) turns 0.067 rad
    in that step, where the guard without its damper judged 0.227 rad and stopped a run of
    random actions after 675 steps. The error's dt bound is the largest step that passes."""
    m, inertia, d, dt = 0.05, 2e-5, 0.02, 0.02
    held = inertia + m * d * d + armature
    kappa = 1.0 / (held + dt * damping)
    u = 0.05 / (dt * dt * kappa)        # [N m] a turn of 0.05 rad in the step
    model = hanging_link(m, inertia, d, dt, u, damping, armature)
    assert guard_kappa(model, ps.make_state(model), u) == pytest.approx(kappa, rel=1e-12)
    turn = dt * dt * u * kappa
    sim = ps.Simulator(model, ps.make_options(turn_limit=1.01 * turn))
    sim.step(np.array([u]))
    assert sim.state.q[0, 2] == pytest.approx(turn, rel=1e-3)
    stopped = ps.Simulator(model, ps.make_options(turn_limit=0.99 * turn))
    with pytest.raises(ps.SimulationDiverged, match="acts faster than the step") as stop:
        stopped.step(np.array([u]))
    if damping > 1e-3:
        assert "N m s/rad of damping" in str(stop.value)
    most = float(str(stop.value).split("Take dt <= ")[1].split(" s")[0])
    for scale, passes in ((0.99, True), (1.01, False)):
        h = most * scale
        k = 1.0 / (held + h * damping)
        assert (h * h * u * k <= 0.99 * turn) == passes


def test_the_reacher_wrist_runs_at_its_files_step():
    """dm_control's reacher wrist at full command from rest at dt 0.02: within the default
    turn_limit with its damper, beyond it without (the guard stops that one)."""
    inertia, dt, u = 8.33e-5, 0.02, 0.05
    for damping, stops in ((0.01, False), (0.0, True)):
        model = hanging_link(1e-9, inertia, 0.0, dt, u, damping)
        sim = ps.Simulator(model)
        if stops:
            with pytest.raises(ps.SimulationDiverged, match="acts faster than the step"):
                sim.step(np.array([u]))
        else:
            sim.step(np.array([u]))
            assert sim.state.q[0, 2] == pytest.approx(dt * dt * u / (inertia + dt * damping),
                                                      rel=1e-3)
