"""Benchmark runner: every benchmark figure in one run of one command.

    planarsim bench                        # everything (same as: python benchmarks/run.py)
    planarsim bench chain4 rod_drop        # only these scenes and their peer comparison
    planarsim bench --parts scenes,peers   # parts: scenes, peers, walkers, batch, startup, envs, stress
    planarsim bench --peers pymunk,box2d   # peers to compare (default: all; 'none' skips)
    planarsim bench --no-cold              # skip the cold-cache start-up (about half a minute)
    planarsim bench --csv DIR              # also write DIR/<machine>/<scene>.csv
    planarsim bench --md benchmarks/results   # also write what it prints to DIR/<machine>.md
    planarsim bench chain32 --parts pareto --pareto-out out/pareto   # accuracy-matched comparison

Parts (each warm after compilation; steps/s = median and min-max of --repeats runs):
- scenes: the named scenes of scenes.py (chains N = 2..64, rod drop, 7-link biped
  collapse, boxes on hills): first-call time (numba compile or cache load), compiled
  steps/s, real-time factor, Python single-step loop steps/s; accuracy figures of the peer
  scenes; log-log slope of the chains' cost per step against N.
- peers: the chain, biped and rod scenes built natively in MuJoCo (mujoco.rollout, one
  thread), pymunk and Box2D (Python loops) from the same description (metrics.SceneSpec),
  timed the same way in the same run: steps/s, ratio planarsim/peer, pin error, energy drift,
  penetration. Needs `pip install planarsim[compare]`; a missing peer is named and skipped.
- walkers: every registered walker walking --walker-seconds (60 s) via its simulate().
- batch: 64 Simple Biped walks on 1 and 2 worker threads (walkers.batch).
- pareto: accuracy-matched comparison (pareto.py) of the named peer scenes (default chain4,
  chain32, rod_drop, biped_collapse): planarsim (its default step, and on scenes without
  contacts its accurate integrators 'rattle', 'rattle4' and 'rattle6'), pymunk (10 and 40 iterations), Box2D (8/3 and
  30/10 iterations) and MuJoCo (Euler, implicitfast, RK4), each at steps dt*8 ... dt/8
  (--quick: the first configuration at dt and dt/2): cost per simulated second against pin,
  energy (chains) and contact error, the ratio at matched accuracy beside the raw ratio, one
  Pareto plot per scene and pareto.csv in --pareto-out (default out/pareto/<machine>).
- startup: import-to-first-step times in fresh subprocesses, warm and cold numba cache
  (startup.py says how the cache is made cold).
- envs: env.step calls per second of every planarsim gymnasium environment, single and
  vectorised (PlanarVectorEnv, --env-copies copies on 2 processes), beside gymnasium's MuJoCo
  environment of the same name in the same run (env_speed.py; needs gymnasium, and mujoco
  for the MuJoCo figures); then every DeepMind Control Suite task (planarsim/dmc-*-v0)
  beside dm_control's own environment, one environment each (needs dm_control).
- stress: Box2D's classic stress scenes and the contact-rich scenes (stress_scenes.py: the
  160-plank bridge (sagging, and Box2D's taut one), the chain holding a 100x ball, the card
  house, the 100:1 boxes, the 20-box stack, 20 dominoes, 50 shapes poured into a U, the
  55-box pyramid) built in planarsim and in every installed --peers: mean and largest step,
  each peer's mean step and the ratio, planarsim's pin gap, overlap and rest drift
  (stress.py; --steps sets the run, default each scene's 1 s).
- worlds: boxes at rest, 10 to 1,035 of them (a 4-row pyramid, ten columns of ten, 20- and
  45-row pyramids, a 40 x 10 staggered brick wall; stress_scenes.WORLD_SCENES), in planarsim
  and every installed --peers, as the stress scenes; then the log-log growth of planarsim's
  step at rest with the bodies against its target, N^1.3 (peak memory per world, each in its
  own process: benchmarks/worlds.py).
Then a table of every benchmark target with the measured figure, met or not met. Targets are
measured here, never asserted by the tests. With --md DIR the run also writes DIR/<machine>.md:
the machine, the date, the command line, the targets as a Markdown table and everything the
run printed (the documentation's benchmarks page shows benchmarks/results/*.md).
"""
from __future__ import annotations

import argparse
import contextlib
import csv
import datetime
import io
import math
import os
import platform
import re
import sys
from pathlib import Path

import numpy as np

from planarsim.compile.caches import _writable_folder  # (made or written: the same test)
from benchmarks.metrics import PEER_SCENES
from benchmarks.pareto import DEFAULT_SCENES
from benchmarks.peers import PEER_MODULES, available_peers, measure_scene
from benchmarks.report import (plot_chain_scaling, print_peers, print_scenes, print_startup, print_targets,
                           print_walkers, targets)
from benchmarks.scenes import SCENES

PARTS = ("scenes", "peers", "pareto", "walkers", "batch", "startup", "envs", "stress", "worlds")


def machine_name() -> str:
    """hostname + CPU model, safe as a directory name."""
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return re.sub(r"[^A-Za-z0-9.+-]+", "-", f"{platform.node()}_{cpu}").strip("-")


def chain_slopes(rows):
    """Log-log slope of cost per step against N over all chains and over N >= 16 (nan when
    fewer than 2 points)."""
    chains = sorted((r["bodies"], 1.0 / r["steps_per_s"]) for r in rows if r["scene"].startswith("chain"))
    out = {}
    for key, pts in (("all", chains), ("tail", [p for p in chains if p[0] >= 16])):
        if len(pts) >= 2:
            n, cost = np.array(pts).T
            out[key] = (float(np.polyfit(np.log(n), np.log(cost), 1)[0]), [int(x) for x in n])
        else:
            out[key] = (math.nan, [int(p[0]) for p in pts])
    return out


def write_csv(results, folder) -> Path:
    """One CSV per scene (rows: engines / walkers / worker counts) and targets.csv (plus
    chain_scaling.png, the log-log plot of the chains, written by main)."""
    out = Path(folder) / machine_name()
    out.mkdir(parents=True, exist_ok=True)
    by_scene = {}
    for row in results["rows"]:
        by_scene.setdefault(row["scene"], []).append(row)
    by_scene["targets"] = [dict(target=t, measured=m, status=s) for t, m, s in results["targets"]]
    for scene, rows in by_scene.items():
        keys = []
        for r in rows:
            keys += [k for k in r if k not in keys]
        with open(out / f"{scene}.csv", "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=keys)
            w.writeheader()
            w.writerows(rows)
    return out


class _Tee(io.TextIOBase):
    """A stream that writes to the real stdout and keeps a copy (for --md)."""

    def __init__(self, out):
        self.out, self.copy = out, io.StringIO()

    def write(self, text):
        self.copy.write(text)
        return self.out.write(text)

    def flush(self):
        self.out.flush()

    def isatty(self):
        try:
            return self.out.isatty()
        except ValueError:      # asked after the stream it wrote to was closed (an atexit hook)
            return False


def _git_commit():
    """The checkout's commit (short hash, '+' when files differ from it), or None outside git."""
    import subprocess
    root = Path(__file__).resolve().parents[1]
    try:
        head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=root, capture_output=True,
                              text=True, timeout=10)
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=root,
                               capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return None
    if head.returncode != 0:
        return None
    return head.stdout.strip() + ("+" if dirty.stdout.strip() else "")


def markdown_report(results, printed, argv, when=None) -> str:
    """The text of benchmarks/results/<machine>.md: a heading naming the machine, how and when
    the figures were made, the targets as a Markdown table, then the run's printed output."""
    when = when or datetime.datetime.now(datetime.timezone.utc)
    command = " ".join(["planarsim bench", *argv])
    commit = _git_commit()
    lines = [f"## Measured on `{machine_name()}`", "",
             f"Written by `{command}` on {when:%Y-%m-%d %H:%M} UTC"
             + (f" at commit {commit}" if commit else "") + f" ({os.cpu_count()} cores, load "
             f"average {os.getloadavg()[0]:.1f} at the end). Timings on a shared machine vary from run "
             f"to run; compare figures within one run.", "",
             "| benchmark target | measured | status |", "|---|---|---|"]
    for target, measured, status in results["targets"]:
        cells = [str(c).replace("|", "\\|") for c in (target, measured, status)]
        lines.append("| " + " | ".join(cells) + " |")
    lines += ["", "Everything the run printed:", "", "```text", printed.rstrip("\n"), "```", ""]
    return "\n".join(lines)


def write_markdown(results, printed, argv, folder) -> Path:
    """Write DIR/<machine>.md (see markdown_report) and return its path."""
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"{machine_name()}.md"
    path.write_text(markdown_report(results, printed, argv))
    return path


def run_pareto(args, peers):
    """Rows of the accuracy-matched comparison of args.pareto_scenes; prints the tables and
    writes one Pareto plot per scene and pareto.csv to args.pareto_out."""
    from benchmarks.pareto import matched, measure_scene as measure_ladder, our_curves
    from benchmarks.pareto_report import plot_scene, print_matched, print_points
    folder = Path(args.pareto_out or Path("out") / "pareto" / machine_name())
    folder.mkdir(parents=True, exist_ok=True)
    if not args.pareto_scenes:
        print(f"pareto: none of the scenes {args.scenes} has a peer version; peer scenes: {list(PEER_SCENES)}")
    if not peers:
        print("pareto: no peer installed (pip install planarsim[compare]); planarsim's ladder only")
    repeats = args.repeats
    rows = []
    for name in args.pareto_scenes:
        pts = measure_ladder(name, peers, quick=args.quick, repeats=repeats, timing_seconds=args.timing_seconds,
                             accuracy_seconds=args.accuracy_seconds)
        print_points(pts, repeats, args.timing_seconds)
        for ours in our_curves(pts):
            print_matched(matched(pts, ours=ours))
        plot_scene(pts, folder / f"pareto_{name}.png")
        rows += pts
    if rows:
        keys = []
        for r in rows:
            keys += [k for k in r if k not in keys]
        with open(folder / "pareto.csv", "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=keys)
            w.writeheader()
            w.writerows(rows)
        print(f"pareto: wrote {folder}", flush=True)
    return rows


def _list(ap, flag, text, known, what):
    """The comma list `text` of --flag; a usage error (exit 2) naming the unknown items and
    the known ones."""
    items = [x for x in text.split(",") if x]
    bad = [x for x in items if x not in known]
    if bad:
        ap.error(f"--{flag} {text}: unknown {what} {bad}; choose from {list(known)}")
    return items


def parse_args(argv):
    import walkers
    ap = argparse.ArgumentParser(prog="planarsim bench", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenes", nargs="*", help=f"scenes (default all): {', '.join(SCENES)}")
    ap.add_argument("--parts", default=None, help=f"comma list of {', '.join(PARTS)} (default: all; "
                    "scenes,peers when scenes are named)")
    ap.add_argument("--peers", default=",".join(PEER_MODULES), help="comma list of mujoco, pymunk, box2d, or none")
    ap.add_argument("--repeats", type=int, default=5, help="timed repeats per figure (default 5)")
    ap.add_argument("--steps", type=int, default=None, help="timing episode in steps (default: the scene's)")
    ap.add_argument("--accuracy-seconds", type=float, default=None,
                    help="accuracy run [s] (default 10 for chains, else the episode)")
    ap.add_argument("--walkers", default=",".join(walkers.WALKERS), help="comma list of walkers (default all)")
    ap.add_argument("--walker-seconds", type=float, default=60.0, help="simulated seconds per walk (60)")
    ap.add_argument("--batch-jobs", type=int, default=64)
    ap.add_argument("--batch-seconds", type=float, default=10.0, help="simulated seconds per batch job (10)")
    ap.add_argument("--env-copies", type=int, default=16, help="copies in the vectorised env figure (16)")
    ap.add_argument("--no-cold", action="store_true", help="skip the cold-cache start-up measurement")
    ap.add_argument("--csv", metavar="DIR", default=None, help="write DIR/<machine>/<scene>.csv")
    ap.add_argument("--md", metavar="DIR", default=None,
                    help="write DIR/<machine>.md: the targets as a table and all the run printed "
                         "(the documentation shows benchmarks/results/*.md)")
    ap.add_argument("--pareto-out", metavar="DIR", default=None,
                    help="folder of the Pareto plots and pareto.csv (default out/pareto/<machine>)")
    ap.add_argument("--quick", action="store_true", help="pareto: short ladder (first configuration, k = 1, 2)")
    ap.add_argument("--timing-seconds", type=float, default=1.0,
                    help="pareto: simulated seconds per timed run (default 1)")
    args = ap.parse_args(argv)
    if args.repeats < 1:
        ap.error(f"--repeats {args.repeats} must be >= 1")
    unknown = [n for n in args.scenes if n not in SCENES]
    if unknown:
        ap.error(f"unknown scene(s) {unknown}; choose from {list(SCENES)}")
    if not args.timing_seconds > 0:
        ap.error(f"--timing-seconds {args.timing_seconds} must be > 0")
    # (checked here, before the runs, each naming its flag; not by the part that reads it)
    for flag, least in (("steps", 1), ("batch_jobs", 1), ("env_copies", 1)):
        value = getattr(args, flag)
        if value is not None and value < least:
            ap.error(f"--{flag.replace('_', '-')} {value} must be >= {least}")
    for flag in ("accuracy_seconds", "walker_seconds", "batch_seconds"):
        value = getattr(args, flag)
        if value is not None and not (math.isfinite(value) and value > 0):
            ap.error(f"--{flag.replace('_', '-')} {value} must be a finite number of seconds > 0")
    for flag in ("csv", "md", "pareto_out"):
        folder = getattr(args, flag)
        if folder is not None and not _writable_folder(folder):
            # (checked before the runs, which take minutes, not after them)
            ap.error(f"--{flag.replace('_', '-')} {folder}: cannot make or write to this folder")
    if args.parts is None:
        args.parts = "scenes,peers" if args.scenes else ",".join(PARTS)
    args.pareto_scenes = [n for n in args.scenes if n in PEER_SCENES] if args.scenes else list(DEFAULT_SCENES)
    args.scenes = args.scenes or list(SCENES)
    args.parts = _list(ap, "parts", args.parts, PARTS, "part(s)")
    args.peers = [] if args.peers == "none" else _list(ap, "peers", args.peers, PEER_MODULES, "peer(s)")
    args.walkers = _list(ap, "walkers", args.walkers, walkers.WALKERS, "walker(s)")
    return args


def main(argv=None):
    argv = list(sys.argv[1:] if argv is None else argv)
    args = parse_args(argv)
    if args.md is None:
        return _status(_run(args))
    tee = _Tee(sys.stdout)
    with contextlib.redirect_stdout(tee):
        results = _run(args)
    path = write_markdown(results, tee.copy.getvalue(), argv, args.md)
    print(f"wrote {path}")
    return _status(results)


def _status(results) -> int:
    """The run's exit status: 1 where a walker asked for failed (its figures are missing:
    the run printed why, and the others), else 0."""
    failed = results.get("walker_errors") if isinstance(results, dict) else None
    if failed:
        print(f"bench: {len(failed)} walker(s) failed: {', '.join(failed)} (exit 1)",
              file=sys.stderr)
        return 1
    return 0


def _run(args):
    """Run the parts args asks for, print their figures; returns the results dictionary."""
    import numba
    print(f"planarsim bench on {machine_name()} ({os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}): "
          f"Python {platform.python_version()}, numpy {np.__version__}, numba {numba.__version__}; "
          f"{args.repeats} repeats", flush=True)
    results = {"rows": [], "scenes": {}, "peers": {}, "walkers": {}, "batch": None, "startup": None}
    rows = results["rows"]
    parts = set(args.parts)
    found = {}
    if parts & {"peers", "pareto"}:
        found, missing = available_peers(args.peers)
        for msg in missing:
            print(msg, flush=True)
    if parts & {"scenes", "peers"}:
        for name in args.scenes:
            compare = found if name in PEER_SCENES and "peers" in parts else {}
            row, peer_rows = measure_scene(name, compare, args.repeats, args.steps, args.accuracy_seconds)
            results["scenes"][name] = row
            rows.append(row)
            if compare:
                results["peers"][name] = peer_rows
                rows += peer_rows
        results["slopes"] = chain_slopes(list(results["scenes"].values()))
        print_scenes(results)
    if results["peers"]:
        print_peers(results)
    elif "peers" in parts and args.peers:
        print("peer comparison skipped: no peer installed (pip install planarsim[compare])\n")
    if "pareto" in parts:
        results["pareto"] = run_pareto(args, found)
    if "walkers" in parts and args.walkers:
        from benchmarks.walker_runs import measure_walker
        for name in args.walkers:
            try:
                row = measure_walker(name, args.walker_seconds, args.repeats)
            except Exception as exc:  # one broken walker must not hide the other figures
                print(f"walker {name}: FAILED with {type(exc).__name__}: {exc}", flush=True)
                results.setdefault("walker_errors", {})[name] = f"{type(exc).__name__}: {exc}"
                continue
            results["walkers"][name] = row
            rows.append(row)
        print_walkers(results)
    if "batch" in parts:
        from benchmarks.walker_runs import measure_batch
        batch = measure_batch(args.batch_jobs, args.batch_seconds, args.repeats)
        results["batch"] = batch
        if batch is None:
            print("batch: walkers.batch is not available; skipped")
        else:
            rows += batch
            print_walkers(results, batch_only=True)
    if "envs" in parts:
        from benchmarks.env_speed import measure_envs, print_envs
        env_rows = measure_envs(repeats=min(args.repeats, 3), copies=args.env_copies)
        results["envs"] = env_rows
        rows += env_rows
        print_envs(env_rows)
        from benchmarks.env_speed import measure_dmc, print_dmc
        dmc_rows = measure_dmc(repeats=min(args.repeats, 3))
        results["dmc"] = dmc_rows
        rows += dmc_rows
        print_dmc(dmc_rows)
    if "stress" in parts:
        from benchmarks.stress import run as run_stress
        from benchmarks.stress_scenes import STRESS_SCENES
        results["stress"] = run_stress(list(STRESS_SCENES), args.peers, args.repeats, steps=args.steps)
        print()
    if "worlds" in parts:
        from benchmarks.stress import run_worlds
        results["worlds"] = run_worlds(args.peers, args.repeats, steps=args.steps)
        print()
    if "startup" in parts:
        from benchmarks.startup import measure_startup
        results["startup"] = measure_startup(cold=not args.no_cold)
        rows += results["startup"]
        print_startup(results)
    results["targets"] = targets(results)
    print_targets(results)
    if args.csv:
        folder = write_csv(results, args.csv)
        plot_chain_scaling(results, folder / "chain_scaling.png")
        print(f"wrote {folder}")
    return results


if __name__ == "__main__":
    sys.exit(main())
