"""Gait analysis: step events, Poincare sections, step-to-step maps, fixed points, Floquet
multipliers, and their plots.

A walking gait is a periodic orbit. Cut it with a Poincare section at touchdown: the state
x_k just after the k-th touchdown. The step-to-step map P : x_k -> x_{k+1} is computed by
simulation (the walker supplies a function that sets the state from x, runs a compiled
rollout to the next touchdown and reads x back). A period-one gait is a fixed point
x* = P(x*); its Floquet multipliers are the eigenvalues of the Jacobian dP/dx at x*, and the
gait is (locally, orbitally) stable when all of them lie inside the unit circle.

Symmetric reduction. A left/right symmetric walker whose section coordinates name the sides
(x = (x_left, x_right, ...)) maps a left-stance section to a right-stance one. With the
relabelling S (the permutation / sign matrix that swaps the sides), the reduced map
P_s = S P has the symmetric period-one gaits as fixed points (one step instead of two), and
since S P = P S for a symmetric walker, the two-step map's multipliers are the squares of
P_s's. Walkers that already write x in stance / swing terms (all of walkers.passive) have
S = identity. ``StepMap(advance, symmetry=S)`` applies it.

Fixed points: Newton on F(x) = P(x) - x with a finite-difference Jacobian (central by
default), solving (J - I) dx = -F, with step halving when |F| does not decrease or the
walker fails (falls) during an evaluation.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np


class StepMapError(RuntimeError):
    """A step-map evaluation failed (the walker fell, or no touchdown happened)."""


# the step-to-step map ------------------------------------------------------------------------
@dataclass
class StepMap:
    """x_k -> x_{k+1}, computed by `advance` (one simulated step of the walker).

    advance : callable (d,) -> (d,); raises StepMapError when the walker fails
    symmetry : optional (d, d) relabelling S; the map is then x -> S advance(x)
    names : optional coordinate names (for printing)
    derivative : optional callable (d,) -> (advance(x), d advance / dx (d, d)): the map's
        exact Jacobian (a passive walker's: walkers.passive.map_jacobian); find_fixed_point
        and multipliers_exact use it
    """
    advance: Callable[[np.ndarray], np.ndarray]
    dim: int
    symmetry: np.ndarray | None = None
    names: tuple = ()
    evaluations: int = 0
    derivative: Callable | None = None

    def __post_init__(self):
        if self.symmetry is not None:
            S = np.asarray(self.symmetry, dtype=np.float64)
            if S.shape != (self.dim, self.dim):
                raise ValueError(f"symmetry must be a ({self.dim}, {self.dim}) matrix, got {S.shape}")
            self.symmetry = S

    def __call__(self, x) -> np.ndarray:
        x = self._checked(x)
        self.evaluations += 1
        y = np.asarray(self.advance(x.copy()), dtype=np.float64)
        if y.shape != (self.dim,):
            raise StepMapError(f"advance returned shape {y.shape}, expected ({self.dim},)")
        if not np.all(np.isfinite(y)):
            raise StepMapError(f"advance returned a non-finite state {y}")
        return y if self.symmetry is None else self.symmetry @ y

    @property
    def exact(self) -> bool:
        """The map has an exact Jacobian (derivative)."""
        return self.derivative is not None

    def value_and_jacobian(self, x):
        """(P(x), dP/dx (d, d)) from the exact derivative (with the relabelling S: S P and
        S dP/dx); NotImplementedError where the map has none (multipliers_by_fit then)."""
        if self.derivative is None:
            raise NotImplementedError("this step map has no exact Jacobian (derivative); "
                                      "use multipliers_by_fit or finite differences")
        x = self._checked(x)
        self.evaluations += 1
        y, J = self.derivative(x.copy())
        y, J = np.asarray(y, dtype=np.float64), np.asarray(J, dtype=np.float64)
        if y.shape != (self.dim,) or J.shape != (self.dim, self.dim):
            raise StepMapError(f"derivative returned shapes {y.shape}, {J.shape}, expected "
                               f"({self.dim},), ({self.dim}, {self.dim})")
        if not (np.all(np.isfinite(y)) and np.all(np.isfinite(J))):
            raise StepMapError(f"derivative returned a non-finite state or Jacobian at x={x}")
        if self.symmetry is not None:
            return self.symmetry @ y, self.symmetry @ J
        return y, J

    def jacobian(self, x) -> np.ndarray:
        """dP/dx (d, d) at x, exact (value_and_jacobian)."""
        return self.value_and_jacobian(x)[1]

    def _checked(self, x):
        x = np.asarray(x, dtype=np.float64)
        if x.shape != (self.dim,):
            raise ValueError(f"step map state must have shape ({self.dim},), got {x.shape}")
        return x

    def iterate(self, x0, n: int) -> np.ndarray:
        """(n + 1, d) orbit x0, P(x0), ..., P^n(x0) (stops early, shorter, if the walker fails)."""
        from ..checks import whole
        n = whole("n", n, 0)
        xs = [np.asarray(x0, dtype=np.float64)]
        for _ in range(n):
            try:
                xs.append(self(xs[-1]))
            except StepMapError:
                break
        return np.array(xs)


def jacobian(f: Callable, x, eps=1e-6, central: bool = True, fx=None) -> np.ndarray:
    """Finite-difference Jacobian (d, d) of f at x; step eps (scalar or per coordinate),
    central differences (2d evaluations) or forward (d, reusing fx = f(x) if given)."""
    x = np.asarray(x, dtype=np.float64)
    d = x.size
    h = np.broadcast_to(finite_differences_step(eps), (d,))
    if not central and fx is None:
        fx = np.asarray(f(x))
    J = np.zeros((d, d))
    for i in range(d):
        e = np.zeros(d)
        e[i] = h[i]
        if central:
            J[:, i] = (np.asarray(f(x + e)) - np.asarray(f(x - e))) / (2.0 * h[i])
        else:
            J[:, i] = (np.asarray(f(x + e)) - fx) / h[i]
    return J


def finite_differences_step(eps):
    """eps, a finite-difference step (a number, or one per coordinate), as a float or float
    array; a ValueError naming it unless every entry is a finite number > 0 (a string failed
    in numpy's conversion, NaN passed "eps <= 0" and gave a NaN Jacobian, True was 1)."""
    from ..checks import holds_bool
    from ..errors import plain
    try:
        h = None if holds_bool(eps) or isinstance(eps, (str, bytes)) else np.asarray(eps, dtype=np.float64)
    except (TypeError, ValueError):
        h = None
    if h is None or h.ndim > 1 or not (np.all(np.isfinite(h)) and np.all(h > 0)) or h.size == 0:
        raise ValueError(f"finite-difference step eps={plain(eps)!r} must be a finite number > 0 "
                         "(or one per coordinate)")
    return float(h) if h.ndim == 0 else h


def sort_multipliers(lam) -> np.ndarray:
    """Eigenvalues ordered by decreasing modulus (ties: by real, then imaginary part)."""
    lam = np.asarray(lam, dtype=complex)
    order = np.lexsort((lam.imag, lam.real, -np.round(np.abs(lam), 12)))
    return lam[order]


def floquet_multipliers(f: Callable, x, eps=1e-6, central: bool = True) -> np.ndarray:
    """Eigenvalues of the step map's Jacobian at x (a fixed point), largest modulus first."""
    return sort_multipliers(np.linalg.eigvals(jacobian(f, x, eps, central)))


@dataclass
class FixedPoint:
    """Result of find_fixed_point.

    x : (d,) fixed point;  residual : |P(x) - x|_inf;  converged : residual <= tol
    jacobian : (d, d) dP/dx at x;  multipliers : its eigenvalues, largest modulus first
    iterations : Newton steps;  evaluations : map evaluations used;  history : residual per step
    noise : the map's measured noise (map_noise, units of x);  tol : the tolerance applied:
    the one asked for, raised to NOISE_FACTOR x noise where the map is noisier than that
    """
    x: np.ndarray
    residual: float
    converged: bool
    jacobian: np.ndarray
    multipliers: np.ndarray
    iterations: int
    evaluations: int
    history: list = field(default_factory=list)
    noise: float = float("nan")
    tol: float = float("nan")

    @property
    def stable(self) -> bool:
        """All multipliers strictly inside the unit circle."""
        return bool(np.all(np.abs(self.multipliers) < 1.0))

    @property
    def spectral_radius(self) -> float:
        return float(np.max(np.abs(self.multipliers)))


# a fixed point counts as converged when its residual is within this many times the map's noise
NOISE_FACTOR = 4.0
# probe step of map_noise, relative to max(1, |x|_inf)
NOISE_PROBE = 1e-8


def map_noise(evaluate, x, probes: int = 3, seed: int = 0) -> float:
    """The map's noise at x [units of x]: the largest |P(x + d) + P(x - d) - 2 P(x)| / 2 over
    `probes` random steps d of size NOISE_PROBE (a smooth map's second difference there is
    ~1e-16 of its curvature; a simulated map's is its noise: solver tolerances, touchdown
    root finding). evaluate(X) -> (Y, ok) as multipliers_with_error's. NaN if the map fails."""
    from ..checks import whole
    probes = whole("probes", probes, 1)
    x = np.asarray(x, dtype=np.float64)
    h = NOISE_PROBE * max(1.0, float(np.max(np.abs(x))))
    D = h * np.random.default_rng(seed).choice([-1.0, 1.0], size=(probes, x.size))
    Y, ok = evaluate(np.vstack([x[None, :], x + D, x - D]))
    if not ok.all():
        return float("nan")
    second = Y[1:probes + 1] + Y[probes + 1:] - 2.0 * Y[0]
    return float(np.max(np.abs(second)) / 2.0)


# the tolerance "auto" asks for where the map is quieter than that [units of x]
AUTO_TOL = 1e-9


def noise_tolerance(tol, noise) -> float:
    """The residual a fixed point must reach: tol ("auto": AUTO_TOL), raised to NOISE_FACTOR x
    noise (a residual below the map's noise cannot be asked for)."""
    floor = NOISE_FACTOR * noise if np.isfinite(noise) else 0.0
    if isinstance(tol, str):
        if tol != "auto":
            raise ValueError(f"tol={tol!r} must be 'auto' or a number")
        return max(floor, AUTO_TOL)
    from ..checks import positive       # (inf converged at once, True was 1)
    return max(positive("tol", tol, "'auto' or the residual a fixed point must reach"), floor)


def find_fixed_point(f: Callable, x0, tol="auto", max_iter: int = 30, eps=1e-6,
                     central: bool = True, max_halvings: int = 12,
                     exact: bool | None = None) -> FixedPoint:
    """Newton's method on F(x) = f(x) - x with the map's exact Jacobian (a StepMap with a
    derivative, unless exact=False) or a finite-difference one (step eps).

    Each step solves (J - I) dx = -F (least squares if singular); the step is halved while the
    new residual is not smaller or the map fails (StepMapError). Stops when |F|_inf <= tol,
    with tol raised to NOISE_FACTOR x the map's noise measured at x0 (map_noise; "auto":
    AUTO_TOL, raised likewise). The returned Jacobian is evaluated at the final x.
    """
    from ..checks import whole
    max_iter = whole("max_iter", max_iter, 0)
    max_halvings = whole("max_halvings", max_halvings, 0)
    eps = finite_differences_step(eps)
    count = [0]
    has = isinstance(f, StepMap) and f.exact
    if exact and not has:
        raise ValueError("exact=True needs a StepMap with a derivative (an exact Jacobian)")
    use = {"exact": has if exact is None else bool(exact)}

    def g(x):
        count[0] += 1
        return np.asarray(f(x), dtype=np.float64)

    def jac(x, fx):
        """dP/dx at x (fx = P(x)): the exact one (one more evaluation) or differences (also
        where the exact one is not covered and was not asked for by exact=True)."""
        if use["exact"]:
            count[0] += 1
            try:
                return f.value_and_jacobian(x)[1]
            except NotImplementedError:
                if exact:
                    raise
                use["exact"] = False
        return jacobian(g, x, eps, central, fx=fx)

    x = np.asarray(x0, dtype=np.float64).copy()
    try:
        F = g(x) - x
    except StepMapError as e:
        raise StepMapError(f"the step map fails at the initial guess x0={x0}: {e}") from None
    r = float(np.max(np.abs(F)))
    noise = map_noise(serial_evaluator(g), x)
    tol = noise_tolerance(tol, noise)
    history = [r]
    it = 0
    eye = np.eye(x.size)
    while r > tol and it < max_iter:
        J = jac(x, F + x)
        try:
            dx = np.linalg.solve(J - eye, -F)
        except np.linalg.LinAlgError:
            dx = np.linalg.lstsq(J - eye, -F, rcond=None)[0]
        step = 1.0
        for _ in range(max_halvings):
            xn = x + step * dx
            try:
                Fn = g(xn) - xn
                rn = float(np.max(np.abs(Fn)))
            except StepMapError:
                rn = np.inf
            if rn < r:
                break
            step *= 0.5
        else:
            break  # no decrease along the Newton direction: give up (reported as not converged)
        x, F, r = xn, Fn, rn
        history.append(r)
        it += 1
    J = jac(x, F + x)
    return FixedPoint(x=x, residual=r, converged=r <= tol, jacobian=J,
                      multipliers=sort_multipliers(np.linalg.eigvals(J)), iterations=it,
                      evaluations=count[0], history=history, noise=noise, tol=tol)


# multipliers with an error estimate ----------------------------------------------------------
class MultiplierWarning(UserWarning):
    """The finite-difference multipliers did not settle: their error estimate exceeds tol."""


# steps of the eps ladder (absolute, in the section coordinates' units): 1e-2 / 4^k
EPS_LADDER = tuple(1e-2 / 4.0 ** k for k in range(7))


def serial_evaluator(f: Callable):
    """evaluate(X (n, d)) -> (Y (n, d), ok (n,)) calling f on each row; a StepMapError (the
    walker fell) gives ok False and a NaN row."""
    def evaluate(X):
        X = np.atleast_2d(np.asarray(X, dtype=np.float64))
        Y = np.full(X.shape, np.nan)
        ok = np.zeros(len(X), bool)
        for i, x in enumerate(X):
            try:
                Y[i] = f(x)
                ok[i] = True
            except StepMapError:
                pass
        return Y, ok
    return evaluate


def central_points(x, eps) -> np.ndarray:
    """(2d, d) stencil x + eps_i e_i, x - eps_i e_i (i = 0..d-1, interleaved)."""
    x = np.asarray(x, dtype=np.float64)
    d = x.size
    h = np.broadcast_to(np.asarray(eps, dtype=np.float64), (d,))
    P = np.repeat(x[None, :], 2 * d, axis=0)
    for i in range(d):
        P[2 * i, i] += h[i]
        P[2 * i + 1, i] -= h[i]
    return P


def central_jacobian(Y, eps) -> np.ndarray:
    """Jacobian (d, d) from the map's values Y (2d, d) on central_points(x, eps)."""
    Y = np.asarray(Y)
    d = Y.shape[1]
    h = np.broadcast_to(np.asarray(eps, dtype=np.float64), (d,))
    return ((Y[0::2] - Y[1::2]) / (2.0 * h)).T


def match_distance(a, b) -> float:
    """Largest |a_i - b_pi(i)| under the pairing pi of two multiplier sets that minimises the
    total distance (so that a reordering by modulus does not count as a change)."""
    from scipy.optimize import linear_sum_assignment
    a, b = np.asarray(a, complex), np.asarray(b, complex)
    C = np.abs(a[:, None] - b[None, :])
    r, c = linear_sum_assignment(C)
    return float(np.max(C[r, c])) if len(r) else 0.0


@dataclass
class Multipliers:
    """Floquet multipliers with an error estimate (multipliers_with_error).

    values : (d,) largest modulus first;  error : estimated largest error of a multiplier;
    eps : finite-difference step that gave `values` (absolute, units of x);
    noise : estimated noise level of the map (units of x; NaN when not seen);
    converged : error <= tol;  jacobian : (d, d) at eps;  ladder : [(eps, values), ...] tried;
    evaluations : map evaluations used
    """
    values: np.ndarray
    error: float
    eps: float
    noise: float
    converged: bool
    jacobian: np.ndarray
    ladder: list = field(default_factory=list)
    evaluations: int = 0

    @property
    def spectral_radius(self) -> float:
        return float(np.max(np.abs(self.values)))

    @property
    def stable(self) -> bool:
        return bool(np.all(np.abs(self.values) < 1.0))


def multipliers_with_error(f: Callable | None, x, eps="auto", tol: float = 3e-3, evaluate=None,
                           warn: bool = True) -> Multipliers:
    """Multipliers of the step map f at x (a fixed point) with an error estimate.

    eps="auto": central differences on the ladder EPS_LADDER (1e-2 / 4^k, coarse to fine).
    Going down the ladder the truncation error shrinks as eps^2 until the map's own noise
    takes over: a simulated map is smooth only down to some scale (touchdown-time root
    finding, solver tolerances, the step in which an impact falls), below which it is
    piecewise smooth with jumps, and differences grow as noise / eps or settle on the slope of
    one smooth piece. The first (coarsest) pair of neighbouring rungs whose multipliers agree
    within tol is taken (none: the pair that agrees best), and the next pairs too while their
change keeps falling by more than 4x (truncation regime): the finer rung gives the values and
    eps, their change the error estimate; the changes further down, times their eps, give
    the noise level. A number eps: central differences at 2 eps and eps, the change between
    them as the error estimate.
    Rungs at which the map fails (the walker falls) are skipped. A MultiplierWarning is issued
    (if warn) when the error exceeds tol. evaluate(X) -> (Y, ok) evaluates many points at once
    (a MapPool's, to use every core); default: f one point after another.
    """
    x = np.asarray(x, dtype=np.float64)
    evaluate = evaluate or serial_evaluator(f)
    if isinstance(eps, str):
        if eps != "auto":
            raise ValueError(f"eps={eps!r} must be 'auto' or a positive number")
        steps = list(EPS_LADDER)
    else:                       # (True was a step of 1)
        from ..checks import positive
        e = positive("finite-difference step eps", eps, "or 'auto'")
        steps = [2.0 * e, e]
    from ..checks import positive
    tol = positive("tol", tol, "the multipliers' error allowed")
    pts = np.concatenate([central_points(x, h) for h in steps])
    Y, ok = evaluate(pts)
    n = 2 * x.size
    rungs = []
    for k, h in enumerate(steps):
        if ok[k * n:(k + 1) * n].all():
            J = central_jacobian(Y[k * n:(k + 1) * n], h)
            rungs.append((h, J, sort_multipliers(np.linalg.eigvals(J))))
    if not rungs:
        raise StepMapError(f"the step map fails at every finite-difference step around x={x}")
    if len(rungs) == 1:
        h, J, lam = rungs[0]
        res = Multipliers(lam, np.inf, h, np.nan, False, J, [(h, lam)], len(pts))
    else:
        diffs = [match_distance(rungs[k][2], rungs[k + 1][2]) for k in range(len(rungs) - 1)]
        agree = [j for j, dj in enumerate(diffs) if dj <= tol]
        k = agree[0] if agree else int(np.argmin(diffs))
        while k + 1 < len(diffs) and diffs[k + 1] < diffs[k] / 4.0:
            k += 1   # still in the truncation regime (changes fall as eps^2: 16x a rung)
        h, J, lam = rungs[k + 1]
        finer = [diffs[j] * rungs[j + 1][0] for j in range(k + 1, len(diffs))]
        noise = float(np.max(finer)) if finer else np.nan
        res = Multipliers(lam, float(diffs[k]), h, noise, bool(diffs[k] <= tol), J,
                          [(r[0], r[2]) for r in rungs], len(pts))
    if warn and not res.converged:
        import warnings
        warnings.warn(f"Floquet multipliers not converged in the finite-difference step: estimated "
                      f"error {res.error:.2g} > tol {tol:g} (eps {res.eps:.2g})", MultiplierWarning,
                      stacklevel=2)
    return res


def multipliers_exact(f: StepMap, x) -> Multipliers:
    """Multipliers of the step map f at x (a fixed point) from its exact Jacobian
    (StepMap.derivative): exact to rounding within the step's contact modes, so error 0 and
    eps 0 (no difference step); one evaluation of the derivative."""
    J = f.jacobian(x)
    lam = sort_multipliers(np.linalg.eigvals(J))
    return Multipliers(lam, 0.0, 0.0, float("nan"), True, J, [(0.0, lam)], 1)


# multipliers from a polynomial fit -----------------------------------------------------------
FIT_WINDOW = 2e-3   # [units of x] half-width of the samples along each coordinate
FIT_POINTS = 17     # samples per coordinate (odd: x itself among them)
FIT_DEGREE = 5      # degree of the polynomial fitted to them


def _fit_columns(s, Y, ok, degree):
    """Slope at s = 0 of a least-squares polynomial of `degree` through (s[ok], Y[ok]) (each
    column of Y), and the fit's rms residual; (None, inf) with too few samples."""
    if np.count_nonzero(ok) < degree + 2:
        return None, np.inf
    c = np.polyfit(s[ok], Y[ok], degree)
    fitted = np.stack([np.polyval(c[:, j], s[ok]) for j in range(Y.shape[1])], axis=1)
    return c[-2], float(np.sqrt(np.mean((Y[ok] - fitted) ** 2)))


def multipliers_by_fit(f: Callable | None, x, window: float = FIT_WINDOW, points: int = FIT_POINTS,
                       degree: int = FIT_DEGREE, tol: float = 3e-3, evaluate=None,
                       warn: bool = True) -> Multipliers:
    """Multipliers of the step map f at x from least-squares polynomials: along each coordinate,
    `points` samples x +- s e_i (|s| <= window, units of x) are fitted by a polynomial of
    `degree` in s, whose slope at 0 is that column of the Jacobian.

    A simulated map is piecewise smooth below ~1e-4 (the touchdown falls in another sim step)
    and strongly curved above ~1e-3 (central differences of the simplest walker near its period
    doubling are off by 1e-2 at eps 1e-3): the fit averages the pieces over the window and
    takes the curvature into its higher terms. The same fit over the inner half of the
    samples (|s| <= window / 2) gives the error estimate (their multipliers' distance over
    1 - 2^-p, for an error ~ window^p: p = degree + 1 for an odd degree); `noise` is the full
    fit's rms residual. Multipliers(eps=window, ladder=[(window, values),
    (window / 2, inner values)]). Samples where the map fails are left out.
    """
    from ..checks import positive, whole
    x = np.asarray(x, dtype=np.float64)
    # (points="21" or degree="3" failed in int() raw, 21.5 points were 21; True was 1)
    points, degree = whole("points", points, 1), whole("degree", degree, 1)
    window = positive("window", window, "units of x")
    tol = positive("tol", tol, "the multipliers' error allowed")
    if points < 2 * degree + 3 or points % 2 == 0:
        raise ValueError(f"points={points} must be odd and >= 2 * degree + 3 = {2 * degree + 3} "
                         "(the inner half is fitted too)")
    if not (window > 0 and np.isfinite(window)):
        raise ValueError(f"window={window} must be > 0 (units of x)")
    evaluate = evaluate or serial_evaluator(f)
    d = x.size
    s = window * np.linspace(-1.0, 1.0, points)
    inner = np.abs(s) <= 0.5 * window * (1 + 1e-12)
    Y, ok = evaluate(np.concatenate([x + np.outer(s, np.eye(d)[i]) for i in range(d)]))
    J, Jin, noise = np.zeros((d, d)), np.zeros((d, d)), 0.0
    for i in range(d):
        rows = slice(i * points, (i + 1) * points)
        col, rms = _fit_columns(s, Y[rows], ok[rows], degree)
        col_in, _ = _fit_columns(s[inner], Y[rows][inner], ok[rows][inner], degree)
        if col is None or col_in is None:
            raise StepMapError(f"the step map fails at too many samples along coordinate {i} "
                               f"around x={x} (window {window:g})")
        J[:, i], Jin[:, i], noise = col, col_in, max(noise, rms)
    lam, lam_in = sort_multipliers(np.linalg.eigvals(J)), sort_multipliers(np.linalg.eigvals(Jin))
    # the full window's error from the change between the windows (Richardson): a fit's slope
    # errs by the map's terms above its degree, an odd degree's first one s^(degree + 2)
    # giving an error ~ window^(degree + 1) (an even degree's: window^degree)
    order = degree + 1 if degree % 2 else degree
    err = match_distance(lam, lam_in) / (1.0 - 0.5 ** order)
    res = Multipliers(lam, err, float(window), noise, bool(err <= tol), J,
                      [(float(window), lam), (0.5 * float(window), lam_in)], len(s) * d)
    if warn and not res.converged:
        import warnings
        warnings.warn(f"Floquet multipliers by fit not converged: estimated error {err:.2g} > "
                      f"tol {tol:g} (window {window:.2g})", MultiplierWarning, stacklevel=2)
    return res
