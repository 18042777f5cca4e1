"""A fast subset of the contact stress corpus (benchmarks/contact_stress.py), judged by the same
acceptance targets: energy never above E0 by more than the integrator's own oscillation bound,
pin gaps <= 1e-9 m and depths below the ground <= 1e-8 m at the end of every step, no
divergence, no audit violation. The subset is the script's --quick corpus (20 cases: every
family, seeds 0-4, one of each dt, the two strategies in turn), run exactly as the script
runs them: ``python benchmarks/contact_stress.py --quick`` prints the same cases as a table,
``python benchmarks/contact_stress.py`` the full corpus.
"""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from benchmarks.contact_stress import corpus, run_case  # noqa: E402


@pytest.mark.parametrize("family,seed,strategy", corpus(quick=True))
def test_contact_stress_case_meets_targets(family, seed, strategy):
    r = run_case(family, seed, strategy)
    assert not r["failed"], (
        f"{family}:{seed}:{strategy} (dt={r['dt']:g} s x {r['steps']}) misses {r['failed']}: "
        f"energy gained {r['gain']:.3g} J (bound {r['e_tol']:.3g} J), pin gap {r['pin']:.3g} m, "
        f"depth {r['depth']:.3g} m, audit {r['audit']}, diverged {r['diverged']!r}")
