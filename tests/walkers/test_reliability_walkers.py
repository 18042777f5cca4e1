"""Issue 12 across the shipped walkers: bit-identical runs (in process and in a fresh process
with a warm cache), and a soak run without divergence (marked slow)."""
import hashlib
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import walkers

SECONDS = 10.0  # 1e4 steps at dt = 1 ms


def frame_hashes(traj):
    """blake2b of the full recorded state at every step."""
    out = []
    for k in range(len(traj.t)):
        h = hashlib.blake2b(digest_size=16)
        for a in (traj.q[k], traj.v[k], traj.contact_mode[k], traj.contact_impulse[k], traj.act_u[k]):
            h.update(np.ascontiguousarray(a).tobytes())
        out.append(h.hexdigest())
    return out


def run_hashes(name, seconds=SECONDS):
    traj, summary, model = walkers.load(name).simulate(seconds, record_every=1)
    return frame_hashes(traj)


@pytest.mark.parametrize("name", sorted(walkers.WALKERS))
def test_walker_runs_are_bit_identical(name):
    a = run_hashes(name)
    b = run_hashes(name)
    assert len(a) >= 0.9 * SECONDS / 1e-3 or len(a) == len(b)
    assert a == b
    code = textwrap.dedent(f"""
        import hashlib
        from tests.walkers.test_reliability_walkers import run_hashes
        print(hashlib.blake2b("".join(run_hashes({name!r})).encode()).hexdigest())
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == hashlib.blake2b("".join(a).encode()).hexdigest()


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(walkers.WALKERS))
def test_walker_soak_ten_simulated_minutes(name):
    import resource
    mod = walkers.load(name)
    rss = []
    for chunk in range(5):
        traj, summary, model = mod.simulate(120.0, record_every=1000)
        assert np.all(np.isfinite(traj.q)) and np.all(np.isfinite(traj.v))
        rss.append(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
    # flat memory: the last chunks do not grow the peak resident set by more than 10 %
    assert rss[-1] <= rss[1] * 1.1
