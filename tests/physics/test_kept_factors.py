"""StepOptions.keep_factors: a pile at rest keeps its sparse factors from step to step
(solve.same_rows_factored, refine_on_kept_factors): the answer is refined against each
step's own matrix, so it is the fresh factorisation's to rounding; where the rows change or
the refinement does not converge, the rows are factored afresh. Off by default: then a
restored State continues bit for bit."""
import numpy as np
import pytest

import planarsim as ps
from planarsim.kernels.info import step_info

from benchmarks.worlds import WORLDS


@pytest.fixture(scope="module")
def pyramid20():
    """The 210-box pyramid (1,568 rows at rest: the sparse factorisation) after its first
    steps, and its state then."""
    sim = ps.Simulator(WORLDS["pyramid20"]())
    sim.steps(3)
    return sim.model, sim.state.copy()


def run(model, state, steps, keep, push=None):
    """A Simulator from `state` after `steps` steps, with kept factors or without; push: (body, force [N]) applied from the 10th step on. Returns it and how many
    of its solves used kept factors."""
    sim = ps.Simulator(model, options=ps.StepOptions(keep_factors=int(keep)))
    sim.state = state
    kept = 0
    for k in range(steps):
        if push is not None and k == 10:
            sim.state.ext_force[push[0], :2] = push[1]
        sim.step()
        kept += step_info(sim.ws)["kept_factors"]
    return sim, kept


def test_a_pile_at_rest_reuses_its_factors_and_gets_the_fresh_answer(pyramid20):
    model, start = pyramid20
    kept, n_kept = run(model, start, 60, True)
    fresh, n_fresh = run(model, start, 60, False)
    assert n_fresh == 0
    assert n_kept >= 55             # (the comparison below is not of one path with itself)
    assert np.abs(kept.state.q - fresh.state.q).max() < 1e-12
    assert np.abs(kept.state.v - fresh.state.v).max() < 1e-10
    assert np.abs(kept.state.q - start.q).max() < 1e-9
    assert np.array_equal(kept.ws.audit, fresh.ws.audit)


@pytest.mark.parametrize("fx, fy", [(5.0, 0.0), (0.0, 60.0), (0.0, 150.0), (9.0, 100.0)])
def test_a_pushed_pile_moves_as_with_fresh_factors(pyramid20, fx, fy):
    """A push on the top box from the 10th step (sideways within its friction; upward beyond
    its weight of 39 N it lifts off, and its contacts' rows go): the factors are made afresh
    where the rows change, and the motion is the fresh factorisation's. (Not a push that
    sets some of its contacts sliding while the others stick, 8 N sideways with 20 N up:
    its complementarity problem over the pile's 1,568 rows runs for minutes, with fresh
    factors as with kept ones.)"""
    model, start = pyramid20
    kept, _ = run(model, start, 30, True, (209, (fx, fy)))
    fresh, _ = run(model, start, 30, False, (209, (fx, fy)))
    scale = 1.0 + np.abs(fresh.state.v).max()
    assert np.abs(kept.state.q - fresh.state.q).max() < 1e-9 * scale
    assert np.abs(kept.state.v - fresh.state.v).max() < 1e-7 * scale
    assert np.array_equal(kept.ws.audit, fresh.ws.audit)


def test_by_default_a_restored_pile_continues_bit_for_bit(pyramid20):
    """Without kept factors nothing but the State carries over from step to step."""
    model, start = pyramid20
    whole, _ = run(model, start, 20, False)
    half, _ = run(model, start, 10, False)
    rest, _ = run(model, half.state.copy(), 10, False)
    assert whole.state.q.tobytes() == rest.state.q.tobytes()
    assert whole.state.v.tobytes() == rest.state.v.tobytes()
