"""Many copies of one planarsim environment in this process, their physics advanced by one
compiled call per vector step: ``BatchedVectorEnv``, the environments' gymnasium
``vector_entry_point`` (``gymnasium.make_vec(id, num_envs=N)``).

A vector step has three phases. (1) Each copy that steps (not one being autoreset) is
marked, and the actions are taken as float64 (as each copy converts its own). (2) One
compiled call (``step_batch``) turns every such copy's action into its actuator commands
(core.set_commands, into its row of one (num_envs, n_act) array) and runs frame_skip physics
steps of it on its own Simulator's state (run_steps, the loop Simulator.steps runs), copy
after copy. (3) gymnasium's ``SyncVectorEnv.step`` steps the copies as it does for any
environment: each copy's ``step`` finds its physics already advanced (PlanarMujocoEnv.
do_simulation only reads qpos, qvel) and computes its observation, reward, termination and
info in Python; autoreset (NEXT_STEP), seeding and info batching are gymnasium's own. The
episodes are therefore bit for bit those of ``SyncVectorEnv`` over the same environment (a
test). ``step_batch`` is compiled once per number of copies (the handles are a tuple) and
bound, so a step pays no numba type dispatch.

Outside the fast compile mode (plain numba, NUMBA_DISABLE_JIT) phase (2) steps the copies
one after another from Python, with the same numbers. An action with a NaN or infinite
entry sends the step to SyncVectorEnv's own loop (whose copy raises, naming it); actions of
the wrong shape are a ValueError naming the shape wanted, before any copy steps. A copy
whose step runs out of solve storage (GUARD_ROOM) or diverges is finished or reported from
Python as Simulator.steps does; a divergence is raised after every copy's physics has run
(SyncVectorEnv raises it before the copies after it step).

>>> import gymnasium, planarsim.envs
>>> envs = gymnasium.make_vec("planarsim/Hopper-v0", num_envs=64)     # doctest: +SKIP
>>> obs, info = envs.reset(seed=0)                                    # doctest: +SKIP
>>> obs, rew, term, trunc, info = envs.step(envs.action_space.sample())  # doctest: +SKIP
"""
from __future__ import annotations

import functools
import numbers

import numpy as np
import gymnasium
from gymnasium.vector import AutoresetMode, SyncVectorEnv

from ..compile import MODE, FAST
from ..compiled import jit
from ..kernels.checks.guards import GUARD_ROOM
from ..link.step import bind, run_steps
from .core import set_commands


@jit
def step_batch(handles, active, ctrl, lo, hi, entry, act_id, gain, u, n, codes, done):
    """Every copy i with active[i] (handles: one Simulator's StepArgs handle per copy, all of
    one type): its commands u[i] from its action ctrl[i] (core.set_commands; lo, hi, entry,
    act_id, gain: the copies' common drives), then n physics steps, in copy order; the guard
    code and steps completed of each into codes[i], done[i] (0, n for a copy left alone).
    Returns how many copies' steps stopped (a nonzero code), or -1, with no copy stepped, if
    an active copy's action has a NaN or infinite entry."""
    for i in range(len(handles)):
        if active[i] and not set_commands(ctrl[i], lo, hi, entry, act_id, gain, u[i]):
            return -1
    stopped = 0
    for i in range(len(handles)):
        codes[i] = 0
        done[i] = n
        if active[i]:
            codes[i], done[i] = run_steps(handles[i], u[i], n)
            stopped += codes[i] != 0
    return stopped


def check_num_envs(num_envs) -> int:
    """num_envs as an int; a ValueError naming it unless it is a positive integer."""
    if isinstance(num_envs, bool) or not isinstance(num_envs, numbers.Integral) or num_envs < 1:
        raise ValueError(f"num_envs={num_envs!r} must be a positive integer (the number of "
                         f"copies of the environment)")
    return int(num_envs)


def check_action_shape(actions, shape, num_envs, env_id) -> np.ndarray:
    """actions as an array; a ValueError naming the shape the num_envs copies of env_id take
    (the action space's `shape`: num_envs rows of one copy's action) when it has another."""
    actions = np.asarray(actions)
    if actions.shape != tuple(shape):
        raise ValueError(f"actions have shape {actions.shape}; {num_envs} copies of {env_id} "
                         f"take shape {tuple(shape)}")
    return actions


class BatchedVectorEnv(SyncVectorEnv):
    """``num_envs`` copies of ``gymnasium.make(env_id, **kwargs)`` (each with gymnasium's
    usual wrappers: TimeLimit at max_episode_steps, order enforcing, the passive checker), a
    gymnasium SyncVectorEnv whose copies' physics for a step run in one compiled call (see
    the module's docstring). Autoreset: gymnasium's NEXT_STEP (a copy that ended is reset by
    the next step, which ignores its action and returns its first observation, reward 0)."""

    def __init__(self, env_id: str, num_envs: int = 1, max_episode_steps: int | None = None,
                 **kwargs):
        num_envs = check_num_envs(num_envs)
        if max_episode_steps is not None:
            kwargs["max_episode_steps"] = max_episode_steps
        super().__init__([functools.partial(gymnasium.make, env_id, **kwargs)] * num_envs,
                         autoreset_mode=AutoresetMode.NEXT_STEP)
        self.env_id = env_id
        self._copies = [env.unwrapped for env in self.envs]
        sims = [c.sim for c in self._copies]
        first = self._copies[0]
        n_act = sims[0].model.n_act
        # each copy's commands are its row of one array (the compiled loop reads rows)
        self._commands = np.zeros((num_envs, n_act))
        for c, row in zip(self._copies, self._commands):
            c._u = row
        self._actions = np.zeros(self.action_space.shape)
        self._active = np.zeros(num_envs, np.bool_)
        self._codes = np.zeros(num_envs, np.int64)
        self._done = np.zeros(num_envs, np.int64)
        self._frames = np.int64(first.frame_skip)
        self._batch_args = (tuple(s._args for s in sims), self._active, self._actions,
                            first._act_lo, first._act_hi, first._drive_entry, first._drive_id,
                            first._drive_gain, self._commands, self._frames, self._codes,
                            self._done)
        # compiled once for these arguments' types and called without numba's type dispatch
        self._step_batch = bind(step_batch, self._batch_args) if MODE == FAST else None
        self._was_reset = False

    def reset(self, *, seed=None, options=None):
        out = super().reset(seed=seed, options=options)
        self._was_reset = True
        return out

    def step(self, actions):
        """One step of every copy (gymnasium's SyncVectorEnv.step, after the copies' physics
        have advanced together). Actions of another shape than action_space's are a
        ValueError naming it, before any copy steps."""
        check_action_shape(actions, self.action_space.shape, self.num_envs, self.env_id)
        if self._was_reset and self._load_actions(actions):
            self._advance_physics()
        return super().step(actions)

    def _load_actions(self, actions) -> bool:
        """Phase 1: the actions as float64 (as each copy converts its own) and the copies
        that step (not being autoreset); False (nothing to run: the copies then step one by
        one and a copy's own step names what is wrong) for actions of the wrong kind, or if a
        copy's frame_skip was changed (set_attr)."""
        np.logical_not(self._autoreset_envs, out=self._active)
        try:
            actions = np.asarray(actions)
            if actions.shape != self._actions.shape or actions.dtype.kind not in "fiub":
                return False
            np.copyto(self._actions, actions, casting="unsafe")
        except (TypeError, ValueError):
            return False
        frames = self._frames
        return all([c.frame_skip == frames for c in self._copies])

    def _advance_physics(self):
        """Phase 2: every active copy's commands and frame_skip physics steps (one compiled
        call), then each told that its next do_simulation finds them done."""
        n = int(self._frames)
        if self._step_batch is not None:
            stopped = self._step_batch(*self._batch_args)
            if stopped < 0:
                return                     # a non-finite action: the copies' steps raise
        else:
            stopped = self._steps_one_by_one(n)
            if stopped < 0:
                return
        for c, active in zip(self._copies, self._active.tolist()):
            if active:
                c._advanced = n
        if stopped:
            for i in np.flatnonzero(self._codes):
                self._finish(i, int(self._codes[i]), int(self._done[i]), n)

    def _steps_one_by_one(self, n) -> int:
        """Phase 2 from Python (no fast compile mode): step_batch's work, copy by copy, with
        its return (Simulator.steps finishes or raises a stopped step itself: 0 stopped)."""
        active = np.flatnonzero(self._active)
        for i in active:
            if not self._copies[i].load_commands(self._actions[i]):
                return -1
        for i in active:
            self._copies[i].sim.steps(n, self._commands[i])
        return 0

    def _finish(self, i, code, done, n):
        """A copy whose batched steps stopped (guard code `code` after `done` of n steps): on
        GUARD_ROOM (the step undone) its storage grows and the rest run as Simulator.steps
        runs them; another code raises SimulationDiverged."""
        sim = self._copies[i].sim
        if code != GUARD_ROOM:
            for c in self._copies:
                c._advanced = None
            sim._raise(code)
        sim._grow()
        sim._run_steps(self._commands[i], n - done)


def make_batched(env_id: str, num_envs: int = 1, **kwargs) -> BatchedVectorEnv:
    """The vector entry point of planarsim's environment `env_id` (registry.py): gymnasium's
    make_vec calls it with num_envs, max_episode_steps and the environment's keywords."""
    return BatchedVectorEnv(env_id, num_envs=num_envs, **kwargs)
