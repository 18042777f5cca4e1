"""Brute-force bifurcation diagrams and basins of attraction: iterate the step map, many
parameter values or initial conditions at once on a MapPool's workers."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..checks import finite_number, whole
from .continuation import write_csv
from .parallel import MapPool, iterate_task


@dataclass
class Diagram:
    """Brute-force bifurcation diagram: for each parameter value p[i], the last section
    points orbits[i] (k_i, d) after `transient` steps (fewer, or none, if the walker fell),
    steps[i] taken, fell[i]."""
    param: str
    p: np.ndarray
    orbits: list
    steps: np.ndarray
    fell: np.ndarray
    transient: int
    keep: int

    def fall_onset(self):
        """The smallest p (in the direction of the sweep) from which the walker fell, or None."""
        idx = np.flatnonzero(self.fell)
        return float(self.p[idx[0]]) if idx.size else None

    def periods(self, tol: float = 1e-6) -> np.ndarray:
        """Apparent period of each kept orbit: the smallest k with |x_{j+k} - x_j| <= tol over
        the kept points (0: none up to half the kept length, as in chaos; -1: fell)."""
        out = np.zeros(len(self.p), int)
        for i, orb in enumerate(self.orbits):
            if self.fell[i] or len(orb) < 2:
                out[i] = -1
                continue
            for k in range(1, len(orb) // 2 + 1):
                if np.max(np.abs(orb[k:] - orb[:-k])) <= tol:
                    out[i] = k
                    break
        return out

    def rows(self, coordinate: int = 0, name: str | None = None) -> list:
        name = name or f"x{coordinate}"
        rows = []
        for p, orb, fell in zip(self.p, self.orbits, self.fell):
            if not len(orb):
                rows.append({self.param: p, name: np.nan, "fell": int(fell)})
            for x in orb:
                rows.append({self.param: p, name: float(x[coordinate]), "fell": int(fell)})
        return rows

    def to_csv(self, path, coordinate: int = 0, name: str | None = None):
        write_csv(path, self.rows(coordinate, name))


def bifurcation_diagram(pool: MapPool, p_values, x0, transient: int = 200, keep: int = 64,
                        param: str = "p", progress=None) -> Diagram:
    """Iterate P(x; p) from x0 (an array, or a callable p -> x0) `transient` steps, keep the
    next `keep` section points, for every p in p_values (in parallel on the pool)."""
    # a period is read among the kept points: fewer than 2 read as a fall (Diagram.periods)
    transient = whole("transient", transient, 0)
    keep = whole("keep", keep, 2)
    ps = np.asarray(p_values, dtype=np.float64)
    x0f = x0 if callable(x0) else (lambda p: np.asarray(x0, dtype=np.float64))
    n = int(transient) + int(keep)
    items = [(float(p), x0f(p), n, int(keep), None, 0.0) for p in ps]
    res = pool.run(iterate_task, items, progress)
    pool.evaluations += int(sum(r[1] + r[2] for r in res))
    return Diagram(param, ps, [r[0] for r in res], np.array([r[1] for r in res]),
                   np.array([r[2] for r in res], bool), int(transient), int(keep))


@dataclass
class Basin:
    """Basin of attraction over a grid of initial conditions: a[i], b[j] the two grid
    coordinates, steps (na, nb) before a fall or the end, fell (na, nb), reached (na, nb):
    came within tol of the attractor."""
    a: np.ndarray
    b: np.ndarray
    steps: np.ndarray
    fell: np.ndarray
    reached: np.ndarray
    names: tuple = ("a", "b")

    @property
    def fraction(self) -> float:
        """Fraction of the grid that reaches the attractor."""
        return float(np.mean(self.reached))

    def rows(self) -> list:
        return [{self.names[0]: float(self.a[i]), self.names[1]: float(self.b[j]),
                 "steps": int(self.steps[i, j]), "fell": int(self.fell[i, j]),
                 "reached": int(self.reached[i, j])}
                for i in range(len(self.a)) for j in range(len(self.b))]

    def to_csv(self, path):
        write_csv(path, self.rows())


def basin_of_attraction(pool: MapPool, p: float, a_values, b_values, state, attractor,
                        n_steps: int = 50, tol: float = 1e-4, names=("a", "b"),
                        progress=None) -> Basin:
    """Which initial conditions on a 2-D grid walk to `attractor` (a fixed point (d,)).

    state(a, b) -> x0 (d,) the section state of grid point (a, b) (say the stance angle and
    rate, the swing leg from the impact law). Each is iterated up to n_steps steps (in
    parallel), stopping when within tol (max norm) of the attractor or at a fall."""
    # (a string n_steps failed in int(), 2.5 steps were 2, a NaN tol reached nothing)
    p = finite_number("p", p)
    n_steps = whole("n_steps", n_steps, 0)
    tol = finite_number("tol", tol, 0.0)
    A, B = np.asarray(a_values, float), np.asarray(b_values, float)
    target = np.asarray(attractor, dtype=np.float64)
    items = [(float(p), np.asarray(state(a, b), dtype=np.float64), int(n_steps), 0, target, float(tol))
             for a in A for b in B]
    res = pool.run(iterate_task, items, progress)
    pool.evaluations += int(sum(r[1] + r[2] for r in res))
    shape = (len(A), len(B))
    steps = np.array([r[1] for r in res]).reshape(shape)
    fell = np.array([r[2] for r in res], bool).reshape(shape)
    reached = np.array([(not r[2]) and r[3] <= tol for r in res], bool).reshape(shape)
    return Basin(A, B, steps, fell, reached, tuple(names))
