"""Many copies of one planarsim environment on every core: ``PlanarVectorEnv``.

The copies are split into contiguous shares, one per worker: this process steps the first
share, a worker process each other one, every share as a gymnasium ``SyncVectorEnv``
(gymnasium's own autoreset and info batching); the physics and the map to
MuJoCo's (qpos, qvel) run in compiled code, the observation and reward in Python. A step
sends each worker its rows of the actions and gathers the rows back, so copy i is the same
environment, with the same seed, as the i-th copy of ``gymnasium.vector.SyncVectorEnv``:
the two give the same episodes bit for bit (a test).

Why processes, not one compiled call over a batch of states (numba ``prange``): an env step
is 2-50 us of compiled physics and 20-40 us of Python (actions, observation, reward,
termination, autoreset), so threads sharing one interpreter gain little; a process per core
runs both parts in parallel. ``planarsim bench --parts envs`` measures it.

>>> import planarsim.envs
>>> from planarsim.envs.vector import PlanarVectorEnv
>>> envs = PlanarVectorEnv("planarsim/Hopper-v0", num_envs=16, workers=2)   # doctest: +SKIP
>>> obs, info = envs.reset(seed=0)                                         # doctest: +SKIP
>>> obs, rew, term, trunc, info = envs.step(envs.action_space.sample())    # doctest: +SKIP
"""
from __future__ import annotations

import multiprocessing as mp
import os

import numpy as np
import gymnasium
from gymnasium.vector import AutoresetMode, SyncVectorEnv, VectorEnv
from gymnasium.vector.utils import batch_space

from .batched import check_action_shape
from .registry import register_all


def _make_sync(env_id, n, kwargs):
    register_all()   # the ids, in a fresh process
    return SyncVectorEnv([lambda: gymnasium.make(env_id, **kwargs) for _ in range(n)],
                         autoreset_mode=AutoresetMode.NEXT_STEP)


def _apply(envs, cmd, arg):
    """One command on a share of the copies: "step" (actions), "reset" ((seeds, options)) or
    "call" ((name, args, kwargs))."""
    if cmd == "step":
        return envs.step(arg)
    if cmd == "reset":
        return envs.reset(seed=arg[0], options=arg[1])
    return envs.call(arg[0], *arg[1], **arg[2])


def _worker(conn, env_id, n, kwargs):
    """A worker's loop: (command, argument) -> ("ok", result) | ("error", exception) until
    ("close", None)."""
    envs = _make_sync(env_id, n, kwargs)
    conn.send(("ready", None))
    try:
        while True:
            cmd, arg = conn.recv()
            if cmd not in ("step", "reset", "call"):
                break
            try:
                out = _apply(envs, cmd, arg)
            except Exception as e:      # the parent raises it
                conn.send(("error", e))
            else:
                conn.send(("ok", out))
    finally:
        envs.close()
        conn.close()


def _merge_infos(parts, sizes, num_envs):
    """Batch the workers' info dicts (gymnasium's layout: key -> array over copies, "_key" ->
    bool mask of the copies that have it, nested dicts alike) into one over all copies."""
    out = {}
    start = 0
    for info, n in zip(parts, sizes):
        _merge_into(out, info, start, n, num_envs)
        start += n
    return out


def _merge_into(out, info, start, n, num_envs):
    for key, value in info.items():
        if isinstance(value, dict):
            _merge_into(out.setdefault(key, {}), value, start, n, num_envs)
            continue
        value = np.asarray(value)
        if key not in out:
            out[key] = np.zeros((num_envs, *value.shape[1:]), dtype=value.dtype)
        out[key][start:start + n] = value


class PlanarVectorEnv(VectorEnv):
    """``num_envs`` copies of ``gymnasium.make(env_id, **kwargs)`` stepped on ``workers``
    processes, this one included (default: the cores this process may use; 1: this process
    alone).
    Autoreset: gymnasium's NEXT_STEP (a copy that ended is reset by the next step, which
    ignores its action and returns its first observation with reward 0).

    context: the multiprocessing start method ("fork" where the platform has it: the
    workers inherit the loaded compiled code; "spawn" or "forkserver" start afresh)."""

    def __init__(self, env_id: str, num_envs: int, workers: int | None = None,
                 context: str | None = None, **kwargs):
        if not isinstance(num_envs, int) or isinstance(num_envs, bool) or num_envs < 1:
            raise ValueError(f"num_envs={num_envs!r} must be a positive integer")
        if workers is None:
            workers = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
        if not isinstance(workers, int) or isinstance(workers, bool) or workers < 1:
            raise ValueError(f"workers={workers!r} must be a positive integer (processes)")
        workers = min(workers, num_envs)
        self.env_id, self.num_envs, self.workers = env_id, num_envs, workers
        self.sizes = [len(c) for c in np.array_split(np.arange(num_envs), workers)]
        probe = gymnasium.make(env_id, **kwargs)
        self.single_observation_space = probe.observation_space
        self.single_action_space = probe.action_space
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self.metadata = {**probe.metadata, "autoreset_mode": AutoresetMode.NEXT_STEP}
        self.render_mode = None
        self.spec = probe.spec
        probe.close()
        self._conns, self._procs = [], []
        ctx = mp.get_context(context or ("fork" if "fork" in mp.get_all_start_methods() else "spawn"))
        for n in self.sizes[1:]:
            parent, child = ctx.Pipe()
            p = ctx.Process(target=_worker, args=(child, env_id, n, kwargs), daemon=True)
            p.start()
            child.close()
            self._conns.append(parent)
            self._procs.append(p)
        self._local = _make_sync(env_id, self.sizes[0], kwargs)     # the first share, here
        for c in self._conns:
            c.recv()

    # the workers ------------------------------------------------------------------------------
    def _rows(self, x):
        """Split a batched array into the workers' contiguous rows."""
        edges = np.cumsum([0] + self.sizes)
        return [x[a:b] for a, b in zip(edges[:-1], edges[1:])]

    def _run(self, cmd, args):
        """Command `cmd` on every share (args: one per share); their results in share order.
        The workers run theirs while this process runs the first share's."""
        for c, arg in zip(self._conns, args[1:]):
            c.send((cmd, arg))
        try:
            local = _apply(self._local, cmd, args[0])
        finally:
            replies = [c.recv() for c in self._conns]     # the pipes stay in step
        for status, value in replies:
            if status == "error":
                raise value
        return [local] + [value for _, value in replies]

    def reset(self, *, seed=None, options=None):
        if seed is None:
            seeds = [None] * self.num_envs
        elif isinstance(seed, (int, np.integer)):
            seeds = [int(seed) + i for i in range(self.num_envs)]
        else:
            seeds = [None if s is None else int(s) for s in seed]
            if len(seeds) != self.num_envs:
                raise ValueError(f"reset: {len(seeds)} seeds for num_envs={self.num_envs}")
        parts = self._run("reset", [(list(s), options)
                                    for s in self._rows(np.array(seeds, dtype=object))])
        if len(parts) == 1:
            return parts[0]
        obs = np.concatenate([p[0] for p in parts])
        return obs, _merge_infos([p[1] for p in parts], self.sizes, self.num_envs)

    def step(self, actions):
        actions = check_action_shape(actions, self.action_space.shape, self.num_envs, self.env_id)
        bad = np.flatnonzero(~np.all(np.isfinite(actions.reshape(self.num_envs, -1)), axis=1))
        if bad.size:     # before any copy steps: all copies stay in step with each other
            raise ValueError(f"actions of copies {bad.tolist()} have NaN or infinite entries: "
                             f"{actions[bad[0]].tolist()}")
        parts = self._run("step", self._rows(actions))
        if len(parts) == 1:
            return parts[0]
        obs, rew, term, trunc = (np.concatenate([p[k] for p in parts]) for k in range(4))
        return obs, rew, term, trunc, _merge_infos([p[4] for p in parts], self.sizes, self.num_envs)

    def call(self, name, *args, **kwargs):
        """Call the method or read the attribute `name` of every copy (a tuple in copy order)."""
        parts = self._run("call", [(name, args, kwargs)] * self.workers)
        return tuple(x for part in parts for x in part)

    def close_extras(self, **kwargs):
        self._local.close()
        for c in self._conns:
            try:
                c.send(("close", None))
            except (BrokenPipeError, OSError):
                pass
        for p in self._procs:
            p.join(timeout=5)
            if p.is_alive():
                p.terminate()
        self._conns, self._procs = [], []
