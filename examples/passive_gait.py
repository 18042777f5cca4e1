"""Gait analysis of a passive walker: fixed point of the step-to-step map, step period, step
length and Floquet multipliers, plus plots (multipliers vs the unit circle, limit cycle).

    python examples/passive_gait.py simplest-walker --slope 0.009 --out out/passive
    python examples/passive_gait.py rimless-wheel --slope 0.1
    python examples/passive_gait.py compass-gait --slope 0.0524
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from planarsim.analysis import (StepMapError, find_fixed_point, multipliers_with_error, plot_limit_cycle,
                                plot_multipliers)
from walkers.passive import CompassParams, PassiveWalker, RimlessParams, SimplestParams

WALKERS = ("simplest-walker", "compass-gait", "rimless-wheel")


def initial_guess(name, params):
    if name == "simplest-walker":
        from walkers.passive.simplest import garcia_start
        return garcia_start()
    if name == "rimless-wheel":
        from walkers.passive.rimless_wheel import closed_form
        return np.array([-closed_form(params)["omega_after"]])
    from walkers.passive.compass_gait import default_start
    return default_start(params)


def analyse(name, slope, dt=1e-3, beta=1e-3, out=None, eps="auto", quiet=False):
    """Find the period-one gait; print and return a dict; save plots into `out` if given."""
    if name == "simplest-walker":
        params = SimplestParams(slope=slope, foot_mass_ratio=beta)
    elif name == "compass-gait":
        params = CompassParams(slope=slope)
    elif name == "rimless-wheel":
        params = RimlessParams(slope=slope)
    else:
        raise ValueError(f"unknown passive walker {name!r}; choose from {WALKERS}")
    walker = PassiveWalker(params, dt=dt)
    step_map = walker.step_map()
    fp = find_fixed_point(step_map, initial_guess(name, params), tol=1e-9, eps=1e-4, exact=False)
    mult = multipliers_with_error(step_map, fp.x, eps)   # the step chosen from the map's noise
    fp.multipliers = mult.values
    walker.advance(fp.x)
    result = dict(walker=name, slope=slope, dt=dt, fixed_point=dict(zip(walker.names, fp.x.tolist())),
                  converged=fp.converged, residual=fp.residual, step_period=walker.last_period,
                  step_length=walker.last_length, multipliers=fp.multipliers, stable=fp.stable,
                  multiplier_error=mult.error, multiplier_eps=mult.eps,
                  evaluations=fp.evaluations)
    if not quiet:
        print(f"{name} on slope {slope} rad, dt = {dt} s" + (f", beta = {beta}" if name == "simplest-walker" else ""))
        print(f"  fixed point ({'converged' if fp.converged else 'NOT converged'}, |P(x)-x| = {fp.residual:.1e}, "
              f"{fp.evaluations} map evaluations):")
        for k, v in result["fixed_point"].items():
            print(f"    {k:10s} = {v:+.8f}")
        print(f"  step period = {walker.last_period:.6f} s, step length = {walker.last_length:.6f} m")
        print("  Floquet multipliers: " + ", ".join(f"{m.real:+.4f}{m.imag:+.4f}j (|{abs(m):.4f}|)" for m in fp.multipliers)
              + f"  (estimated error {mult.error:.1e}, eps {mult.eps:.2g})")
        print(f"  {'stable' if fp.stable else 'UNSTABLE'} (spectral radius {fp.spectral_radius:.4f})")
    if out is not None:
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        plot_multipliers(fp.multipliers, out / f"{name}_multipliers.png", title=f"{name}: Floquet multipliers")
        angle, rate, sec = limit_cycle(walker, fp.x, n_steps=4)
        plot_limit_cycle(angle, rate, out / f"{name}_limit_cycle.png", section=sec,
                         labels=("stance-leg angle theta [rad]", "theta rate [rad/s]"),
                         title=f"{name}: limit cycle (stance leg), 4 steps")
        result["plots"] = [str(out / f"{name}_multipliers.png"), str(out / f"{name}_limit_cycle.png")]
        if not quiet:
            print("  plots: " + ", ".join(result["plots"]))
    return result


def limit_cycle(walker, x, n_steps=4):
    """Stance-leg angle and rate [rad, rad/s] over n_steps steps of the step map from x
    (recorded by the compiled rollout), and the section points (angle, rate) after each step."""
    angle, rate, sec = [], [], []
    for _ in range(n_steps):
        walker.advance(x, record_every=1)
        traj = walker.last_traj
        for q, v in zip(traj.q[:-1], traj.v[:-1]):   # the last frame lies past the touchdown
            th, thd = walker.stance_angle(q, v, walker.feet[0])
            angle.append(th)
            rate.append(thd)
        x = walker.coords()
        sec.append(walker.stance_angle())
    return np.array(angle), np.array(rate), np.array(sec)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("walker", choices=WALKERS)
    ap.add_argument("--slope", type=float, default=None, help="slope gamma [rad] (default: the walker's)")
    ap.add_argument("--dt", type=float, default=1e-3, help="step size [s]")
    ap.add_argument("--beta", type=float, default=1e-3, help="foot mass ratio (simplest walker)")
    ap.add_argument("--out", default="out/passive", help="folder for the plots")
    a = ap.parse_args(argv)
    defaults = {"simplest-walker": SimplestParams().slope, "compass-gait": CompassParams().slope,
                "rimless-wheel": RimlessParams().slope}
    try:
        analyse(a.walker, defaults[a.walker] if a.slope is None else a.slope, a.dt, a.beta, a.out)
    except (StepMapError, ValueError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
