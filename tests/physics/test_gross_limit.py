"""A step that cannot hold a joint or a contact stops the run at once, naming it and what to
change (StepOptions.gross_limit); below the limit the audit counts and the run goes on."""
import numpy as np
import pytest

import planarsim as ps
from planarsim.compiled import audit_counts


def stiff_scene(seed=13):
    """The stress corpus's stiff_motors case `seed`: a chain of boxes on the ground with a
    motor of 100-1000 N m at every pin, driven bang-bang at its limit at dt = 20 ms (its
    first step tears a pin open by 0.11 m: run with turn_limit 0, the check that would stop
    it before its first step, jump_limit 0, which would stop it where a link is thrown
    1.98 m in that step, farther than its velocities explain, and max_substeps 1: taken in
    sub-steps, as by default, its links' turns are resolved and no pin opens); returns
    (model, start state, commands)."""
    from benchmarks.contact_stress import build, commands
    model, ground, q0, v0 = build("stiff_motors", seed)
    return model, ps.make_state(model, q0, v0), commands("stiff_motors", seed, model, 100)


def test_a_pin_torn_open_by_stiff_motors_stops_the_run_naming_it():
    model, start, u = stiff_scene()
    sim = ps.Simulator(model, ps.make_options(turn_limit=0.0, jump_limit=0.0, max_substeps=1),
                       state=start)
    with pytest.raises(ps.SimulationDiverged) as err:
        for k in range(len(u)):
            sim.step(u[k])
    text = str(err.value)
    assert "pin '" in text and "is open by" in text
    assert "smaller dt" in text and "gross_limit" in text
    assert err.value.field == "pin_gap" and err.value.value > 1e-6


def test_without_a_gross_limit_the_audit_counts_it_and_the_run_goes_on():
    model, start, u = stiff_scene()
    sim = ps.Simulator(model, ps.make_options(gross_limit=0.0, energy_limit=0.0, turn_limit=0.0,
                                                jump_limit=0.0, max_substeps=1),
                       state=start)
    for k in range(len(u)):
        sim.step(u[k])
    assert audit_counts(sim.ws)["pin_gap"] > 0


def stiff_chain(dt, torque):
    """Three links (0.3 m, 0.2 kg) hanging from a world pin, a motor at every pin."""
    b = ps.ModelBuilder(dt=dt)
    prev = None
    for i in range(3):
        b.add_body(f"link{i}", 0.2, 0.2 * 0.3 ** 2 / 12, pos=(0.15 + 0.3 * i, 1.0))
        b.add_pin(f"pin{i}", prev, f"link{i}", anchor_world=(0.3 * i, 1.0))
        b.add_pin_motor(f"motor{i}", f"pin{i}", limit=(-torque, torque))
        prev = f"link{i}"
    return b.compile()


def test_a_gentle_chain_is_not_stopped():
    """The same chain with 1 N m motors at dt = 1 ms: every pin held, nothing raised."""
    sim = ps.Simulator(stiff_chain(dt=1e-3, torque=1.0))
    for k in range(500):
        sim.step(np.array([1.0, -1.0, 1.0]) * (1.0 if k % 2 == 0 else -1.0))
    assert audit_counts(sim.ws)["pin_gap"] == 0
