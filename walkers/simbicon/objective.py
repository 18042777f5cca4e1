"""Tuning objective of the SIMBICON biped (used by planarsim tune).

score = distance [m] walked in an unpushed run of `duration`
        + push_bonus * (number of push runs survived) + sum of their distances / n_push
        - fall_penalty * (fraction of the run lost to a fall, per run; a solver glitch loses
          the whole run and its distance)
        - effort_weight * (mean over runs of the torque effort per second) [N^2 m^2]
Pushes are given as forces [N] at the torso, `push_duration` long, starting at `push_time`.
Everything is deterministic: the same parameters give the same score in any process.
"""
from __future__ import annotations

from .params import SimbiconParams
from .rollout import run

Params = SimbiconParams

DEFAULT_SETTINGS = dict(duration=10.0, pushes=(60.0, -60.0), push_time=4.0, push_duration=0.2,
                        push_bonus=2.0, fall_penalty=10.0, effort_weight=1e-6, dt=1e-3)


def evaluate(params: SimbiconParams, settings: dict | None = None) -> dict:
    """Score one parameter set; returns dict(score=..., distance=..., survived=..., ...)."""
    st = dict(DEFAULT_SETTINGS, **(settings or {}))
    T = float(st["duration"])
    runs = [None] + [dict(force=float(f), start=st["push_time"], duration=st["push_duration"])
                     for f in st["pushes"]]
    score, effort, survived, dist0, dist_push = 0.0, 0.0, 0, 0.0, 0.0
    for i, push in enumerate(runs):
        # an engine divergence ends the run as a glitch (scored below) instead of raising
        _, s, _ = run(params, T, dt=st["dt"], push=push, record=False, glitch_ok=True)
        lost = 1.0 - s["time"] / T if s["fell"] else 0.0
        if s["glitch"]:   # the contact solver blew up: no credit for the (meaningless) distance
            lost, s["distance"] = 1.0, 0.0
        score -= st["fall_penalty"] * lost
        effort += s["effort"] / max(s["time"], 1e-9) / len(runs)
        if i == 0:
            dist0 = s["distance"]
        else:
            survived += 0 if s["fell"] else 1
            dist_push += s["distance"] / (len(runs) - 1)
    score += dist0 + dist_push + st["push_bonus"] * survived - st["effort_weight"] * effort
    return dict(score=float(score), distance=float(dist0), survived=int(survived),
                effort=float(effort))
