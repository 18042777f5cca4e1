"""Many runs of a registered walker on all cores (planarsim.batch.run_parallel: threads over
the compiled rollouts, which release the GIL); bit-identical to running them one by one."""
from __future__ import annotations

from typing import Sequence

from planarsim.batch import run_parallel


def simulate_batch(walker: str, jobs: Sequence[dict], duration: float, workers: int | None = None) -> list:
    """Run the registered walker's ``simulate(duration, **job)`` for every job (keyword
    dictionaries: gait, seed, params, terrain, ...) in parallel; returns the list of
    (Trajectory, summary, Model) in job order."""
    from walkers import load

    module = load(walker)
    jobs = [dict(job) for job in jobs]
    return run_parallel([(lambda job=job: module.simulate(duration, **job)) for job in jobs], workers)
