"""Continuation of gaits in one parameter: fixed points of P^n(x; p) (n = 1 for a period-one
gait, 2^k after k period doublings) followed as p changes, with their multipliers
(multipliers_with_error) and the bifurcations between points:

- period doubling: a real multiplier through -1 (det(J + I) changes sign); located by
  regula falsi on det(J + I) over p, re-solving the fixed point at each trial p;
- fold: a real multiplier through +1 (det(J - I) changes sign; arclength continuation turns
  back in p there);

The multipliers come from polynomial fits of the map (stepmap.multipliers_by_fit) with an
error estimate. A point whose multiplier nearest -1 (+1) lies within its error of it does not
tell the sign of det(J + I) (det(J - I)): its multipliers are refined (more samples, a
smaller window) and, if that does not settle it, the crossing is taken between the resolved
points on either side of it (the branch's next points: a finer spacing there). Such a
bifurcation's `note` says so, and its p is located to within the multipliers' error.
- Neimark-Sacker: a complex pair through the unit circle (located by interpolating its
  modulus).

Natural-parameter continuation steps p and re-solves x by Newton from a secant predictor;
pseudo-arclength continuation solves for (x, p) together on [P^n(x; p) - x; t . (y - y_pred)]
= 0 with the branch tangent t, so it passes folds. After a period doubling,
``period_doubling_branch`` starts the period-2n orbit (x* +- a v, v the eigenvector of the
multiplier -1) and continues it. Every batch of map evaluations (Jacobian columns, the
multipliers' eps ladder) runs on a MapPool's workers.
"""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass, field

import numpy as np

from ..checks import finite_number, positive, whole
from ..trajectory import atomic_write
from .parallel import MapPool
from .stepmap import (FIT_POINTS, FIT_WINDOW, Multipliers, StepMapError, central_jacobian,
                      central_points, finite_differences_step, map_noise, multipliers_by_fit,
                      noise_tolerance, sort_multipliers)

KINDS = ("period-doubling", "fold", "neimark-sacker")


@dataclass
class BranchPoint:
    """One gait on a branch: parameter p, section state x (d,) of a fixed point of P^period,
    multipliers of P^period (largest modulus first), their error estimate, |P^n(x) - x|_inf."""
    p: float
    x: np.ndarray
    multipliers: np.ndarray
    error: float
    residual: float
    period: int = 1

    @property
    def stable(self) -> bool:
        return bool(np.all(np.abs(self.multipliers) < 1.0))


@dataclass
class Bifurcation:
    """A bifurcation found between two branch points: kind (KINDS), parameter p, state x,
    the multipliers there, period of the orbit it happens to, located (refined by solving
    at trial p to p_tol, or to the width the multipliers' error allows: p_error) or not,
    bracket: width of the last bracket in p, p_error: the error in p that the multipliers'
    error estimate implies (error / |d lambda / dp|), note: how a crossing within the
    multipliers' noise was refined."""
    kind: str
    p: float
    x: np.ndarray
    multipliers: np.ndarray
    period: int
    located: bool = False
    bracket: float = math.nan
    p_error: float = math.nan
    note: str = ""


@dataclass
class Branch:
    """A continued branch: points in continuation order, bifurcations on it, why it ended."""
    param: str
    period: int
    points: list = field(default_factory=list)
    bifurcations: list = field(default_factory=list)
    end: str = ""
    evaluations: int = 0

    @property
    def p(self) -> np.ndarray:
        return np.array([b.p for b in self.points])

    @property
    def x(self) -> np.ndarray:
        return np.array([b.x for b in self.points])

    @property
    def multipliers(self) -> np.ndarray:
        return np.array([b.multipliers for b in self.points])

    def nearest(self, p) -> np.ndarray:
        """The state of the branch's point nearest in the parameter to p: where to start
        iterating the map at p (bifurcation_diagram's x0; past the branch's end, its last
        point)."""
        return self.points[int(np.argmin(np.abs(self.p - float(p))))].x

    def first(self, kind: str):
        """The first bifurcation of `kind` along the branch, or None."""
        return next((b for b in self.bifurcations if b.kind == kind), None)

    def rows(self, names=None) -> list:
        """One dict per point: param, period, x coordinates, |multiplier|s, stable, error."""
        names = list(names) if names is not None else [f"x{i}" for i in range(len(self.points[0].x))] if self.points else []
        out = []
        for b in self.points:
            row = {self.param: b.p, "period": b.period}
            row.update({n: float(v) for n, v in zip(names, b.x)})
            for i, lam in enumerate(b.multipliers):
                row[f"mult{i}_re"], row[f"mult{i}_im"] = float(lam.real), float(lam.imag)
            row.update(spectral_radius=float(np.max(np.abs(b.multipliers))), stable=int(b.stable),
                       multiplier_error=b.error, residual=b.residual)
            out.append(row)
        return out

    def to_csv(self, path, names=None):
        """Write rows() to a CSV file (written in one step: a temporary file, then renamed)."""
        write_csv(path, self.rows(names))


def write_csv(path, rows):
    """Rows (dicts with the same keys) as CSV, atomically."""
    rows = list(rows)

    def write(f):
        if not rows:
            return
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    atomic_write(path, write, binary=False)


# test functions ------------------------------------------------------------------------------
def bifurcation_tests(lam) -> dict:
    """det(J + I), det(J - I) (real, from the multipliers) and the number of complex
    multipliers outside the unit circle."""
    lam = np.asarray(lam, complex)
    cplx = np.abs(lam.imag) > 1e-9 * np.maximum(1.0, np.abs(lam))
    return {"period-doubling": float(np.prod(1.0 + lam).real),
            "fold": float(np.prod(lam - 1.0).real),
            "neimark-sacker": int(np.sum(cplx & (np.abs(lam) > 1.0)))}


# Newton --------------------------------------------------------------------------------------
def fixed_point_tolerance(pool: MapPool, p, x, period=1, tol="auto") -> float:
    """Newton's tolerance on |P^period(x) - x| at p: tol ("auto": stepmap.AUTO_TOL) raised to
    NOISE_FACTOR x the map's noise measured at x (stepmap.map_noise)."""
    return noise_tolerance(tol, map_noise(pool.evaluator(p, period), x))


def newton_fixed_point(pool: MapPool, p, x0, period=1, tol="auto", max_iter=20, eps=1e-4,
                       max_halvings=8):
    """Newton on P^period(x; p) - x with the Jacobian's columns (central differences, step
    eps: a simulated map is piecewise smooth below ~1e-5, see multipliers_with_error)
    evaluated in one batch; tol "auto" or a number: fixed_point_tolerance.
    Returns (x, residual, converged, J at the last iterate)."""
    period = whole("period", period, 1)
    max_iter = whole("max_iter", max_iter, 0)
    max_halvings = whole("max_halvings", max_halvings, 0)
    eps = finite_differences_step(eps)
    x = np.asarray(x0, dtype=np.float64).copy()
    if isinstance(tol, str):
        tol = fixed_point_tolerance(pool, p, x, period, tol)
    d = x.size
    J = None
    r = np.inf
    for _ in range(max_iter + 1):
        Y, ok = pool.evaluate(np.vstack([x[None, :], central_points(x, eps)]), p, period)
        if not ok[0]:
            return x, np.inf, False, J
        F = Y[0] - x
        r = float(np.max(np.abs(F)))
        if ok.all():
            J = central_jacobian(Y[1:], eps)
        if r <= tol or J is None or not ok.all():
            return x, r, r <= tol, J
        try:
            dx = np.linalg.solve(J - np.eye(d), -F)
        except np.linalg.LinAlgError:
            dx = np.linalg.lstsq(J - np.eye(d), -F, rcond=None)[0]
        step = 1.0
        for _ in range(max_halvings):
            Yn, okn = pool.evaluate((x + step * dx)[None, :], p, period)
            if okn[0] and np.max(np.abs(Yn[0] - x - step * dx)) < r:
                break
            step *= 0.5
        else:
            return x, r, False, J
        x = x + step * dx
    return x, r, r <= tol, J


def _multipliers(pool, p, x, period, mult_tol, points=FIT_POINTS):
    """The multipliers of P^period at x: from its exact Jacobian where the pool takes it
    (MapPool.exact: error 0), else multipliers_by_fit: the window FIT_WINDOW / period, then
    half of it if the error exceeds mult_tol; the estimate with the smaller error."""
    if pool.exact(p):
        try:
            J = pool.jacobian(p, x, period)[1]
            lam = sort_multipliers(np.linalg.eigvals(J))
            return Multipliers(lam, 0.0, 0.0, float("nan"), True, J, [(0.0, lam)], period)
        except NotImplementedError:
            if pool.use_exact:
                raise                   # (asked for: MapPool(exact=True))
    best = None
    for window in (FIT_WINDOW / period, 0.5 * FIT_WINDOW / period):
        m = multipliers_by_fit(None, x, window, points, tol=mult_tol,
                               evaluate=pool.evaluator(p, period), warn=False)
        if best is None or m.error < best.error:
            best = m
        if best.converged:
            break
    return best


def _point(pool, p, x, period, residual, mult_tol):
    m = _multipliers(pool, p, x, period, mult_tol)
    return BranchPoint(float(p), x, m.values, m.error, residual, period)


def _locate(pool, a: BranchPoint, b: BranchPoint, kind, tol, p_tol, mult_tol, max_iter=12):
    """Regula falsi (Illinois) on the test function of `kind` between a and b."""
    fa = bifurcation_tests(a.multipliers)[kind]
    fb = bifurcation_tests(b.multipliers)[kind]
    pa, pb, xa, xb = a.p, b.p, a.x, b.x
    best = a if abs(fa) < abs(fb) else b
    side = 0
    for _ in range(max_iter):
        if abs(pb - pa) <= p_tol:
            break
        pc = pb - fb * (pb - pa) / (fb - fa) if fb != fa else 0.5 * (pa + pb)
        w = (pc - pa) / (pb - pa)
        x, r, conv, _ = newton_fixed_point(pool, pc, xa + w * (xb - xa), a.period, tol)
        if not conv:
            break
        c = _point(pool, pc, x, a.period, r, mult_tol)
        fc = bifurcation_tests(c.multipliers)[kind]
        best = c
        if np.sign(fc) == np.sign(fa):
            pa, xa, fa = pc, x, fc
            if side == -1:
                fb *= 0.5
            side = -1
        else:
            pb, xb, fb = pc, x, fc
            if side == 1:
                fa *= 0.5
            side = 1
    p_err = _p_error(a, b, best, -1.0 if kind == "period-doubling" else 1.0)
    located = (abs(pb - pa) <= max(p_tol, p_err)
               or abs(bifurcation_tests(best.multipliers)[kind]) < 1e-9)
    return Bifurcation(kind, best.p, best.x, best.multipliers, a.period, located, abs(pb - pa),
                       p_err)


def _nearest(q, critical) -> complex:
    return q.multipliers[np.argmin(np.abs(q.multipliers - critical))]


def _p_error(a, b, c, critical) -> float:
    """The error in p of a crossing at c that c's multiplier error implies: c.error over the
    rate of change of the crossing multiplier between a and b."""
    slope = abs((_nearest(b, critical) - _nearest(a, critical)) / (b.p - a.p)) if b.p != a.p else 0.0
    return float(c.error / slope) if slope > 0 else math.inf


def _interpolated(a, b, kind):
    if kind == "neimark-sacker":
        ra = np.max(np.abs(a.multipliers[np.abs(a.multipliers.imag) > 0] if np.any(a.multipliers.imag) else a.multipliers))
        rb = np.max(np.abs(b.multipliers[np.abs(b.multipliers.imag) > 0] if np.any(b.multipliers.imag) else b.multipliers))
        fa, fb = ra - 1.0, rb - 1.0
    else:
        fa, fb = bifurcation_tests(a.multipliers)[kind], bifurcation_tests(b.multipliers)[kind]
    w = fa / (fa - fb) if fa != fb else 0.5
    w = min(max(w, 0.0), 1.0)
    return Bifurcation(kind, a.p + w * (b.p - a.p), a.x + w * (b.x - a.x),
                       a.multipliers + w * (b.multipliers - a.multipliers), a.period, False,
                       abs(b.p - a.p))


def _side(q, kind) -> int:
    """Sign of q's test function for `kind` ("period-doubling" or "fold") when the multiplier
    nearest -1 (+1) is farther from it than its error estimate; 0 when it is not (the sign
    may be noise)."""
    critical = -1.0 if kind == "period-doubling" else 1.0
    if abs(_nearest(q, critical) - critical) <= q.error:
        return 0
    return int(np.sign(bifurcation_tests(q.multipliers)[kind]))


def _refine(pool, q, kind, mult_tol):
    """q with its multipliers re-estimated from twice the samples (FIT_POINTS * 2 - 1 per
    coordinate) when its crossing multiplier lies within its error of +-1; the estimate with
    the smaller error is kept. Returns (q, whether it was refined)."""
    if pool is None or _side(q, kind) != 0:
        return q, False
    m = _multipliers(pool, q.p, q.x, q.period, mult_tol, points=2 * FIT_POINTS - 1)
    if m.error < q.error:
        q.multipliers, q.error = m.values, m.error
    return q, True


def _last_resolved(points, kind, skip_first=False):
    """Index of the last point of `points` whose sign for `kind` is resolved, or None."""
    first = 1 if skip_first else 0
    for i in range(len(points) - 1, first - 1, -1):
        if _side(points[i], kind) != 0:
            return i
    return None


def _note(points, i, b, kind, refined):
    """How a crossing within the multipliers' noise was settled ('' when it was not)."""
    critical = -1 if kind == "period-doubling" else 1
    unresolved = [q.p for q in points[i + 1:]]
    samples = f"{2 * FIT_POINTS - 1} samples a coordinate"
    parts = []
    if refined:
        parts.append(f"multipliers at p={b.p:.7g} refined ({samples})")
    if unresolved:
        parts.append(f"multiplier within its error of {critical:+d} at p=" +
                     ", ".join(f"{v:.7g}" for v in unresolved) +
                     f" (refined with {samples}): crossing taken between p={points[i].p:.7g} "
                     f"and {b.p:.7g}")
    return "; ".join(parts)


def _detect(pool, points, b, locate, tol, p_tol, mult_tol, folded=False, born=False):
    """Bifurcations between the branch's points so far (`points`) and its new point b: a
    period doubling or fold where the resolved sign of the test function (_side) differs
    from that of the last resolved point; unresolved points are refined (_refine) and
    otherwise skipped, so the crossing is taken between the resolved points around them.
    born: points[0] lies half a step past the doubling the branch was born at
    (period_doubling_branch), where its multiplier passes +1 by construction (P^2n's
    pitchfork): it is no reference for a fold."""
    a = points[-1]
    found = []
    for kind in ("period-doubling", "fold"):
        if kind == "fold" and folded:
            found.append(_interpolated(a, b, "fold"))
            continue
        b, refined = _refine(pool, b, kind, mult_tol)
        sb = _side(b, kind)
        i = _last_resolved(points, kind, skip_first=born and kind == "fold")
        if sb == 0 or i is None or _side(points[i], kind) == sb:
            continue
        if kind == "period-doubling" and locate:
            bf = _locate(pool, points[i], b, kind, tol, p_tol, mult_tol)
        else:
            bf = _interpolated(points[i], b, kind)
        bf.note = _note(points, i, b, kind, refined)
        found.append(bf)
    if bifurcation_tests(a.multipliers)["neimark-sacker"] != bifurcation_tests(b.multipliers)["neimark-sacker"]:
        found.append(_interpolated(a, b, "neimark-sacker"))
    return found


def _pending(branch):
    """A crossing the branch's last points leave open: their test functions' signs differ
    from the last resolved point's but all lie within the multipliers' noise. Reported
    (not located) so that it is not lost."""
    out = []
    pts = branch.points
    for kind in ("period-doubling", "fold"):
        i = _last_resolved(pts, kind)
        if i is None or i == len(pts) - 1:
            continue
        s0 = np.sign(bifurcation_tests(pts[i].multipliers)[kind])
        last = pts[-1]
        if np.sign(bifurcation_tests(last.multipliers)[kind]) != s0:
            bf = _interpolated(pts[i], last, kind)
            bf.note = (f"the multiplier stays within its error of {-1 if kind == 'period-doubling' else 1:+d} "
                       f"from p={pts[i + 1].p:.7g} to the branch's end: extend the range to locate it")
            out.append(bf)
    return out


# continuation --------------------------------------------------------------------------------
def continue_branch(pool: MapPool, x0, p0: float, p1: float, points: int = 30,
                    method: str = "natural", period: int = 1, tol="auto",
                    locate: bool = True, p_tol: float | None = None, mult_tol: float = 3e-3,
                    param: str = "p", progress=None, max_points: int | None = None,
                    subperiod: int | None = None, born_at_doubling: bool = False) -> Branch:
    """Follow the fixed point of P^period(x; p) near x0 from p0 toward p1.

    method "natural": `points` equally spaced values of p (a failed Newton halves the step,
    up to 4 times, before the branch ends); "arclength": pseudo-arclength with the same
    initial step, adapted (passes folds; ends when p leaves [p0, p1] or after max_points).
    Bifurcations between neighbouring points are detected and, with locate, period
    doublings located to p_tol (default 1e-5 of |p1 - p0|; Bifurcation.bracket is the
    bracket reached: the map's noise can stop it earlier). progress(done, total) is called
    after each point. subperiod: reject solutions that are fixed points of P^subperiod (the
    period-n orbit a period-2n branch was born from; natural continuation). born_at_doubling:
    x0 lies half a step past the doubling the branch was born at (period_doubling_branch), so
    a +1 crossing in the first interval is that birth, not a fold. Returns a Branch.
    """
    if method not in ("natural", "arclength"):
        raise ValueError(f"method={method!r} must be 'natural' or 'arclength'")
    # (a string p0 failed in math.isfinite(), points="30" in int(), 2.7 points were 2)
    p0, p1 = finite_number("p0", p0), finite_number("p1", p1)
    if p0 == p1:
        raise ValueError(f"continuation range {p0}:{p1} must be two different finite numbers")
    points = whole("points", points, 2)
    period = whole("period", period, 1)
    mult_tol = positive("mult_tol", mult_tol, "the multipliers' error allowed")
    if max_points is not None:
        max_points = whole("max_points", max_points, 2)
    if subperiod is not None:
        subperiod = whole("subperiod", subperiod, 1)
    p_tol = 1e-5 * abs(p1 - p0) if p_tol is None else positive("p_tol", p_tol, "how closely "
                                                                "a bifurcation is located")
    ev0 = pool.evaluations
    branch = Branch(param, int(period))
    tol = fixed_point_tolerance(pool, p0, np.asarray(x0, dtype=np.float64), period, tol)
    x, r, conv, _ = newton_fixed_point(pool, p0, x0, period, tol)
    if not conv:
        branch.end = f"no fixed point of period {period} near x0 at {param}={p0:g} (residual {r:.2g})"
        return branch
    branch.points.append(_point(pool, p0, x, period, r, mult_tol))
    h = (p1 - p0) / (int(points) - 1)
    total = int(points) if method == "natural" else (max_points or 4 * int(points))
    if progress:
        progress(1, total)
    if method == "natural":
        _natural(pool, branch, p0, p1, h, period, tol, locate, p_tol, mult_tol, progress, total,
                 subperiod, born_at_doubling)
    else:
        _arclength(pool, branch, p0, p1, h, period, tol, locate, p_tol, mult_tol, progress, total,
                   born_at_doubling)
    branch.bifurcations += _pending(branch)
    branch.evaluations = pool.evaluations - ev0
    return branch


def _natural(pool, branch, p0, p1, h, period, tol, locate, p_tol, mult_tol, progress, total,
             subperiod=None, born_at_doubling=False):
    p = p0
    halvings = 0
    while (p1 - p) * np.sign(h) > 1e-12 * abs(p1 - p0):
        step = h / 2 ** halvings
        pn = p + step
        if (pn - p1) * np.sign(h) > 0:
            pn = p1
        pts = branch.points
        guess = pts[-1].x if len(pts) < 2 else pts[-1].x + (pts[-1].x - pts[-2].x) * (pn - p) / (pts[-1].p - pts[-2].p)
        x, r, conv, _ = newton_fixed_point(pool, pn, guess, period, tol)
        if conv and subperiod:
            y, ok = pool.evaluate(x[None, :], pn, subperiod)
            conv = bool(ok[0]) and np.max(np.abs(y[0] - x)) > max(1e3 * tol, 1e-8)
        if not conv:
            halvings += 1
            if halvings > 4:
                branch.end = f"Newton failed beyond {branch.param}={p:g} (residual {r:.2g})"
                return
            continue
        halvings = max(0, halvings - 1)
        b = _point(pool, pn, x, period, r, mult_tol)
        branch.bifurcations += _detect(pool, pts, b, locate, tol, p_tol, mult_tol,
                                       born=born_at_doubling)
        pts.append(b)
        p = pn
        if progress:
            progress(min(len(pts), total), total)
    branch.end = f"reached {branch.param}={p1:g}"


def _arclength(pool, branch, p0, p1, h, period, tol, locate, p_tol, mult_tol, progress, total,
               born_at_doubling=False):
    d = branch.points[0].x.size
    lo, hi = min(p0, p1), max(p0, p1)
    ds = abs(h)
    dp_fd = 1e-6 * max(1.0, abs(p0))
    tangent = None
    while len(branch.points) < total:
        a = branch.points[-1]
        y = np.append(a.x, a.p)
        # tangent: null vector of [J - I, F_p] at a
        X = np.vstack([a.x[None, :], central_points(a.x, 1e-5), a.x[None, :], a.x[None, :]])
        pp = np.r_[[a.p] * (2 * d + 1), a.p + dp_fd, a.p - dp_fd]
        Y, ok = pool.evaluate(X, pp, period)
        if not ok.all():
            branch.end = f"the map fails next to {branch.param}={a.p:g}"
            return
        A = np.hstack([central_jacobian(Y[1:2 * d + 1], 1e-5) - np.eye(d),
                       ((Y[-2] - Y[-1]) / (2 * dp_fd))[:, None]])
        t = np.linalg.svd(A)[2][-1]
        if tangent is None:
            t = t if t[-1] * (p1 - p0) > 0 else -t
        elif t @ tangent < 0:
            t = -t
        tangent = t
        for attempt in range(6):
            yp = y + ds * t
            yn, conv = _arclength_newton(pool, yp, t, period, tol, dp_fd)
            if conv:
                break
            ds *= 0.5
        else:
            branch.end = f"arclength corrector failed after {branch.param}={a.p:g}"
            return
        xn, pn = yn[:-1], float(yn[-1])
        r = float(np.max(np.abs(pool.evaluate(xn[None, :], pn, period)[0][0] - xn)))
        b = _point(pool, pn, xn, period, r, mult_tol)
        folded = len(branch.points) >= 2 and (pn - a.p) * (a.p - branch.points[-2].p) < 0
        found = _detect(pool, branch.points, b, locate and not folded, tol, p_tol, mult_tol,
                        born=born_at_doubling)
        for bf in found:
            if bf.kind == "fold" and len(branch.points) >= 2:
                # p is quadratic in the fold's test function near the fold: fit three points
                pts3 = [branch.points[-2], a, b]
                tau = [bifurcation_tests(q.multipliers)["fold"] for q in pts3]
                if len(set(tau)) == 3:
                    bf.p = float(np.polyval(np.polyfit(tau, [q.p for q in pts3], 2), 0.0))
        branch.bifurcations += found
        branch.points.append(b)
        if progress:
            progress(len(branch.points), total)
        if not lo - 1e-12 <= pn <= hi + 1e-12:
            branch.end = f"left the range at {branch.param}={pn:g}"
            return
        if attempt == 0:
            ds = min(ds * 1.3, 4 * abs(h))
    branch.end = f"{total} points"


def _arclength_newton(pool, yp, t, period, tol, dp_fd, max_iter=10):
    y = yp.copy()
    d = y.size - 1
    for _ in range(max_iter):
        x, p = y[:-1], y[-1]
        X = np.vstack([x[None, :], central_points(x, 1e-5), x[None, :], x[None, :]])
        pp = np.r_[[p] * (2 * d + 1), p + dp_fd, p - dp_fd]
        Y, ok = pool.evaluate(X, pp, period)
        if not ok.all():
            return y, False
        F = Y[0] - x
        g = t @ (y - yp)
        if np.max(np.abs(F)) <= tol and abs(g) <= tol:
            return y, True
        A = np.vstack([np.hstack([central_jacobian(Y[1:2 * d + 1], 1e-5) - np.eye(d),
                                  ((Y[-2] - Y[-1]) / (2 * dp_fd))[:, None]]), t[None, :]])
        y = y + np.linalg.solve(A, -np.append(F, g))
    return y, False


def period_doubling_branch(pool: MapPool, bif: Bifurcation, p1: float, points: int = 20,
                           tol=1e-6, amplitudes=(1e-3, 3e-3, 1e-2, 3e-2, 0.1), **kw) -> Branch:
    """The period-2n orbit born at period doubling `bif` (of the period-n orbit), continued
    from just past bif.p toward p1 (the side where it exists: where the period-n gait lost
    stability). Starts Newton on P^2n from x* +- a v (v: eigenvector of the multiplier
    nearest -1) for the amplitudes a in turn and takes the first solution that is not the
    period-n point. Raises StepMapError when none is found. tol: Newton's residual on
    P^2n, raised to the map's noise (fixed_point_tolerance); Newton on P^2n is ill-conditioned
    next to the doubling (a multiplier of P^2n near +1), hence 1e-6 by default."""
    n = bif.period
    p1 = finite_number("p1", p1)
    points = whole("points", points, 2)
    dp = (p1 - bif.p) / (points - 1)
    pstart = bif.p + 0.5 * dp
    J = _multipliers(pool, pstart, bif.x, n, 3e-3).jacobian
    lam, V = np.linalg.eig(J)
    v = np.real(V[:, np.argmin(np.abs(lam + 1.0))])
    v /= np.max(np.abs(v))
    tol_n = fixed_point_tolerance(pool, pstart, bif.x, n, tol)
    tol_2n = fixed_point_tolerance(pool, pstart, bif.x, 2 * n, tol)
    x1, r1, c1, _ = newton_fixed_point(pool, pstart, bif.x, n, tol_n)
    base = x1 if c1 else bif.x
    apart = 100 * max(tol_n, tol_2n, 1e-10)
    for a in amplitudes:
        for s in (1.0, -1.0):
            x, r, conv, _ = newton_fixed_point(pool, pstart, base + s * a * v, 2 * n, tol_2n)
            if conv and np.max(np.abs(x - base)) > apart and \
                    np.max(np.abs(pool.evaluate(x[None, :], pstart, n)[0][0] - x)) > apart:
                return continue_branch(pool, x, pstart, p1, points, period=2 * n, tol=tol_2n,
                                       subperiod=n, born_at_doubling=True, **kw)
    raise StepMapError(f"no period-{2 * n} orbit found next to the period doubling at {bif.p:g}")
