"""Simulator: a thin Python wrapper over the compiled step.

>>> sim = Simulator(model)            # doctest: +SKIP
>>> sim.step(u)                       # one step under commands u (n_act,)
>>> traj = sim.run(2.0, u, record_every=10)   # 2 s, a frame every 10 steps

The state lives in ``sim.state`` (a State of numpy arrays, mutated in place); ``snapshot()`` and
``restore()`` copy it. A guard failure raises SimulationDiverged naming step, time, body and
field, with the state at the start of the failed step.
"""
from __future__ import annotations

import warnings

import numpy as np

from .checks import MAX_STEPS, callable_or_none, flag, to_float, whole
from .errors import diverged
from .integrator import check_integrator
from .model import Model, ModelArrays
from .options import StepOptions, check_options
from .speed_bound import resolve_speed_limit
from .start_check import (check_guard_limit, check_overlap, check_start, outside_limits,
                          overlapping)
from .kernels.checks.guards import GUARD_ROOM
from .state import (ArrayCopier, State, Workspace, array_pairs, check_state, forget_ground_queries,
                    forget_kept_factors, forget_pairs, grow_workspace, make_state, make_workspace,
                    refresh_chains, workspace_capacity)
from .trajectory import Trajectory, check_recording, make_recorder, record_state


def _link():
    """link/step.py, imported with the first Simulator (its compiled functions publish the
    step before their first call: from the numba cache, or its first-ever compile)."""
    from .link import step   # (imported here for start-up time: about 0.1 s of import planarsim)
    return step



class Simulator:
    """Steps one Model.

    Parameters
    ----------
    model : Model
    options : StepOptions (contact-mode strategy, position refinement, guards)
    state : State to start from (default: the model's build pose)
    allow_below_ground : start even where a contact is more than START_TOLERANCE (1 mm) below
        the ground (the first step then moves it to the surface); by default that start is a
        ModelError naming the contact, its body and its depth (planarsim.start_check)
    allow_overlap : start even where two shapes that may collide overlap by more than
        START_TOLERANCE (the first step then pushes them apart, and a warning names the pair and
        the depth); by default that start is a ModelError naming both shapes and the depth
    """

    def __init__(self, model: Model, options: StepOptions | None = None, state: State | None = None,
                 allow_below_ground: bool = False, allow_overlap: bool = False):
        if not isinstance(model, Model):
            raise TypeError(f"Simulator needs a Model from ModelBuilder.compile(), got {type(model).__name__}")
        flag("Simulator: allow_below_ground", allow_below_ground)
        flag("Simulator: allow_overlap", allow_overlap)
        self._model = model
        self._state = make_state(model)
        self._ws = make_workspace(model)
        if state is not None:
            self.state = state
        if not allow_below_ground:
            check_start(model, self._state)
        if not allow_overlap:
            check_overlap(model, self._state)
        else:
            count, said = overlapping(model, self._state)
            if count:
                warnings.warn(f"{said}; the first step pushes them apart (allow_overlap=True)",
                              stacklevel=2)
        count, said = outside_limits(model, self._state)
        if count:
            warnings.warn(f"{said}; the first step moves it onto its limit", stacklevel=2)
        self._u0 = np.zeros(model.n_act)
        self._recorded_entry = None
        self._args = None
        self.options = options if options is not None else StepOptions()

    @property
    def model(self) -> Model:
        return self._model

    @model.setter
    def model(self, value: Model) -> None:
        """Swap in a model with the same bodies, pins, contacts and actuators (new gravity,
        friction, actuator limits, ...); the state carries over, and a speed limit resolved
        from the model (StepOptions.speed_limit -1) is resolved again from the new one."""
        if not isinstance(value, Model):
            raise TypeError(f"model must be a Model, got {type(value).__name__}")
        old = self._model
        for name in ModelArrays._fields:
            a, b = getattr(old.arrays, name), getattr(value.arrays, name)
            if isinstance(a, np.ndarray) and np.shape(a) != np.shape(b):
                raise ValueError(f"model.arrays.{name} has shape {np.shape(b)}; this simulator's "
                                 f"model has {np.shape(a)} (build a new Simulator instead)")
        check_integrator(value, self._options)
        self._model = value
        # the ground queries' references belong to the old terrain and contact points
        forget_ground_queries(self._ws)
        forget_pairs(self._ws)
        forget_kept_factors(self._ws)
        refresh_chains(value, self._ws)
        if getattr(self, "_speed_from_model", False):
            # the bound follows the model it was resolved from (its gravity, its actuators)
            self._options = resolve_speed_limit(self._options._replace(speed_limit=-1.0),
                                                value, self._state.v, self._state.q)
        self._repack()
        self._recorded_entry = None

    @property
    def ws(self) -> Workspace:
        """The step's scratch arrays (contact points, impulses, rows of the last step)."""
        return self._ws

    @property
    def dt(self) -> float:
        """[s] the length of this simulator's steps: StepOptions.dt, or the model's dt when
        that is 0."""
        return float(self._options.dt) if self._options.dt > 0.0 else float(self.model.dt)

    @property
    def options(self) -> StepOptions:
        return self._options

    @options.setter
    def options(self, value: StepOptions) -> None:
        """Options for the steps to come; speed_limit -1 is resolved here from the model and
        the current state (planarsim.speed_bound; again when a state is put in)."""
        value = check_options(value)
        check_integrator(self._model, value)
        self._speed_from_model = value.speed_limit == -1.0
        check_guard_limit(self._model, self._state, value.guard_limit)
        self._options = resolve_speed_limit(value, self._model, self._state.v, self._state.q)
        forget_kept_factors(self._ws)
        self._new_options()

    def _new_options(self):
        """Point the step's table at self._options: its few slots rewritten, the rest of the
        table (the model's, the state's and the workspace's arrays) and the bound step kept."""
        if self._args is None:
            self._repack()
            return
        self._args.refill(_link().StepArgs(self._model.arrays, self._state, self._ws,
                                           self._options), "opt")

    def _repack(self):
        """The table that Simulator.step / steps hand to the compiled run_steps."""
        args = _link().StepArgs(self._model.arrays, self._state, self._ws, self._options)
        if self._args is None:
            self._args = _link().Handle(args)
        else:
            self._args.repack(args)
        self._steps_entry = None  # bound on the first step (_bind_steps)

    # the state is always this simulator's own arrays (of the types its compiled step expects)
    @property
    def state(self) -> State:
        """The current State (numpy arrays, mutated in place by stepping)."""
        return self._state

    @state.setter
    def state(self, value: State) -> None:
        """Copy `value` into the simulator's own state arrays; a state that does not fit the
        model (state.check_state: shapes, finite numbers, codes in range) raises ValueError."""
        if not isinstance(value, State):
            raise TypeError(f"state must be a planarsim State, got {type(value).__name__}")
        check_state(value, self._model)
        self._state.restore(value)
        forget_pairs(self._ws)
        forget_kept_factors(self._ws)
        if getattr(self, "_speed_from_model", False):
            self._options = resolve_speed_limit(self._options._replace(speed_limit=-1.0),
                                                self._model, self._state.v, self._state.q)
            self._new_options()

    # commands -------------------------------------------------------------------------------
    def _commands(self, u):
        if u is None:
            return self._u0
        if (type(u) is np.ndarray and u.dtype == np.float64 and u.shape == self._u0.shape
                and u.flags.c_contiguous):
            return u
        # contiguous float64: the bound kernels were compiled for exactly that layout
        try:
            u = np.ascontiguousarray(u, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError(f"commands u={u!r} must be numbers, shape ({self.model.n_act},) "
                             f"(one per actuator: {list(self.model.act_names)})") from None
        if u.shape != (self.model.n_act,):
            raise ValueError(f"commands u must have shape ({self.model.n_act},) "
                             f"(one per actuator: {list(self.model.act_names)}), got {u.shape}")
        return u

    def _raise(self, code):
        raise diverged(self.model, self._ws, code, self._options.guard_limit)

    # stepping -------------------------------------------------------------------------------
    def step(self, u=None) -> None:
        """One step of `dt` (the options' dt, else the model's) under actuator commands u
        (n_act,) [N or N m]."""
        self._run_steps(self._u0 if u is None else self._commands(u), 1)

    def _run_steps(self, u, n):
        """n compiled steps under commands u (checked); a step that ran out of room
        (GUARD_ROOM: undone) is taken again after the storage grows (_grow)."""
        entry = self._steps_entry or self._bind_steps()
        code, done = entry(self._args, u, n)
        while code == GUARD_ROOM:
            self._grow()
            n -= done
            code, done = self._bind_steps()(self._args, u, n)
        if code:
            self._raise(code)

    def _grow(self):
        """A step ran out of room for its rows (GUARD_ROOM: it was undone): the solve's
        storage grown (state.grow_workspace) for the step to be taken again."""
        self._ws = grow_workspace(self._model, self._ws)
        self._fresh_ws = None
        self._repack()

    def _bind_steps(self):
        """run_steps compiled (or loaded from the cache) for this simulator's handle, then
        called directly: numba's type dispatch is skipped (the handle's type never changes)."""
        self._steps_entry = _link().bind_steps(self._args)
        return self._steps_entry

    def _run_recorded(self, u, n, every, rec, k0):
        """link.step.run_recorded on this simulator (bound once: see _bind); a step that
        ran out of room (GUARD_ROOM) is taken again after the storage grows."""
        entry = self._recorded_entry
        if entry is None:
            entry = self._recorded_entry = self._bind(_link().run_recorded, (n, every, rec, k0))
        total = 0
        while True:
            code, done, k0 = entry(self.model.arrays, self._state, self._ws, self._options, u,
                                   n - total, every, rec, k0)
            total += done
            if code != GUARD_ROOM:
                return code, total, k0
            self._grow()

    def _bind(self, kernel, extra):
        """`kernel` compiled for this simulator's argument types (model, state, workspace,
        options, commands, *extra), to be called directly, without numba's type dispatch (the
        recorder's arrays would be typed again on every call); the simulator owns its arrays,
        so their types cannot change."""
        args = (self.model.arrays, self._state, self.ws, self.options, self._u0) + tuple(extra)
        return _link().bind(kernel, args)

    def steps(self, n: int, u=None) -> None:
        """n steps under constant commands, compiled as one loop; n a whole number from 0 to
        MAX_STEPS (planarsim.checks)."""
        n = _step_count("n", n)
        self._run_steps(self._commands(u), n)

    def run(self, duration: float | None = None, u=None, controller=None, n_steps: int | None = None,
            record_every: int = 1, control_every: int = 1, labels=None) -> Trajectory:
        """Run for `duration` [s] (or `n_steps`, at most MAX_STEPS in one call) and return the
        recorded Trajectory.

        u : constant commands (n_act,), or
        controller : callable ``controller(sim) -> u`` called every `control_every` steps (the
            Python path; compiled walkers have their own rollout kernels). Between calls the
            steps run compiled. Frame 0 is the state the run starts from (at sim.t), then a
            frame after every step whose count is a multiple of `record_every`.
        labels : optional callable ``labels(sim) -> dict of scalars`` sampled at each frame
            (only with a controller), stored in Trajectory.labels.
        """
        n = _count_steps(self.dt, duration, n_steps)
        callable_or_none("controller", controller, "a function controller(sim) -> u")
        callable_or_none("labels", labels, "a function labels(sim) -> dict of scalars")
        if controller is not None and u is not None:
            raise ValueError("give u (constant commands) or controller, not both: the "
                             "controller's commands would replace u at every call")
        if labels is not None and controller is None:
            raise ValueError("labels are sampled only with a controller (the Python path); "
                             "without one the steps run compiled and nothing samples them")
        every = whole("record_every", record_every)
        if every < 1 or whole("control_every", control_every) < 1:
            raise ValueError("record_every and control_every must be >= 1")
        # frame 0: the start; then the steps whose count is a multiple of `every`
        check_recording(self.model, n // every + 2,
                        f"run of {n:,} steps of {self.dt:g} s, a frame every {every} steps")
        _within_one_call(self.dt, duration, n_steps, n)
        rec = make_recorder(self.model, n // every + 2)
        record_state(rec, 0, self._state, self._ws)
        k = 1
        if controller is None:
            code, done, k = self._run_recorded(self._commands(u), n, every, rec, k)
            if code:
                self._raise(code)
        else:
            series = {} if labels is None else {key: np.full(len(rec.t), float(val))
                                                for key, val in labels(self).items()}
            done = 0
            chunk = int(control_every)
            while done < n:
                uk = controller(self)
                if uk is None:
                    raise TypeError(
                        f"controller {getattr(controller, '__name__', controller)!r} returned None "
                        f"at t={self.t:.6g} s; it must return the commands u, shape "
                        f"({self.model.n_act},), one per actuator {list(self.model.act_names)} "
                        "(did it forget `return`?)")
                uk = self._commands(uk)
                todo = min(chunk, n - done)
                k_before = k
                code, did, k = self._run_recorded(uk, todo, every, rec, k)
                if code:
                    self._raise(code)
                done += todo
                if labels is not None and k > k_before:
                    for key, val in labels(self).items():
                        series.setdefault(key, np.zeros(len(rec.t)))[k_before:k] = val
            labels_out = {key: arr[:k] for key, arr in series.items()}
            return Trajectory.from_recorder(self.model, rec, k, labels=labels_out,
                                            info={"dt": self.dt})
        return Trajectory.from_recorder(self.model, rec, k, info={"dt": self.dt})

    # state ----------------------------------------------------------------------------------
    @property
    def t(self) -> float:
        return float(self.state.time[0])

    def start_over(self, q=None, v=None) -> None:
        """Start again from poses q and velocities v (n_body, 3) [m, rad; m/s, rad/s] (default:
        the model's build pose and velocities) as a new Simulator would: time 0, no contact
        modes, impulses, warm starts or ground queries carried over; but keeping this one's
        compiled binding and options, so it takes microseconds (an environment's reset). Like
        the `state` setter it does not check the start against the ground; q and v must be
        finite (ValueError naming the body)."""
        st = make_state(self._model, q, v)
        for name, a in (("q", st.q), ("v", st.v)):
            bad = np.flatnonzero(~np.all(np.isfinite(a), axis=1))
            if bad.size:
                raise ValueError(f"start_over: {name} of body {self._model.body_names[bad[0]]!r} "
                                 f"({bad[0]}) is {a[bad[0]].tolist()}; it must be finite")
        fresh = getattr(self, "_fresh_ws", None)
        if fresh is None or fresh[0] is not self._ws:
            # a fresh workspace's arrays and this one's, paired once: a reset copies them all
            made = make_workspace(self._model, *workspace_capacity(self._model, self._ws))
            self._fresh_ws = fresh = (self._ws, ArrayCopier(array_pairs(self._ws, made)))
        fresh[1].copy()
        if getattr(self, "_speed_from_model", False):
            self.state = st          # the setter bounds the speeds again from this start
        else:                        # made by make_state: shapes and codes right already
            self._state.restore(st)
            forget_pairs(self._ws)

    def snapshot(self) -> State:
        return self.state.copy()

    def restore(self, snap: State) -> None:
        """Continue from `snap` (checked as the `state` setter checks it)."""
        self.state = snap

    def set_contact_enabled(self, contact, enabled: bool) -> None:
        """Turn contact `contact` (its name or index 0..n_contact-1) on or off."""
        if isinstance(contact, str):
            i = self.model.contact(contact)
        else:
            i = whole("contact", contact)
            if not 0 <= i < self.model.n_contact:
                raise IndexError(f"contact={contact} is not a contact of the model: it has "
                                 f"{self.model.n_contact}, indices 0..{self.model.n_contact - 1}")
        if not (isinstance(enabled, (bool, np.bool_)) or (isinstance(enabled, (int, np.integer))
                                                          and enabled in (0, 1))):
            # a string such as "off" is true: the contact would have been switched on
            raise TypeError(f"set_contact_enabled: enabled={enabled!r} must be True or False")
        self.state.contact_enabled[i] = 1 if enabled else 0

    def contact_impulses(self) -> np.ndarray:
        """(n_contact, 2) normal and tangential impulse of the last step [N s]."""
        return self.ws.contact_impulse.copy()


def _step_count(said, n) -> int:
    """n steps as an int: a whole number from 0 to MAX_STEPS, or a ValueError naming it."""
    return whole(said, n, 0, MAX_STEPS, why="steps in one call; take more in several calls")


def _count_steps(dt, duration, n_steps):
    if (duration is None) == (n_steps is None):
        raise ValueError("give exactly one of duration [s] or n_steps")
    if n_steps is not None:
        n = whole("n_steps", n_steps, 0)
    else:
        seconds = to_float(duration)
        if seconds is None:
            raise ValueError(f"duration={duration!r} must be a number of seconds")
        duration = seconds
        if not np.isfinite(duration) or duration < 0:
            raise ValueError(f"duration={duration} must be finite and >= 0 seconds")
        n = int(round(duration / dt))
        if n == 0 and duration > 0:
            raise ValueError(f"duration={duration:g} s is less than half a step (dt={dt:g} s): "
                             "the run would take no step")
    return n


def _within_one_call(dt, duration, n_steps, n) -> None:
    """A ValueError naming n_steps, or duration [s] and dt [s], where a run of n steps would
    take more than MAX_STEPS (checked after its recording: one that cannot fit in memory is
    named as such)."""
    if n_steps is not None:
        _step_count("n_steps", n_steps)
    elif n > MAX_STEPS:
        raise ValueError(f"duration={duration:g} s at dt={dt:g} s is {n:,} steps, more than "
                         f"{MAX_STEPS:,} in one call; run it in several calls")
