"""Across the shipped walkers: bit-identical runs (twice in process, and in a fresh
process with a cold or warm numba cache), snapshots, and a soak run (marked slow)."""
import hashlib
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import walkers
from planarsim.model import JOINT_FREE_BIT

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
    return run_with_hashes(name, seconds)[0]


def run_with_hashes(name, seconds=SECONDS):
    """(per-step hashes, Trajectory, summary) of a `seconds` run of walker `name`."""
    traj, summary, model = walkers.load(name).simulate(seconds, record_every=1)
    return frame_hashes(traj), traj, summary


# every shipped walker walks at 0.28 m/s or more on its default gait (quadruped 0.28 m/s,
# simplest walker 0.32, Ranger 0.51, ..., SIMBICON 1.26 over 10 s): 0.1 m/s is the least a
# walk that did not stall or fall covers
MIN_SPEED = 0.1   # [m/s]


def assert_walked(traj, summary, seconds, frame=1e-3):
    """The run covered the whole `seconds` (its last frame, recorded every `frame` [s], within
    a frame of the end; passive walkers' refined impacts end within a step of it), the walker
    did not fall, and it went forward at MIN_SPEED or more."""
    assert traj.t[-1] >= seconds - frame - 2e-3, traj.t[-1]
    assert not summary["fell"], summary
    assert summary["distance"] >= MIN_SPEED * seconds, summary["distance"]


@pytest.mark.parametrize("name", sorted(walkers.WALKERS))
def test_walker_runs_are_bit_identical(name):
    a, traj, summary = run_with_hashes(name)
    b = run_hashes(name)
    # what is compared is a walk: a walker that fell or stopped early would compare a fall
    assert_walked(traj, summary, SECONDS)
    assert a == b


def all_walker_digests():
    """{walker: blake2b over the per-step hashes of its 1e4-step run}."""
    return {name: hashlib.blake2b("".join(run_hashes(name)).encode()).hexdigest()
            for name in sorted(walkers.WALKERS)}


def test_fresh_process_cold_or_warm_cache_gives_the_same_bits(tmp_path):
    """Every shipped walker, 1e4 steps: the per-step state hashes of this process equal those of
    a fresh process. One of the two compiled the kernels from an empty numba cache: if this
    process compiled the step kernel itself (a fresh checkout, as in CI), the subprocess loads
    the cache it wrote (warm); if this process loaded it from the cache, the subprocess gets an
    empty cache directory and compiles everything (cold). Either way cold and warm are compared."""
    import json
    import os
    from walkers.simple_biped.rollout import rollout_simple_biped as rollout   # links step
    here = all_walker_digests()
    compiled_here = bool(rollout.stats.cache_misses)
    env = dict(os.environ)
    if not compiled_here:
        env["NUMBA_CACHE_DIR"] = str(tmp_path / "cold-cache")
    code = textwrap.dedent("""
        import json
        from walkers.simple_biped.rollout import rollout_simple_biped as rollout
        from tests.walkers.test_reliability_walkers import all_walker_digests
        digests = all_walker_digests()
        print(json.dumps({"digests": digests, "cache_misses": len(rollout.stats.cache_misses),
                          "cache_hits": len(rollout.stats.cache_hits)}))
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         env=env, timeout=1800)
    there = json.loads(out.stdout.strip().splitlines()[-1])
    # the subprocess really was the other kind: cold when this one was warm, and vice versa
    if compiled_here:
        assert there["cache_hits"] >= 1, there
    else:
        assert there["cache_misses"] >= 1, there
    assert there["digests"] == here


def joint_residuals(model, q):
    """Largest pin gap and rod length error [m] over the frames q (K, n_body, 3) (a free
    root's coordinates, MJCF slides and hinge, hold nothing: skipped)."""
    a = model.arrays

    def points(bodies, anchors):
        out = []
        for body, (lx, ly) in zip(bodies, anchors):
            if body < 0:
                out.append(np.broadcast_to([lx, ly], (q.shape[0], 2)))
            else:
                c, s = np.cos(q[:, body, 2]), np.sin(q[:, body, 2])
                out.append(np.stack([q[:, body, 0] + c * lx - s * ly, q[:, body, 1] + s * lx + c * ly], 1))
        return out
    worst = 0.0
    for j in range(model.n_pin):
        if a.pin_kind[j] & JOINT_FREE_BIT:     # a free body's coordinate: it holds nothing
            continue
        pa, pb = points(a.pin_body[j], a.pin_anchor[j])
        worst = max(worst, float(np.max(np.hypot(*(pb - pa).T))))
    for j in range(model.n_rod):
        pa, pb = points(a.rod_body[j], a.rod_anchor[j])
        worst = max(worst, float(np.max(np.abs(np.hypot(*(pb - pa).T) - a.rod_length[j]))))
    return worst


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(walkers.WALKERS))
def test_walker_soak_ten_simulated_minutes(name):
    """5 runs of 2 simulated minutes (1.2e6 steps in all): no divergence, no fall (each run
    walks the whole 2 minutes forward; measured 36-184 m, quadruped to SIMBICON), joints closed
    to the engine's bound (1e-9 m) at every recorded frame, and no growth of resident memory."""
    import resource
    mod = walkers.load(name)
    rss = []
    for chunk in range(5):
        traj, summary, model = mod.simulate(120.0, record_every=100)
        assert np.all(np.isfinite(traj.q)) and np.all(np.isfinite(traj.v))
        assert_walked(traj, summary, 120.0, frame=0.1)
        assert joint_residuals(model, traj.q) <= 1e-9
        rss.append(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
    # flat memory: the later chunks do not grow the peak resident set by more than 10 %
    assert rss[-1] <= rss[1] * 1.1


def test_walker_snapshot_with_controller_memory_continues_bit_for_bit(tmp_path):
    """Snapshot the Simple Biped mid-walk (engine state + controller memory) to disk, restore
    it into a fresh walker, and continue 1e3 steps: every recorded step hashes the same."""
    import planarsim as ps
    from walkers.simple_biped import Run
    ref = Run(record_every=1)
    ref.run(3.0)
    path = ps.save_snapshot(tmp_path / "walk.npz", ref.state, memory={"controller": ref.memory})
    expected = frame_hashes(ref.run(1.0))
    state, memory = ps.load_snapshot(path)
    again = Run(record_every=1)
    again.state.restore(state)
    again.memory[:] = memory["controller"]
    cont = again.run(1.0)
    assert np.array_equal(cont.q[0], state.q)   # a fresh walker's frame 0: the restored state
    assert frame_hashes(cont)[1:] == expected


def test_a_walker_divergence_names_the_body_and_field():
    """A huge push on the Simple Biped's hip: the walker's own rollout raises the engine's
    error naming step, body and field, with the state at the start of the failed step."""
    import planarsim as ps
    from walkers.simple_biped import Run
    w = Run(record_every=1)
    w.run(0.2)
    w.state.ext_force[0, 0] = 1e16     # N: the hip's velocity leaves the guard's bound
    with pytest.raises(ps.SimulationDiverged, match=r"simple-biped diverged at step 200 .*body 'hip' \(0\) vx=") as e:
        w.run(0.1)
    assert e.value.step == 200 and e.value.body == "hip" and e.value.field == "vx"
    assert e.value.last_state.step[0] == 200
