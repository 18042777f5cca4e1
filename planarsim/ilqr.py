"""Iterative LQR (Li and Todorov 2004; Tassa, Erez and Todorov 2012) on the engine's exact step
derivatives: a locally optimal command sequence and its feedback gains for a cost over a
horizon.

    result = ilqr(sim, us, QuadraticCost(goal, Q, R, Q_final))
    run = follow(sim, result)        # the commands with the gains closing the loop

Each iteration takes the derivative of every step along the current rollout
(derivatives.rollout_jacobians: exact, the implicit function theorem on the step's own
answer), solves the Riccati recursion of the cost's quadratic model backwards (regularised in
the state, mu I added to the next state's cost Hessian, mu raised tenfold where the commands'
Hessian is not positive definite or no step length lowers the cost), and rolls the commands forward with the new feedback, u = u_k + alpha k_k + K_k (x -
x_k), alpha halved until the cost falls by a share of what the model expected. The state is
the simulator's x = (q.ravel(), v.ravel()) [m, rad, m/s, rad/s]; the commands are clipped to
the actuators' ranges (a saturated command's derivative is 0: the step's B). A step outside
what step_jacobian covers raises its NotImplementedError, naming the step.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .derivatives import rollout_jacobians

#: a line search's step lengths (alpha)
ALPHAS = 0.5 ** np.arange(10)
#: a step of the line search is taken when the cost falls by at least this share of the fall
#: the quadratic model expects
ACCEPT_SHARE = 1e-4
REG_MIN = 1e-6
REG_MAX = 1e10
#: the regularisation at most at which a quadratic model that expects no fall counts as
#: convergence (a large one shrinks the step whatever the cost's slope)
CONVERGED_REG = 1e-3


@dataclass(frozen=True)
class QuadraticCost:
    """sum_k (x_k - goal)^T Q (x_k - goal) / 2 + u_k^T R u_k / 2 over the steps, plus (x_T -
    goal)^T Q_final (x_T - goal) / 2 at the end. goal (n_x,); Q, Q_final (n_x, n_x) and R (n_u,
    n_u) symmetric, Q and Q_final positive semidefinite and R positive definite."""
    goal: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    Q_final: np.ndarray

    def step_terms(self, x, u):
        """(l, l_x, l_u, l_xx, l_uu, l_ux) of one step."""
        e = x - self.goal
        Qe = self.Q @ e
        Ru = self.R @ u
        return (0.5 * e @ Qe + 0.5 * u @ Ru, Qe, Ru, self.Q, self.R,
                np.zeros((u.size, x.size)))

    def final_terms(self, x):
        """(l, l_x, l_xx) at the horizon's end."""
        e = x - self.goal
        Qe = self.Q_final @ e
        return 0.5 * e @ Qe, Qe, self.Q_final


@dataclass(frozen=True)
class ILQRResult:
    """us (T, n_u) the commands; xs (T + 1, n_x) the states they give from the start; gains
    (T, n_u, n_x) the feedback K_k (u = us[k] + K_k (x - xs[k])); cost the total; costs the
    total after each iteration (the start's first); converged: the last iteration changed the
    cost by less than the tolerance."""
    us: np.ndarray
    xs: np.ndarray
    gains: np.ndarray
    cost: float
    costs: list
    converged: bool


def state_vector(sim) -> np.ndarray:
    """x = (q.ravel(), v.ravel()) of sim's state."""
    return np.concatenate([sim.state.q.ravel(), sim.state.v.ravel()])


def _command_range(sim):
    a = sim.model.arrays
    return a.act_range[:, 0], a.act_range[:, 1]


def _rollout(sim, start, us, cost, xs=None, ks=None, gains=None, alpha=0.0):
    """Run from `start` under us (with feedback about xs when gains are given); returns (xs,
    us applied, total cost), or None where the simulator raised (the run left the model's
    range). sim is left at `start`."""
    lo, hi = _command_range(sim)
    T = us.shape[0]
    new_xs = np.empty((T + 1, 2 * sim.state.q.size))
    new_us = np.empty_like(us)
    total = 0.0
    sim.restore(start)
    try:
        for k in range(T):
            x = state_vector(sim)
            u = us[k]
            if gains is not None:
                u = u + alpha * ks[k] + gains[k] @ (x - xs[k])
            u = np.clip(u, lo, hi)
            new_xs[k] = x
            new_us[k] = u
            total += cost.step_terms(x, u)[0]
            sim.step(u)
        new_xs[T] = state_vector(sim)
    except Exception as exc:                      # noqa: BLE001 (a diverged trial run)
        if isinstance(exc, NotImplementedError):
            raise
        return None
    finally:
        sim.restore(start)
    total += cost.final_terms(new_xs[T])[0]
    if not np.isfinite(total):
        return None
    return new_xs, new_us, total


def _backward(jacs, xs, us, cost, reg, lo, hi):
    """The Riccati recursion: (ks, gains, expected fall terms (d1, d2)) or None where the
    commands' Hessian is not positive definite at this regularisation. A command at a bound
    of its range (lo, hi) that the step would push further out is held there (its k and its
    row of the gain 0, the others solved without it: box-constrained DDP's clamped set,
    Tassa, Mansard and Todorov 2014)."""
    T = us.shape[0]
    _, Vx, Vxx = cost.final_terms(xs[T])
    ks = np.empty_like(us)
    gains = np.empty((T, us.shape[1], xs.shape[1]))
    d1 = d2 = 0.0
    for k in range(T - 1, -1, -1):
        A, B = jacs[k].A, jacs[k].B
        _, lx, lu, lxx, luu, lux = cost.step_terms(xs[k], us[k])
        Qx = lx + A.T @ Vx
        Qu = lu + B.T @ Vx
        Qxx = lxx + A.T @ Vxx @ A
        Quu = luu + B.T @ Vxx @ B
        Qux = lux + B.T @ Vxx @ A
        # regularised in the state (Tassa et al. 2012): as if the next state's cost were
        # reg |dx|^2 / 2 steeper, which keeps the gains' scale whatever the commands' units
        Vreg = reg * np.eye(Vxx.shape[0])
        Quu_reg = Quu + B.T @ Vreg @ B
        Qux_reg = Qux + B.T @ Vreg @ A
        try:
            L = np.linalg.cholesky(Quu_reg)
        except np.linalg.LinAlgError:
            return None
        solve = lambda rhs: np.linalg.solve(L.T, np.linalg.solve(L, rhs))  # noqa: E731
        kk = -solve(Qu)
        K = -solve(Qux_reg)
        held = ((us[k] >= hi) & (kk > 0.0)) | ((us[k] <= lo) & (kk < 0.0))
        if held.any():
            free = ~held
            kk = np.zeros_like(kk)
            K = np.zeros_like(K)
            if free.any():
                Qff = Quu_reg[np.ix_(free, free)]
                kk[free] = -np.linalg.solve(Qff, Qu[free])
                K[free] = -np.linalg.solve(Qff, Qux_reg[free])
        ks[k] = kk
        gains[k] = K
        d1 += kk @ Qu
        d2 += 0.5 * kk @ Quu @ kk
        Vx = Qx + K.T @ Quu @ kk + K.T @ Qu + Qux.T @ kk
        Vxx = Qxx + K.T @ Quu @ K + K.T @ Qux + Qux.T @ K
        Vxx = 0.5 * (Vxx + Vxx.T)
    return ks, gains, (d1, d2)


def _jacobians(sim, start, us):
    """The step derivatives along the run of us from `start` (rollout_jacobians), or the
    NotImplementedError of the first step they do not cover; sim is left at `start`."""
    sim.restore(start)
    try:
        return rollout_jacobians(sim, us)
    except NotImplementedError as exc:
        return exc
    finally:
        sim.restore(start)


def ilqr(sim, us, cost, iterations=100, tol=1e-6) -> ILQRResult:
    """Iterative LQR from sim's current state over the horizon of the commands us (T, n_u)
    [N or N m] (the first guess) for `cost` (QuadraticCost, or any object with its step_terms
    and final_terms). A trial run whose steps step_jacobian does not cover (derivatives.py: a
    limit reached, say) is refused as one whose cost rose. Stops after `iterations`, when an
    iteration lowers the cost, or the quadratic model expects it to, by less than tol of it
    (converged), or when no step length lowers it. sim is left at the state it started
    from."""
    us = np.array(us, dtype=float)
    if us.ndim != 2 or us.shape[1] != sim.model.n_act or us.shape[0] == 0:
        raise ValueError(f"us must have shape (T > 0, {sim.model.n_act}), got {us.shape}")
    if not np.all(np.isfinite(us)):
        raise ValueError("us must be finite")
    start = sim.snapshot()
    lo, hi = _command_range(sim)
    first = _rollout(sim, start, us, cost)
    if first is None:
        raise ValueError("the first guess of the commands does not run: the simulator raised")
    xs, us, total = first
    jacs = _jacobians(sim, start, us)
    if isinstance(jacs, NotImplementedError):
        raise jacs
    costs = [total]
    reg = REG_MIN
    gains = np.zeros((us.shape[0], us.shape[1], xs.shape[1]))
    converged = False
    for _ in range(iterations):
        accepted = None
        first = True        # (the iteration's first backward pass, before any refused trial)
        while accepted is None and reg <= REG_MAX:
            back = _backward(jacs, xs, us, cost, reg, lo, hi)
            if back is None:
                reg *= 10.0
                continue
            ks, trial_gains, (d1, d2) = back
            if first and reg <= CONVERGED_REG and -(d1 + d2) <= tol * abs(total):
                converged = True        # (the model expects no more than tol of the cost)
                break
            first = False
            for alpha in ALPHAS:
                trial = _rollout(sim, start, us, cost, xs, ks, trial_gains, alpha)
                if trial is None:
                    continue
                expected = -(alpha * d1 + alpha * alpha * d2)
                if not (total - trial[2] > ACCEPT_SHARE * max(expected, 0.0)
                        and trial[2] < total):
                    continue
                trial_jacs = _jacobians(sim, start, trial[1])
                if not isinstance(trial_jacs, NotImplementedError):
                    accepted = trial
                    break
            if accepted is None:
                reg *= 10.0
        if accepted is None or converged:
            break
        fall = total - accepted[2]
        xs, us, total = accepted
        jacs = trial_jacs
        gains = trial_gains
        costs.append(total)
        reg = max(REG_MIN, reg / 10.0)
        if fall <= tol * abs(total):
            converged = True
            break
    # the gains about the final run itself, at the least regularisation that serves
    reg = REG_MIN
    while reg <= REG_MAX:
        back = _backward(jacs, xs, us, cost, reg, lo, hi)
        if back is not None:
            gains = back[1]
            break
        reg *= 10.0
    return ILQRResult(us=us, xs=xs, gains=gains, cost=total, costs=costs, converged=converged)


def follow(sim, result, extra_steps=0):
    """Run sim from its current state under result's commands with its feedback closing the
    loop, u = us[k] + K_k (x - xs[k]), then extra_steps more holding the last command and gain
    (a stabilised end state stays held). Returns the states visited, (T + extra_steps + 1,
    n_x); sim ends after the last step."""
    lo, hi = _command_range(sim)
    T = result.us.shape[0]
    out = [state_vector(sim)]
    for k in range(T + extra_steps):
        i = min(k, T - 1)
        x = out[-1]
        target = result.xs[min(k, T)]
        u = np.clip(result.us[i] + result.gains[i] @ (x - target), lo, hi)
        sim.step(u)
        out.append(state_vector(sim))
    return np.array(out)
