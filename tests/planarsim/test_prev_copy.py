"""The State a step keeps as its start (Workspace.prev) copied only where it can differ
(kernels/prev_copy.py: the ground contacts and the pairs listed since the last copy): after
every step taken whole ws.prev is, bit for bit, the State the step began from, on every
contact slot of every pair of shapes (a step taken in sub-steps keeps its last sub-step's
start there); and a run whose State is never handed out (so each step copies only the
listed pairs) ends bit for bit where one that copies every slot at every step ends. Scenes:
the stress corpus's piles of 4-12 shapes falling on flat ground and on hills (pairs joining
and leaving the broad phase's list, steps taken in sub-steps) and a small pyramid struck after
it settled (complementarity solves)."""
import numpy as np
import pytest

import planarsim as ps
from benchmarks import contact_stress, worlds
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


def _copy(state):
    return [np.array(a, copy=True) for a in state]


CASES = ([("shape_pile", s) for s in (0, 4, 6, 10)] + [("shape_hills", s) for s in (1, 4, 9)]
         + [("struck_pyramid", 4)])


@pytest.mark.parametrize("case", CASES, ids=[f"{f}-{s}" for f, s in CASES])
def test_prev_is_the_steps_start_on_every_slot_and_runs_agree_bit_for_bit(case):
    listed, whole = _start(case), _start(case)
    steps = 60 if case[0] != "struck_pyramid" else 6
    partial_copies = whole_steps = 0
    for _ in range(steps):
        before = _copy(listed._state)          # (not `state`: that makes the next copy whole)
        partial_copies += int(listed.ws.prev_whole[0] == 0)
        listed.step()
        if listed.ws.info[INFO_TURN_SUBSTEPS] == 1:     # (else: the last sub-step's start)
            whole_steps += 1
            for name, kept, was in zip(listed.ws.prev._fields, listed.ws.prev, before):
                assert np.array_equal(kept, was), f"ws.prev.{name} is not the step's start"
        whole.state                            # handed out: every slot copied at each step
        whole.step()
    assert partial_copies >= steps - 1         # the listed copy was what ran
    assert whole_steps > steps // 2
    for name, a, b in zip(listed._state._fields, listed._state, whole._state):
        assert np.array_equal(a, b), f"{name} differs between the listed and the whole copies"
    assert listed.model.arrays.n_shape_pair > 0


def test_a_state_put_in_or_edited_in_place_is_copied_whole():
    sim = _start(("shape_pile", 0))
    sim.steps(5)
    assert sim.ws.prev_whole[0] == 0
    sim.state.contact_enabled[:] = 0             # edited in place through the handed-out state
    assert sim.ws.prev_whole[0] == 1
    sim.steps(1)
    assert np.array_equal(sim.ws.prev.contact_enabled, np.zeros_like(sim.ws.prev.contact_enabled))
    snap = sim.snapshot()
    sim.steps(3)
    sim.restore(snap)
    assert sim.ws.prev_whole[0] == 1
