"""A model whose step cannot fit in memory is refused before anything is allocated, with the
sizes that make it so and what to change (state.check_workspace)."""
import pickle

import numpy as np
import pytest

import planarsim as ps
from planarsim import state as state_module


def columns(n_columns, n_rows):
    """Columns of 0.2 m boxes (100 kg/m^2), every pair of which may touch."""
    b = ps.ModelBuilder(dt=1e-3)
    for c in range(n_columns):
        for r in range(n_rows):
            b.add_body(f"box{c}_{r}", pos=(0.5 * c, 0.1 + 0.2 * r),
                       shapes=[("box", (0.0, 0.0), 0.2, 0.2)], density=100.0)
    return b.compile()


def test_the_dense_matrices_counted_are_the_ones_allocated():
    model = columns(2, 3)
    ws = ps.Simulator(model).ws
    allocated = sum(getattr(ws, f).nbytes for f in ("A", "lcp_B", "lcp_G", "lcp_S", "lcp_M", "lcp_T"))
    assert state_module.dense_workspace_bytes(model) == allocated


def test_a_model_too_large_for_the_machine_is_refused_before_allocating(monkeypatch):
    """Ten columns of ten boxes: 4,950 pairs of shapes, 10,300 contact slots, about 50 GiB
    of dense matrices. On a machine said to have 1 GiB the Simulator refuses it with a
    WorkspaceTooLarge (a MemoryError) naming the memory, the slots and the pairs."""
    import planarsim.trajectory as trajectory
    monkeypatch.setattr(trajectory, "machine_memory", lambda: 2 ** 30)
    model = columns(10, 10)
    with pytest.raises(ps.WorkspaceTooLarge) as err:
        ps.Simulator(model)
    text = str(err.value)
    assert "GiB" in text and "10,300 contact slots" in text and "4,950 pairs" in text
    assert "collide=False" in text
    assert err.value.nbytes == state_module.dense_workspace_bytes(model) > 2 ** 30
    assert isinstance(err.value, MemoryError)
    again = pickle.loads(pickle.dumps(err.value))
    assert again.nbytes == err.value.nbytes and str(again) == text


def test_a_model_that_fits_is_not_refused(monkeypatch):
    import planarsim.trajectory as trajectory
    model = columns(2, 3)
    monkeypatch.setattr(trajectory, "machine_memory", lambda: state_module.dense_workspace_bytes(model))
    sim = ps.Simulator(model)
    sim.steps(5)
    assert np.all(np.isfinite(sim.state.q))
