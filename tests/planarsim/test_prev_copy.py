"""The State a step keeps as its start (Workspace.prev) copied only where it can differ
(kernels/prev_copy.py: within one call, the ground contacts and the pairs listed since the
last copy): after a step taken whole ws.prev is, bit for bit, the State the step began from,
on every contact slot of every pair of shapes (a step taken in sub-steps keeps its last
sub-step's start there); a run of one call (its later steps copy the listed slots) ends bit
for bit where a run of a call a step (each copying every slot) ends; a State changed in
place between calls keeps the change. Scenes:
the stress corpus's piles of 4-12 shapes falling on flat ground and on hills (pairs joining
and leaving the broad phase's list, steps taken in sub-steps) and a small pyramid struck after
it settled (complementarity solves)."""
import numpy as np
import pytest

import planarsim as ps
from benchmarks import contact_stress, worlds
from planarsim.kernels.codes import CONTACT_PAIR
from planarsim.kernels.info import INFO_TURN_SUBSTEPS


def _start(case):
    family, seed = case
    if family == "struck_pyramid":
        sim = ps.Simulator(worlds.pyramid(seed))
        sim.steps(worlds.SETTLE)
        worlds._push_third_level(sim.state.q, sim.state.v)
        return sim
    model, _, q0, v0 = contact_stress.build(family, seed)
    return ps.Simulator(model, state=ps.make_state(model, q0, v0))


CASES = ([("shape_pile", s) for s in (0, 4, 6, 10)] + [("shape_hills", s) for s in (1, 4, 9)]
         + [("struck_pyramid", 4)])


def _run(case, calls):
    """The case's simulator after Simulator.steps(n) for each n of `calls`."""
    sim = _start(case)
    for n in calls:
        sim.steps(n)
    return sim


@pytest.mark.parametrize("case", CASES, ids=[f"{f}-{s}" for f, s in CASES])
def test_prev_is_the_steps_start_on_every_slot_and_runs_agree_bit_for_bit(case):
    steps = 60 if case[0] != "struck_pyramid" else 6
    listed = _run(case, [steps])              # one call: its later steps copy the listed slots
    whole = _run(case, [1] * steps)           # a call a step: each copies every slot
    for name, a, b in zip(listed.state._fields, listed.state, whole.state):
        assert np.array_equal(a, b), f"{name} differs between the listed and the whole copies"
    assert listed.model.arrays.n_shape_pair > 0
    checked = 0
    for k in (steps // 3, steps // 2, steps):
        sim = _run(case, [k])
        if sim.ws.info[INFO_TURN_SUBSTEPS] != 1:    # (a step in sub-steps keeps the last one's)
            continue
        before = _run(case, [k - 1]).state          # the state the k-th step began from
        for name, kept, was in zip(sim.ws.prev._fields, sim.ws.prev, before):
            assert np.array_equal(kept, was), f"ws.prev.{name} is not step {k}'s start"
        checked += 1
    assert checked >= 2


def test_a_state_changed_in_place_between_calls_is_kept():
    """A reference to the State held across calls and changed through it: every shape pair's
    contacts disabled after two steps stay disabled (a step begun again from its start must not
    bring back what ws.prev held before the change), as when changed through a fresh
    `Simulator.state`."""
    held, fresh = _start(("shape_pile", 4)), _start(("shape_pile", 4))
    pairs = np.flatnonzero(held.model.arrays.contact_kind == CONTACT_PAIR)
    state = held.state
    held.steps(2)
    fresh.steps(2)
    state.contact_enabled[pairs] = 0
    fresh.state.contact_enabled[pairs] = 0
    for _ in range(40):
        held.steps(10)
        fresh.steps(10)
        assert not state.contact_enabled[pairs].any()
    for name, a, b in zip(held.state._fields, held.state, fresh.state):
        assert np.array_equal(a, b), name
