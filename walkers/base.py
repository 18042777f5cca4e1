"""The walker contract: what a walker module registered in walkers.WALKERS offers, so that the
command line, tuning, batches, the viewer and the summary treat every walker alike
(tests/walkers/test_contract.py checks every shipped walker against it).

A walker module has
  NAME            its command-line name
  GAITS           its gait names; simulate's `gait` default is one of them
  GAIT_DOCS       {gait: what the walker does in it, one line}: every gait of GAITS
                  (planarsim list shows them)
  Params          its parameter dataclass (walkers.common.params.WalkerParams: every field with
                  unit, bounds and doc; TUNABLE names the fields tuning may vary)
  SUMMARY_EXTRAS  {raw summary key: (name with unit, meaning) or None}: its own numbers beyond
                  the common summary (walkers.common.summary)
  FEET            optional: groups of contact names that are one foot each (default: by name)
  Run             its run class, a WalkerRun (below)
  simulate(duration, gait=..., terrain=None, dt=1e-3, seed=0, params=None, record_every=10, ...)
                  -> (Trajectory, summary dict, Model): ``simulation(Run)``, a Run from the
                  start for duration [s]; the summary has at least `fell`, `audit` and `time`
                  (or `duration`) and otherwise only keys its SUMMARY_EXTRAS or
                  walkers.common.summary.REPLACED declare
  live(gait=..., terrain=None, ...)
                  optional: the interactive viewer's hook (planarsim.render.viewer.view_walker)
and, to be tunable, a sibling module `objective` (Params, DEFAULT_SETTINGS,
evaluate(params, settings) -> {"score": ...}).

A run (WalkerRun) holds the model, State, Workspace, StepOptions, parameters, controller table
and memory of one walker in the world; ``run(seconds)`` advances it with the walker's compiled
rollout and returns that chunk's Trajectory, so running a then b seconds ends bit for bit where
running a + b seconds does. A subclass supplies only what differs: it builds model, table and
memory in its __init__, names its LABELS (per-frame copies of memory slots LABEL_SLOTS,
walkers.common.slots.label_slots of its memory layout),
FELL_SLOT and ROLLOUT (its compiled rollout; advance() calls it, or a walker whose rollout takes
more overrides advance) and implements ``numbers`` (its raw summary numbers). A rollout records
through walkers.common.record.record_labelled.

An actuated walker's compiled controller is ``control(m, s, ws, tab, mem, u)``: model arrays,
State, Workspace, the walker's read-only table of parameters and constants (a NamedTuple of
arrays, or the float parameter array itself; Ranger's also carries the step log, a row per
heel strike, its controller writes), its float64 memory vector (read and written; the
numbers ``numbers`` takes from the controller come from it, so a snapshot of state and memory
restored into a fresh Run reports them as one run does) and the command vector u (written,
n_act). Its compiled rollout stops with planarsim.compiled's run
codes: RUN_OK, an engine failure (raised with check_run), or its own reasons from RUN_WALKER up
(RUN_FELL).
"""
from __future__ import annotations

import inspect
import math

import numpy as np

SIMULATE_KEYWORDS = ("gait", "terrain", "dt", "seed", "params", "record_every")
# the most steps one run takes: at the walkers' 2 to 20 microseconds a step, minutes; a
# duration at a tiny dt (1e-9 s) would otherwise run for practically ever
MAX_RUN_STEPS = 10 ** 8
REQUIRED = ("NAME", "GAITS", "Params", "SUMMARY_EXTRAS", "Run", "simulate")


# [s] the largest step an actuated walker takes: the walkers are built and tuned at 1e-3 s;
# larger steps lose their impacts and motors (at 0.02 s Ranger stops at once, the simplest
# walker takes 2 of its 4 steps in 5 s; at 0.05 s the Simple Biped falls, and at 0.2 s it is
# thrown 1 m up in 3 steps). The passive walkers, with no controller, take any step.
MAX_DT = 0.01


def check_controlled_dt(name: str, dt: float) -> None:
    """ValueError naming dt [s] where a walker with a controller would take steps of more
    than MAX_DT (called by WalkerRun, and by a walker whose controller is built before it)."""
    if dt > MAX_DT:
        raise ValueError(f"{name}: dt={dt:g} s is too large; use a step of at most "
                         f"{MAX_DT:g} s (1e-3 is usual): its controller is tuned at 1e-3 s, "
                         f"and at 0.02 s walkers already lose their impacts or stop")


class WalkerRun:
    """One walker in the world, run in chunks by its compiled rollout.

    Attributes: model, state (State), ws (Workspace), options (StepOptions), params (the
    walker's Params), tables (its controller table), memory (its controller memory), u
    (commands, n_act), record_every (steps between recorded frames; 0 records none), chunks
    (the Trajectory of every run() so far).
    """

    NAME = "walker"    # recorded in Trajectory.info["walker"] and named by engine errors
    LABELS = ()        # per-frame labels: the columns advance() writes into `lab`
    FELL_SLOT = None   # memory slot the rollout sets non-zero when the walker falls (required)
    # the compiled rollout advance() calls, as staticmethod(f) with f(m, s, ws, opt, tab, mem,
    # u, n, every, rec, lab, LABEL_SLOTS, k0) -> (run code, steps done, next frame); a walker
    # whose rollout takes more overrides advance()
    ROLLOUT = None
    LABEL_SLOTS = None  # int64 memory slots recorded per frame, one per LABELS name

    def __init__(self, model, params, tables, memory, *, state=None, ws=None, options=None,
                 record_every=10):
        import planarsim as ps
        from planarsim.options import check_options
        from planarsim.state import make_workspace
        if not (isinstance(record_every, (int, np.integer)) and record_every >= 0):
            raise ValueError(f"record_every={record_every!r} must be an integer >= 0 (steps between frames)")
        self.model = model
        self.params = params
        self.tables = tables
        self.memory = memory
        self.state = state if state is not None else ps.make_state(model)
        self.ws = ws if ws is not None else make_workspace(model)
        from planarsim.speed_bound import resolve_speed_limit
        self.options = resolve_speed_limit(ps.StepOptions() if options is None else check_options(options),
                                           model, self.state.v, self.state.q)
        if self.options.dt not in (0.0, model.dt):
            # the controllers integrate (work, effort, motor currents, ramps) with the model's dt
            raise ValueError(f"{self.NAME}: options.dt={self.options.dt} s differs from the model's "
                             f"dt={model.dt} s; build the walker with dt={self.options.dt} instead")
        if model.n_act > 0:
            check_controlled_dt(self.NAME, self.dt)
        self.u = np.zeros(model.n_act)
        self.record_every = int(record_every)
        self.chunks = []

    # what a walker supplies -----------------------------------------------------------------
    def advance(self, n: int, every: int, rec, lab):
        """Run the compiled rollout n steps, recording every `every`-th step into rec / lab
        from frame 0; return (run code, frames recorded)."""
        if self.ROLLOUT is None:
            raise NotImplementedError(f"{type(self).__name__} sets no ROLLOUT (or overrides advance)")
        code, done, k = self.ROLLOUT(self.model.arrays, self.state, self.ws, self.options, self.tables,
                                     self.memory, self.u, n, every, rec, lab, self.LABEL_SLOTS, 0)
        return code, k

    def numbers(self) -> dict:
        """The walker's raw summary numbers (its summary without `audit`)."""
        raise NotImplementedError

    def frames(self, n: int) -> int:
        """Recorder frames a chunk of n steps needs."""
        return n // self.record_every + 1 if self.record_every else 0

    def stopped(self, code: int) -> int:
        """The run code of a chunk, before engine failures are raised (a walker may take some
        of them as its own outcome)."""
        return code

    # the contract ---------------------------------------------------------------------------
    @property
    def dt(self) -> float:
        """The step length actually used [s]: options.dt, or the model's dt where it is 0."""
        return self.options.dt if self.options.dt else self.model.dt

    @property
    def time(self) -> float:
        """Simulated time [s]."""
        return float(self.state.time[0])

    @property
    def fell(self) -> bool:
        if self.FELL_SLOT is None:
            raise NotImplementedError(f"{type(self).__name__} sets no FELL_SLOT (or overrides fell)")
        return bool(self.memory[self.FELL_SLOT])

    def run(self, seconds: float):
        """Advance `seconds` [s] (rounded to whole steps; stops early on a fall) and return
        this chunk's Trajectory; the first chunk's frame 0 is the initial state. Engine
        failures raise (planarsim.compiled.check_run)."""
        from planarsim.compiled import check_run, make_recorder
        from planarsim.trajectory import Trajectory
        n, frames = self.check_memory(seconds)
        if not self.chunks:
            self.start_below_ground = self.contacts_below_ground()
        rec = make_recorder(self.model, frames)
        lab = np.zeros((frames, len(self.LABELS)))
        start = self.start_frame() if self.record_every and not self.chunks else None
        code, k = self.advance(n, max(self.record_every, 1), rec, lab)
        check_run(self.stopped(int(code)), self.model, self.ws, self.options, self.NAME)
        traj = Trajectory.from_recorder(self.model, rec, k,
                                        labels={name: lab[:k, j].copy() for j, name in enumerate(self.LABELS)},
                                        info={"dt": self.dt, "walker": self.NAME})
        if start is not None:
            traj = Trajectory.concatenate([start, traj])
        self.chunks.append(traj)
        return traj

    def check_memory(self, seconds: float, said: str | None = None, too_short: str = "",
                     too_long: str = "") -> tuple:
        """(steps, frames) that run(seconds) would take and record; ValueError for a bad
        `seconds`, planarsim.errors.RecordingTooLarge (a ValueError) for frames that cannot
        fit in the machine's memory, then run_steps' ValueError for a run of no step or too
        many (said, too_short, too_long: its words), before anything is allocated or run."""
        from planarsim.checks import to_float
        from planarsim.trajectory import check_recording
        x = to_float(seconds)
        if x is None:
            raise ValueError(f"seconds={seconds!r} must be a number of seconds")
        if not (math.isfinite(x) and x >= 0.0):
            raise ValueError(f"seconds={seconds!r} must be finite and >= 0")
        seconds = x
        # a walker that fell stays where it fell: its rollout would otherwise take one more step
        n = 0 if self.fell else int(round(seconds / self.dt))
        frames = self.frames(n)
        check_recording(self.model, frames,
                        f"{self.NAME}: run({seconds:g} s) at dt={self.dt:g} s, a frame every "
                        f"{self.record_every} steps", extra_columns=len(self.LABELS))
        if not self.fell:
            run_steps(seconds, self.dt, said or f"{self.NAME}: run({seconds:g} s)", too_short, too_long)
        return n, frames

    def start_frame(self):
        """A one-frame Trajectory of the walker as it stands now (the first chunk's frame 0:
        its initial state), labelled with its memory slots LABEL_SLOTS."""
        from planarsim.compiled import make_recorder
        from planarsim.trajectory import Trajectory, record_state
        rec = make_recorder(self.model, 1)
        record_state(rec, 0, self.state, self.ws)
        slots = self.LABEL_SLOTS if self.LABEL_SLOTS is not None else ()
        labels = {name: np.array([float(self.memory[slots[j]])]) for j, name in enumerate(self.LABELS)}
        return Trajectory.from_recorder(self.model, rec, 1, labels=labels,
                                        info={"dt": self.dt, "walker": self.NAME})

    def trajectory(self):
        """All chunks run so far, joined (empty ones left out)."""
        from planarsim.compiled import make_recorder
        from planarsim.trajectory import Trajectory
        full = [c for c in self.chunks if len(c)]
        if full:
            return Trajectory.concatenate(full)
        if self.chunks:
            return self.chunks[0]
        return Trajectory.from_recorder(self.model, make_recorder(self.model, 0), 0,
                                        info={"dt": self.dt, "walker": self.NAME})

    def contacts_below_ground(self) -> int:
        """How many contacts are more than planarsim.start_check.START_TOLERANCE (1 mm) below
        the ground now (at the start: a foot set flat on hills dips into them; the first
        step lifts it onto the surface). Each is reported once on stderr (a warning naming
        the deepest) and counted in the summary's audit as ``start_below_ground``."""
        import warnings

        from planarsim.start_check import below_ground
        count, said = below_ground(self.model, self.state, who=self.NAME)
        if count:
            warnings.warn(f"{said}; the first step moves it to the surface (counted as audit "
                          f"start_below_ground)", stacklevel=3)
        return count

    def summary(self) -> dict:
        """The walker's numbers (numbers()) and `audit`, the engine's audit counts plus
        ``start_below_ground`` (contacts that started more than 1 mm below the ground)."""
        from planarsim.compiled import audit_counts
        return {**self.numbers(), "audit": {**audit_counts(self.ws),
                                            "start_below_ground": getattr(self, "start_below_ground", 0)}}


def simulation(run_class):
    """The module-level ``simulate(duration, **keywords)`` of a walker: a `run_class` built with
    the keywords (its __init__'s, keyword-only here) runs `duration` [s] from its start; returns (Trajectory of
    the run, summary dict, Model). The Trajectory's info records the gait and seed."""
    init = inspect.signature(run_class.__init__)
    keywords = [prm.replace(kind=inspect.Parameter.KEYWORD_ONLY) for prm in list(init.parameters.values())[1:]]

    def simulate(duration, **kwargs):
        if kwargs.get("params") is not None:
            kwargs["params"] = _walker_params(run_class, kwargs["params"])
        bound = init.bind(None, **kwargs)
        bound.apply_defaults()
        run = run_class(**kwargs)
        run.run(duration)
        traj = run.trajectory()
        traj.info.update({k: bound.arguments[k] for k in ("gait", "seed") if k in bound.arguments})
        return traj, run.summary(), run.model

    duration = inspect.Parameter("duration", inspect.Parameter.POSITIONAL_OR_KEYWORD)
    simulate.__signature__ = inspect.Signature([duration] + keywords)
    simulate.__module__ = run_class.__module__
    simulate.__qualname__ = simulate.__name__ = "simulate"
    simulate.__doc__ = (f"Run {run_class.NAME} from its start for `duration` [s]; returns (Trajectory, "
                        f"summary dict, Model). Keywords: those of {run_class.__name__}.")
    return simulate


def _walker_params(run_class, params):
    """params as run_class's walker's Params: an instance as it is, a dict of some of its fields
    over the defaults; anything else (another walker's Params) a TypeError naming both."""
    import importlib
    from collections.abc import Mapping
    module = importlib.import_module(run_class.__module__)
    cls = getattr(module, "Params", None) or getattr(
        importlib.import_module(run_class.__module__.rsplit(".", 1)[0]), "Params", None)
    if cls is None or isinstance(params, cls):
        return params
    if isinstance(params, Mapping):
        unknown = sorted(set(params) - set(cls().as_dict()))
        if unknown:
            raise TypeError(f"params: {unknown} are not fields of {cls.__name__}")
        return cls(**{**cls().as_dict(), **params})
    raise TypeError(f"params must be a {cls.__name__} (or a dict of its fields), not "
                    f"{type(params).__name__}")


def terrain_of(terrain):
    """A Terrain from a Terrain, a spec string (planarsim.terrain.parse) or None (flat); a
    TypeError naming anything else (terrain=5 failed inside the walker's model builder)."""
    import planarsim as ps
    if isinstance(terrain, str):
        return ps.terrain.parse(terrain)
    if terrain is not None and not isinstance(terrain, ps.terrain.Terrain):
        raise TypeError(f"terrain={terrain!r} must be a planarsim.terrain.Terrain, a spec such "
                        "as 'slope:-3' or 'hills', or None (flat)")
    return terrain


def target_speed(name, speed, params=None) -> float:
    """A walker's commanded speed [m/s] as a float within the bounds of its params' `speed`
    field (the same a SimpleBipedParams(speed=...) keeps to; any finite speed without
    params); a ValueError naming the walker and the speed otherwise (a NaN speed stopped the
    run at its first step naming a leg actuator's command, a string failed in float(), the
    quadruped's 100 m/s ran silently)."""
    from planarsim.checks import finite_number
    lo, hi = -math.inf, math.inf
    if params is not None:
        lo, hi = params.bounds()[params.names().index("speed")]
    return finite_number(f"{name}: speed", speed, lo, hi, strict=False, unit=" m/s")


def run_steps(seconds: float, dt: float, said: str, too_short: str = "", too_long: str = "") -> int:
    """Steps a run of `seconds` [s] at `dt` [s] takes; a ValueError beginning with `said` (the
    run as the caller names it) where that is no step (less than half a step) or more than
    MAX_RUN_STEPS (naming dt and the steps), ending with too_short or too_long (advice)."""
    n = int(round(seconds / dt))
    if n == 0 and seconds > 0.0:
        raise ValueError(f"{said} is less than half a step (dt={dt:g} s): the run would take no "
                         f"step{too_short}")
    if n > MAX_RUN_STEPS:
        raise ValueError(f"{said} at dt={dt:g} s would take {n:,} steps, more than {MAX_RUN_STEPS:,} "
                         f"(a run that long would take practically forever){too_long}")
    return n


def start_rng(name, seed):
    """numpy's generator of a walker's start perturbation for `seed`, a whole number >= 0; a
    ValueError naming the walker and the seed otherwise (numpy said only "expected
    non-negative integer")."""
    if (isinstance(seed, (bool, np.bool_)) or not isinstance(seed, (int, np.integer))
            or seed < 0):
        raise ValueError(f"{name}: seed={seed!r} must be a whole number >= 0")
    return np.random.default_rng(seed)


def contract_problems(name: str, module) -> list:
    """What walker module `module` (registered as `name`) lacks of the contract; [] if nothing."""
    problems = [f"no {attr}" for attr in REQUIRED if not hasattr(module, attr)]
    if problems:
        return problems
    if module.NAME != name:
        problems.append(f"NAME is {module.NAME!r}, registered as {name!r}")
    sig = inspect.signature(module.simulate)
    missing = [k for k in SIMULATE_KEYWORDS if k not in sig.parameters]
    if missing:
        problems.append(f"simulate() lacks the keywords {missing}")
    elif sig.parameters["gait"].default not in module.GAITS:
        problems.append(f"simulate()'s default gait {sig.parameters['gait'].default!r} is not in GAITS")
    undocumented = [g for g in module.GAITS if not getattr(module, "GAIT_DOCS", {}).get(g)]
    if undocumented:
        problems.append(f"GAIT_DOCS does not explain the gaits {undocumented}")
    from walkers.common.params import WalkerParams
    if not (isinstance(module.Run, type) and issubclass(module.Run, WalkerRun)):
        problems.append("Run is not a WalkerRun subclass")
    if not (isinstance(module.Params, type) and issubclass(module.Params, WalkerParams)):
        problems.append("Params is not a WalkerParams dataclass")
    for key, spec in module.SUMMARY_EXTRAS.items():
        if spec is not None and not (isinstance(spec, tuple) and len(spec) == 2 and all(spec)):
            problems.append(f"SUMMARY_EXTRAS[{key!r}] is not (name with unit, meaning)")
    return problems
