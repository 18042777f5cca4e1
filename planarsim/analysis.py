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

Step events from a recorded run: the touchdown of a contact is a frame whose contact mode is
in contact (pinned or sliding) after a frame where it was not (free, or disabled: -1).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

IN_CONTACT = (1, 2)   # contact modes that touch the ground: pinned, sliding


class StepMapError(RuntimeError):
    """A step-map evaluation failed (the walker fell, or no touchdown happened)."""


# step events ---------------------------------------------------------------------------------
def touchdowns(contact_mode: np.ndarray) -> np.ndarray:
    """Frames at which a contact touches down.

    contact_mode : (K,) modes of one contact per recorded frame (0 free, 1 pinned, 2 sliding,
        -1 disabled).
    Returns the frame indices k >= 1 with mode[k] in contact and mode[k-1] not.
    """
    mode = np.asarray(contact_mode)
    if mode.ndim != 1:
        raise ValueError(f"contact_mode must be 1-D (frames of one contact), got shape {mode.shape}")
    on = np.isin(mode, IN_CONTACT)
    return np.flatnonzero(on[1:] & ~on[:-1]) + 1


@dataclass(frozen=True)
class StepEvents:
    """Touchdowns of several contacts, in time order.

    frame : (n,) int   recorded frame just after the touchdown
    time : (n,) [s]
    contact : (n,) int contact index that touched down
    """
    frame: np.ndarray
    time: np.ndarray
    contact: np.ndarray

    def __len__(self):
        return len(self.frame)

    @property
    def periods(self) -> np.ndarray:
        """(n - 1,) time between consecutive touchdowns [s]."""
        return np.diff(self.time)


def _contact_index(traj, contact) -> int:
    if isinstance(contact, str):
        names = list(traj.contact_names)
        if contact not in names:
            raise KeyError(f"no contact named {contact!r} in the trajectory; have {names}")
        return names.index(contact)
    c = int(contact)
    if not 0 <= c < traj.contact_mode.shape[1]:
        raise IndexError(f"contact index {c} out of range 0..{traj.contact_mode.shape[1] - 1}")
    return c


def step_events(traj, contacts: Sequence | None = None) -> StepEvents:
    """Touchdown events of `contacts` (names or indices; default all) in a Trajectory."""
    if contacts is None:
        contacts = range(traj.contact_mode.shape[1])
    frames, which = [], []
    for c in contacts:
        ci = _contact_index(traj, c)
        f = touchdowns(traj.contact_mode[:, ci])
        frames.append(f)
        which.append(np.full(len(f), ci))
    frame = np.concatenate(frames) if frames else np.zeros(0, int)
    contact = np.concatenate(which) if which else np.zeros(0, int)
    order = np.argsort(frame, kind="stable")
    frame, contact = frame[order], contact[order]
    return StepEvents(frame=frame, time=np.asarray(traj.t)[frame], contact=contact)


def poincare_section(traj, coords: Callable, contacts: Sequence | None = None):
    """Section points at touchdown: X[i] = coords(q, v, contact) at each event frame.

    coords(q (n_body, 3), v (n_body, 3), contact) -> (d,) section coordinates of the state
    whose new stance contact is `contact`. Returns (StepEvents, X (n, d)).
    """
    ev = step_events(traj, contacts)
    X = np.array([np.asarray(coords(traj.q[f], traj.v[f], c), dtype=np.float64)
                  for f, c in zip(ev.frame, ev.contact)])
    return ev, X.reshape(len(ev), -1)


# the step-to-step map ------------------------------------------------------------------------
@dataclass
class StepMap:
    """x_k -> x_{k+1}, computed by `advance` (one simulated step of the walker).

    advance : callable (d,) -> (d,); raises StepMapError when the walker fails
    symmetry : optional (d, d) relabelling S; the map is then x -> S advance(x)
    names : optional coordinate names (for printing)
    """
    advance: Callable[[np.ndarray], np.ndarray]
    dim: int
    symmetry: np.ndarray | None = None
    names: tuple = ()
    evaluations: int = 0

    def __post_init__(self):
        if self.symmetry is not None:
            S = np.asarray(self.symmetry, dtype=np.float64)
            if S.shape != (self.dim, self.dim):
                raise ValueError(f"symmetry must be a ({self.dim}, {self.dim}) matrix, got {S.shape}")
            self.symmetry = S

    def __call__(self, x) -> np.ndarray:
        x = np.asarray(x, dtype=np.float64)
        if x.shape != (self.dim,):
            raise ValueError(f"step map state must have shape ({self.dim},), got {x.shape}")
        self.evaluations += 1
        y = np.asarray(self.advance(x.copy()), dtype=np.float64)
        if y.shape != (self.dim,):
            raise StepMapError(f"advance returned shape {y.shape}, expected ({self.dim},)")
        if not np.all(np.isfinite(y)):
            raise StepMapError(f"advance returned a non-finite state {y}")
        return y if self.symmetry is None else self.symmetry @ y

    def iterate(self, x0, n: int) -> np.ndarray:
        """(n + 1, d) orbit x0, P(x0), ..., P^n(x0) (stops early, shorter, if the walker fails)."""
        xs = [np.asarray(x0, dtype=np.float64)]
        for _ in range(int(n)):
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
    h = np.broadcast_to(np.asarray(eps, dtype=np.float64), (d,))
    if np.any(h <= 0):
        raise ValueError(f"finite-difference step eps={eps} must be > 0")
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
    """
    x: np.ndarray
    residual: float
    converged: bool
    jacobian: np.ndarray
    multipliers: np.ndarray
    iterations: int
    evaluations: int
    history: list = field(default_factory=list)

    @property
    def stable(self) -> bool:
        """All multipliers strictly inside the unit circle."""
        return bool(np.all(np.abs(self.multipliers) < 1.0))

    @property
    def spectral_radius(self) -> float:
        return float(np.max(np.abs(self.multipliers)))


def find_fixed_point(f: Callable, x0, tol: float = 1e-10, max_iter: int = 30, eps=1e-6,
                     central: bool = True, max_halvings: int = 12) -> FixedPoint:
    """Newton's method on F(x) = f(x) - x with a finite-difference Jacobian.

    Each step solves (J - I) dx = -F (least squares if singular); the step is halved while the
    new residual is not smaller or the map fails (StepMapError). Stops when |F|_inf <= tol.
    The returned Jacobian is evaluated at the final x.
    """
    count = [0]

    def g(x):
        count[0] += 1
        return np.asarray(f(x), dtype=np.float64)

    x = np.asarray(x0, dtype=np.float64).copy()
    try:
        F = g(x) - x
    except StepMapError as e:
        raise StepMapError(f"the step map fails at the initial guess x0={x0}: {e}") from None
    r = float(np.max(np.abs(F)))
    history = [r]
    it = 0
    eye = np.eye(x.size)
    while r > tol and it < max_iter:
        J = jacobian(g, x, eps, central, fx=F + x)
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
    J = jacobian(g, x, eps, central, fx=F + x)
    return FixedPoint(x=x, residual=r, converged=r <= tol, jacobian=J,
                      multipliers=sort_multipliers(np.linalg.eigvals(J)), iterations=it,
                      evaluations=count[0], history=history)


# plots ---------------------------------------------------------------------------------------
def _axes(ax, figsize=(4.5, 4.5)):
    import matplotlib
    if ax is not None:
        return ax.figure, ax
    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=figsize)
    return fig, ax


def _finish(fig, path):
    if path is not None:
        fig.tight_layout()
        fig.savefig(path, dpi=120)
        import matplotlib.pyplot as plt
        plt.close(fig)
    return fig


def plot_multipliers(multipliers, path=None, ax=None, title="Floquet multipliers", label=None):
    """Multipliers in the complex plane against the unit circle; saved to `path` if given."""
    lam = np.asarray(multipliers, dtype=complex)
    fig, ax = _axes(ax)
    th = np.linspace(0.0, 2.0 * np.pi, 361)
    ax.plot(np.cos(th), np.sin(th), color="0.5", lw=1.0, label="unit circle")
    ax.axhline(0.0, color="0.85", lw=0.8)
    ax.axvline(0.0, color="0.85", lw=0.8)
    ax.plot(lam.real, lam.imag, "x", ms=9, mew=2, color="C3", label=label or "multipliers")
    lim = max(1.2, 1.1 * float(np.max(np.abs(lam))) if lam.size else 1.2)
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_aspect("equal")
    ax.set_xlabel("Re")
    ax.set_ylabel("Im")
    ax.set_title(title)
    ax.legend(loc="upper right", fontsize=8)
    return _finish(fig, path)


def plot_limit_cycle(angle, rate, path=None, ax=None, section=None, labels=("angle [rad]", "rate [rad/s]"),
                     title="limit cycle", **style):
    """Phase portrait (angle vs rate) of a recorded gait; `section` (n, 2) marks the
    Poincare-section points (touchdowns). Saved to `path` if given."""
    fig, ax = _axes(ax, figsize=(5.5, 4.2))
    ax.plot(np.asarray(angle), np.asarray(rate), lw=1.0, **style)
    if section is not None and len(section):
        sec = np.asarray(section)
        ax.plot(sec[:, 0], sec[:, 1], "o", ms=4, color="C3", label="touchdown section")
        ax.legend(fontsize=8)
    ax.set_xlabel(labels[0])
    ax.set_ylabel(labels[1])
    ax.set_title(title)
    return _finish(fig, path)
