"""Batches of rollouts on every core.

The compiled kernels release the GIL (``nogil=True``), so a plain thread pool runs independent
rollouts truly in parallel: each thread calls a compiled rollout on its own State, Workspace and
controller memory, nothing is shared, and the results are bit-for-bit those of running the same
rollouts one after another. Threads (rather than processes or numba's ``prange``) keep the numba
cache, the walkers' compiled controllers and Python objects (Trajectory, summaries) as they are,
and cost nothing to start.

>>> import planarsim as ps
>>> sims = [ps.Simulator(model) for _ in range(64)]            # doctest: +SKIP
>>> ps.batch.steps_batch(sims, 10_000)                           # doctest: +SKIP
>>> # many runs of a registered walker: walkers.batch.simulate_batch
"""
from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from typing import Callable, Sequence


def default_workers() -> int:
    """Worker threads by default: the cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover (not Linux)
        return max(1, os.cpu_count() or 1)


def _check_workers(workers):
    if workers is None:
        return default_workers()
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ValueError(f"workers={workers!r} must be a positive integer (threads)")
    return workers


def run_parallel(tasks: Sequence[Callable[[], object]], workers: int | None = None) -> list:
    """Call every zero-argument callable in `tasks` on `workers` threads (default: all cores);
    return their results in task order. The first exception raised by a task is re-raised
    (after the running tasks finish).

    Each task must own its data (its own Simulator or walker); sharing one between tasks is a
    race. The first task runs alone first, so a cold numba cache compiles once, not per thread.
    """
    tasks = list(tasks)
    for i, task in enumerate(tasks):
        if not callable(task):
            raise TypeError(f"task {i} is {type(task).__name__}, not a callable")
    if not tasks:
        return []
    workers = _check_workers(workers)
    first = tasks[0]()
    if workers == 1 or len(tasks) == 1:
        return [first] + [task() for task in tasks[1:]]
    with ThreadPoolExecutor(max_workers=workers) as pool:
        rest = list(pool.map(lambda task: task(), tasks[1:]))
    return [first] + rest


def steps_batch(sims, n: int, u=None, workers: int | None = None) -> None:
    """Advance every Simulator in `sims` by n steps under commands u (one array for all, or a
    sequence with one per simulator), in parallel. Each must be a distinct Simulator."""
    sims = list(sims)
    if len({id(s) for s in sims}) != len(sims):
        raise ValueError("steps_batch needs distinct Simulator objects (one state each)")
    if u is None or (hasattr(u, "ndim") and u.ndim == 1):
        us = [u] * len(sims)
    else:
        us = list(u)
        if len(us) != len(sims):
            raise ValueError(f"{len(us)} command arrays for {len(sims)} simulators")
    run_parallel([(lambda s=s, uk=uk: s.steps(n, uk)) for s, uk in zip(sims, us)], workers)
