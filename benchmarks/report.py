"""Printing of the benchmark figures and the table of benchmark targets (met / not met).

`results` is the dictionary built by bench.main: scenes {name: row}, peers {scene: [rows]},
walkers {name: row}, batch [rows] or None, startup [rows] or None, slopes.
"""
from __future__ import annotations

import math
import os

import numpy as np

from benchmarks.walker_runs import WALKER_TARGETS

PIN_TOL = 1e-9  # [m] pin residual bound of the targets


def _num(x, unit=""):
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "-"
    for scale, suffix in ((1e6, "M"), (1e3, "k")):
        if abs(x) >= scale:
            return f"{x / scale:.3g}{suffix}{unit}"
    return f"{x:.3g}{unit}"


def _spread(r):
    return f"{_num(r['steps_per_s'])} ({_num(r['steps_per_s_min'])}-{_num(r['steps_per_s_max'])})"


def _len(x):
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "-"
    return "0" if x == 0 else f"{x:.2e} m" if abs(x) < 1e-4 else f"{x * 1e3:.3g} mm"


def _pct(x):
    return f"{100 * x:7.2f}%" if abs(x) < 10 else f"{100 * x:7.1e}%"


def print_scenes(res):
    print("\nplanarsim scenes (compiled Simulator.steps; Python loop of Simulator.step alongside; the first "
          "scene's first call loads or compiles the step kernel that all scenes share)")
    print(f"{'scene':15s} {'bodies':>6s} {'first call':>10s} {'steps/s median (min-max)':>26s} "
          f"{'x real time':>11s} {'python step/s':>13s} {'python/floor':>12s}")
    for r in res["scenes"].values():
        print(f"{r['scene']:15s} {r['bodies']:6d} {r['first_call_s']:9.2f}s {_spread(r):>26s} "
              f"{r['rtf']:11,.0f} {_num(r['python_steps_per_s']):>13s} {r['python_over_floor']:11.2f}x")
    if res["scenes"]:
        floor = next(iter(res["scenes"].values()))["call_floor_s"]
        print(f"python/floor = time of one Simulator.step() in a Python loop / (the step's compiled cost "
              f"+ one empty compiled call from Python, {floor * 1e9:.0f} ns)")
    sl = res.get("slopes", {})
    for key, label in (("all", "all chains"), ("tail", "N >= 16")):
        slope, ns = sl.get(key, (math.nan, []))
        if len(ns) >= 2:
            print(f"chain cost per step ~ N^{slope:.2f} (log-log fit, {label}: N = {', '.join(map(str, ns))})")
    print(flush=True)


def print_peers(res):
    print("peer comparison, same run (ratio = planarsim steps/s / peer steps/s; energy drift = "
          "(E_end - E_0) / the scene's energy scale)")
    timing = {}
    for scene, peers in res["peers"].items():
        for r in [res["scenes"][scene]] + peers:
            timing.setdefault(f"{r['engine']} {r['version']}", r["timing"])
    print("timed as: " + "; ".join(f"{k}: {v}" for k, v in timing.items()))
    empty = {r["engine"]: r["empty_step_s"] for peers in res["peers"].values() for r in peers
             if "empty_step_s" in r}
    if empty:
        print("an empty world's step by the same call: " + ", ".join(f"{e} {t * 1e6:.2f} us" for e, t in empty.items())
              + "; 'net' = the ratio with that taken off every peer step (planarsim's own call is one per run)")
    print(f"{'scene':15s} {'engine':9s} {'version':8s} {'steps/s median (min-max)':>26s} {'ratio':>6s} {'net':>6s} "
          f"{'pin error':>10s} {'E drift':>8s} {'|dE| max':>8s} {'penetration':>11s} {'rest gap':>9s}")
    for scene, peers in res["peers"].items():
        ps_row = res["scenes"][scene]
        for r in [ps_row] + peers:
            ratio = "-" if r is ps_row else f"{ps_row['steps_per_s'] / r['steps_per_s']:.2f}x"
            net = f"{ps_row['steps_per_s'] / r['steps_per_s_net']:.2f}x" if "steps_per_s_net" in r else "-"
            line = (f"{scene:15s} {r['engine']:9s} {r['version']:8s} {_spread(r):>26s} {ratio:>6s} {net:>6s} "
                    f"{_len(r.get('pin_error_m')):>10s} {_pct(r['energy_drift'])} "
                    f"{_pct(r['energy_err_max'])} {_len(r.get('penetration_m')):>11s} "
                    f"{_len(r.get('rest_gap_m')):>9s}")
            if scene == "rod_drop":
                line += (f"  impact {r['impact_speed']:.3f} m/s, rebound {r['rebound_speed']:.3f} m/s, "
                         f"at rest after {r['time_to_rest']:.3f} s")
            if r.get("warning"):
                line += f"  [{r['engine']} warning: {r['warning']}]"
            print(line)
    for family, label in FAMILIES.items():
        slopes = engine_slopes(res, family)
        if slopes:
            print(f"{label} cost per step ~ N^slope (log-log fit over the {label}s run): "
                  + ", ".join(f"{e} {sl:.2f}" for e, sl in slopes.items()))
    print(flush=True)


#: scene families of sizes N (scene name = prefix + N) whose cost growth is fitted
FAMILIES = {"chain": "chain", "box_column": "box column"}


def _family_costs(res, family="chain"):
    """{engine: [(N, seconds per step)]} of the family's scenes (chains, box columns) in the
    peer comparison, planarsim's also where no peer ran."""
    out = {}
    for scene, r in res["scenes"].items():
        if scene.startswith(family) and scene not in res["peers"]:
            out.setdefault(r["engine"], []).append((r["bodies"], 1.0 / r["steps_per_s"]))
    for scene, peers in res["peers"].items():
        if scene.startswith(family):
            for r in [res["scenes"][scene]] + peers:
                out.setdefault(r["engine"], []).append((r["bodies"], 1.0 / r["steps_per_s"]))
    return out


def engine_slopes(res, family="chain"):
    """{engine: log-log slope of cost per step against N} (engines with >= 2 sizes)."""
    out = {}
    for engine, pts in _family_costs(res, family).items():
        if len(pts) >= 2:
            n, cost = np.array(sorted(pts)).T
            out[engine] = float(np.polyfit(np.log(n), np.log(cost), 1)[0])
    return out


def plot_chain_scaling(res, path):
    """Log-log plot of cost per step against N for every engine, with the fitted slopes."""
    import matplotlib
    import matplotlib.ticker
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    costs, slopes = _family_costs(res), engine_slopes(res)
    if not slopes:
        return None
    fig, ax = plt.subplots(figsize=(5.5, 4))
    for engine, pts in costs.items():
        if engine in slopes:
            n, cost = np.array(sorted(pts)).T
            ax.loglog(n, cost * 1e6, "o-", label=f"{engine} (slope {slopes[engine]:.2f})")
    ns = sorted({n for pts in costs.values() for n, _ in pts})
    ax.set_xticks(ns, [str(n) for n in ns])
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.yaxis.set_major_locator(matplotlib.ticker.LogLocator(subs=(1.0, 2.0, 5.0)))
    ax.yaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
    ax.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.set_xlabel("links N")
    ax.set_ylabel("wall time per step [us]")
    ax.set_title("pendulum chain: cost per step")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def print_walkers(res, batch_only=False):
    if not batch_only:
        print("walkers (simulate(seconds, gait): compiled rollout + model build + Trajectory; overhead = "
              "a 10-step walk, included)")
        print(f"{'walker':16s} {'gait':7s} {'first call':>10s} {'steps':>7s} {'steps/s median (min-max)':>26s} "
              f"{'x real time':>11s} {'fell':>5s} {'distance':>9s} {'overhead':>9s}")
        for r in res["walkers"].values():
            print(f"{r['walker']:16s} {r['gait']:7s} {r['first_call_s']:9.2f}s {r['steps']:7d} {_spread(r):>26s} "
                  f"{r['rtf']:11,.0f} {str(r['fell']):>5s} {r['distance_m']:7.1f} m {1e3 * r['overhead_s']:6.1f} ms")
        print(flush=True)
        return
    rows = res["batch"]
    print(f"batch: {rows[0]['jobs']} {rows[0]['walker']} walks of {rows[0]['seconds']:g} s (walkers.batch.simulate_batch)")
    for r in rows:
        print(f"  workers={r['workers']}: {_spread(r)} simulated steps/s, {r['cores_busy']:.2f} cores busy "
              f"(CPU time / wall), falls {r['falls']}")
    if len(rows) >= 2:
        print(f"  {rows[1]['workers']} workers / 1 worker: {rows[1]['steps_per_s'] / rows[0]['steps_per_s']:.2f}x "
              f"(load average now {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores)")
        print(f"  machine check: {rows[1]['workers']} independent Python processes ran "
              f"{rows[0]['machine_capacity']:.2f}x the work of one in the same time "
              f"({rows[1]['workers']:.1f}x = that many free cores; lower = the machine is shared or oversubscribed)")
    print(flush=True)


def print_startup(res):
    print("start-up (fresh subprocess; seconds from before `import planarsim`)")
    for r in res["startup"]:
        print(f"  {r['cache']:4s} numba cache: import {r['import_s']:.2f} s, first engine step {r['engine_step_s']:.2f} s, "
              f"first Simple Biped step {r['walker_step_s']:.2f} s (whole process {r['process_s']:.2f} s)")
        if r["cache"] == "cold":
            print(f"       compile times: engine step kernel {r['engine_step_s'] - r['import_s']:.1f} s, "
                  f"Simple Biped rollout on top {r['walker_step_s'] - r['engine_step_s']:.1f} s")
    print(flush=True)


def _status(ok):
    return "met" if ok else "NOT MET"


def targets(res):
    """[(target, measured, 'met' | 'NOT MET' | 'not measured')] of every benchmark target."""
    out = []
    scenes, peers = res["scenes"], res["peers"]
    # raw speed at pins <= PIN_TOL: (scene, label, the peer to beat (None: the fastest), ratio)
    raw = [("biped_collapse", "7-link biped collapse", "box2d", 2.0), ("rod_drop", "rod drop", None, 2.0),
           ("chain4", "4-link chain", None, 2.0)]
    raw += [(f"chain{n}", f"{n}-link chain", None, 1.0) for n in (2, 8, 16, 32, 64)]
    for scene, label, peer, goal in raw:
        pins = scene != "rod_drop"
        target = (f"{label}: >= {goal:g}x {peer or 'fastest peer'}"
                  + (f", pin residual <= {PIN_TOL:g} m" if pins else ""))
        r = scenes.get(scene)
        pr = [p for p in peers.get(scene, []) if peer is None or p["engine"] == peer]
        if r is None or not pr:
            out.append((target, "no peer measured" if r else "scene not run", "not measured"))
            continue
        best = max(pr, key=lambda p: p["steps_per_s"])
        ratio = r["steps_per_s"] / best["steps_per_s"]
        ok = ratio >= goal
        text = f"{ratio:.2f}x {best['engine']} ({_num(r['steps_per_s'])} vs {_num(best['steps_per_s'])} steps/s)"
        if pins:
            ok = ok and r["pin_error_m"] <= PIN_TOL
            text += f", pin residual {r['pin_error_m']:.1e} m"
        out.append((target, text, _status(ok)))
    for scene in ("box_column10", "box_column40", "box_pyramid", "box_piles"):
        r, pr = scenes.get(scene), peers.get(scene)
        if r is not None and pr:
            best = max(pr, key=lambda p: p["steps_per_s"])
            out.append((f"{scene}: raw ratio to the fastest peer (reported)",
                        f"{r['steps_per_s'] / best['steps_per_s']:.2f}x {best['engine']}", "reported"))
    box = engine_slopes(res, "box_column").get("planarsim")
    out.append(("box columns: cost per step grows <= N^1.5 (log-log slope)",
                "needs box_column scenes" if box is None else f"slope {box:.2f}",
                "not measured" if box is None else _status(box <= 1.5)))
    if scenes:
        worst = max(scenes.values(), key=lambda r: r["python_over_floor"])
        out.append(("Python step() within 2x of one compiled call (floor)",
                    f"worst {worst['python_over_floor']:.2f}x ({worst['scene']})",
                    _status(worst["python_over_floor"] <= 2.0)))
    slope, ns = res.get("slopes", {}).get("tail", (math.nan, []))
    if len(ns) >= 2:
        out.append(("chains: cost per step linear in N (log-log slope, N >= 16, <= 1.15)",
                    f"slope {slope:.2f} (all N: {res['slopes']['all'][0]:.2f})", _status(slope <= 1.15)))
    else:
        out.append(("chains: cost per step linear in N", "needs chains N >= 16", "not measured"))
    for name, goal in WALKER_TARGETS.items():
        r = res["walkers"].get(name)
        target = f"{name}: >= {_num(goal)} steps/s (one core)"
        if r is None:
            error = res.get("walker_errors", {}).get(name)
            out.append((target, f"failed: {error}"[:60] if error else "not run", "not measured"))
        else:
            out.append((target, f"{_num(r['steps_per_s'])} steps/s" + (", FELL" if r["fell"] else ""),
                        _status(r["steps_per_s"] >= goal)))
    batch = res["batch"]
    target = "batch of 64 on 2 cores: >= 1.8x one core"
    if not batch or len(batch) < 2:
        out.append((target, "batch not run", "not measured"))
    else:
        ratio = batch[1]["steps_per_s"] / batch[0]["steps_per_s"]
        out.append((target, f"{ratio:.2f}x ({batch[0]['jobs']} jobs; machine check {batch[0]['machine_capacity']:.2f}x)",
                    _status(ratio >= 1.8 and batch[0]["jobs"] >= 64)))
    st = {r["cache"]: r for r in res["startup"] or []}
    for cache, goal in (("cold", 15.0), ("warm", 2.0)):
        target = f"start-up, {cache} cache: <= {goal:g} s to a walker's first step"
        r = st.get(cache)
        if r is None:
            out.append((target, "not run", "not measured"))
        else:
            out.append((target, f"{r['walker_step_s']:.2f} s (engine step {r['engine_step_s']:.2f} s)",
                        _status(r["walker_step_s"] <= goal)))
    return out


def print_targets(res):
    print("benchmark targets (measured in this run)")
    width = max(len(t) for t, _, _ in res["targets"])
    for target, measured, status in res["targets"]:
        print(f"  {target:{width}s}  {measured:52s} {status}")
    print(flush=True)
