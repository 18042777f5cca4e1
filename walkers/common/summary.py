"""One summary for every walker's run (what `planarsim run` prints and writes).

Common keys, the same for every walker, units in their names:
  walker, gait, terrain, duration_s, params_changed
  time_s            simulated time reached [s] (less than duration_s after a fall)
  fell              the walker's own fall test fired (or the engine stopped it)
  distance_m        horizontal displacement of the centre of mass [m] from the first
                    recorded frame (the start, t = 0) to the last
  mean_speed_m_per_s  distance_m over the time between those frames [m/s]
  steps             foot touchdowns over the run (from the recorded contact modes; a foot
                    is its contacts together, FEET of the walker; a landing counts after
                    at least MIN_AIR_S in the air, so a bounce lands once, and feet landing
                    within MIN_AIR_S of each other land once: a jump is one landing)
  whole_steps, step_period_s, step_length_m, step_speed_m_per_s
                    over whole steps, first to last touchdown (planarsim.analysis.step_summary):
                    they do not depend on where in a step the run ends; NaN before two touchdowns
  audit             the engine's self-audit counts (all 0: no contact pulled, added energy, ...)
  wall_time_s       {"compile": numba compile or cache load and model build, "run": the
                    simulation, "output": files written}
  extras            the walker's own numbers, named with units in its module's SUMMARY_EXTRAS
                    (docs/walkers.md lists them)
"""
from __future__ import annotations

import math

import numpy as np

from planarsim.analysis import foot_groups, step_events
from planarsim.measure import summary as measure_summary

MIN_AIR_S = 0.05     # [s] a foot must be off the ground this long for its next landing to count
# the walkers' own keys that the common part stands in for: the same quantity, measured the same
# way (the run's time and end, the touchdowns' whole steps). A walker whose own number of that
# name measures something else (a hip along the slope, its own heel strikes) declares it in its
# SUMMARY_EXTRAS under a name that says so, and then it is printed there, never replaced
REPLACED = ("time", "duration", "distance", "fell", "falls", "audit", "walker", "gait", "code",
            "mean_speed", "speed", "step_length", "step_period", "step_speed", "whole_steps")


def feet_of(mod, model) -> list:
    """Contact index groups that are one foot each: the walker's FEET (names), else the
    contacts grouped by name (planarsim.analysis.foot_groups)."""
    feet = getattr(mod, "FEET", None)
    if feet is None:
        return foot_groups(model.contact_names)
    names = list(model.contact_names)
    return [[names.index(c) for c in group] for group in feet]


def _plain(v):
    """JSON-friendly: numpy scalars to Python, NaN and inf to None."""
    if isinstance(v, dict):
        return {k: _plain(x) for k, x in v.items()}
    if isinstance(v, (np.floating, float)):
        v = float(v)
        return v if math.isfinite(v) else None
    if isinstance(v, (np.integer,)):
        return int(v)
    if isinstance(v, np.bool_):
        return bool(v)
    return v


def walker_summary(mod, traj, model, raw: dict, *, walker, gait, terrain, duration,
                   params_changed=None, wall=None) -> dict:
    """The common summary (module docstring) of one run: `raw` is the walker's own summary
    (simulate's second result), `mod` its module (FEET, SUMMARY_EXTRAS). A raw key declared in
    SUMMARY_EXTRAS is printed in extras under its declared name (even one that REPLACED lists:
    the walker's own measure of it); a key neither declared nor in REPLACED is an error naming it."""
    extras_spec = getattr(mod, "SUMMARY_EXTRAS", {})
    unknown = sorted(k for k in raw if k not in REPLACED and k not in extras_spec)
    if unknown:
        raise KeyError(f"walker {walker!r} reports {unknown} without declaring them in "
                       f"{mod.__name__}.SUMMARY_EXTRAS (name with unit, explanation)")
    t = float(raw.get("time", raw.get("duration", traj.t[-1] if len(traj.t) else 0.0)))
    feet = feet_of(mod, model)
    # a walker's landings are its steps, wherever they land (a jump or a trot in place lands
    # once per flight: the walker's own gaits say which it does)
    ss = measure_summary(traj, model, feet=feet, min_air=MIN_AIR_S, together=MIN_AIR_S, min_stride=0.0)
    dist = ss["distance"]
    touchdowns = len(step_events(traj, feet=feet, min_air=MIN_AIR_S, together=MIN_AIR_S))
    out = {"walker": walker, "gait": gait, "terrain": terrain, "duration_s": float(duration),
           "params_changed": params_changed or {},
           "time_s": t, "fell": bool(raw.get("fell", False)), "distance_m": dist,
           "mean_speed_m_per_s": ss["mean_speed"] if math.isfinite(ss["mean_speed"]) else 0.0,
           "steps": int(touchdowns), "whole_steps": int(ss["whole_steps"]),
           "step_period_s": ss["step_period"], "step_length_m": ss["step_length"],
           "step_speed_m_per_s": ss["speed"], "audit": raw.get("audit", {}),
           "wall_time_s": wall or {},
           "extras": {extras_spec[k][0]: raw[k] for k in raw
                      if k in extras_spec and extras_spec[k] is not None}}
    return _plain(out)
