"""The step's solve storage follows the contacts a step touches with, not every pair of shapes
that might touch: a workspace holds room for the contacts a step is likely to have
(state.contact_capacity), a step that needs more is undone and taken again after the
Simulator grows it (GUARD_ROOM, state.grow_workspace), with the same bits as with room for
all; growth that cannot fit the machine is refused before allocating (WorkspaceTooLarge)."""
import pickle

import numpy as np
import pytest

import planarsim as ps
from planarsim import state as state_module
from planarsim.compiled import audit_counts, step_from_python


def columns(n_columns, n_rows, gap=0.5):
    """Columns of 0.2 m boxes (100 kg/m^2) `gap` [m] apart, every pair of which may touch."""
    b = ps.ModelBuilder(dt=1e-3)
    for c in range(n_columns):
        for r in range(n_rows):
            b.add_body(f"box{c}_{r}", pos=(gap * c, 0.1 + 0.2 * r),
                       shapes=[("box", (0.0, 0.0), 0.2, 0.2)], density=100.0)
    return b.compile()


def tumbling_boxes():
    """Twelve 0.2 m boxes dropped tilted onto each other: the contacts a step holds grow from
    none to dozens as they land."""
    b = ps.ModelBuilder(dt=1e-3)
    for k in range(12):
        b.add_body(f"box{k}", pos=(0.05 * ((k * 37) % 7 - 3), 0.3 + 0.3 * k),
                   angle=0.3 * ((k * 53) % 5 - 2), shapes=[("box", (0.0, 0.0), 0.2, 0.2)],
                   density=100.0)
    return b.compile()


def test_the_solve_storage_counted_is_the_storage_allocated():
    model = columns(2, 3)
    ws = ps.Simulator(model).ws
    names = state_module._solve_shapes(model, 1, 1, 1)
    allocated = sum(getattr(ws, f).nbytes for f in names)
    held, profile, lcp_rows = state_module.workspace_capacity(model, ws)
    rows = state_module.max_rows(model)
    assert held == model.n_contact      # a small model has room for every slot,
    assert profile == rows * (rows + 1) // 2     # their full envelope
    assert lcp_rows == rows             # and one complementarity problem of them all
    assert state_module.solve_bytes(model, held, profile, lcp_rows) == allocated


def test_ten_columns_of_ten_boxes_stand_in_a_workspace_sized_by_their_contacts():
    """4,950 pairs of shapes, 10,300 contact slots: room for all of them in dense matrices
    would be about 60 GiB (docs/shapes.md; 60.1 GiB). The workspace holds room for the contacts the boxes touch with,
    the envelope of their rows and complementarity problems of a few hundred rows, and the
    columns stand: no box moves more than 1e-9 m, every audit count 0."""
    model = columns(10, 10)
    rows = state_module.max_rows(model)
    assert 55 * 2 ** 30 < state_module.solve_bytes(model, model.n_contact, rows * (rows + 1) // 2, rows) < 65 * 2 ** 30
    assert model.n_contact == 10_300 and model.n_body * (model.n_body - 1) // 2 == 4_950
    sim = ps.Simulator(model)
    held = state_module.workspace_contacts(model, sim.ws)
    assert held < model.n_contact // 10
    q0 = sim.state.q.copy()
    sim.steps(20)
    assert np.max(np.abs(sim.state.q - q0)) <= 1e-9
    assert sum(audit_counts(sim.ws).values()) == 0
    assert state_module.solve_bytes(model, *state_module.workspace_capacity(model, sim.ws)) < 2 ** 27


@pytest.mark.parametrize("how", ["step", "steps", "run"])
def test_a_workspace_grown_step_by_step_gives_the_bits_of_one_with_room_for_all(monkeypatch, how):
    """A workspace made with room for one contact grows (doubling) each time a step needs
    more, the step undone and taken again from its start: the run is bit for bit the run of a
    workspace with room for every slot, through Simulator.step, steps and run alike."""
    model = tumbling_boxes()
    n = 700

    def frames(capacity):
        monkeypatch.setattr(state_module, "contact_capacity", capacity)
        sim = ps.Simulator(model)
        if how == "step":
            out = []
            for _ in range(n):
                sim.step()
                out.append(np.concatenate([sim.state.q.ravel(), sim.state.v.ravel()]))
            return np.array(out), sim
        if how == "steps":
            sim.steps(n)
            return np.concatenate([sim.state.q.ravel(), sim.state.v.ravel()]), sim
        traj = sim.run(n_steps=n)
        return np.concatenate([traj.q.ravel(), traj.v.ravel()]), sim

    full, sim_full = frames(lambda m: m.n_contact)
    grown, sim_grown = frames(lambda m: 1)
    assert state_module.workspace_contacts(model, sim_grown.ws) > 1        # it grew
    assert state_module.workspace_contacts(model, sim_grown.ws) < model.n_contact
    assert np.array_equal(full, grown)
    assert audit_counts(sim_full.ws) == audit_counts(sim_grown.ws)
    assert sim_full.state.step[0] == sim_grown.state.step[0] == n


def test_a_workspace_nothing_grows_stops_saying_so():
    """Stepped through step_from_python with a workspace of one's own that holds one
    contact, a step that needs more stops with a SimulationDiverged saying what to do, and the
    state is left at that step's start."""
    model = tumbling_boxes()
    st = ps.make_state(model)
    ws = state_module.make_workspace(model, contacts=1)
    opt = ps.StepOptions()
    u = np.zeros(model.n_act)
    code = 0
    for _ in range(2000):
        before = st.copy()
        code = step_from_python(model.arrays, st, ws, opt, u)
        if code != 0:
            break
    assert code != 0
    err = ps.errors.diverged(model, ws, code, opt.guard_limit)
    assert isinstance(err, ps.SimulationDiverged)
    assert "make_workspace(model, contacts=...)" in str(err)
    assert np.array_equal(st.q, before.q) and np.array_equal(st.v, before.v)
    assert st.step[0] == before.step[0]


def test_growth_beyond_the_machine_is_refused_before_allocating(monkeypatch):
    """On a machine said to have 1 GiB, room for one complementarity problem of every slot of
    ten columns of ten boxes (about 50 GiB) is refused with a WorkspaceTooLarge (a
    MemoryError) naming the memory, the contacts, the slots and the pairs, and what to
    change."""
    import planarsim.memory as memory
    monkeypatch.setattr(memory, "machine_memory", lambda: 2 ** 30)
    model = columns(10, 10)
    rows = state_module.max_rows(model)
    with pytest.raises(ps.WorkspaceTooLarge) as err:
        state_module.make_workspace(model, contacts=model.n_contact, lcp_rows=rows)
    text = str(err.value)
    assert "GiB" in text and "10,300 contact slots" in text and "4,950 pairs" in text
    assert "collide=False" in text
    profile = state_module.first_capacity(model, model.n_contact)[0]
    assert err.value.nbytes == state_module.solve_bytes(model, model.n_contact, profile, rows) > 2 ** 30
    assert isinstance(err.value, MemoryError)
    again = pickle.loads(pickle.dumps(err.value))
    assert again.nbytes == err.value.nbytes and str(again) == text
    ps.Simulator(model).steps(3)     # its own capacity fits that machine


def test_a_model_that_fits_is_not_refused(monkeypatch):
    import planarsim.memory as memory
    model = columns(2, 3)
    held = state_module.contact_capacity(model)
    need = state_module.solve_bytes(model, held, *state_module.first_capacity(model, held))
    monkeypatch.setattr(memory, "machine_memory", lambda: need)
    sim = ps.Simulator(model)
    sim.steps(5)
    assert np.all(np.isfinite(sim.state.q))
