"""The folded four-bar loops of the stress corpus (contact_stress.py's loop_inertia family)
against the folded-loop test's rule: no step may gain more than 1 % of its kinetic energy
(plus 1e-6 J) beyond symplectic Euler's own gravity term (step_gains; the test is
tests/physics/test_energy_audit.py).

    python benchmarks/folded_loops.py              # seeds 0-199
    python benchmarks/folded_loops.py 36 42 162    # these seeds
    python benchmarks/folded_loops.py --explain $(seq 0 999)   # and where each miss comes from

Prints, per seed missing the rule, its worst step (number, gain [J], kinetic energy [J]) and
the largest pin impulse of the run [N s]; then how many seeds miss it. --explain adds, per
miss, the worst step taken again: its gain split into the velocity stage's (integrated with
the solve's velocity, ws.v_solved) and the position correction's, KE at its start, KE(v*)
and KE of the solve's answer [J], whether the complementarity solve ran, the step's largest
pin impulse [N s] and its vertical momentum at start and end [kg m/s].
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import planarsim as ps  # noqa: E402
from benchmarks.contact_stress import MAX_STEPS, SECONDS, build  # noqa: E402

G = 9.81


def gravity_term(h, dp, mass):
    """The energy change [J] a step of h [s] owes gravity when the bodies' total vertical
    momentum changes by dp [kg m/s] (mass [kg] their total):

        max((h / 2) g dp, -dp^2 / (2 mass)).

    The first is symplectic Euler's exact change, dE = (h / 2) g dp, of a step without
    impulses (dp = -mass g h) and of one at rest on the ground (dp = 0): the same there. The
    second is a loop that lands within the step: rising at less than g h, its ground contacts
    take out part of one step of gravity's momentum and stop it, exactly as if it rose and
    fell back within the step; it loses its kinetic energy, at least its centre of mass's
    dp^2 / (2 mass), while (h / 2) g dp reads the momentum its contacts took as gravity's
    and calls up to mass (g h)^2 / 8 a gain (tests/physics/test_energy_audit.py shows it on
    a ball, exactly)."""
    return np.maximum(0.5 * h * G * dp, -dp * dp / (2.0 * mass))


def step_gains(model, q, v):
    """Each step's energy change beyond its gravity term (gravity_term) [J] over frames q, v,
    and each step's kinetic energy at its start [J]."""
    a = model.arrays
    kinetic = 0.5 * np.sum(a.body_mass * (v[..., 0] ** 2 + v[..., 1] ** 2)
                           + a.body_inertia * v[..., 2] ** 2, axis=-1)
    energy = kinetic + G * np.sum(a.body_mass * q[..., 1], axis=-1)
    dp = np.diff(np.sum(a.body_mass * v[..., 1], axis=-1))
    return np.diff(energy) - gravity_term(model.dt, dp, float(np.sum(a.body_mass))), kinetic[:-1]


def worst_step(seed):
    """(step, gain [J], kinetic energy at its start [J], largest pin impulse [N s]) of the
    step of loop_inertia seed `seed` furthest beyond the rule, and whether the run raised."""
    model, _, q0, v0 = build("loop_inertia", seed)
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
    gains, kinetic = step_gains(model, np.array(q), np.array(v))
    k = int(np.argmax(gains - 0.01 * kinetic))
    return k + 1, float(gains[k]), float(kinetic[k]), pin, raised


def explain(seed, step):
    """One line: where the gain of loop_inertia seed `seed`'s step `step` comes from."""
    from planarsim.kernels.info import step_info
    model, _, q0, v0 = build("loop_inertia", seed)
    a = model.arrays
    h = model.dt
    sim = ps.Simulator(model, ps.make_options(), ps.make_state(model, q0, v0))
    for _ in range(step - 1):
        sim.step()
    q, v = sim.state.q.copy(), sim.state.v.copy()
    sim.step()
    ws = sim.ws

    def kinetic(vel):
        return 0.5 * float(np.sum(a.body_mass * (vel[:, 0] ** 2 + vel[:, 1] ** 2)
                                  + a.body_inertia * vel[:, 2] ** 2))

    def momentum(vel):
        return float(np.sum(a.body_mass * vel[:, 1]))

    def gain(q1, v1):
        lift = G * float(np.sum(a.body_mass * (q1[:, 1] - q[:, 1])))
        return float(kinetic(v1) - kinetic(v) + lift
                     - gravity_term(h, momentum(v1) - momentum(v), float(np.sum(a.body_mass))))

    total = gain(sim.state.q, sim.state.v)
    solve = gain(ws.q_solved, ws.v_solved)
    info = step_info(ws)
    return (f"    dt {h:g}: velocity stage {solve:.3g} J, correction {total - solve:.3g} J; KE start "
            f"{kinetic(v):.3g} v* {kinetic(ws.v_pred):.3g} answer {kinetic(ws.v_new):.3g} J; "
            f"{'complementarity' if info['lcp_solves'] else 'linear'} solve; pin impulse "
            f"{float(np.abs(sim.state.last_pin_impulse).max()):.3g} N s; p_y {momentum(v):.3g} -> "
            f"{momentum(sim.state.v):.3g}")


def main(argv):
    detail = "--explain" in argv
    argv = [s for s in argv if s != "--explain"]
    seeds = [int(s) for s in argv] or list(range(200))
    misses = 0
    for seed in seeds:
        step, gain, kinetic, pin, raised = worst_step(seed)
        if raised or gain > 0.01 * kinetic + 1e-6:
            misses += 1
            print(f"seed {seed:3d}: step {step} gains {gain:.3g} J at {kinetic:.3g} J of motion; "
                  f"largest pin impulse {pin:.3g} N s{'; raised' if raised else ''}")
            if detail:
                print(explain(seed, step))
    print(f"{misses} of {len(seeds)} seeds miss the folded-loop rule")
    return 1 if misses else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
