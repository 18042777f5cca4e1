"""What each stage of the step costs on its own: ns per call of the engine's kernels on a
bench scene's workspace (not a test).

    python benchmarks/kernel_times.py chain4
    python benchmarks/kernel_times.py biped_collapse --warm-steps 1000

The scene runs --warm-steps steps (its workspace then holds that step's rows, contacts and
factor); then each kernel is called --calls times in one compiled loop on a fresh copy of that
simulator, best of --repeats, less the loop's own cost (the "empty" line). A kernel that moves
the state (the whole step, the energy bound) keeps moving it while it is timed, so its figure
is of a nearby state. Kernels timed on their own lose what LLVM gains by inlining them into
the step: their sum is an upper bound. For the shares of a real run, see profile_kernels.py;
for what removing a stage saves, time the whole step ("step") with the stage taken out.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import planarsim as ps  # noqa: E402
from benchmarks.scenes import SCENES  # noqa: E402
from planarsim.compiled import jit, step  # noqa: E402
from planarsim.kernels.checks.audit import audit_impulses  # noqa: E402
from planarsim.kernels.geometry.contacts import find_contacts  # noqa: E402
from planarsim.kernels.checks.guards import check_guards  # noqa: E402
from planarsim.kernels.dynamics.integrate import bound_correction_work, max_residual  # noqa: E402
from planarsim.kernels.math2d import update_trig  # noqa: E402
from planarsim.kernels.solver.modes import engage_limits, rule_breaks  # noqa: E402
from planarsim.kernels.constraints.rows import build_rows  # noqa: E402
from planarsim.kernels.solver.matrix import assemble, factor_solve  # noqa: E402
from planarsim.kernels.solver.solve import solve_impulses  # noqa: E402
from planarsim.kernels.step import copy_state  # noqa: E402
from planarsim.kernels.checks.work import joints_add_energy  # noqa: E402

KERNELS = (
    ("empty", "the loop alone"),
    ("step", "the whole step"),
    ("build_rows", "the rows at q and the joints' errors at q + h v*"),
    ("solve_impulses", "the velocity solve: envelope, L D L^T, substitution, impulses"),
    ("correction_solve", "the correction's non-symmetric assembly, LU and substitution"),
    ("max_residual", "the rows' errors at q (sin / cos cached)"),
    ("update_trig", "sin / cos of every body"),
    ("copy_state", "the step's start kept in ws.prev"),
    ("check_guards", "the state's finite and size checks"),
    ("engage_limits", "joint limits the velocity would pass"),
    ("rule_breaks", "the answer's check against the contact and limit rules"),
    ("joints_add_energy", "the joints' energy check"),
    ("bound_correction_work", "the correction's energy bound"),
    ("audit_impulses", "the audit of the contact and joint impulses"),
    ("find_contacts", "the contacts' ground queries and pair search"),
)


@jit
def _run(m, s, ws, opt, u, which, calls):
    """`calls` calls of kernel number `which` (KERNELS) at step length m.dt."""
    h = m.dt
    acc = 0.0
    for _ in range(calls):
        n = ws.n_row[0]
        if which == 1:
            acc += step(m, s, ws, opt, u)
        elif which == 2:
            acc += build_rows(m, s, ws, h)
        elif which == 3:
            acc += solve_impulses(m, s, ws, h, opt.pivot_tol, True, False)
        elif which == 4:
            for r in range(n):
                ws.rhs[r] = 1.0
            assemble(m, ws, ws.row_Jp, ws.row_J, n, False)
            acc += factor_solve(ws, ws.rhs, ws.lam, n, opt.refine_pivot_tol)
        elif which == 5:
            acc += max_residual(m, s, ws)
        elif which == 6:
            for i in range(ws.body_cs.shape[0]):
                ws.body_cs[i, 2] = 1e300      # not the angle: computed again
            update_trig(s.q, ws.body_cs)
        elif which == 7:
            copy_state(s, ws.prev)
        elif which == 8:
            acc += check_guards(s, ws, opt.guard_limit)
        elif which == 9:
            acc += engage_limits(m, s, ws, h, ws.v_new)
        elif which == 10:
            acc += rule_breaks(m, s, ws, h, False)
        elif which == 11:
            acc += joints_add_energy(m, s, ws, h)[0]
        elif which == 12:
            acc += bound_correction_work(m, s, ws, h, False)
        elif which == 13:
            acc += audit_impulses(m, s, ws, opt, h)
        elif which == 14:
            find_contacts(m, s, ws, h)
        else:
            acc += 1.0
    return acc


def kernel_times(scene, warm_steps=300, calls=20000, repeats=5):
    """{kernel: ns per call} on `scene` after `warm_steps` steps (module docstring)."""
    if scene not in SCENES:
        raise SystemExit(f"unknown scene {scene!r}; scenes: {', '.join(SCENES)}")
    model = SCENES[scene][0]()

    def fresh():
        sim = ps.Simulator(model)
        sim.steps(warm_steps - 1)
        sim.ws.chain_on[0] = 0      # (the last step by the general stages: the chain path
        sim.steps(1)                # leaves no row arrays for the kernels timed here)
        return (sim.model.arrays, sim.state, sim.ws, sim.options, sim._u0)

    out = {}
    for which, (name, _) in enumerate(KERNELS):
        _run(*fresh(), which, 1)                      # compile or load
        best = float("inf")
        for _ in range(repeats):
            args = fresh()
            t0 = time.perf_counter()
            _run(*args, which, calls)
            best = min(best, time.perf_counter() - t0)
        out[name] = best / calls * 1e9
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene", help=", ".join(SCENES))
    ap.add_argument("--warm-steps", type=int, default=300)
    ap.add_argument("--calls", type=int, default=20000)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args(argv)
    if args.warm_steps < 1 or args.calls < 1 or args.repeats < 1:
        ap.error("--warm-steps, --calls and --repeats must be at least 1")
    times = kernel_times(args.scene, args.warm_steps, args.calls, args.repeats)
    empty = times.pop("empty")
    print(f"{args.scene} after {args.warm_steps} steps: ns per call, less the loop's "
          f"{empty:.1f} ns (best of {args.repeats} x {args.calls} calls)")
    for name, what in KERNELS[1:]:
        print(f"  {name:22s} {max(times[name] - empty, 0.0):9.1f}   {what}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
