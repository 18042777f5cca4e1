"""A pile at rest with contacts at their friction cone's edge keeps its modes from step to step.

State: the stress bench's pour50 (50 circles and capsules, 0.2 kg each, poured into a static U,
dt 1 ms) at step 2000, 1 s after the last shape landed, as the engine reached it before the
slip-reversal rule took the solve's rounding floor (modes.rule_breaks, VELOCITY_FLOOR). About
ten of its contacts need all the friction their cone allows. Under the old rule each step's
modes carried over broke a rule at such a contact, whichever way it had gone: held, its friction
came out 1e-8 to 2e-6 beyond the cone; sliding, its slip came out reversed at 1e-14 to 1e-11 m/s
against a tolerance of 1e-12 of the free motion (2e-14 m/s). The switching rounds went from one
to the other without an answer, and each step ended in a complementarity solve of the whole
pile: 0.9 of them a step, 430 pivots each, 25 ms a step (single steps 0.5 s) for 2.7 s until
the pile happened onto modes that held. Such reversals are the solve's rounding, by the
audit's own measure (a contact velocity under VELOCITY_FLOOR, 1e-8 m/s).
"""
import sys
from pathlib import Path

import numpy as np

import planarsim as ps
from planarsim.kernels.checks.audit import AUDIT_NAMES
from planarsim.kernels.info import INFO_LCP_SOLVES, INFO_SOLVES

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from benchmarks.stress_scenes import ALL_SCENES, build_model  # noqa: E402


def settled_pour():
    """A Simulator at the saved state of the pour (module docstring)."""
    model = build_model(ALL_SCENES["pour50"])
    data = np.load(Path(__file__).parents[1] / "data" / "pour50_step2000_state.npz")
    state = ps.make_state(model)
    for k in data.files:
        getattr(state, k)[...] = data[k]
    return ps.Simulator(model, state=state)


def test_a_pile_at_its_cone_edges_keeps_its_modes_without_complementarity_solves():
    """100 steps of the settled pile: its modes carried over hold (one linear solve a step);
    a complementarity solve is rare (the old rule: 39 of 40 steps); it stays at rest within
    the worlds' bound (no body moves 1e-9 m) and draws no audit."""
    sim = settled_pour()
    for _ in range(5):          # (the saved modes are the old rule's: they settle first)
        sim.step()
    start = sim.state.q.copy()
    steps = 100
    lcp_steps = 0
    one_solve = 0
    audits = np.zeros_like(sim.ws.audit)
    for _ in range(steps):
        sim.step()
        lcp_steps += sim.ws.info[INFO_LCP_SOLVES] > 0
        one_solve += sim.ws.info[INFO_SOLVES] == 1
        audits += sim.ws.audit
    assert lcp_steps <= 0.05 * steps, f"{lcp_steps} of {steps} steps needed the complementarity solve"
    assert one_solve >= 0.9 * steps, f"only {one_solve} of {steps} steps kept their modes"
    assert audits.sum() == 0, dict(zip(AUDIT_NAMES, audits))
    assert np.abs(sim.state.v).max() < 1e-9
    assert np.abs(sim.state.q[:, :2] - start[:, :2]).max() < 1e-9
