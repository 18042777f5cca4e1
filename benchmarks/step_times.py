"""Each step of a bench scene timed alone: how the steps that need the complementarity solve
compare with the others (not a test).

    python benchmarks/step_times.py biped_collapse
    python benchmarks/step_times.py boxes_on_hills --repeats 25 --strategy all
    python benchmarks/step_times.py stress:pour50 --repeats 1      # a stress scene (stress_scenes.py)

Every step of the scene's bench run is timed on its own (Simulator.steps(1), best of
--repeats runs from the same start), less the cost of an empty call. Prints the total, the
steps that ran the complementarity (Lemke) solve and their mean, the other steps' mean, the
share of the run the complementarity steps take, and which rules the guess of those steps
broke (step_info's guess_* counts: equations a dropped dependent row left unmet, contacts
that pull, sliding contacts whose slip reversed, friction outside its cone, limits that
pull), i.e. why the linear solves did not do; the other steps are split into those the
switching rounds answered and the rest.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import planarsim as ps  # noqa: E402
from benchmarks.scenes import SCENES  # noqa: E402
from benchmarks.stress_scenes import ALL_SCENES, build_model  # noqa: E402
from planarsim.compiled import step_info  # noqa: E402
from planarsim.kernels.info import INFO_NAMES  # noqa: E402


def _scene(name):
    """(model, steps) of bench scene `name`, or of stress scene `stress:<name>` (its seconds)."""
    if name.startswith("stress:") and name[7:] in ALL_SCENES:
        scene = ALL_SCENES[name[7:]]
        return build_model(scene), int(round(scene.seconds / scene.dt))
    if name not in SCENES:
        raise SystemExit(f"unknown scene {name!r}; scenes: {', '.join(SCENES)}, or "
                         f"stress:<{'|'.join(ALL_SCENES)}>")
    build, n = SCENES[name]
    return build(), n


# the rules the guess broke (step_info's guess_* slots), reported for the complementarity steps
GUESS_RULES = tuple(name[6:] for name in INFO_NAMES if name.startswith("guess_"))


def step_times(name, repeats=15, strategy="alternating"):
    """(best time of each step [ns], bool array: the step ran the complementarity solve,
    (steps, len(GUESS_RULES)) int array: the rules each step's guess broke, by rule, bool
    array: the step took switching rounds (step.switch_rounds))."""
    model, n = _scene(name)
    options = ps.make_options(strategy)
    best = np.full(n, np.inf)
    lcp = np.zeros(n, bool)
    guess = np.zeros((n, len(GUESS_RULES)), np.int64)
    rounds = np.zeros(n, bool)
    clock = time.perf_counter_ns
    ps.Simulator(model, options=options).steps(1)     # (compiled before the clock runs)
    for _ in range(repeats):
        sim = ps.Simulator(model, options=options)
        for k in range(n):
            t0 = clock()
            sim.steps(1)
            best[k] = min(best[k], clock() - t0)
            info = step_info(sim.ws)
            lcp[k] = info["lcp_solves"] > 0
            guess[k] = [info["guess_" + rule] for rule in GUESS_RULES]
            rounds[k] = info["switch_rounds"] > 0
    sim = ps.Simulator(model, options=options)
    empty = np.inf
    for _ in range(2000):
        t0 = clock()
        sim.steps(0)
        empty = min(empty, clock() - t0)
    return best - empty, lcp, guess, rounds


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene", help=", ".join(SCENES) + ", or stress:<name> (stress_scenes.py)")
    ap.add_argument("--repeats", type=int, default=15)
    ap.add_argument("--strategy", choices=("alternating", "all"), default="alternating")
    args = ap.parse_args(argv)
    t, lcp, guess, rounds = step_times(args.scene, args.repeats, args.strategy)
    us = t / 1e3
    print(f"{args.scene}: {len(t)} steps, {us.sum() / 1e3:.2f} ms in all")
    if lcp.any():
        print(f"  {lcp.sum()} steps with the complementarity solve: {us[lcp].mean():.2f} us "
              f"each, {us[lcp].sum() / us.sum():.0%} of the run")
        print("  the rules their guess (the first answer, under the last step's modes) broke:")
        for j, rule in enumerate(GUESS_RULES):
            broke = guess[lcp, j] > 0
            if broke.any():
                print(f"    {rule:<10} in {broke.sum():>4} of them ({guess[lcp, j][broke].mean():.1f} "
                      f"rows each)")
    else:
        print("  no step needed the complementarity solve")
    if (~lcp).any():
        print(f"  {(~lcp).sum()} other steps: {us[~lcp].mean():.2f} us each")
        answered = rounds & ~lcp
        if answered.any():
            rest = ~lcp & ~rounds
            print(f"    {answered.sum()} answered by the switching rounds: {us[answered].mean():.2f} us "
                  f"each (median {np.median(us[answered]):.2f}), {us[answered].sum() / us.sum():.0%} "
                  f"of the run")
            if rest.any():
                print(f"    {rest.sum()} without rounds: {us[rest].mean():.2f} us each (median "
                      f"{np.median(us[rest]):.2f})")


if __name__ == "__main__":
    main()
