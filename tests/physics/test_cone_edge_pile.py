"""Contacts at their friction cone's edge in a pour: a pile at rest keeps its modes from step to
step, and a landing pile's switching rounds switch only the contacts that break a rule.

The settled pile's state: the stress bench's pour50 (50 circles and capsules, 0.2 kg each, poured into a static U,
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

The landing pile's states: the same pour at steps 346 and 419, while shapes still land, where
the step's switching rounds (step.switch_rounds) ended in the complementarity solve of the
whole pile when they switched every contact by the rules' bare signs. Two contacts at their
cones' edges took turns: one held beyond its cone was set sliding, and at the next round the
other, now sliding with its slip reversed by rounding only (no rule broken by the check's
tolerances), was stuck again, beyond its cone once more. The rounds now switch the contacts
that break a rule by the check's own tolerances (modes.switch_broken) and find the modes in
linear solves.
"""
import sys
from pathlib import Path

import numpy as np
import pytest

import planarsim as ps
from planarsim.kernels.checks.audit import AUDIT_NAMES
from planarsim.kernels.info import INFO_LCP_SOLVES, INFO_SOLVES

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from benchmarks.stress_scenes import ALL_SCENES, build_model  # noqa: E402


def pour_at(step):
    """A Simulator at the saved state of the pour at `step` (module docstring)."""
    model = build_model(ALL_SCENES["pour50"])
    data = np.load(Path(__file__).parents[1] / "data" / f"pour50_step{step}_state.npz")
    state = ps.make_state(model)
    for k in data.files:
        getattr(state, k)[...] = data[k]
    return ps.Simulator(model, state=state)


def test_a_pile_at_its_cone_edges_keeps_its_modes_without_complementarity_solves():
    """100 steps of the settled pile: its modes carried over hold (one linear solve a step);
    a complementarity solve is rare (the old rule: 39 of 40 steps); it stays at rest within
    the worlds' bound (no body moves 1e-9 m) and draws no audit."""
    sim = pour_at(2000)
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


@pytest.mark.parametrize("step", [346, 419])
def test_switching_rounds_of_a_landing_pile_switch_only_rule_breakers(step):
    """From each saved landing state (module docstring) the step finds its modes by linear
    solves (no complementarity solve; before: one of hundreds of pivots), and its answer
    draws no audit."""
    sim = pour_at(step)
    sim.step()
    assert sim.ws.info[INFO_LCP_SOLVES] == 0, f"{sim.ws.info[INFO_SOLVES]} solves, then the LCP"
    assert sim.ws.audit.sum() == 0, dict(zip(AUDIT_NAMES, sim.ws.audit))
