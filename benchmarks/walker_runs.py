"""Walker benchmarks: every registered walker (walkers.WALKERS) walking, and batch throughput.

Walkers: each walker's uniform entry point ``simulate(seconds, gait=...)`` (gait "walk" when
the walker has one, else its first gait), i.e. its compiled rollout (physics + controller +
recording every 10 steps) plus building the model and assembling the Trajectory, which is
what a user's run costs. One short call first (compile or cache load, timed), then `repeats`
runs from the same start; steps/s = simulated steps / wall time (median and min-max),
real-time factor = simulated seconds / wall second; `fell` from the walker's summary;
overhead = wall time of a 10-step walk (model build, first steps, Trajectory), included in the
figures. A walker that raises is reported with its error and the others go on.

Batch: walkers.batch.simulate_batch of `jobs` Simple Biped walks (target speeds spread over
0.8-1.2 m/s) on 1 and on 2 worker threads (the compiled rollouts release the GIL); throughput
= simulated steps of all jobs / wall time, median (min-max) of `repeats` batches after a
warm-up batch; cores busy = CPU time of this process / wall time (2.0 when both threads really
run at once: below that, the GIL or other processes on the machine hold them back).
"""
from __future__ import annotations

import statistics
import time

import walkers

#: the steps/s targets of walkers (one core)
WALKER_TARGETS = {"simple-biped": 2e6, "ranger": 5e5, "simbicon": 3e5, "quadruped": 3e5}


def _gait(module):
    return "walk" if "walk" in module.GAITS else module.GAITS[0]


def _fell(summary) -> bool:
    if "fell" in summary:
        return bool(summary["fell"])
    return bool(summary.get("falls", 0))


def measure_walker(name, seconds=60.0, repeats=5):
    """Figures of walker `name` walking `seconds` [s] (see module doc)."""
    module = walkers.load(name)
    gait = _gait(module)
    t0 = time.perf_counter()
    module.simulate(0.01, gait=gait)
    first = time.perf_counter() - t0
    fixed = []
    for _ in range(3):  # warm cost of a 10-step walk: build, first steps, Trajectory
        t0 = time.perf_counter()
        module.simulate(0.01, gait=gait)
        fixed.append(time.perf_counter() - t0)
    walls, steps, summary = [], 0, {}
    for _ in range(repeats):
        t0 = time.perf_counter()
        traj, summary, model = module.simulate(seconds, gait=gait)
        walls.append(time.perf_counter() - t0)
        simulated = float(traj.t[-1]) if len(traj.t) else 0.0
        steps = int(round(simulated / model.dt))
    med = statistics.median(walls)
    return dict(scene=f"walker_{name}", engine="planarsim", walker=name, gait=gait, seconds=seconds,
                first_call_s=first, overhead_s=statistics.median(fixed), steps=steps, steps_per_s=steps / med,
                steps_per_s_min=steps / max(walls), steps_per_s_max=steps / min(walls), rtf=steps * model.dt / med, fell=_fell(summary),
                distance_m=float(summary.get("distance", float("nan"))))


_BURN = ("import time\nt0 = time.perf_counter()\nx = 0\nfor i in range(4_000_000):\n    x += i\n"
         "print(time.perf_counter() - t0)")


def machine_parallel_capacity(n=2):
    """Control for the batch figure: wall time of a fixed pure-Python loop in one process
    alone, then in `n` independent processes at once; returns n * t_alone / t_slowest (n when
    the machine gives this run n free cores; about 1 when other load or an oversubscribed
    virtual machine leaves one)."""
    import subprocess
    import sys

    def start():
        return subprocess.Popen([sys.executable, "-c", _BURN], stdout=subprocess.PIPE, text=True)
    alone = float(start().communicate()[0])
    procs = [start() for _ in range(n)]
    together = max(float(p.communicate()[0]) for p in procs)
    return n * alone / together


def measure_batch(jobs=64, seconds=10.0, repeats=3, workers=(1, 2), walker="simple-biped"):
    """Throughput of a batch of `jobs` walks on each worker count; None if planarsim.batch is
    missing."""
    try:
        from walkers import batch
    except ImportError:
        return None
    speeds = [0.8 + 0.4 * i / max(1, jobs - 1) for i in range(jobs)]
    job_list = [{"gait": "walk", "speed": s} for s in speeds]
    batch.simulate_batch(walker, job_list[:2], 0.05, workers=1)  # warm-up (cache load)
    capacity = machine_parallel_capacity(max(workers))
    # repeats interleave the worker counts (1, 2, 1, 2, ...): on a shared machine whose speed
    # drifts over seconds, each count then sees the same conditions
    rates = {w: [] for w in workers}
    cores = {w: [] for w in workers}
    steps = {w: 0 for w in workers}
    outs = {w: [] for w in workers}
    for _ in range(repeats):
        for w in workers:
            t0, c0 = time.perf_counter(), time.process_time()
            out = batch.simulate_batch(walker, job_list, seconds, workers=w)
            wall = time.perf_counter() - t0
            cores[w].append((time.process_time() - c0) / wall)
            steps[w] = sum(int(round(float(traj.t[-1]) / model.dt)) for traj, _, model in out)
            rates[w].append(steps[w] / wall)
            outs[w] = out
    rows = []
    for w in workers:
        rows.append(dict(scene="batch", engine="planarsim", walker=walker, jobs=jobs, seconds=seconds,
                         machine_capacity=capacity,
                         workers=w, steps=steps[w], steps_per_s=statistics.median(rates[w]),
                         steps_per_s_min=min(rates[w]), steps_per_s_max=max(rates[w]),
                         cores_busy=statistics.median(cores[w]),
                         falls=sum(_fell(s) for _, s, _ in outs[w])))
    return rows
