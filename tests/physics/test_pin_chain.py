"""The step's pin-chain path (kernels/solver/pin_chain.py, step.chain_step) against the general
stages: the same answer to rounding and the same checks, on chains of any masses, inertias
(point masses too), anchors, speeds and ends (free, hanging from the world, a bridge held at
both ends); and which models take it (planarsim/pin_chains.py)."""
import math

import numpy as np
import pytest
from hypothesis import example, given, settings, strategies as st

import planarsim as ps
from planarsim.pin_chains import pin_chain_order
from planarsim.kernels.info import step_info
from planarsim.state import make_workspace


def chain_model(masses, inertias, offsets, speeds, ends, dt=1e-3, reverse=False, motors=False):
    """A chain of len(masses) bodies, body i at x = i (offsets[i]: its COM off the line),
    pinned to the next half way; ends: 'free', 'hung' (pin 0 to the world) or 'bridge' (both
    ends to the world). inertias[i] 0: a point mass. reverse: bodies and pins added last
    first."""
    b = ps.ModelBuilder(dt=dt)
    n = len(masses)
    idx = list(range(n))[::-1] if reverse else list(range(n))
    ids = {}
    for i in idx:
        pos = (float(i), float(offsets[i]))
        vel = (float(speeds[i][0]), float(speeds[i][1]))
        if inertias[i] == 0.0:
            ids[i] = b.add_point_mass(f"b{i}", mass=masses[i], pos=pos, vel=vel)
        else:
            ids[i] = b.add_body(f"b{i}", mass=masses[i], inertia=inertias[i], pos=pos,
                                vel=vel, omega=float(speeds[i][2]))
    point = [inertias[i] == 0.0 for i in range(n)]

    def at(i, k, where):
        """A pin's world anchor: on the point mass i or k if either is one."""
        for body in (i, k):
            if body is not None and point[body]:
                return (float(body), float(offsets[body]))
        return where

    pins = []
    if ends in ("hung", "bridge"):
        pins.append(("w0", None, 0, at(0, None, (-0.5, 0.4))))
    for i in range(n - 1):
        pins.append((f"p{i}", i, i + 1, at(i, i + 1, (i + 0.5, 0.3 * math.sin(i)))))
    if ends == "bridge":
        pins.append(("w1", n - 1, None, at(n - 1, None, (n - 0.5, 0.4))))
    for name, a, c, at in (pins[::-1] if reverse else pins):
        j = b.add_pin(name, None if a is None else ids[a], None if c is None else ids[c],
                      anchor_world=at)
        if motors:
            b.add_pin_motor(f"m{name}", j)
    return b.compile()


def run(model, steps, chain_path, u=None):
    """A Simulator after `steps` steps with the chain path on or off; sim.chain_steps: how
    many the chain path took."""
    sim = ps.Simulator(model)
    sim.ws.chain_on[0] = int(chain_path)
    sim.chain_steps = 0
    for _ in range(steps):
        sim.step(u)
        sim.chain_steps += step_info(sim.ws)["chain_path"]
    return sim


@st.composite
def chains(draw):
    ends = draw(st.sampled_from(["free", "hung", "bridge"]))
    n = draw(st.integers(3 if ends == "bridge" else 2, 9))
    masses = [10.0 ** draw(st.floats(-2, 2)) for _ in range(n)]
    # a point mass is pinned at its centre; never two in a row (they would share a point);
    # none in a bridge (2 of its 3 coordinates could leave the bridge's rows dependent: the
    # general stages take such steps)
    inertias = []
    for m in masses:
        point = (draw(st.integers(0, 3)) == 0 and (not inertias or inertias[-1] > 0.0)
                 and ends != "bridge")
        inertias.append(0.0 if point else m * 10.0 ** draw(st.floats(-3, 0)))
    offsets = [draw(st.floats(-0.3, 0.3)) for _ in range(n)]
    speeds = [(draw(st.floats(-3, 3)), draw(st.floats(-3, 3)), draw(st.floats(-20, 20)))
              for _ in range(n)]
    return dict(masses=masses, inertias=inertias, offsets=offsets, speeds=speeds, ends=ends,
                reverse=draw(st.booleans()), dt=draw(st.sampled_from([1e-4, 1e-3, 4e-3])))


@settings(max_examples=120, deadline=None)
@given(chains())
# a point mass and a body falling as one, with no motion of their own: the pins' work is
# all rounding, which the path judged by handing every step to the general stages (found
# by an unseeded search: the path took none of the 40 steps)
@example(case=dict(masses=[1.0, 1.0], inertias=[0.0, 1.0], offsets=[0.0, 0.0],
                   speeds=[(1.0903667740405519e-153, 0.0, 0.0), (0.0, 0.0, 0.0)],
                   ends="free", reverse=False, dt=1e-4))
def test_the_chain_path_gives_the_general_steps_answer(case):
    """40 steps of the general stages; from each step's start the chain path's step too: the
    same answer to rounding (relative to the motion's size; step by step, so that a chaotic
    chain does not grow the difference), the pins held as tightly, the same audits; the
    chain path took some of the steps (the bench chains' test below: nearly all). Where the
    general step stops, the path stops at the same step."""
    model = chain_model(**case)
    assert make_workspace(model).chain_on[0] == 1
    slow = ps.Simulator(model)
    slow.ws.chain_on[0] = 0
    fast = ps.Simulator(model)
    taken = 0
    for _ in range(40):
        fast.state = slow.state
        try:
            slow.step()
        except ps.SimulationDiverged as stop:
            with pytest.raises(ps.SimulationDiverged) as same:
                fast.step()
            assert str(same.value).split(":")[0] == str(stop).split(":")[0]
            return
        fast.step()
        taken += step_info(fast.ws)["chain_path"]
        scale = 1.0 + np.abs(slow.state.v).max()
        assert np.abs(fast.state.q - slow.state.q).max() <= 1e-11 * scale
        assert np.abs(fast.state.v - slow.state.v).max() <= 1e-9 * scale
        assert np.array_equal(fast.ws.audit, slow.ws.audit)
        assert pin_gap(model, fast.state.q) <= max(1e-9, 2 * pin_gap(model, slow.state.q))
    assert taken >= 1       # (else the comparison would be of the general stages with themselves)


def pin_gap(model, q):
    """The largest distance [m] between a pin's two anchors at configuration q."""
    a = model.arrays
    worst = 0.0
    for j, bodies in enumerate(np.asarray(a.pin_body)):
        ends = []
        for e, body in enumerate(bodies):
            x, y = a.pin_anchor[j, e]
            if body >= 0:
                c, s = math.cos(q[body, 2]), math.sin(q[body, 2])
                x, y = q[body, 0] + c * x - s * y, q[body, 1] + s * x + c * y
            ends.append((x, y))
        worst = max(worst, math.dist(*ends))
    return worst


def test_the_bench_chains_take_the_path_at_nearly_every_step():
    """10 s of the 32-link bench chain falling from horizontal (its tip whips at tens of
    rad/s, so some steps are taken in turn sub-steps, by the chain path too)."""
    from benchmarks.scenes import chain
    sim = run(chain(32), 10_000, True)
    assert sim.chain_steps >= 9_900


def test_motors_and_a_reversed_build_take_the_path_and_agree():
    """Torques at every pin of a 6-link chain built last link first: the same motion."""
    rng = np.random.default_rng(3)
    n = 6
    model = chain_model([1.0] * n, [0.02] * n, [0.0] * n, [(0, 0, 0)] * n, "hung",
                        reverse=True, motors=True)
    assert make_workspace(model).chain_on[0] == 1
    u = rng.uniform(-2, 2, model.n_act)
    fast = run(model, 500, True, u)
    slow = run(model, 500, False, u)
    assert fast.chain_steps == 500
    assert np.abs(fast.state.q - slow.state.q).max() < 1e-8
    assert np.abs(fast.state.v - slow.state.v).max() < 1e-6


def test_same_bits_from_the_same_start_and_from_a_restored_state():
    """Nothing but the State carries over: a run restored half way ends on the same bits."""
    model = chain_model([1.0] * 8, [0.02] * 8, [0.0] * 8, [(0, 0, 0)] * 8, "hung")
    a, b = run(model, 300, True), run(model, 300, True)
    assert a.state.q.tobytes() == b.state.q.tobytes()
    assert a.state.v.tobytes() == b.state.v.tobytes()
    half = run(model, 150, True)
    rest = ps.Simulator(model, state=half.state.copy())
    for _ in range(150):
        rest.step()
    assert rest.state.q.tobytes() == a.state.q.tobytes()
    assert rest.state.v.tobytes() == a.state.v.tobytes()


def _builder_with(n=3, **pin):
    b = ps.ModelBuilder()
    ids = [b.add_body(f"b{i}", mass=1.0, inertia=0.1, pos=(float(i), 0.0)) for i in range(n)]
    return b, ids


@pytest.mark.parametrize("what", ["limit", "stiffness", "damping", "armature", "frictionloss",
                                  "rod", "contact", "ring", "three pins on a body", "two pins, same bodies"])
def test_models_with_more_than_open_pin_chains_take_the_general_stages(what):
    b, ids = _builder_with(4)
    extra = {"limit": dict(limit=(-1.0, 1.0)), "stiffness": dict(stiffness=1.0),
             "damping": dict(damping=1.0), "armature": dict(armature=0.1),
             "frictionloss": dict(frictionloss=0.1)}.get(what, {})
    b.add_pin("p0", ids[0], ids[1], anchor_world=(0.5, 0.0), **extra)
    b.add_pin("p1", ids[1], ids[2], anchor_world=(1.5, 0.0))
    if what == "rod":
        b.add_rod("r", ids[2], ids[3], anchor_a=(0.0, 0.0), anchor_b=(0.0, 0.0))
    elif what == "contact":
        b.add_point_contact("c", ids[2], (0.0, 0.0))
    elif what == "ring":
        b.add_pin("p2", ids[2], ids[0], anchor_world=(1.0, 1.0))
    elif what == "three pins on a body":
        b.add_pin("p2", ids[1], ids[3], anchor_world=(1.0, 0.5))
    elif what == "two pins, same bodies":
        b.add_pin("p2", ids[1], ids[2], anchor_world=(1.5, 0.5))
    assert pin_chain_order(b.compile()) is None


def test_chains_are_found_in_the_order_their_rows_are_eliminated():
    """Two chains: each chain's pins in sequence with increasing indices (the general solve's
    elimination order), each next to the pin it shares a body with. A chain listed out of
    order along it takes the general stages (its pivots there would differ)."""
    b, ids = _builder_with(6)
    b.add_pin("p21", ids[2], ids[1], anchor_world=(1.5, 0.0))
    b.add_pin("p10", ids[1], ids[0], anchor_world=(0.5, 0.0))
    b.add_pin("p34", ids[3], ids[4], anchor_world=(3.5, 0.0))
    b.add_pin("p45", ids[4], ids[5], anchor_world=(4.5, 0.0))
    b.add_pin("w5", ids[5], None, anchor_world=(5.0, 1.0))
    model = b.compile()
    order, ends = pin_chain_order(model)
    pins = np.asarray(model.arrays.pin_body)
    assert order.tolist() == [0, 1, 2, 3, 4]
    assert ends[:, 0].tolist() == [-1, 0, -1, 0, 1]     # (a pin to the world lists it first)
    for k in (1, 3, 4):
        assert pins[order[k], ends[k, 0]] == pins[order[k - 1], ends[k, 1]] >= 0
    b, ids = _builder_with(4)
    b.add_pin("p23", ids[2], ids[3], anchor_world=(2.5, 0.0))
    b.add_pin("p01", ids[0], ids[1], anchor_world=(0.5, 0.0))
    b.add_pin("p12", ids[1], ids[2], anchor_world=(1.5, 0.0))
    assert pin_chain_order(b.compile()) is None


def test_a_model_swapped_in_with_limits_takes_the_general_stages():
    """Simulator.model = a model of the same pins with joint limits: the limits hold (the
    chain path, which has no limit rows, is not taken)."""
    def build(limit):
        b = ps.ModelBuilder()
        ids = [b.add_body(f"b{i}", mass=1.0, inertia=0.02, pos=(i + 0.5, 0.0)) for i in range(3)]
        b.add_pin("w", None, ids[0], anchor_world=(0.0, 0.0))
        for i in range(2):
            b.add_pin(f"p{i}", ids[i], ids[i + 1], anchor_world=(i + 1.0, 0.0), limit=limit)
        return b.compile()
    sim = ps.Simulator(build(None))
    assert sim.ws.chain_on[0] == 1
    sim.model = build((-0.1, 0.1))
    assert sim.ws.chain_on[0] == 0
    for _ in range(1000):
        sim.step()
        assert step_info(sim.ws)["chain_path"] == 0
    q = sim.state.q
    assert abs(q[1, 2] - q[0, 2]) <= 0.1 + 1e-9 and abs(q[2, 2] - q[1, 2]) <= 0.1 + 1e-9


def test_joints_close_a_loop_only_through_a_ring_of_bodies_or_the_world_twice():
    """pin_chains.joints_form_no_loop: a chain hanging from the world, a rod pendulum and a
    free pinned pair close no loop; a bridge (a chain pinned to the world at both ends) and
    a ring of three bodies do (the world counts as one body)."""
    from planarsim.pin_chains import joints_form_no_loop

    def model(pins, rods=()):
        b = ps.ModelBuilder(dt=0.01)
        bodies = [b.add_body(f"b{i}", 1.0, 0.1, pos=(float(i), 1.0)) for i in range(3)]
        for k, (i, j) in enumerate(pins):
            x = 0.5 * ((i if i >= 0 else j) + (j if j >= 0 else i))
            b.add_pin(f"p{k}", None if i < 0 else bodies[i], None if j < 0 else bodies[j],
                      anchor_world=(x, 1.0))
        for k, (i, j) in enumerate(rods):
            b.add_rod(f"r{k}", None if i < 0 else bodies[i], bodies[j])
        return b.compile()
    assert joints_form_no_loop(model([(-1, 0), (0, 1), (1, 2)]))
    assert joints_form_no_loop(model([(0, 1)], rods=[(-1, 2)]))
    assert not joints_form_no_loop(model([(-1, 0), (0, 1), (1, 2), (2, -1)]))
    assert not joints_form_no_loop(model([(0, 1), (1, 2)], rods=[(0, 2)]))
