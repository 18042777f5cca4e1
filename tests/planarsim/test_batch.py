"""Batches: parallel rollouts give exactly the serial results (threads over nogil kernels)."""
import numpy as np
import pytest

import planarsim as ps
from planarsim.batch import run_parallel, steps_batch
from walkers.batch import simulate_batch
from benchmarks.scenes import chain


def test_steps_batch_equals_serial_bit_for_bit():
    model = chain(4)
    rng = np.random.default_rng(3)
    starts = []
    for _ in range(6):
        st = ps.make_state(model)
        st.v[:, 2] = rng.uniform(-2, 2, model.n_body)   # different initial states
        starts.append(st)
    serial = [ps.Simulator(model, state=st) for st in starts]
    for sim in serial:
        sim.steps(3000)
    batch = [ps.Simulator(model, state=st) for st in starts]
    steps_batch(batch, 3000, workers=2)
    for a, b in zip(serial, batch):
        assert np.array_equal(a.state.q, b.state.q) and np.array_equal(a.state.v, b.state.v)
    # the batch really ran different rollouts
    assert not np.array_equal(batch[0].state.q, batch[1].state.q)


def test_walker_batch_equals_serial():
    jobs = [{"seed": s} for s in (0, 1, 2, 3)]
    serial = [simulate_batch("simple-biped", [job], 1.5, workers=1)[0] for job in jobs]
    parallel = simulate_batch("simple-biped", jobs, 1.5, workers=2)
    for (ta, sa, _), (tb, sb, _) in zip(serial, parallel):
        assert np.array_equal(ta.q, tb.q) and np.array_equal(ta.v, tb.v)
        assert sa["distance"] == sb["distance"] and sa["steps"] == sb["steps"]
    assert not np.array_equal(parallel[0][0].q, parallel[1][0].q)


def test_run_parallel_order_errors_and_bad_input():
    assert run_parallel([lambda i=i: i * i for i in range(10)], workers=2) == [i * i for i in range(10)]
    assert run_parallel([]) == []

    def boom():
        raise RuntimeError("task failed")
    with pytest.raises(RuntimeError, match="task failed"):
        run_parallel([lambda: 1, boom], workers=2)
    with pytest.raises(TypeError, match="task 1"):
        run_parallel([lambda: 1, 3])
    with pytest.raises(ValueError, match="workers=0"):
        run_parallel([lambda: 1], workers=0)
    sim = ps.Simulator(chain(2))
    with pytest.raises(ValueError, match="distinct"):
        steps_batch([sim, sim], 10)
    with pytest.raises(KeyError, match="unknown walker"):
        simulate_batch("no-such-walker", [{}], 1.0)
