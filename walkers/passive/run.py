"""The passive walkers' run class (a walkers.base.WalkerRun): walk down the slope from a
section state with the compiled rollout (walkers.passive.rollout).

Touchdowns, ``impacts``:
  "refined" (default): every touchdown is located and resolved as in the step map
      (PassiveWalker.refine_touchdown; one Python call per walking step, none per sim step);
  "engine": the engine's contacts find the touchdowns on their own (continuous collision for
      point feet, the "all" mode strategy releasing the trailing foot), the end-to-end path.
Either way a recorded run holds a frame at each whole step of the clock, round(t / dt), that
is a multiple of record_every (rollout.clock_step: a refined touchdown counts two engine steps
in state.step where the clock moves less than one, so the schedule follows the clock, and a
run of whole frames ends on its last frame) and a frame at each touchdown (whole-step
summaries start and end on them); the step a refined touchdown takes back leaves no frame.
Chunks end where one run of their total length would be: run(a); run(b) walks to step
round(a / dt) + round(b / dt) like run(a + b). A chunk's end is counted from the state's own
clock (a touchdown moves the clock off the grid of whole steps by less than half a step), so a
state and memory put back from a snapshot go on from there.
"""
from __future__ import annotations

import math

import numpy as np

from planarsim import dense
from planarsim.errors import plain
from planarsim.analysis import step_summary

from walkers.base import WalkerRun, terrain_of
from walkers.common.record import record_one

from .gait import PassiveWalker, check_dt
from .rollout import DETECT, FELL, NO_EVENT

GAITS = ("passive",)
GAIT_DOCS = {"passive": "no motors: walks down the slope under gravity alone"}
IMPACTS = ("refined", "engine")
MIN_STEP_PERIOD = 0.05   # [s] touchdowns assumed at most this often (room for event frames)


def slope_from_terrain(terrain, default):
    """Slope gamma [rad] of a constant-slope terrain (falling toward +x), or `default`."""
    if terrain is None:
        return default
    coef = np.asarray(terrain.coef)
    if coef[2] != 0:
        raise ValueError(f"passive walkers need a constant slope (terrain 'slope:DEG' with DEG < 0 "
                         f"for downhill), got {getattr(terrain, 'name', 'terrain')!r}")
    gamma = -math.atan(coef[1])
    if gamma < 0:
        raise ValueError(f"passive walkers walk downhill toward +x: use a negative slope angle, "
                         f"got {math.degrees(-gamma):g} deg")
    return gamma


# the passive walkers' own numbers (PassiveRun.numbers) under names that say what they measure:
# the hip and the centre of mass along the slope, where the common summary measures the centre
# of mass horizontally
PASSIVE_EXTRAS = {
    "distance": ("hip_distance_along_slope_m", "the hip's displacement along the slope since the start"),
    "mean_speed": ("hip_mean_speed_along_slope_m_per_s", "hip_distance_along_slope_m over the simulated time"),
    "step_length": ("step_length_along_slope_m", "the centre of mass's advance along the slope per whole step (the cost of transport's distance)"),
    "speed": ("step_speed_along_slope_m_per_s", "step_length_along_slope_m over the step period"),
    "cost_of_transport": ("cost_of_transport", "mechanical energy lost per weight and distance along the slope over whole steps: sin(slope) on a steady gait"),
    "impacts": ("impacts", "how touchdowns were resolved: refined (located and resolved exactly) or engine"),
    "steps": ("controller_steps", "touchdowns the rollout recorded"),
}


class PassiveRun(WalkerRun):
    """A passive walker walking down its slope. A walker module subclasses it with NAME, Params
    (its parameter class) and ``start(params)`` (the default section state).

    Parameters
    ----------
    params : the walker's Params (defaults if None); its slope is taken from `terrain` if given
    terrain : a constant downhill slope (planarsim.terrain spec 'slope:DEG', DEG < 0) or None
    dt : step size [s]
    gait : "passive"
    seed : accepted for the common interface (the walker is deterministic)
    x0 : section state to start from (PassiveWalker.coords; default start(params))
    record_every : whole steps of the clock between recorded frames (0: none)
    impacts : "refined" | "engine" (module doc)
    """

    Params = None

    def __init__(self, params=None, terrain=None, dt=1e-3, gait="passive", seed=0, x0=None,
                 record_every=10, impacts="refined"):
        if gait not in GAITS:
            raise ValueError(f"{self.NAME}: unknown gait {gait!r}; gaits: {GAITS}")
        if impacts not in IMPACTS:
            raise ValueError(f"impacts={impacts!r} must be 'refined' or 'engine'")
        dt = check_dt(dt, f"{self.NAME}: dt")
        terrain = terrain_of(terrain)
        p = params or self.Params()
        p = self.Params(**{**p.as_dict(), "slope": slope_from_terrain(terrain, p.slope)})
        self.walker = w = PassiveWalker(p, dt=dt)
        w.set_coords(self.start(p) if x0 is None else self._section_state(x0, w.names))
        super().__init__(w.model, p, None, w.memory, state=w.sim.state, ws=w.sim.ws,
                         options=w.sim.options, record_every=record_every)
        self.impacts = impacts
        self.hip0 = self.state.q[w.hip, :2].copy()
        self.end_step = 0         # the grid step the chunk under way ends at
        self.code = 0             # run code of the last chunk (0, or FELL; FELL stays)

    def _section_state(self, x0, names) -> np.ndarray:
        """x0 as a float array of one finite number per coordinate in `names`; a ValueError
        naming it otherwise (a longer one was cut silently, a NaN one diverged at step 0
        naming a body)."""
        try:
            x = np.array(x0, dtype=np.float64)
        except (TypeError, ValueError):
            x = None
        if x is None or x.shape != (len(names),):
            raise ValueError(f"{self.NAME}: x0={plain(x0)!r} must be {len(names)} number(s), "
                             f"the section state ({', '.join(names)})")
        for name, value in zip(names, x):
            if not math.isfinite(value):
                raise ValueError(f"{self.NAME}: x0 {name}={value} must be finite")
        return x

    def start(self, params) -> np.ndarray:
        """Default section state for `params`."""
        raise NotImplementedError

    @property
    def fell(self) -> bool:
        return self.code == FELL

    def max_touchdowns(self, n: int) -> int:
        return int(n * self.dt / MIN_STEP_PERIOD) + 10

    def frames(self, n: int) -> int:
        # frames on the clock's schedule, one per touchdown, and as many again to spare (the
        # refined path records the step a foot crosses the ground in before taking it back)
        return n // self.record_every + 2 + 2 * self.max_touchdowns(n) if self.record_every else 0

    def advance(self, n, every, rec, lab):
        if self.fell:
            return FELL, 0        # it stays where it fell
        self.end_step = int(round(float(self.state.time[0]) / self.dt)) + n
        code, k = (self._engine if self.impacts == "engine" else self._refined)(n, rec)
        self.code = int(code)
        return code, k

    def _engine(self, n, rec):
        """The engine finds the touchdowns (events logged in walker.event_time / event_contact)."""
        w = self.walker
        need = int(w.memory[1]) + self.max_touchdowns(n)
        if need > w.event_time.size:
            w.event_time = np.concatenate([w.event_time, np.zeros(need - w.event_time.size)])
            w.event_contact = np.concatenate([w.event_contact,
                                              np.zeros(need - w.event_contact.size, np.int64)])
        code, done, k = self.walker.run_compiled(n, 1 << 60, rec, self.record_every, 0)
        return code, k

    def _refined(self, n, rec):
        """Rollouts from touchdown to touchdown, each touchdown refined, up to grid step
        end_step (the state's clock at the chunk's start in whole steps, plus n)."""
        w, s = self.walker, self.state
        end = self.end_step * self.dt
        k, code = 0, NO_EVENT
        toggle = w.toggle
        w.toggle = DETECT
        try:
            s.contact_enabled[w.feet] = 0
            s.contact_enabled[w.feet[w.memory[0]]] = 1
            while s.time[0] < end - 0.5 * self.dt:
                old = int(w.memory[0])
                left = int(round((end - s.time[0]) / self.dt))
                code, done, k = w.run_compiled(left, int(w.memory[1]) + 1, rec, self.record_every, k)
                if code != 0:
                    break
                k = self._unrecord_crossing(rec, k)
                w.refine_touchdown(old)
                s.contact_enabled[w.feet[old]] = 0
                if self.record_every and k < rec.t.shape[0]:
                    record_one(s, self.ws, rec, k)
                    k += 1
        finally:
            w.toggle = toggle
        return (0 if code == NO_EVENT else code), k

    def _unrecord_crossing(self, rec, k: int) -> int:
        """The next frame k of rec less the frame of the step in which a foot crossed the
        ground, where the schedule recorded one: refine_touchdown takes that step back (its
        state lies past the touchdown, its time after the touchdown's frame's)."""
        return k - 1 if k > 0 and rec.t[k - 1] == self.state.time[0] else k

    def numbers(self) -> dict:
        """steps (touchdowns), distance [m] (hip displacement along the slope), mean_speed [m/s]
        (distance / duration), fell, duration [s], code (the last chunk's run code), and over
        whole steps, first to last touchdown (planarsim.analysis.step_summary of the recorded
        touchdowns; NaN without recording or with fewer than two touchdowns): whole_steps,
        step_period [s], step_length [m] and speed [m/s] (centre of mass along the slope),
        cost_of_transport (energy lost per weight and distance along the slope: sin(slope) on
        a steady gait)."""
        w = self.walker
        distance = dense.dot(self.state.q[w.hip, :2] - self.hip0, w.t_hat)
        t_end = self.time
        whole = dict(whole_steps=0, step_period=math.nan, step_length=math.nan, speed=math.nan,
                     cost_of_transport=math.nan)
        traj = self.trajectory()
        if len(traj):
            ws = step_summary(traj, self.model, w.feet, direction=w.t_hat)
            whole = {k: ws[k] for k in whole}
        return dict(walker=w.kind, impacts=self.impacts, steps=int(w.memory[1]), distance=distance,
                    mean_speed=distance / t_end if t_end > 0 else 0.0, fell=self.fell,
                    **whole, duration=t_end, code=self.code)
