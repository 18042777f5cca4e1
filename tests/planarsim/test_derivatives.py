"""planarsim.derivatives.step_jacobian against centred finite differences of the engine's own
step, on the mechanisms it covers so far: pin chains of 1-5 links with masses and inertias
over three decades (with rotors, springs and implicit dampers), sliders on the world and on a
turning arm, a closed four-bar loop, and gymnasium's planar models in the air (free roots,
rotors, dampers, springs, forces along a rail), under gravity, pin torques, body forces and
torques, from random states. The finite differences take the whole step (velocity solve,
Newton correction, checks) at x +- eps; the Jacobian comes from the implicit function theorem
on the step's own answer, so they agree to the differences' own error (measured: 1e-10 to
5e-8 of the largest entry)."""
import numpy as np
import pytest
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st

import planarsim as ps
from planarsim.derivatives import rollout_jacobians, step_jacobian
from test_derivatives_contact import difference_error as surface_difference_error, stepper

REL_TOL = 1e-6      # the bound on the relative error against finite differences
EPS_X = 1e-6        # [m, rad, m/s, rad/s] the state's finite-difference step
EPS_U = 1e-2        # [N m] the commands' (the step is linear in them but for the curvature)


def chain(masses, lengths, dt=1e-3, armature=None, stiffness=None, damping=None):
    """Links hinged end to end from a world pin (each with a pin motor, the last pushed by a
    body force and turned by a body torque), horizontal at the build; armature [kg m^2],
    stiffness [N m/rad], damping [N m s/rad]: per hinge (None: none)."""
    b = ps.ModelBuilder(dt=dt)
    prev, x = None, 0.0
    for i, (m, L) in enumerate(zip(masses, lengths)):
        body = b.add_body(f"link{i}", mass=m, inertia=m * L * L / 12, pos=(x + L / 2, 0.0))
        b.add_pin(f"pin{i}", prev, body, anchor_world=(x, 0.0),
                  armature=0.0 if armature is None else armature[i],
                  stiffness=0.0 if stiffness is None else stiffness[i], rest_angle=0.3,
                  damping=0.0 if damping is None else damping[i])
        b.add_pin_motor(f"motor{i}", f"pin{i}")
        prev, x = body, x + L
    b.add_body_force("push", prev, direction=(0.6, 0.8))
    b.add_body_torque("twist", prev)
    return b.compile()


def finite_differences(sim, u):
    """(A, B) of one step by centred differences, sim restored after each step."""
    x0, step = stepper(sim)
    A = np.empty((x0.size, x0.size))
    for i in range(x0.size):
        e = np.zeros_like(x0)
        e[i] = EPS_X
        A[:, i] = (step(x0 + e, u) - step(x0 - e, u)) / (2 * EPS_X)
    B = np.empty((x0.size, u.size))
    for k in range(u.size):
        e = np.zeros_like(u)
        e[k] = EPS_U
        B[:, k] = (step(x0, u + e) - step(x0, u - e)) / (2 * EPS_U)
    return A, B


#: [m, rad, m/s, rad/s] the finer difference step where the step's map bends within EPS_X of
#: the state (its rounding still 1e-9 of the largest entry)
EPS_FINE = 1e-8
#: [m, rad, m/s, rad/s] the coarser step of a Richardson-extrapolated difference, for a map
#: whose end carries its correction's tolerance as noise (1e-12 m over EPS_X is 1e-6: a
#: step taken in sub-steps ends after more corrections)
EPS_COARSE = 1e-4
#: [m, rad, m/s, rad/s] the step between them, where the map bends within EPS_COARSE (the
#: energy bound's share of the correction kept, changing regime) and is noisy at EPS_X
EPS_BETWEEN = 1e-5


def _agrees(exact, approx, i, n, blocks):
    """Column i of exact within REL_TOL of approx's, the positions' and the velocities' rows
    apart, each against the largest entry of its block of columns (blocks: slices; the
    velocities' rows' derivatives by the positions are 1 / h those by the velocities)."""
    cols = next(b for b in blocks if b.start <= i < b.stop)
    return all(np.abs(exact[rows, i] - approx[rows, i]).max()
               <= REL_TOL * np.abs(approx[rows, cols]).max()
               for rows in (slice(0, n), slice(n, None)))


def _settle_column(exact, approx, i, n, blocks, estimates):
    """The first of `estimates` (callables giving column i's difference estimate) that agrees
    with exact's column i replaces approx's; returns whether one did."""
    for estimate in estimates:
        trial = approx.copy()
        trial[:, i] = estimate()
        if _agrees(exact, trial, i, n, blocks):
            approx[:, i] = trial[:, i]
            return True
    return False


def differences_agree(jac, sim, u):
    """The Jacobian against centred differences at EPS_X (each block of A's columns, the
    derivatives by the positions and by the velocities, against its own largest entry). A
    state column that disagrees is judged again against Richardson's extrapolation of centred
    differences at EPS_COARSE and half of it (error O(eps^4), the step's noise divided by 5e-5
    instead of 1e-6: a step taken in sub-steps), then centred at EPS_BETWEEN, then at EPS_FINE,
    and only if the step's map bends within EPS_X of the state: its one-sided differences at
    EPS_X then differ from each other by more than the tolerance (a correction opening a pin
    gap of 1e-6 m whose velocity change the energy bound holds back, say). A command's column
    that disagrees at EPS_U is judged again at 1e-4 (Richardson's pair) and 1e-5. Returns
    (relative error of A, of B)."""
    A, B = finite_differences(sim, u)
    x0, step = stepper(sim)
    n = x0.size // 2
    state_blocks = (slice(0, n), slice(n, 2 * n))

    def centred(i, eps):
        e = np.zeros_like(x0)
        e[i] = eps
        return (step(x0 + e, u) - step(x0 - e, u)) / (2 * eps)

    for i in range(x0.size):
        if _agrees(jac.A, A, i, n, state_blocks):
            continue
        if _settle_column(jac.A, A, i, n, state_blocks, (
                lambda: (4 * centred(i, EPS_COARSE / 2) - centred(i, EPS_COARSE)) / 3,
                lambda: centred(i, EPS_BETWEEN))):
            continue
        e = np.zeros_like(x0)
        e[i] = EPS_X
        mid = step(x0, u)
        right = (step(x0 + e, u) - mid) / EPS_X
        left = (mid - step(x0 - e, u)) / EPS_X
        assert relative_error(right[:, None], left[:, None]) > REL_TOL, (
            f"column {i} disagrees with the differences where the step is smooth")
        A[:, i] = centred(i, EPS_FINE)

    def centred_u(k, eps):
        e = np.zeros_like(u)
        e[k] = eps
        return (step(x0, u + e) - step(x0, u - e)) / (2 * eps)

    command_blocks = (slice(0, u.size),)
    for k in range(u.size):
        if not _agrees(jac.B, B, k, n, command_blocks):
            # the bound's bend within EPS_U: Richardson's pair at 1e-4, then centred at 1e-5
            _settle_column(jac.B, B, k, n, command_blocks, (
                lambda: (4 * centred_u(k, 5e-5) - centred_u(k, 1e-4)) / 3,
                lambda: centred_u(k, 1e-5)))
    return (relative_error(jac.A, A, state_blocks),
            relative_error(jac.B, B, command_blocks))


def relative_error(exact, approx, blocks=None):
    """max |exact - approx| over max |approx|, for the positions' and the velocities' rows
    apart (the velocities' are 1 / h larger) and for each block of columns (blocks: slices;
    None: all columns together)."""
    n = exact.shape[0] // 2
    worst = 0.0
    for rows in (slice(0, n), slice(n, None)):
        for cols in blocks or (slice(None),):
            scale = np.abs(approx[rows, cols]).max(initial=0.0)
            if scale > 0.0:
                worst = max(worst, np.abs(exact[rows, cols] - approx[rows, cols]).max() / scale)
    return worst


#: the refusals that depend on the step taken, not on the model (a projection of the positions
#: after the correction: Walker2d at hypothesis seed 1987267, its limits hit under random
#: commands, before and after held contacts' second-order targets alike)
NOT_COVERED_STEPS = ("sub-steps", "do not reproduce", "a complementarity projection")


def rotor_chain(masses, lengths, dt, rng):
    """(armature, stiffness) of a chain's hinges: armature 1e-3 to 1e2 times the link's
    inertia and a spring the step resolves (a twentieth of the stiffness at which the step
    would take it at its end, kernels/constraints/soft.py)."""
    inertia = masses * lengths ** 2 / 12
    armature = inertia * 10 ** rng.uniform(-3, 2, masses.size)
    kappa = 1.0 / inertia + np.concatenate([[0.0], 1.0 / inertia[:-1]])
    return armature, 0.05 * 0.5 * (1.0 + armature * kappa) / (dt * dt * kappa)


def dampers(masses, lengths, dt, rng):
    """Hinge dampers whose implicit share of a step, h c / I of the link's inertia I, spans
    1e-3 to 10 (from barely felt to the link dragged along with its neighbour)."""
    return masses * lengths ** 2 / 12 / dt * 10 ** rng.uniform(-3, 1, masses.size)


def random_case(masses, lengths, dt, armature, stiffness, rng, damping=None):
    """(sim moved to a random state, commands u): commands of a third of the lightest link's
    weight times its length, for 20-60 steps (the links swing at up to about 15 rad/s)."""
    model = chain(masses, lengths, dt=dt, armature=armature, stiffness=stiffness,
                  damping=damping)
    sim = ps.Simulator(model)
    swing = 0.3 * masses.min() * 9.81 * lengths.min()
    moved_state(sim, rng, swing)
    return sim, rng.uniform(-1.0, 1.0, model.n_act) * swing


def moved_state(sim, rng, swing):
    """Run the mechanism from its build pose under random torques for a while: a state with
    the links turned and moving (swing [N m] of the commands)."""
    sim.steps(int(rng.integers(20, 60)), rng.uniform(-swing, swing, sim.model.n_act))


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(links=st.integers(1, 5), seed=st.integers(0, 2 ** 31 - 1),
       mass_decades=st.floats(0.0, 3.0), dt=st.sampled_from([1e-3, 5e-3]), rotors=st.booleans(),
       damped=st.booleans())
# found by the search: Newton's last step taken at a residual of ~1e-6 m left the end's
# derivative 1.1e-6 off the converged correction's (until the correction ended with one more
# step on its last factors)
@example(links=4, seed=386, mass_decades=2.5, dt=5e-3, rotors=False, damped=False)
def test_step_jacobian_is_the_steps_derivative(links, seed, mass_decades, dt, rotors, damped):
    """rotors: each hinge with armature of 1e-3 to 1e2 times its link's inertia and a spring
    the step resolves (a twentieth of the stiffness whose step angle would need the spring at the
    step's end); damped: each hinge with an implicit damper (dampers)."""
    rng = np.random.default_rng(seed)
    masses = 10 ** rng.uniform(-mass_decades / 2, mass_decades / 2, links)
    lengths = rng.uniform(0.2, 0.8, links)
    armature, stiffness = rotor_chain(masses, lengths, dt, rng) if rotors else (None, None)
    damping = dampers(masses, lengths, dt, rng) if damped else None
    sim, u = random_case(masses, lengths, dt, armature, stiffness, rng, damping)
    before = sim.snapshot()
    try:
        jac = step_jacobian(sim, u)
    except NotImplementedError as exc:
        # a step the engine took in sub-steps or whose correction its energy bound held
        # back: not covered yet (test_most_random_chains_are_covered counts them)
        assume(not any(why in str(exc) for why in NOT_COVERED_STEPS))
        raise
    assert np.array_equal(sim.state.q, before.q) and np.array_equal(sim.state.v, before.v)
    error_A, error_B = differences_agree(jac, sim, u)
    assert error_A <= REL_TOL, error_A
    assert error_B <= REL_TOL, error_B
    assert not jac.modes_changed


@pytest.mark.parametrize("rotors, covered", [(False, 60), (True, 50)])
def test_most_random_chains_are_covered(rotors, covered):
    """Of 60 seeded chains (1-5 links, masses over three decades, dt 1 or 5 ms) step_jacobian
    covers every step without rotors and at least 50 with them (measured 53: 4 steps taken in
    sub-steps, 3 whose correction's velocity change the energy bound held back; each refused
    by name, never a derivative of another map)."""
    count = 0
    for seed in range(60):
        rng = np.random.default_rng(seed)
        links, decades, dt = int(rng.integers(1, 6)), rng.uniform(0, 3), (1e-3, 5e-3)[seed % 2]
        masses = 10 ** rng.uniform(-decades / 2, decades / 2, links)
        lengths = rng.uniform(0.2, 0.8, links)
        armature, stiffness = rotor_chain(masses, lengths, dt, rng) if rotors else (None, None)
        sim, u = random_case(masses, lengths, dt, armature, stiffness, rng)
        try:
            step_jacobian(sim, u)
            count += 1
        except NotImplementedError as exc:
            assert any(why in str(exc) for why in NOT_COVERED_STEPS), exc
    assert count >= covered, count


def slider_mechanism(masses, tilt, dt, armature, rail=None):
    """A cart on a world rail tilted by `tilt` [rad] (limits +-5 m), an arm hinged to it (with
    armature, a pin motor), a block sliding along the arm in a groove that turns with it
    (limits +-1 m) and hinged to it a pendulum (a body force and a body torque on it): both
    kinds of slider, their limits out of reach, under gravity. rail: the rail's armature [kg],
    damping [N s/m] and stiffness [N/m] (add_slider's keywords) and a force along it."""
    b = ps.ModelBuilder(dt=dt)
    m0, m1, m2, m3 = masses
    cart = b.add_body("cart", mass=m0, inertia=m0 * 0.02, pos=(0.0, 0.0))
    b.add_slider("rail", None, cart, axis=(np.cos(tilt), np.sin(tilt)), limit=(-5.0, 5.0),
                 **(rail or {}))
    if rail:
        b.add_slider_motor("drive", "rail")
    arm = b.add_body("arm", mass=m1, inertia=m1 * 0.36 / 12, pos=(0.3, 0.0))
    b.add_pin("shoulder", cart, arm, anchor_world=(0.0, 0.0), armature=armature)
    b.add_pin_motor("motor", "shoulder")
    block = b.add_body("block", mass=m2, inertia=m2 * 0.01, pos=(0.45, 0.05))
    b.add_slider("groove", arm, block, axis=(1.0, 0.0), anchor_world=(0.45, 0.0),
                 limit=(-1.0, 1.0))
    bob = b.add_body("bob", mass=m3, inertia=m3 * 0.09 / 12, pos=(0.6, 0.05))
    b.add_pin("elbow", block, bob, anchor_world=(0.45, 0.05))
    b.add_body_force("push", bob, direction=(0.6, 0.8))
    b.add_body_torque("twist", bob)
    return b.compile()


@settings(max_examples=16, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2 ** 31 - 1), mass_decades=st.floats(0.0, 2.0),
       tilt=st.floats(-0.6, 0.6), dt=st.sampled_from([1e-3, 5e-3]), soft_rail=st.booleans())
def test_a_slider_mechanisms_step_jacobian_is_its_derivative(seed, mass_decades, tilt, dt,
                                                             soft_rail):
    """Sliders on the world and on a turning arm (their axis, and so their perpendicular row,
    turns with it), with limits out of reach and a hinge with armature; soft_rail: the world
    rail with a rotor (1e-2 to 10 times the cart's mass), an implicit damper, a spring the step
    resolves and a force along it."""
    rng = np.random.default_rng(seed)
    masses = 10 ** rng.uniform(-mass_decades / 2, mass_decades / 2, 4)
    rail = None
    if soft_rail:
        rail = dict(armature=masses[0] * 10 ** rng.uniform(-2, 1),
                    damping=masses[0] / dt * 10 ** rng.uniform(-3, 0),
                    stiffness=0.05 * masses[0] / dt ** 2)
    model = slider_mechanism(masses, tilt, dt, armature=0.05 * masses[1], rail=rail)
    sim = ps.Simulator(model)
    swing = 0.3 * masses.min() * 9.81 * 0.3
    moved_state(sim, rng, swing)
    u = rng.uniform(-1.0, 1.0, model.n_act) * swing
    before = sim.snapshot()
    try:
        jac = step_jacobian(sim, u)
    except NotImplementedError as exc:
        # (a limit of the groove, whose rate row turns with the arm)
        assume(not any(why in str(exc) for why in NOT_COVERED_STEPS + ("limit reached",)))
        raise
    assert np.array_equal(sim.state.q, before.q) and np.array_equal(sim.state.v, before.v)
    assert np.abs(sim.state.v[[0, 2], :2]).max() > 0.0     # (the sliders slide)
    assume(not jac.modes_changed)
    if limit_reached(sim, u):
        error, kinks, edge = surface_difference_error(sim, u)
        assume(not edge and not kinks)
        assert error <= REL_TOL, error
        return
    error_A, error_B = differences_agree(jac, sim, u)
    assert error_A <= REL_TOL, error_A
    assert error_B <= REL_TOL, error_B


def test_a_closed_loop_and_the_sim_continues_as_if_never_asked():
    """A four-bar loop (its last link pinned to the world too): the derivative holds, and a
    run asked for it continues bit for bit as one that was not."""
    b = ps.ModelBuilder(dt=1e-3)
    left = b.add_body("crank", mass=1.0, inertia=1.0 / 48, pos=(0.0, 0.25), angle=np.pi / 2)
    top = b.add_body("coupler", mass=0.5, inertia=0.5 / 12, pos=(0.5, 0.5))
    right = b.add_body("rocker", mass=1.0, inertia=1.0 / 48, pos=(1.0, 0.25), angle=np.pi / 2)
    b.add_pin("a", None, left, anchor_world=(0.0, 0.0))
    b.add_pin("b", left, top, anchor_world=(0.0, 0.5))
    b.add_pin("c", top, right, anchor_world=(1.0, 0.5))
    b.add_pin("d", right, None, anchor_world=(1.0, 0.0))
    b.add_pin_motor("drive", "a")
    model = b.compile()
    sim, twin = ps.Simulator(model), ps.Simulator(model)
    u = np.array([0.7])
    for s in (sim, twin):
        s.steps(100, u)
    jac = step_jacobian(sim, u)
    error_A, error_B = differences_agree(jac, sim, u)
    assert error_A <= REL_TOL and error_B <= REL_TOL, (error_A, error_B)
    sim.steps(50, u)
    twin.steps(50, u)
    assert np.array_equal(sim.state.q, twin.state.q) and np.array_equal(sim.state.v, twin.state.v)


def test_a_saturated_command_moves_nothing_and_one_at_its_bound_is_a_mode_change():
    b = ps.ModelBuilder(dt=1e-3)
    link = b.add_body("link", mass=1.0, inertia=1.0 / 12, pos=(0.5, 0.0))
    b.add_pin("hinge", None, link, anchor_world=(0.0, 0.0))
    b.add_pin_motor("motor", "hinge", limit=(-1.0, 1.0))
    sim = ps.Simulator(b.compile())
    sim.steps(30, np.array([0.5]))
    assert not np.any(step_jacobian(sim, np.array([3.0])).B)
    assert not step_jacobian(sim, np.array([3.0])).modes_changed
    assert step_jacobian(sim, np.array([1.0])).modes_changed
    assert np.any(step_jacobian(sim, np.array([0.5])).B)


def _arm_with_groove(**groove):
    """A cart on a world rail, an arm hinged to it, a block in a groove along the arm (the
    groove's axis turns with the arm); groove: add_slider's keywords."""
    b = ps.ModelBuilder(dt=1e-3)
    cart = b.add_body("cart", mass=1.0, inertia=0.1, pos=(0.0, 0.0))
    b.add_slider("rail", None, cart, axis=(1.0, 0.0), anchor_world=(0.0, 0.0))
    arm = b.add_body("arm", mass=1.0, inertia=0.03, pos=(0.3, 0.0))
    b.add_pin("shoulder", cart, arm, anchor_world=(0.0, 0.0))
    block = b.add_body("block", mass=0.5, inertia=0.01, pos=(0.45, 0.0))
    b.add_slider("groove", arm, block, axis=(1.0, 0.0), anchor_world=(0.45, 0.0), **groove)
    return b


def test_what_is_not_covered_yet_is_named():
    with pytest.raises(NotImplementedError, match="armature on slider 'groove', whose rate row"):
        step_jacobian(ps.Simulator(_arm_with_groove(armature=0.5).compile()))
    with pytest.raises(NotImplementedError, match="a damper on slider 'groove'"):
        step_jacobian(ps.Simulator(_arm_with_groove(damping=0.5).compile()))
    b = _arm_with_groove()
    b.add_slider_motor("drive", "groove")
    with pytest.raises(NotImplementedError, match="actuator 'drive', a force along a slider"):
        step_jacobian(ps.Simulator(b.compile()))
    b = ps.ModelBuilder(dt=1e-3)
    cart = b.add_body("cart", mass=1.0, inertia=0.1, pos=(0.0, 0.0))
    b.add_slider("rail", None, cart, axis=(1.0, 0.0), anchor_world=(0.0, 0.0),
                 limit=(-0.1, 0.0))
    b.add_body_force("push", cart, direction=(1.0, 0.0))
    sim = ps.Simulator(b.compile())
    sim.steps(100, np.array([50.0]))        # pushed against its upper limit
    assert limit_reached(sim, np.array([50.0]))
    error, kinks, edge = surface_difference_error(sim, np.array([50.0]))
    assert error <= REL_TOL and not kinks and not edge, (error, kinks, edge)
    b = ps.ModelBuilder(dt=1e-3)
    link = b.add_body("link", mass=1.0, inertia=1.0 / 12, pos=(0.5, 0.0))
    b.add_pin("hinge", None, link, anchor_world=(0.0, 0.0), frictionloss=0.1)
    with pytest.raises(NotImplementedError, match="dry friction on joint 'hinge'"):
        step_jacobian(ps.Simulator(b.compile()))
    with pytest.raises(ValueError, match="finite"):
        step_jacobian(ps.Simulator(chain([1.0], [0.5])), np.array([np.nan]))


def test_a_rollouts_derivative_is_the_product_of_its_steps():
    """Ten steps of a three-link chain under changing torques: the product of the steps' A
    (and the chain rule for the first command) against differences of the ten-step map."""
    model = chain([1.0, 0.5, 2.0], [0.4, 0.6, 0.3])
    sim = ps.Simulator(model)
    rng = np.random.default_rng(3)
    moved_state(sim, rng, 0.5)
    us = rng.uniform(-0.5, 0.5, (10, model.n_act))
    start = sim.snapshot()
    jacs = rollout_jacobians(sim, us)
    end = sim.snapshot()
    sim.restore(start)
    for u in us:
        sim.step(u)
    assert np.array_equal(sim.state.q, end.q)          # as plain steps leave it
    total = np.eye(jacs[0].A.shape[0])
    for j in jacs:
        total = j.A @ total
    n = model.n_body
    x0 = np.concatenate([start.q.ravel(), start.v.ravel()])

    def rollout(x):
        s = start.copy()
        s.q[:] = x[:3 * n].reshape(n, 3)
        s.v[:] = x[3 * n:].reshape(n, 3)
        sim.restore(s)
        for u in us:
            sim.step(u)
        return np.concatenate([sim.state.q.ravel(), sim.state.v.ravel()])

    fd = np.empty_like(total)
    for i in range(x0.size):
        e = np.zeros_like(x0)
        e[i] = EPS_X
        fd[:, i] = (rollout(x0 + e) - rollout(x0 - e)) / (2 * EPS_X)
    assert relative_error(total, fd) <= REL_TOL, relative_error(total, fd)
    # d x_10 / d u_0 = A_9 ... A_1 B_0
    chained = jacs[0].B
    for j in jacs[1:]:
        chained = j.A @ chained
    k = 1
    bumped = [us.copy(), us.copy()]
    bumped[0][0, k] += EPS_U
    bumped[1][0, k] -= EPS_U
    ends = []
    for seq in bumped:
        sim.restore(start)
        for u in seq:
            sim.step(u)
        ends.append(np.concatenate([sim.state.q.ravel(), sim.state.v.ravel()]))
    fd_u = (ends[0] - ends[1]) / (2 * EPS_U)
    assert relative_error(chained[:, k:k + 1], fd_u[:, None]) <= REL_TOL
    with pytest.raises(ValueError, match="us must have shape"):
        rollout_jacobians(sim, np.zeros(3))


def test_at_rest_and_held_still_and_the_simulator_keeps_its_options_and_counters():
    """Equilibria (a pendulum hanging at rest, one held level by its motor) are covered, and
    asking leaves the simulator's speed bound, audit and counters as they were."""
    b = ps.ModelBuilder(dt=1e-3)
    link = b.add_body("link", mass=1.0, inertia=1.0 / 12, pos=(0.0, -0.5), angle=-np.pi / 2)
    b.add_pin("hinge", None, link, anchor_world=(0.0, 0.0))
    b.add_pin_motor("motor", "hinge", limit=(-20.0, 20.0))
    sim = ps.Simulator(b.compile())
    jac = step_jacobian(sim)
    A, B = finite_differences(sim, np.zeros(1))
    assert relative_error(jac.A, A) <= REL_TOL and relative_error(jac.B, B) <= REL_TOL
    level = ps.Simulator(chain([1.0], [0.5]))
    hold = np.array([9.81 * 0.25, 0.0, 0.0])       # the motor holds the link's weight
    sim.steps(7, np.array([3.0]))
    options, audit, info = sim.options, sim.ws.audit.copy(), sim.ws.info.copy()
    step_jacobian(sim, np.array([19.0]))
    assert sim.options is options
    assert np.array_equal(sim.ws.audit, audit) and np.array_equal(sim.ws.info, info)
    jac = step_jacobian(level, hold)
    A, B = finite_differences(level, hold)
    assert relative_error(jac.A, A) <= REL_TOL and relative_error(jac.B, B) <= REL_TOL


def test_open_pins_and_dependent_hinges_are_refused():
    sim = ps.Simulator(chain([1.0, 2.0], [0.5, 0.5]), ps.StepOptions(refine_iters=0))
    with pytest.raises(NotImplementedError, match="no position correction"):
        step_jacobian(sim)
    # a parallelogram with a third, redundant link: its hinges' rows are dependent
    b = ps.ModelBuilder(dt=1e-3)
    bodies = [b.add_body(f"bar{i}", mass=1.0, inertia=1.0 / 48, pos=(x, -0.25),
                         angle=-np.pi / 2) for i, x in enumerate((0.0, 0.5, 1.0))]
    top = b.add_body("top", mass=1.0, inertia=1.0 / 12, pos=(0.5, -0.5))
    for i, x in enumerate((0.0, 0.5, 1.0)):
        b.add_pin(f"world{i}", None, bodies[i], anchor_world=(x, 0.0))
        b.add_pin(f"top{i}", bodies[i], top, anchor_world=(x, -0.5))
    sim = ps.Simulator(b.compile())
    sim.steps(5)
    with pytest.raises(NotImplementedError, match="dependent joints"):
        step_jacobian(sim)


def test_springs_without_rotors_are_covered():
    """A hinge spring with neither rotor nor damper that the step resolves is an explicit force
    of the step (forces.spring_as_force): three-link chains with such springs on every hinge,
    or on all but one that has a rotor, match centred differences (relative error <= 1e-6)."""
    rng = np.random.default_rng(11)
    for mixed in (False, True):
        masses, lengths = rng.uniform(0.3, 3.0, 3), rng.uniform(0.2, 0.8, 3)
        inertia = masses * lengths ** 2 / 12
        kappa = 1.0 / inertia + np.concatenate([[0.0], 1.0 / inertia[:-1]])
        stiffness = 0.05 / (1e-3 ** 2 * kappa)          # h^2 k kappa = 0.05: well resolved
        armature = np.zeros(3)
        if mixed:
            armature[1] = 2.0 * inertia[1]
        sim, u = random_case(masses, lengths, 1e-3, armature, stiffness, rng)
        jac = step_jacobian(sim, u)
        error_A, error_B = differences_agree(jac, sim, u)
        assert error_A <= REL_TOL and error_B <= REL_TOL, (error_A, error_B)


GYM_MODELS = ("Hopper", "Walker2d", "HalfCheetah", "InvertedPendulum", "InvertedDoublePendulum",
              "Reacher")
_GYM = {}


def gym_env(name):
    """planarsim's gymnasium environment `name`, unwrapped (one per test session)."""
    if name not in _GYM:
        gym = pytest.importorskip("gymnasium")
        import planarsim.envs  # noqa: F401  (registers the environments)
        _GYM[name] = gym.make(f"planarsim/{name}-v0").unwrapped
    return _GYM[name]


@pytest.mark.parametrize("name", GYM_MODELS)
@settings(max_examples=4, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2 ** 31 - 1))
def test_the_gymnasium_models_step_jacobian_under_torque(name, seed):
    """gymnasium's planar models as planarsim loads them (free roots' slides and hinge, hinges
    with rotors, implicit dampers and springs, InvertedPendulum's force along its rail), the
    walkers lifted 1 m off the ground, from states reached under random commands: A, and B
    (the derivative with respect to the motors' commands), match centred differences."""
    env = gym_env(name)
    env.reset(seed=seed)
    sim = env.sim
    rng = np.random.default_rng(seed)
    if name in ("Hopper", "Walker2d", "HalfCheetah"):
        start = sim.state.copy()
        start.q[:, 1] += 1.0
        sim.state = start
    lo, hi = sim.model.arrays.act_range.T
    span = np.where(np.isfinite(hi - lo), hi - lo, 2.0)
    sim.steps(int(rng.integers(2, 10)), np.clip(rng.uniform(-0.5, 0.5, lo.size) * span, lo, hi))
    middle = np.where(np.isfinite(lo + hi), 0.5 * (lo + hi), 0.0)
    u = middle + rng.uniform(-0.45, 0.45, lo.size) * span   # (differences by EPS_U inside)
    try:
        jac = step_jacobian(sim, u)
    except NotImplementedError as exc:
        assume(not any(why in str(exc) for why in NOT_COVERED_STEPS))
        raise
    assert np.abs(jac.B).max() > 0.0
    assume(not jac.modes_changed)       # (a limit let go in the step: on its surface)
    if limit_reached(sim, u):
        # a limit row is unilateral: the positions moved along its surface only
        error, kinks, edge = surface_difference_error(sim, u)
        assume(not edge and not kinks)
        assert error <= REL_TOL, error
        return
    error_A, error_B = differences_agree(jac, sim, u)
    assert error_A <= REL_TOL, error_A
    assert error_B <= REL_TOL, error_B


def limit_reached(sim, u):
    """Some joint limit is active at the end of sim's next step under u (sim restored)."""
    start = sim.snapshot()
    sim.step(u)
    active = bool(sim.state.limit_active.any())
    sim.restore(start)
    return active
