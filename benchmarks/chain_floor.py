"""How fast the engine's algorithm can run the pendulum chains at all (not a test).

    python benchmarks/chain_floor.py                 # N = 4 and 32, median of 5 runs each
    python benchmarks/chain_floor.py --links 4 8 16 32 64
    python benchmarks/chain_floor.py --peers pymunk  # and a peer's step, timed in the same run

Times the engine on the bench chains (scenes.chain: 0.5 m, 1 kg thin rods, horizontal
at rest, dt = 1 ms) next to two dedicated chain steps written for this one model, in the
same process:

- "dedicated": the engine's algorithm with nothing general left. Gravity, a velocity solve
  of the pins aimed at their errors at q + h v* (Jacobian at the step's start), symplectic
  Euler, then Newton-SHAKE corrections along the start-of-step directions until every pin
  holds to 1e-12 m (at most 4). Fixed row layout (pin k: rows 2k, 2k+1 on links k-1, k),
  one banded LU (bandwidth 3) for both solves (the engine factors the symmetric velocity
  solve as L D L^T, half the work), no row kinds, contacts, modes, guards or state copies.
- "light": the scheme of a throwaway prototype: the velocity solve
  linearised at q + h v* (a first Newton-SHAKE step) and one correction, with no residual
  checks at all.

The first shows what the engine's generality costs; the second what a lighter scheme gains
and what it gives up (its residual and energy columns). All three are judged alike: the
largest pin gap over a 10 s run (sampled every 0.1 s), and the energy change over it as a
share of the bench's scale m g L sum(i + 1/2).

--peers (mujoco, pymunk, box2d; `pip install planarsim[compare]`): the peers' steps of the
same chains (benchmarks/peers, as `planarsim bench` times them) go round with the three
above, and each N ends with the dedicated step's ratio to the fastest of them: how fast the
engine could be against the peers with nothing general left. The fastest is the one with the
most steps/s, whatever its accuracy (the bench's raw ratio); the peers are judged the same
way as the runners above (pin gaps sampled every 0.1 s, energy change over the 10 s).
"""
from __future__ import annotations

import argparse
import math
import statistics
import sys
from pathlib import Path

import numpy as np
from numba import njit

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import planarsim as ps  # noqa: E402
from benchmarks.metrics import energy, pin_separation, spec_from_model  # noqa: E402
from benchmarks.peers import _rates  # noqa: E402
from benchmarks.scenes import G, chain  # noqa: E402

# the engine's compile flags, with numba's runtime (run_chain allocates its scratch arrays)
jit = njit(cache=True, fastmath=False, error_model="numpy")

LENGTH = 0.5       # [m] link length (scenes.chain)
MASS = 1.0         # [kg]
INERTIA = MASS * LENGTH ** 2 / 12   # [kg m^2] thin rod about its centre
INV_MASS = 1.0 / MASS
INV_INERTIA = 1.0 / INERTIA
DT = 1e-3          # [s]
TOL = ps.StepOptions().refine_tol          # [m] the engine's default
MAX_ITERS = ps.StepOptions().refine_iters  # the engine's default
BAND = 3           # rows of pin k couple to those of pins k - 1 and k + 1


@jit
def _trig(q, cs):
    for k in range(q.shape[0]):
        cs[k, 0] = math.cos(q[k, 2])
        cs[k, 1] = math.sin(q[k, 2])


@jit
def _pins(q, cs, J, c):
    """Pin k joins the right end of link k - 1 (the world origin for k = 0) to the left end
    of link k: rows 2k (x) and 2k + 1 (y); J[r, 0:3] on link k - 1, J[r, 3:6] on link k."""
    half = 0.5 * LENGTH
    for k in range(q.shape[0]):
        rbx = -half * cs[k, 0]
        rby = -half * cs[k, 1]
        rax = 0.0
        ray = 0.0
        ax = 0.0
        ay = 0.0
        if k > 0:
            rax = half * cs[k - 1, 0]
            ray = half * cs[k - 1, 1]
            ax = q[k - 1, 0] + rax
            ay = q[k - 1, 1] + ray
        x = 2 * k
        J[x, 0] = -1.0
        J[x, 1] = 0.0
        J[x, 2] = ray
        J[x, 3] = 1.0
        J[x, 4] = 0.0
        J[x, 5] = -rby
        J[x + 1, 0] = 0.0
        J[x + 1, 1] = -1.0
        J[x + 1, 2] = -rax
        J[x + 1, 3] = 0.0
        J[x + 1, 4] = 1.0
        J[x + 1, 5] = rbx
        c[x] = q[k, 0] + rbx - ax
        c[x + 1] = q[k, 1] + rby - ay


@jit
def _dot(JL, i, si, JR, j, sj):
    """The mass-weighted product of row i's block on slot si (0: link k - 1, 1: link k) with
    row j's block on slot sj: J W J^T of one shared link."""
    a = 3 * si
    b = 3 * sj
    return ((JL[i, a] * JR[j, b] + JL[i, a + 1] * JR[j, b + 1]) * INV_MASS
            + JL[i, a + 2] * JR[j, b + 2] * INV_INERTIA)


@jit
def _solve(JL, JR, A, rhs, x):
    """x = (JL W JR^T)^-1 rhs by a banded LU (rhs destroyed). Rows of pin k touch links k - 1
    and k, so A couples them to pins k - 1 and k + 1 only: a band of 3 on either side."""
    n = rhs.shape[0]
    for i in range(n):
        pin = i // 2
        for j in range(2 * pin, i + 1):             # rows of the same pin: links pin - 1, pin
            A[i, j] = _dot(JL, i, 1, JR, j, 1)
            if pin > 0:
                A[i, j] += _dot(JL, i, 0, JR, j, 0)
            if j != i:
                A[j, i] = _dot(JL, j, 1, JR, i, 1)
                if pin > 0:
                    A[j, i] += _dot(JL, j, 0, JR, i, 0)
        if pin > 0:
            for j in range(2 * pin - 2, 2 * pin):   # rows of the pin before: link pin - 1
                A[i, j] = _dot(JL, i, 0, JR, j, 1)
                A[j, i] = _dot(JL, j, 1, JR, i, 0)
    for k in range(n):
        inv = 1.0 / A[k, k]
        last = min(n, k + BAND + 1)
        for i in range(k + 1, last):
            f = A[i, k] * inv
            A[i, k] = f
            for j in range(k + 1, last):
                A[i, j] -= f * A[k, j]
            rhs[i] -= f * rhs[k]
    for k in range(n - 1, -1, -1):
        acc = rhs[k]
        for j in range(k + 1, min(n, k + BAND + 1)):
            acc -= A[k, j] * x[j]
        x[k] = acc / A[k, k]


@jit
def _apply(J, lam, dv, scale):
    """dv += scale W J^T lam."""
    for k in range(dv.shape[0]):
        for r in (2 * k, 2 * k + 1):
            l = lam[r] * scale
            if k > 0:
                dv[k - 1, 0] += J[r, 0] * l * INV_MASS
                dv[k - 1, 1] += J[r, 1] * l * INV_MASS
                dv[k - 1, 2] += J[r, 2] * l * INV_INERTIA
            dv[k, 0] += J[r, 3] * l * INV_MASS
            dv[k, 1] += J[r, 4] * l * INV_MASS
            dv[k, 2] += J[r, 5] * l * INV_INERTIA


@jit
def run_chain(q, v, n_steps, light):
    """n_steps of the dedicated chain step (light: see the module docstring) on q, v
    (N, 3) in place."""
    N = q.shape[0]
    n = 2 * N
    J0 = np.zeros((n, 6))
    J1 = np.zeros((n, 6))
    c = np.zeros(n)
    A = np.zeros((n, n))
    rhs = np.zeros(n)
    lam = np.zeros(n)
    cs = np.zeros((N, 2))
    dv = np.zeros((N, 3))
    qp = np.zeros((N, 3))
    for _ in range(n_steps):
        _trig(q, cs)
        _pins(q, cs, J0, c)
        for k in range(N):
            v[k, 1] -= G * DT
            for d in range(3):
                qp[k, d] = q[k, d] + DT * v[k, d]
        _trig(qp, cs)
        _pins(qp, cs, J1, rhs)
        for r in range(n):
            rhs[r] = -rhs[r] / DT
        _solve(J1 if light else J0, J0, A, rhs, lam)
        _apply(J0, lam, v, 1.0)
        for k in range(N):
            for d in range(3):
                q[k, d] += DT * v[k, d]
        for it in range(1 if light else MAX_ITERS + 1):
            _trig(q, cs)
            _pins(q, cs, J1, c)
            worst = 0.0
            for r in range(n):
                worst = max(worst, abs(c[r]))
                rhs[r] = -c[r]
            if not light and (worst <= TOL or it == MAX_ITERS):
                break
            _solve(J1, J0, A, rhs, lam)
            dv[:] = 0.0
            _apply(J0, lam, dv, 1.0)
            for k in range(N):
                for d in range(3):
                    q[k, d] += dv[k, d]
                    v[k, d] += dv[k, d] / DT


def _print_row(n_links, key, rates, spec, poses, start, end):
    """One runner's or peer's line: steps/s, ratio to the engine, largest pin gap over the
    sampled poses, energy change from start (q, v) to end (q, v) as a share of the scale."""
    drift = (energy(spec, *end) - energy(spec, *start)) / spec.energy_scale
    print(f"{n_links:3d}  {key:10s} {rates[key] / 1e3:8.0f}k  "
          f"{rates[key] / rates['engine']:8.2f}  "
          f"{pin_separation(spec, poses):15.1e}  {drift:+21.2%}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--links", type=int, nargs="+", default=[4, 32])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--peers", default="none",
                    help="comma-separated peers timed alongside (mujoco, pymunk, box2d; 'all')")
    args = ap.parse_args(argv)
    if any(n < 1 for n in args.links):
        ap.error("--links: every chain needs at least one link")
    peers = {}
    if args.peers != "none":
        from benchmarks.peers import PEER_MODULES, available_peers
        names = None if args.peers == "all" else [x.strip() for x in args.peers.split(",")]
        unknown = [x for x in names or () if x not in PEER_MODULES]
        if unknown:
            ap.error(f"--peers: unknown {', '.join(unknown)}; "
                     f"peers: {', '.join(sorted(PEER_MODULES))}")
        peers, missing = available_peers(names)
        for line in missing:
            print(line, file=sys.stderr)
        if not peers:
            print("chain_floor: no peer to time (see above)", file=sys.stderr)
            return 1
    n_steps, n_accuracy = 5000, 10000      # 5 s timing episode, 10 s accuracy run (the bench's)
    print(f"{'N':>3s}  {'runner':10s} {'steps/s':>9s}  {'x engine':>8s}  {'largest pin gap':>15s}  "
          f"{'energy change / scale':>21s}")
    for n_links in args.links:
        model = chain(n_links, dt=DT, length=LENGTH, mass=MASS)
        spec = spec_from_model(f"chain{n_links}", model, n_accuracy * DT)
        box = {}

        def reset_engine():
            box["sim"] = ps.Simulator(model)

        def reset_dedicated():
            box["q"], box["v"] = model.q0.copy(), np.zeros((n_links, 3))
        # runner: (run n steps, reset to the start (not timed), current (q, v))
        runners = {
            "engine": (lambda n: box["sim"].steps(n), reset_engine,
                       lambda: (box["sim"].state.q, box["sim"].state.v)),
            "dedicated": (lambda n: run_chain(box["q"], box["v"], n, False), reset_dedicated,
                          lambda: (box["q"], box["v"])),
            "light": (lambda n: run_chain(box["q"], box["v"], n, True), reset_dedicated,
                      lambda: (box["q"], box["v"])),
        }
        worlds = {key: mod.World(spec) for key, mod in peers.items()}
        engines = {key: r[:2] for key, r in runners.items()}
        engines.update({key: (w.run, w.reset) for key, w in worlds.items()})
        timed = _rates(engines, n_steps, args.repeats)
        rates = {key: statistics.median(r) for key, r in timed.items()}
        for key, (run, reset, pose) in runners.items():
            # accuracy: poses sampled every 100 steps (0.1 s) over the 10 s run
            reset()
            q0, v0 = (x.copy() for x in pose())
            poses = [q0]
            for _ in range(n_accuracy // 100):
                run(100)
                poses.append(pose()[0].copy())
            _print_row(n_links, key, rates, spec, np.array(poses), (q0, v0), pose())
        for key, world in worlds.items():
            q, v = world.record(n_accuracy)      # every step: sampled as the runners'
            _print_row(n_links, key, rates, spec, q[::100], (q[0], v[0]), (q[-1], v[-1]))
        if worlds:
            best = max(worlds, key=lambda k: rates[k])
            print(f"{n_links:3d}  dedicated / fastest peer ({best}): "
                  f"{rates['dedicated'] / rates[best]:.2f}x; engine / {best}: "
                  f"{rates['engine'] / rates[best]:.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
