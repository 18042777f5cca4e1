"""Scenes with many shapes touching at once: their complementarity problems are large and
degenerate (dominoes leaning on each other, corners on faces), where Lemke's path may end on a
ray or astray. Such a step keeps the answer of the nearest regularised problem (a compliance
of at most 1e-6 in scaled units, kernels/solver/mixed_lcp.py) rather than dropping the friction of
the island: the run ends with every audit count 0."""
import numpy as np

import planarsim as ps
from planarsim.compiled import audit_counts


def dominoes(seed, n=20):
    """n dominoes (1-3 cm x 10-30 cm, 50-200 g) on flat ground, 0.3-0.7 of their height
    apart, mu 0.2-0.8; the first tipped forward at 2-6 rad/s."""
    rng = np.random.default_rng(seed)
    b = ps.ModelBuilder(dt=float(rng.choice([1e-3, 2e-3])))
    w, h = rng.uniform(0.01, 0.03), rng.uniform(0.1, 0.3)
    gap = rng.uniform(0.3, 0.7) * h
    mu = rng.uniform(0.2, 0.8)
    for k in range(n):
        m = rng.uniform(0.05, 0.2)
        b.add_body(f"d{k}", m, m * (w * w + h * h) / 12, pos=(k * gap, h / 2),
                   omega=(-rng.uniform(2, 6) if k == 0 else 0.0),
                   shapes=[("box", (0.0, 0.0), w, h, {"mu": mu})])
    strategy = str(rng.choice(["alternating", "all"]))
    return ps.Simulator(b.compile(), ps.make_options(strategy))


def test_twenty_dominoes_topple_with_every_audit_count_zero():
    """Seed 5 (dt 2e-3, 3 s): at step 950 Lemke's path on the 53 rows of the leaning dominoes ends
    on a ray, and astray with diagonal terms 1e-12 to 1e-8; at 1e-6 it solves, and the
    answer's basis cannot be made exact. It was counted as a fallback and solved without
    friction. Now all 20 fall, each coming to rest on the next, and the audit is clean."""
    sim = dominoes(5)
    sim.steps(int(round(3.0 / sim.dt)))
    counts = audit_counts(sim.ws)
    assert all(v == 0 for v in counts.values()), counts
    assert np.all(np.abs(sim.state.q[:, 2]) > 0.3), sim.state.q[:, 2]
