"""Continuation of gaits in one parameter: fixed points of P^n(x; p) (n = 1 for a period-one
gait, 2^k after k period doublings) followed as p changes, with their multipliers
(multipliers_with_error) and the bifurcations between points:

- period doubling: a real multiplier through -1 (det(J + I) changes sign); located by
  regula falsi on det(J + I) over p, re-solving the fixed point at each trial p;
- fold: a real multiplier through +1 (det(J - I) changes sign; arclength continuation turns
  back in p there);
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

from .parallel import MapPool
from .stepmap import StepMapError, central_jacobian, central_points, multipliers_with_error

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
    at trial p to p_tol) or not, bracket: width of the last bracket in p."""
    kind: str
    p: float
    x: np.ndarray
    multipliers: np.ndarray
    period: int
    located: bool = False
    bracket: float = math.nan


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
    from ..trajectory import atomic_write
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
def newton_fixed_point(pool: MapPool, p, x0, period=1, tol=1e-9, max_iter=20, eps=1e-4,
                       max_halvings=8):
    """Newton on P^period(x; p) - x with the Jacobian's columns (central differences, step
    eps: a simulated map is piecewise smooth below ~1e-5, see multipliers_with_error)
    evaluated in one batch.
    Returns (x, residual, converged, J at the last iterate)."""
    x = np.asarray(x0, dtype=np.float64).copy()
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


def _point(pool, p, x, period, residual, mult_tol):
    m = multipliers_with_error(None, x, "auto", tol=mult_tol, evaluate=pool.evaluator(p, period),
                               warn=False)
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
    located = abs(pb - pa) <= p_tol or abs(bifurcation_tests(best.multipliers)[kind]) < 1e-9
    return Bifurcation(kind, best.p, best.x, best.multipliers, a.period, located, abs(pb - pa))


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


def _resolved(a, b, critical):
    """Whether the multiplier nearest `critical` (+1 or -1) is farther from it than its error
    estimate at both points (else a sign change of the test function may be noise: just past
    a period doubling the new orbit's multiplier sits at +1)."""
    return all(np.min(np.abs(q.multipliers - critical)) > q.error for q in (a, b))


def _detect(pool, a, b, locate, tol, p_tol, mult_tol, folded=False, born=False):
    """Bifurcations between branch points a and b. born: a is the first point of a period-2n
    branch, half a step past the doubling where it was born: there its multiplier passes +1
    by construction (P^2n's pitchfork), so a +1 crossing next to it is the birth, not a fold."""
    ta, tb = bifurcation_tests(a.multipliers), bifurcation_tests(b.multipliers)
    found = []
    if np.sign(ta["period-doubling"]) != np.sign(tb["period-doubling"]) and _resolved(a, b, -1.0):
        found.append(_locate(pool, a, b, "period-doubling", tol, p_tol, mult_tol) if locate
                     else _interpolated(a, b, "period-doubling"))
    if folded or (not born and np.sign(ta["fold"]) != np.sign(tb["fold"]) and _resolved(a, b, 1.0)):
        found.append(_interpolated(a, b, "fold"))
    if ta["neimark-sacker"] != tb["neimark-sacker"]:
        found.append(_interpolated(a, b, "neimark-sacker"))
    return found


# continuation --------------------------------------------------------------------------------
def continue_branch(pool: MapPool, x0, p0: float, p1: float, points: int = 30,
                    method: str = "natural", period: int = 1, tol: float = 1e-9,
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
    if not (math.isfinite(p0) and math.isfinite(p1)) or p0 == p1:
        raise ValueError(f"continuation range {p0}:{p1} must be two different finite numbers")
    if int(points) < 2:
        raise ValueError(f"points={points} must be at least 2")
    p_tol = 1e-5 * abs(p1 - p0) if p_tol is None else p_tol
    ev0 = pool.evaluations
    branch = Branch(param, int(period))
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
        branch.bifurcations += _detect(pool, pts[-1], b, locate, tol, p_tol, mult_tol,
                                       born=born_at_doubling and len(pts) == 1)
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
        found = _detect(pool, a, b, locate and not folded, tol, p_tol, mult_tol,
                        born=born_at_doubling and len(branch.points) == 1)
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
                           tol: float = 1e-6, amplitudes=(1e-3, 3e-3, 1e-2, 3e-2, 0.1), **kw) -> Branch:
    """The period-2n orbit born at period doubling `bif` (of the period-n orbit), continued
    from just past bif.p toward p1 (the side where it exists: where the period-n gait lost
    stability). Starts Newton on P^2n from x* +- a v (v: eigenvector of the multiplier
    nearest -1) for the amplitudes a in turn and takes the first solution that is not the
    period-n point. Raises StepMapError when none is found. tol: Newton's residual on
    P^2n (a simulated map's noise, ~1e-7 for the passive walkers, compounds over 2n steps)."""
    n = bif.period
    d = bif.x.size
    dp = (p1 - bif.p) / max(int(points) - 1, 1)
    pstart = bif.p + 0.5 * dp
    J = multipliers_with_error(None, bif.x, evaluate=pool.evaluator(pstart, n), warn=False).jacobian
    lam, V = np.linalg.eig(J)
    v = np.real(V[:, np.argmin(np.abs(lam + 1.0))])
    v /= np.max(np.abs(v))
    x1, r1, c1, _ = newton_fixed_point(pool, pstart, bif.x, n, tol)
    base = x1 if c1 else bif.x
    for a in amplitudes:
        for s in (1.0, -1.0):
            x, r, conv, _ = newton_fixed_point(pool, pstart, base + s * a * v, 2 * n, tol)
            if conv and np.max(np.abs(x - base)) > 100 * tol and \
                    np.max(np.abs(pool.evaluate(x[None, :], pstart, n)[0][0] - x)) > 100 * tol:
                return continue_branch(pool, x, pstart, p1, points, period=2 * n, tol=tol,
                                       subperiod=n, born_at_doubling=True, **kw)
    raise StepMapError(f"no period-{2 * n} orbit found next to the period doubling at {bif.p:g}")
