"""The chains' accuracy-matched tables of docs/benchmarks.md, made from the pareto.csv that
`planarsim bench chain4 ... chain64 --parts pareto --pareto-out DIR` writes.

    python -m benchmarks.pareto_tables DIR/pareto.csv

Table 1, per chain at the scene's dt (1 ms): each planarsim curve's and MuJoCo RK4's cost [ms
of wall time per simulated s] and energy error (|dE| max / scale over 10 s); "at ours": RK4's
cost on its Pareto front at that curve's error over the curve's cost at dt; the observed orders
(pareto.order). Table 2: RK4's cost over planarsim's on their fronts at each energy error,
for the default step alone and for the default step with rattle and rattle4 (pareto.front,
pareto.cost_at; "-": a front does not reach that error)."""
from __future__ import annotations

import csv
import math
import sys

from benchmarks.pareto import cost_at, curves, front, order

OURS = ("planarsim", "planarsim-rattle", "planarsim-rattle4")
PEER = "mujoco RK4"
ERRORS = (1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7)


def load(path):
    """{scene: [rows]} of pareto.csv, numbers as floats (warning kept as text)."""
    out = {}
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            row = {}
            for key, val in r.items():
                try:
                    row[key] = float(val)
                except (TypeError, ValueError):
                    row[key] = val
            out.setdefault(r["scene"], []).append(row)
    return out


def _at_dt(rows):
    return next(r for r in rows if r["k"] == 1)


def _x(ratio):
    return "-" if math.isnan(ratio) else f"{ratio:.2g}x"


def table_at_dt(scenes):
    lines = ["| chain | planarsim | planarsim-rattle | planarsim-rattle4 | RK4 | at ours: default / rattle / rattle4 "
             "| orders default / rattle / rattle4 / RK4 |", "|---|---|---|---|---|---|---|"]
    for scene, rows in scenes.items():
        by = curves(rows)
        peer = front(by[PEER], "energy_err_max")
        cells, ratios = [], []
        for label in OURS + (PEER,):
            r = _at_dt(by[label])
            cells.append(f"{r['cost_s_per_s'] * 1e3:.3g}, {r['energy_err_max']:.1e}")
        for label in OURS:
            r = _at_dt(by[label])
            cost, _ = cost_at(peer, r["energy_err_max"])
            ratios.append(_x(cost / r["cost_s_per_s"]))
        orders = " / ".join(f"{order(by[label], 'energy_err_max'):.1f}" for label in OURS + (PEER,))
        lines.append(f"| {scene[5:]} | " + " | ".join(cells) + f" | {' / '.join(ratios)} | {orders} |")
    return "\n".join(lines)


def table_on_fronts(scenes):
    lines = ["| chain | planarsim's curves | " + " | ".join(f"{e:.0e}" for e in ERRORS) + " |",
             "|---|---|" + "---:|" * len(ERRORS)]
    for scene, rows in scenes.items():
        by = curves(rows)
        peer = front(by[PEER], "energy_err_max")
        for name, labels in (("default only", OURS[:1]), ("default, rattle, rattle4", OURS)):
            ours = front([r for label in labels for r in by[label]], "energy_err_max")
            cells = []
            for e in ERRORS:
                a, b = cost_at(peer, e)[0], cost_at(ours, e)[0]
                cells.append(_x(a / b))
            lines.append(f"| {scene[5:]} | {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 1:
        print(__doc__.split("\n\n")[1].strip(), file=sys.stderr)
        return 2
    scenes = {s: rows for s, rows in load(argv[0]).items() if s.startswith("chain")}
    if not scenes:
        print(f"{argv[0]}: no chain scenes", file=sys.stderr)
        return 1
    print(table_at_dt(scenes))
    print()
    print(table_on_fronts(scenes))
    return 0


if __name__ == "__main__":
    sys.exit(main())
