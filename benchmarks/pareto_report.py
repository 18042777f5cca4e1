"""Printing and plotting of the accuracy-matched comparison (pareto.py): one table of the
ladder points and one of the matched ratios per scene, one Pareto plot per scene."""
from __future__ import annotations

import math

from benchmarks.pareto import ERRORS, FLOORS, _err, curves, figures
from benchmarks.report import _len, _num

LABELS = {"energy_err_max": "energy error |dE| max / scale", "pin_error_m": "pin error [m]",
          "contact_error_m": "contact error: max(sink, |end gap|) [m]"}
SHORT = {"energy_err_max": "energy", "pin_error_m": "pin", "contact_error_m": "contact"}


def _e(x):
    return "-" if x is None or math.isnan(x) else f"{x:.2e}"


def step_label(k):
    """'dt/4', 'dt' or 'dt*4' for k steps per scene dt."""
    return "dt" if k == 1 else f"dt/{k:g}" if k > 1 else f"dt*{1 / k:g}"


def _ratio(ratio, note):
    if note is None:
        return "not reached"
    if note == "diverged":
        return "diverged"
    return f"{ratio:.3g}x" + (" cheapest" if note == "cheapest" else "")


def print_points(rows, repeats, timing_seconds):
    """The ladder points of one scene: cost, steps/s and the accuracy figures."""
    scene = rows[0]["scene"]
    print(f"\npareto {scene}: cost = wall s per simulated s (median of {repeats} runs of {timing_seconds:g} s), "
          "accuracy over the accuracy run, same metrics for every engine")
    print(f"{'curve':22s} {'step':>6s} {'[s]':>8s} {'cost s/s':>9s} {'steps/s':>8s} {'pin error':>10s} "
          f"{'|dE| max':>9s} {'E drift':>9s} {'penetration':>11s} {'end gap':>10s}")
    for r in rows:
        line = (f"{r['curve']:22s} {step_label(r['k']):>6s} {r['dt']:8.2e} {r['cost_s_per_s']:9.3g} "
                f"{_num(r['steps_per_s']):>8s} {_len(r.get('pin_error_m')):>10s} {_e(r['energy_err_max']):>9s} "
                f"{r['energy_drift']:+9.2e} {_len(r.get('penetration_m')):>11s} {_len(r.get('rest_gap_m')):>10s}")
        if r.get("warning"):
            line += f"  [warning: {r['warning']}]"
        print(line)


def print_matched(summary):
    """One line per peer curve and accuracy figure: the raw ratio, the ratio at planarsim's
    error at dt and at the peer's error at dt, the observed orders and where the fronts cross."""
    if not summary:
        return
    ours = summary[0].get("ours", "planarsim")
    print(f"pareto {summary[0]['scene']}: {ours} speed-up = peer cost / {ours} cost. raw: both at dt; "
          f"at ours: the peer's Pareto front at {ours}'s error at dt; at peer's: {ours}'s front at "
          "the peer's error at dt ('cheapest': that front's cheapest point is already as accurate; "
          "'not reached': not on its ladder; 'diverged': the peer's run at dt diverged); order: slope of log error vs log step, peer/planarsim")
    print(f"{'curve':22s} {'figure':11s} {'raw':>7s} {'ours':>9s} {'at ours':>15s} {'peer':>9s} "
          f"{'at peer':>15s} {'order':>11s}  fronts cross at")
    for s in summary:
        for m in ERRORS:
            if m not in s:
                continue
            x = s[m]
            cross = ", ".join(f"{c:.2e}" for c in x["cross"]) or "-"
            print(f"{s['curve']:22s} {SHORT[m]:11s} {s['raw_ratio']:6.3g}x {x['target']:9.2e} "
                  f"{_ratio(x['ratio'], x['note']):>15s} {x['peer_target']:9.2e} "
                  f"{_ratio(x['ratio_at_peer'], x['note_at_peer']):>15s} "
                  f"{x['order']:5.2f}/{x['our_order']:<5.2f}  {cross}")
    print(flush=True)


def plot_scene(rows, path):
    """Cost against each accuracy figure (log-log), one curve per engine configuration, each
    point labelled with k; planarsim's error at the scene's dt drawn as a vertical line."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    scene = rows[0]["scene"]
    metrics = figures(rows)
    if not metrics:
        return None
    fig, axes = plt.subplots(1, len(metrics), figsize=(5.2 * len(metrics), 4.2), squeeze=False)
    by = curves(rows)
    diverged = sum(bool(r.get("warning")) for r in rows)
    for ax, m in zip(axes[0], metrics):
        for label, pts in by.items():
            pts = [r for r in pts if not r.get("warning")]
            if not pts:
                continue
            xs = [_err(r, m) for r in pts]
            ys = [r["cost_s_per_s"] for r in pts]
            style = (dict(lw=2.5, color="k") if label == "planarsim" else
                     dict(lw=2.0, ls="--") if label.startswith("planarsim") else dict(lw=1.2))
            line, = ax.loglog(xs, ys, marker="o", ls=style.pop("ls", "-"), label=label, **style)
            for x, y, r in zip(xs, ys, pts):
                ax.annotate(step_label(r["k"]), (x, y), textcoords="offset points", xytext=(3, 3), fontsize=7,
                            color=line.get_color())
        base = next(r for r in by["planarsim"] if r["k"] == 1)
        if not math.isnan(_err(base, m)):
            ax.axvline(_err(base, m), color="k", ls=":", lw=1)
        ax.set_xlabel(LABELS[m] + (f" (floor {FLOORS[m]:g})" if any(_err(r, m) == FLOORS[m] for r in rows)
                                   else ""))
        ax.set_ylabel("wall s per simulated s")
        ax.grid(True, which="both", alpha=0.3)
        ax.set_title(f"{scene}: cost vs {SHORT[m]} error"
                     + (f" ({diverged} diverged runs not drawn)" if diverged else ""), fontsize=10)
    axes[0][0].legend(fontsize=7)
    fig.text(0.01, 0.01, "labels: step (dt = the scene's 1 ms); dotted: planarsim's error at dt",
             fontsize=7)
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path
