"""The folded four-bar loops of the stress corpus (contact_stress.py's loop_inertia family)
against the folded-loop test's rule: no step may gain more than 1 % of its kinetic energy
(plus 1e-6 J) beyond symplectic Euler's own gravity term (tests/physics/test_energy_audit.py).

    python benchmarks/folded_loops.py              # seeds 0-199
    python benchmarks/folded_loops.py 36 42 162    # these seeds

Prints, per seed missing the rule, its worst step (number, gain [J], kinetic energy [J]) and
the largest pin impulse of the run [N s]; then how many seeds miss it.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import planarsim as ps  # noqa: E402
from benchmarks.contact_stress import MAX_STEPS, SECONDS, build  # noqa: E402

G = 9.81


def worst_step(seed):
    """(step, gain [J], kinetic energy at its start [J], largest pin impulse [N s]) of the
    step of loop_inertia seed `seed` furthest beyond the rule, and whether the run raised."""
    model, _, q0, v0 = build("loop_inertia", seed)
    a = model.arrays
    n = min(int(round(SECONDS["loop_inertia"] / model.dt)), MAX_STEPS)
    sim = ps.Simulator(model, ps.make_options(), ps.make_state(model, q0, v0))
    q, v, pin = [q0.copy()], [v0.copy()], 0.0
    raised = False
    try:
        for _ in range(n):
            sim.step()
            q.append(sim.state.q.copy())
            v.append(sim.state.v.copy())
            pin = max(pin, float(np.abs(sim.state.last_pin_impulse).max()))
    except ps.SimulationDiverged:
        raised = True
    q, v = np.array(q), np.array(v)
    kinetic = 0.5 * np.sum(a.body_mass * (v[..., 0] ** 2 + v[..., 1] ** 2)
                           + a.body_inertia * v[..., 2] ** 2, axis=-1)
    energy = kinetic + G * np.sum(a.body_mass * q[..., 1], axis=-1)
    py = np.sum(a.body_mass * v[..., 1], axis=-1)
    gains = np.diff(energy) - 0.5 * model.dt * G * np.diff(py)
    k = int(np.argmax(gains - 0.01 * kinetic[:-1]))
    return k + 1, float(gains[k]), float(kinetic[k]), pin, raised


def main(argv):
    seeds = [int(s) for s in argv] or list(range(200))
    misses = 0
    for seed in seeds:
        step, gain, kinetic, pin, raised = worst_step(seed)
        if raised or gain > 0.01 * kinetic + 1e-6:
            misses += 1
            print(f"seed {seed:3d}: step {step} gains {gain:.3g} J at {kinetic:.3g} J of motion; "
                  f"largest pin impulse {pin:.3g} N s{'; raised' if raised else ''}")
    print(f"{misses} of {len(seeds)} seeds miss the folded-loop rule")
    return 1 if misses else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
