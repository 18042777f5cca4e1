"""How fast the engine's algorithm can run the pendulum chains at all (not a test).

    python benchmarks/chain_floor.py                 # N = 4 and 32, median of 5 runs each
    python benchmarks/chain_floor.py --links 2 4 8 16 32 64 --peers pymunk box2d mujoco

Times the engine on the bench chains (scenes.chain: 0.5 m, 1 kg thin rods pinned end to end,
link 0 to the world, horizontal at rest, dt = 1 ms) next to "dedicated", a step written for
this one model, in the same process.

"dedicated" is the engine's scheme with nothing general left: symplectic Euler with the pins
enforced at the step's end, i.e. gravity, then q+ = q + h v* + W J0^T mu with mu such that
every pin holds at q+ to 1e-12 m (J0: the pins' Jacobian at the step's start, W the inverse
masses), v+ = v* + W J0^T mu / h. The same answer as the engine's (a velocity solve aimed at
the gaps at q + h v*, then Newton corrections along J0 to 1e-12 m) to rounding, computed as:

- Newton on C(q + h v* + W J0^T mu) = 0, the first pass (the velocity solve) linearised at
  the prediction, started from mu extrapolated from the last three steps' (3 mu1 - 3 mu2 +
  mu3); later passes reuse the first pass's factorisation (a fresh one only while some gap is
  still above 1e-9 m), and the corrections stop at the first pass whose gaps are all within
  1e-12 m (at most the engine's 4 corrections). A Newton pass that turned no link by more
  than 1e-6 rad needs no measuring: its gaps are the turns' second-order terms, within
  (L/2) dtheta^2 <= 1e-12 m / 4;
- J W J0^T is block tridiagonal with 2x2 blocks (pin k couples to pins k - 1 and k + 1
  through links k - 1 and k): a block LU, twisted (pivots eliminated from both ends of the
  chain at once, two independent chains of dependent products half as long, meeting at the
  middle pin), each pivot's inverse as adj / det so that the division is off the products'
  path;
- (cos, sin) of every angle carried from step to step and turned by each increment with its
  Taylor series (Estrin's order; two terms for corrections under 1e-4 rad, math.cos/sin above
  0.1 rad), resynced from theta every 64 steps;
- every per-body (or per-pin) quantity a row of one work array at a row stride that is a
  compile-time constant (kernels for up to 7 and up to 263 links; longer chains take a
  kernel with the stride known at run time only), so the compiler sees the rows disjoint and
  the loops over bodies (prediction, gaps, corrections, velocities) vectorise without
  runtime overlap checks; the multipliers' history, the carried (cos, sin) and the counters
  are part of the state (fresh_state), so a run split into calls anywhere gives the same
  bits.
No row kinds, contacts, modes, guards or state copies; fastmath stays off, as in the engine
(it would change the bits). The "light" runner of earlier versions (a velocity solve
linearised at the prediction and one unchecked correction) is gone: the dedicated step now
takes that linearisation and still checks every gap.

Both runners are judged alike: the largest pin gap over a 10 s run (sampled every 0.1 s), and
the energy change over it as a share of the bench's scale m g L sum(i + 1/2).

--peers (mujoco, pymunk, box2d, apart or comma-separated, or all; `pip install
planarsim[compare]`): the peers' steps of the same chains (benchmarks/peers, as `planarsim
bench` times them) go round with the two above, and each N ends with the dedicated step's
ratio to the fastest of them (the "x peer" column): how fast the engine's scheme can be
against the peers with nothing general left. The fastest is the one with the most steps/s,
whatever its accuracy (the bench's raw ratio); the peers are judged the same way as the
runners above (pin gaps sampled every 0.1 s, energy change over the 10 s).
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
HALF = 0.5 * LENGTH
RESYNC = 64        # steps between resyncs of the carried (cos, sin) from theta
TAYLOR_MAX = 0.1   # [rad] increments up to this turn (cos, sin) by the series below
TOL2 = TOL * TOL
NUDGE_MAX = 1e-4   # [rad] corrections up to this turn (cos, sin) by the shorter series
CLOSED_TURN = math.sqrt(TOL / (4 * HALF))   # [rad] see the end of a Newton pass
FAR = 1e-9         # [m] gaps above this after a correction: factor again (else reuse)
FAR2 = FAR * FAR


@njit(inline="always")
def _turn(c, s, d):
    """(cos, sin) of theta + d from those of theta: Taylor series of cos d and sin d to
    d^8 and d^9 (error below 3e-17 for |d| <= TAYLOR_MAX), summed in Estrin's order (a
    shorter chain of dependent products than Horner's)."""
    d2 = d * d
    d4 = d2 * d2
    d8 = d4 * d4
    cd = (1.0 - d2 * (1.0 / 2)) + d4 * (1.0 / 24 - d2 * (1.0 / 720)) + d8 * (1.0 / 40320)
    sd = d * ((1.0 - d2 * (1.0 / 6)) + d4 * (1.0 / 120 - d2 * (1.0 / 5040))
              + d8 * (1.0 / 362880))
    return c * cd - s * sd, s * cd + c * sd


@njit(inline="always")
def _nudge(c, s, d):
    """_turn for |d| <= NUDGE_MAX: cos d = 1 - d^2 / 2, sin d = d - d^3 / 6 (error below
    5e-18)."""
    d2 = d * d
    cd = 1.0 - d2 * (1.0 / 2)
    sd = d - d * d2 * (1.0 / 6)
    return c * cd - s * sd, s * cd + c * sd


@njit(inline="always")
def _pivot(s00, s01, s10, s11, inv, b00, b01, b10, b11, e00, e01, e10, e11):
    """(P, 1 / det P) of the pivot P = E - B S^-1 B that eliminating a pin whose pivot is S
    (inv = 1 / det S) leaves on its neighbour (coupling B, diagonal block E): S^-1 as
    adj(S) / det S, the division off the path of the products."""
    p00, p01, p10, p11 = _schur(s00, s01, s10, s11, inv, b00, b01, b10, b11,
                                e00, e01, e10, e11)
    return p00, p01, p10, p11, 1.0 / (p00 * p11 - p01 * p10)


@njit(inline="always")
def _schur(s00, s01, s10, s11, inv, b00, b01, b10, b11, e00, e01, e10, e11):
    """E - B S^-1 B (see _pivot)."""
    t00 = b00 * s11 - b01 * s10
    t01 = b01 * s00 - b00 * s01
    t10 = b10 * s11 - b11 * s10
    t11 = b11 * s00 - b10 * s01
    p00 = e00 - (t00 * b00 + t01 * b10) * inv
    p01 = e01 - (t00 * b01 + t01 * b11) * inv
    p10 = e10 - (t10 * b00 + t11 * b10) * inv
    p11 = e11 - (t10 * b01 + t11 * b11) * inv
    return p00, p01, p10, p11


@jit
def _coefficients(nh):
    """Weights of the newest, the one before and the oldest of nh steps' multipliers in the
    next step's first guess: quadratic extrapolation (linear, constant, none at the start)."""
    if nh >= 3:
        return 3.0, -3.0, 1.0
    if nh == 2:
        return 2.0, -1.0, 0.0
    if nh == 1:
        return 1.0, 0.0, 0.0
    return 0.0, 0.0, 0.0


@njit(inline="always")
def _run(q, v, cs, hist, count, n_steps, NM):
    """run_chain's kernel. Every per-body or per-pin quantity is a row of one flat array W at
    stride NM. Inlined where NM is a constant (_run_short, _run_long), the compiler sees
    that the rows are disjoint and vectorises the loops over bodies without runtime checks
    of overlap (which cost more than the loops themselves at 8 to 32 links)."""
    N = q.shape[0]
    h = DT
    im = INV_MASS
    ii = INV_INERTIA
    X_ = 0 * NM
    Y_ = 1 * NM
    T_ = 2 * NM
    VX_ = 3 * NM
    VY_ = 4 * NM
    VW_ = 5 * NM
    C_ = 6 * NM
    S_ = 7 * NM
    QX_ = 8 * NM
    QY_ = 9 * NM
    QT_ = 10 * NM
    CN_ = 11 * NM
    SN_ = 12 * NM
    U0X_ = 13 * NM
    U0Y_ = 14 * NM
    GX_ = 15 * NM
    GY_ = 16 * NM
    DX_ = 17 * NM
    DY_ = 18 * NM
    DT__ = 19 * NM
    R00_ = 20 * NM
    R01_ = 21 * NM
    R10_ = 22 * NM
    R11_ = 23 * NM
    RX_ = 24 * NM
    RY_ = 25 * NM
    ZX_ = 26 * NM
    ZY_ = 27 * NM
    H0X_ = 28 * NM
    H0Y_ = 29 * NM
    H1X_ = 30 * NM
    H1Y_ = 31 * NM
    H2X_ = 32 * NM
    H2Y_ = 33 * NM
    W = np.zeros(34 * NM)
    for k in range(N):
        W[X_ + k] = q[k, 0]
        W[Y_ + k] = q[k, 1]
        W[T_ + k] = q[k, 2]
        W[VX_ + k] = v[k, 0]
        W[VY_ + k] = v[k, 1]
        W[VW_ + k] = v[k, 2]
        W[C_ + k] = cs[k, 0]
        W[S_ + k] = cs[k, 1]
        W[H0X_ + k] = hist[0, 0, k]
        W[H0Y_ + k] = hist[0, 1, k]
        W[H1X_ + k] = hist[1, 0, k]
        W[H1Y_ + k] = hist[1, 1, k]
        W[H2X_ + k] = hist[2, 0, k]
        W[H2Y_ + k] = hist[2, 1, k]
    # the factorisation, per pin: FS the pivot's inverse S_k^-1, FM = S_k^-1 (coupling to
    # the next pin of its sweep), FB the coupling to the one before (the middle pin: FB to
    # mid - 1, FM to mid + 1); Z the forward sweeps' unknowns
    FS = np.empty((N, 4))
    FM = np.empty((N, 4))
    FB = np.empty((N, 4))
    mid = N // 2            # the pin where the two eliminations meet
    nbot = N - 1 - mid      # pins eliminated from the bottom
    # the first guess of mu: extrapolated from the history (newest first)
    a0, a1, a2 = _coefficients(count[1])
    for k in range(N):
        W[GX_ + k] = a0 * W[H0X_ + k] + a1 * W[H1X_ + k] + a2 * W[H2X_ + k]
        W[GY_ + k] = a0 * W[H0Y_ + k] + a1 * W[H1Y_ + k] + a2 * W[H2Y_ + k]
    for _ in range(n_steps):
        if count[0] % RESYNC == 0:
            for k in range(N):
                W[C_ + k] = math.cos(W[T_ + k])
                W[S_ + k] = math.sin(W[T_ + k])
        # gravity, and the prediction q + h v* + W J0^T mu
        big = 0
        for k in range(N):
            W[VY_ + k] -= G * h
            u0x = HALF * W[S_ + k]
            u0y = -HALF * W[C_ + k]
            W[U0X_ + k] = u0x
            W[U0Y_ + k] = u0y
            gx = W[GX_ + k]
            gy = W[GY_ + k]
            gx1 = W[GX_ + k + 1]
            gy1 = W[GY_ + k + 1]
            dx = h * W[VX_ + k] + (gx - gx1) * im
            dy = h * W[VY_ + k] + (gy - gy1) * im
            dt = h * W[VW_ + k] + (u0x * (gx + gx1) + u0y * (gy + gy1)) * ii
            W[QX_ + k] = W[X_ + k] + dx
            W[QY_ + k] = W[Y_ + k] + dy
            W[QT_ + k] = W[T_ + k] + dt
            W[DT__ + k] = dt
            big += abs(dt) > TAYLOR_MAX
        for k in range(N):
            W[CN_ + k], W[SN_ + k] = _turn(W[C_ + k], W[S_ + k], W[DT__ + k])
            # W[CN_ + k] = c * cd - s * sd
        if big:
            for k in range(N):
                if abs(W[DT__ + k]) > TAYLOR_MAX:
                    W[CN_ + k] = math.cos(W[QT_ + k])
                    W[SN_ + k] = math.sin(W[QT_ + k])
        # Newton on C(q* + W J0^T mu) = 0. A pass: the gaps at the iterate (every pin's at
        # once); stop when all are <= TOL (after the first pass); else factor J(q) W J0^T at
        # the iterate (the first pass, or when the gaps are still far from closed) or reuse
        # the last factorisation, solve, and apply the correction.
        for it in range(MAX_ITERS + 2):
            # pin k: left end of link k minus right end of link k - 1 (the origin for k = 0)
            rx = W[QX_ + 0] - HALF * W[CN_ + 0]
            ry = W[QY_ + 0] - HALF * W[SN_ + 0]
            W[RX_ + 0] = rx
            W[RY_ + 0] = ry
            g = rx * rx + ry * ry
            bad = g > TOL2
            far = g > FAR2
            for k in range(1, N):
                rx = (W[QX_ + k] - HALF * W[CN_ + k]) - (W[QX_ + k - 1] + HALF * W[CN_ + k - 1])
                ry = (W[QY_ + k] - HALF * W[SN_ + k]) - (W[QY_ + k - 1] + HALF * W[SN_ + k - 1])
                W[RX_ + k] = rx
                W[RY_ + k] = ry
                g = rx * rx + ry * ry
                bad |= g > TOL2
                far |= g > FAR2
            if it > 0:
                count[2] += 1
                if not bad or it == MAX_ITERS + 1:
                    break
            newton = it == 0 or far
            if newton:
                count[3] += 1
                # block LU of A = J W J0^T: diagonal blocks D_k = I/m + R_k (+ I/m + R_{k-1}),
                # B_k = R_k - I/m between pins k and k + 1 both ways, R_k = (1/I) un_k u0_k^T
                # (un at the iterate). Twisted: pivots eliminated from both ends at once (two
                # independent chains of half the length) until they meet at pin mid.
                for k in range(N):
                    hs = HALF * W[SN_ + k] * ii
                    hc = -HALF * W[CN_ + k] * ii
                    W[R00_ + k] = hs * W[U0X_ + k]
                    W[R01_ + k] = hs * W[U0Y_ + k]
                    W[R10_ + k] = hc * W[U0X_ + k]
                    W[R11_ + k] = hc * W[U0Y_ + k]
                # top: pins 0, 1, ..., mid - 1, S_k = D_k - B_{k-1} S_{k-1}^-1 B_{k-1}
                ts00, ts01, ts10, ts11, tinv = 1.0, 0.0, 0.0, 1.0, 0.0
                tb00, tb01, tb10, tb11 = 0.0, 0.0, 0.0, 0.0
                tzx, tzy = 0.0, 0.0
                # bottom: pins N - 1, ..., mid + 1, S_k = D_k - B_k S_{k+1}^-1 B_k
                bs00, bs01, bs10, bs11, binv = 1.0, 0.0, 0.0, 1.0, 0.0
                bb00, bb01, bb10, bb11 = 0.0, 0.0, 0.0, 0.0
                bzx, bzy = 0.0, 0.0
                for i in range(mid):
                    k = i
                    e00 = im + W[R00_ + k]
                    e01 = W[R01_ + k]
                    e10 = W[R10_ + k]
                    e11 = im + W[R11_ + k]
                    if k > 0:
                        e00 += tb00 + 2.0 * im      # I/m + R_{k-1} = B_{k-1} + 2 I/m
                        e01 += tb01
                        e10 += tb10
                        e11 += tb11 + 2.0 * im
                    ts00, ts01, ts10, ts11, tinv = _pivot(ts00, ts01, ts10, ts11, tinv,
                                                          tb00, tb01, tb10, tb11,
                                                          e00, e01, e10, e11)
                    i00 = ts11 * tinv
                    i01 = -ts01 * tinv
                    i10 = -ts10 * tinv
                    i11 = ts00 * tinv
                    yx = W[RX_ + k] + tb00 * tzx + tb01 * tzy     # -(the right-hand side)
                    yy = W[RY_ + k] + tb10 * tzx + tb11 * tzy
                    tzx = -(i00 * yx + i01 * yy)
                    tzy = -(i10 * yx + i11 * yy)
                    FB[k, 0] = tb00
                    FB[k, 1] = tb01
                    FB[k, 2] = tb10
                    FB[k, 3] = tb11
                    tb00 = W[R00_ + k] - im                      # B_k, towards the middle
                    tb01 = W[R01_ + k]
                    tb10 = W[R10_ + k]
                    tb11 = W[R11_ + k] - im
                    FS[k, 0] = i00
                    FS[k, 1] = i01
                    FS[k, 2] = i10
                    FS[k, 3] = i11
                    FM[k, 0] = i00 * tb00 + i01 * tb10     # S_k^-1 B_k
                    FM[k, 1] = i00 * tb01 + i01 * tb11
                    FM[k, 2] = i10 * tb00 + i11 * tb10
                    FM[k, 3] = i10 * tb01 + i11 * tb11
                    W[ZX_ + k] = tzx
                    W[ZY_ + k] = tzy
                    if i < nbot:
                        k = N - 1 - i
                        c00 = W[R00_ + k - 1] - im               # B_{k-1}, towards the middle
                        c01 = W[R01_ + k - 1]
                        c10 = W[R10_ + k - 1]
                        c11 = W[R11_ + k - 1] - im
                        e00 = (im + W[R00_ + k]) + (c00 + 2.0 * im)
                        e01 = W[R01_ + k] + c01
                        e10 = W[R10_ + k] + c10
                        e11 = (im + W[R11_ + k]) + (c11 + 2.0 * im)
                        bs00, bs01, bs10, bs11, binv = _pivot(bs00, bs01, bs10, bs11, binv,
                                                              bb00, bb01, bb10, bb11,
                                                              e00, e01, e10, e11)
                        i00 = bs11 * binv
                        i01 = -bs01 * binv
                        i10 = -bs10 * binv
                        i11 = bs00 * binv
                        yx = W[RX_ + k] + bb00 * bzx + bb01 * bzy
                        yy = W[RY_ + k] + bb10 * bzx + bb11 * bzy
                        bzx = -(i00 * yx + i01 * yy)
                        bzy = -(i10 * yx + i11 * yy)
                        FB[k, 0] = bb00
                        FB[k, 1] = bb01
                        FB[k, 2] = bb10
                        FB[k, 3] = bb11
                        bb00, bb01, bb10, bb11 = c00, c01, c10, c11
                        FS[k, 0] = i00
                        FS[k, 1] = i01
                        FS[k, 2] = i10
                        FS[k, 3] = i11
                        FM[k, 0] = i00 * c00 + i01 * c10    # S_k^-1 B_{k-1}
                        FM[k, 1] = i00 * c01 + i01 * c11
                        FM[k, 2] = i10 * c00 + i11 * c10
                        FM[k, 3] = i10 * c01 + i11 * c11
                        W[ZX_ + k] = bzx
                        W[ZY_ + k] = bzy
                # pin mid: both neighbours' eliminations (tb: B_{mid-1}, bb: B_mid)
                k = mid
                e00 = im + W[R00_ + k]
                e01 = W[R01_ + k]
                e10 = W[R10_ + k]
                e11 = im + W[R11_ + k]
                if k > 0:
                    e00 += tb00 + 2.0 * im
                    e01 += tb01
                    e10 += tb10
                    e11 += tb11 + 2.0 * im
                e00, e01, e10, e11 = _schur(bs00, bs01, bs10, bs11, binv,
                                            bb00, bb01, bb10, bb11, e00, e01, e10, e11)
                ts00, ts01, ts10, ts11, tinv = _pivot(ts00, ts01, ts10, ts11, tinv,
                                                      tb00, tb01, tb10, tb11,
                                                      e00, e01, e10, e11)
                FS[k, 0] = ts11 * tinv
                FS[k, 1] = -ts01 * tinv
                FS[k, 2] = -ts10 * tinv
                FS[k, 3] = ts00 * tinv
                FB[k, 0] = tb00
                FB[k, 1] = tb01
                FB[k, 2] = tb10
                FB[k, 3] = tb11
                FM[k, 0] = bb00                             # the middle keeps B_mid here
                FM[k, 1] = bb01
                FM[k, 2] = bb10
                FM[k, 3] = bb11
            else:
                tzx, tzy, bzx, bzy = 0.0, 0.0, 0.0, 0.0
                for i in range(mid):
                    k = i
                    yx = W[RX_ + k] + FB[k, 0] * tzx + FB[k, 1] * tzy
                    yy = W[RY_ + k] + FB[k, 2] * tzx + FB[k, 3] * tzy
                    tzx = -(FS[k, 0] * yx + FS[k, 1] * yy)
                    tzy = -(FS[k, 2] * yx + FS[k, 3] * yy)
                    W[ZX_ + k] = tzx
                    W[ZY_ + k] = tzy
                    if i < nbot:
                        k = N - 1 - i
                        yx = W[RX_ + k] + FB[k, 0] * bzx + FB[k, 1] * bzy
                        yy = W[RY_ + k] + FB[k, 2] * bzx + FB[k, 3] * bzy
                        bzx = -(FS[k, 0] * yx + FS[k, 1] * yy)
                        bzy = -(FS[k, 2] * yx + FS[k, 3] * yy)
                        W[ZX_ + k] = bzx
                        W[ZY_ + k] = bzy
            # the middle pin's unknown, then back substitution outwards from it
            k = mid
            yx = W[RX_ + k] + FB[k, 0] * tzx + FB[k, 1] * tzy + FM[k, 0] * bzx + FM[k, 1] * bzy
            yy = W[RY_ + k] + FB[k, 2] * tzx + FB[k, 3] * tzy + FM[k, 2] * bzx + FM[k, 3] * bzy
            mx = -(FS[k, 0] * yx + FS[k, 1] * yy)
            my = -(FS[k, 2] * yx + FS[k, 3] * yy)
            W[DX_ + k] = mx
            W[DY_ + k] = my
            txx, txy, bxx, bxy = mx, my, mx, my
            for i in range(1, mid + 1):
                k = mid - i
                nx = W[ZX_ + k] - (FM[k, 0] * txx + FM[k, 1] * txy)
                txy = W[ZY_ + k] - (FM[k, 2] * txx + FM[k, 3] * txy)
                txx = nx
                W[DX_ + k] = txx
                W[DY_ + k] = txy
                if i <= nbot:
                    k = mid + i
                    nx = W[ZX_ + k] - (FM[k, 0] * bxx + FM[k, 1] * bxy)
                    bxy = W[ZY_ + k] - (FM[k, 2] * bxx + FM[k, 3] * bxy)
                    bxx = nx
                    W[DX_ + k] = bxx
                    W[DY_ + k] = bxy
            nudge = 0
            big = 0
            coarse = 0
            for k in range(N):
                nx = W[DX_ + k]
                ny = W[DY_ + k]
                xx = W[DX_ + k + 1]
                xy = W[DY_ + k + 1]
                dt = (W[U0X_ + k] * (nx + xx) + W[U0Y_ + k] * (ny + xy)) * ii
                W[QX_ + k] += (nx - xx) * im
                W[QY_ + k] += (ny - xy) * im
                W[QT_ + k] += dt
                W[DT__ + k] = dt
                W[GX_ + k] += nx
                W[GY_ + k] += ny
                nudge += abs(dt) > NUDGE_MAX
                big += abs(dt) > TAYLOR_MAX
                coarse += abs(dt) > CLOSED_TURN
            if nudge:
                for k in range(N):
                    W[CN_ + k], W[SN_ + k] = _turn(W[CN_ + k], W[SN_ + k], W[DT__ + k])
            else:
                for k in range(N):
                    W[CN_ + k], W[SN_ + k] = _nudge(W[CN_ + k], W[SN_ + k], W[DT__ + k])
            if big:
                for k in range(N):
                    if abs(W[DT__ + k]) > TAYLOR_MAX:
                        W[CN_ + k] = math.cos(W[QT_ + k])
                        W[SN_ + k] = math.sin(W[QT_ + k])
            # after a Newton pass (the Jacobian of the iterate's own gaps) the new gaps are
            # the turns' second-order terms, at most (L/2) max dtheta^2 (the translations are
            # linear): with every turn within CLOSED_TURN every gap is within TOL / 4, closed
            # without measuring them again
            if newton and not coarse:
                break
        # v = v* + W J0^T mu / h; the step's end is the iterate; mu into the history and the
        # next step's first guess (quadratic extrapolation of the last three steps' mu)
        nh = min(count[1] + 1, 3)
        a0, a1, a2 = _coefficients(nh)
        for k in range(N):
            gx = W[GX_ + k]
            gy = W[GY_ + k]
            gx1 = W[GX_ + k + 1]
            gy1 = W[GY_ + k + 1]
            W[VX_ + k] += (gx - gx1) * (im / h)
            W[VY_ + k] += (gy - gy1) * (im / h)
            W[VW_ + k] += (W[U0X_ + k] * (gx + gx1) + W[U0Y_ + k] * (gy + gy1)) * (ii / h)
            W[X_ + k] = W[QX_ + k]
            W[Y_ + k] = W[QY_ + k]
            W[T_ + k] = W[QT_ + k]
            W[C_ + k] = W[CN_ + k]
            W[S_ + k] = W[SN_ + k]
            W[H2X_ + k] = W[H1X_ + k]
            W[H2Y_ + k] = W[H1Y_ + k]
            W[H1X_ + k] = W[H0X_ + k]
            W[H1Y_ + k] = W[H0Y_ + k]
            W[H0X_ + k] = gx
            W[H0Y_ + k] = gy
        for k in range(N):
            W[GX_ + k] = a0 * W[H0X_ + k] + a1 * W[H1X_ + k] + a2 * W[H2X_ + k]
            W[GY_ + k] = a0 * W[H0Y_ + k] + a1 * W[H1Y_ + k] + a2 * W[H2Y_ + k]
        count[0] += 1
        count[1] = nh
    for k in range(N):
        q[k, 0] = W[X_ + k]
        q[k, 1] = W[Y_ + k]
        q[k, 2] = W[T_ + k]
        v[k, 0] = W[VX_ + k]
        v[k, 1] = W[VY_ + k]
        v[k, 2] = W[VW_ + k]
        cs[k, 0] = W[C_ + k]
        cs[k, 1] = W[S_ + k]
        hist[0, 0, k] = W[H0X_ + k]
        hist[0, 1, k] = W[H0Y_ + k]
        hist[1, 0, k] = W[H1X_ + k]
        hist[1, 1, k] = W[H1Y_ + k]
        hist[2, 0, k] = W[H2X_ + k]
        hist[2, 1, k] = W[H2Y_ + k]


@jit
def _run_short(q, v, cs, hist, count, n_steps):
    _run(q, v, cs, hist, count, n_steps, 40)


@jit
def _run_long(q, v, cs, hist, count, n_steps):
    _run(q, v, cs, hist, count, n_steps, 264)


@jit
def _run_any(q, v, cs, hist, count, n_steps):
    _run(q, v, cs, hist, count, n_steps, q.shape[0] + 1)


#: (most links, kernel) of the kernels with a constant row stride (40 and 264 numbers, at
#: least N + 1). Measured (2 to 64 links): at 264 every loop over bodies vectorises, at 40
#: to 136 some do not (the compiler's dependence analysis gives up on them); 40 is a little
#: faster up to 7 links. Longer chains than 263 links take _run_any (stride N + 1, the
#: overlap checked at run time).
KERNELS = ((7, _run_short), (263, _run_long))


def run_chain(q, v, cs, hist, count, n_steps):
    """n_steps of the dedicated chain step on q, v (N, 3) in place.

    cs (N, 2): cos, sin of q[:, 2] carried from step to step (turned by each increment,
    resynced from theta every RESYNC steps and at count[0] == 0); hist (3, 2, N + 1): the last
    three steps' multipliers, newest first (column N stays 0); count: [steps taken, steps of
    history (at most 3), correction passes checked, factorisations]. The state of a run is
    (q, v, cs, hist, count); fresh_state makes one.
    """
    for most, kernel in KERNELS:
        if q.shape[0] <= most:
            kernel(q, v, cs, hist, count, n_steps)
            return
    _run_any(q, v, cs, hist, count, n_steps)


def fresh_state(model):
    """(q, v, cs, hist, count) of a dedicated run from the model's start, at rest."""
    q = model.q0.copy()
    n = q.shape[0]
    return (q, np.zeros((n, 3)), np.zeros((n, 2)), np.zeros((3, 2, n + 1)),
            np.zeros(4, np.int64))


def _print_row(n_links, key, rates, best, spec, poses, start, end):
    """One runner's or peer's line: us/step, steps/s, ratio to the engine and to the fastest
    peer, largest pin gap over the sampled poses, energy change from start (q, v) to end
    (q, v) as a share of the scale."""
    drift = (energy(spec, *end) - energy(spec, *start)) / spec.energy_scale
    peer = f"{rates[key] / rates[best]:7.2f}" if best else f"{'-':>7s}"
    print(f"{n_links:3d}  {key:10s} {1e6 / rates[key]:8.3f}  {rates[key] / 1e3:8.0f}k  "
          f"{rates[key] / rates['engine']:8.2f}  {peer}  "
          f"{pin_separation(spec, poses):15.1e}  {drift:+21.3%}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--links", type=int, nargs="+", default=[4, 32])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--peers", nargs="+", default=["none"],
                    help="peers timed alongside (mujoco pymunk box2d, or comma-separated; 'all')")
    args = ap.parse_args(argv)
    if any(n < 1 for n in args.links):
        ap.error("--links: every chain needs at least one link")
    asked = [x.strip() for arg in args.peers for x in arg.split(",") if x.strip()]
    peers = {}
    if asked and asked != ["none"]:
        from benchmarks.peers import PEER_MODULES, available_peers
        names = None if "all" in asked else asked
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
    print(f"{'N':>3s}  {'runner':10s} {'us/step':>8s}  {'steps/s':>9s}  {'x engine':>8s}  "
          f"{'x peer':>7s}  {'largest pin gap':>15s}  {'energy change / scale':>21s}")
    for n_links in args.links:
        model = chain(n_links, dt=DT, length=LENGTH, mass=MASS)
        spec = spec_from_model(f"chain{n_links}", model, n_accuracy * DT)
        box = {}

        def reset_engine():
            box["sim"] = ps.Simulator(model)

        def reset_dedicated():
            box["state"] = fresh_state(model)
        # runner: (run n steps, reset to the start (not timed), current (q, v))
        runners = {
            "engine": (lambda n: box["sim"].steps(n), reset_engine,
                       lambda: (box["sim"].state.q, box["sim"].state.v)),
            "dedicated": (lambda n: run_chain(*box["state"], n), reset_dedicated,
                          lambda: box["state"][:2]),
        }
        worlds = {key: mod.World(spec) for key, mod in peers.items()}
        engines = {key: r[:2] for key, r in runners.items()}
        engines.update({key: (w.run, w.reset) for key, w in worlds.items()})
        timed = _rates(engines, n_steps, args.repeats)
        rates = {key: statistics.median(r) for key, r in timed.items()}
        best = max(worlds, key=lambda k: rates[k]) if worlds else None
        for key, (run, reset, pose) in runners.items():
            # accuracy: poses sampled every 100 steps (0.1 s) over the 10 s run
            reset()
            q0, v0 = (x.copy() for x in pose())
            poses = [q0]
            for _ in range(n_accuracy // 100):
                run(100)
                poses.append(pose()[0].copy())
            _print_row(n_links, key, rates, best, spec, np.array(poses), (q0, v0), pose())
        for key, world in worlds.items():
            q, v = world.record(n_accuracy)      # every step: sampled as the runners'
            _print_row(n_links, key, rates, best, spec, q[::100], (q[0], v[0]), (q[-1], v[-1]))
        if worlds:
            print(f"{n_links:3d}  dedicated / fastest peer ({best}): "
                  f"{rates['dedicated'] / rates[best]:.2f}x; engine / {best}: "
                  f"{rates['engine'] / rates[best]:.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
