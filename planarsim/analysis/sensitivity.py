"""The gait sensitivity norm (Hobbelen and Wisse 2007): how strongly a gait's indicators (step
time, step length, ...) respond, over every step after it, to a disturbance at one step (a
floor height or a tilt of the ground under that step).

Linearised at the gait's fixed point x* (disturbance e = 0), the step map and the indicators
of the step taken from x are

    x_{k+1} = A x_k + B e_k,        g_k = C x_k + D e_k.

A unit disturbance at step 0 alone gives g_0 = D, g_k = C A^(k-1) B for k >= 1, and the norm
is the size of that whole response,

    GSN^2 = sum_k |g_k|^2 = |D|^2 + trace(C X C^T),    X = sum_k A^k B B^T (A^k)^T,

X from the discrete Lyapunov equation X = A X A^T + B B^T (Frobenius norms: with several
disturbances, the root of the sum of their squared norms). It is infinite for a gait with a
multiplier on or outside the unit circle. The indicators are the user's choice (their units
set the norm's); the disturbance too, as a step function of it.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np


@dataclass
class GaitSensitivity:
    """The gait sensitivity norm and the linearisation it came from: A (d, d), B (d, m),
    C (p, d), D (p, m); response (steps, p, m): g_0, g_1, ... of a unit disturbance."""
    norm: float
    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    response: np.ndarray


def _as_matrix(M, rows, cols, name) -> np.ndarray:
    M = np.atleast_2d(np.asarray(M, dtype=np.float64))
    if M.shape != (rows, cols):
        raise ValueError(f"{name} must be ({rows}, {cols}), got {M.shape}")
    if not np.all(np.isfinite(M)):
        raise ValueError(f"{name} has non-finite entries")
    return M


def gait_sensitivity_norm(A, B, C, D=None) -> float:
    """GSN (module docstring) of the linearised map A (d, d), disturbance input B (d, m),
    indicators C (p, d) and their direct part D (p, m; default 0); inf where A has an
    eigenvalue of modulus >= 1."""
    A = np.atleast_2d(np.asarray(A, dtype=np.float64))
    d = A.shape[0]
    A = _as_matrix(A, d, d, "A")
    B = np.asarray(B, dtype=np.float64).reshape(d, -1)
    B = _as_matrix(B, d, B.shape[1], "B")
    C = np.atleast_2d(np.asarray(C, dtype=np.float64))
    C = _as_matrix(C, C.shape[0], d, "C")
    D = np.zeros((C.shape[0], B.shape[1])) if D is None else _as_matrix(
        np.asarray(D, dtype=np.float64).reshape(C.shape[0], -1), C.shape[0], B.shape[1], "D")
    if np.max(np.abs(np.linalg.eigvals(A))) >= 1.0:
        return float("inf")
    # X - A X A^T = B B^T: vec(X) = (I - A (x) A)^-1 vec(B B^T)  (d is a gait's few coordinates)
    X = np.linalg.solve(np.eye(d * d) - np.kron(A, A), (B @ B.T).reshape(-1)).reshape(d, d)
    X = 0.5 * (X + X.T)
    return float(np.sqrt(max(np.sum(D * D) + np.trace(C @ X @ C.T), 0.0)))


def impulse_response(A, B, C, D, steps: int) -> np.ndarray:
    """(steps, p, m): g_0 = D, g_k = C A^(k-1) B."""
    out = [np.asarray(D, dtype=np.float64)]
    AkB = np.asarray(B, dtype=np.float64)
    for _ in range(int(steps) - 1):
        out.append(C @ AkB)
        AkB = A @ AkB
    return np.array(out)


def gait_sensitivity(step: Callable, x, disturbances: int = 1, eps: float = 1e-6, eps_x=None,
                     A=None, steps: int = 20) -> GaitSensitivity:
    """The gait sensitivity norm of a gait with fixed point x, from its disturbed step
    `step(x, e) -> (next x (d,), indicators g (p,))` (e: (disturbances,), e = 0 the
    undisturbed step): B, C and D by central differences (step eps in e, eps_x in x: default
    eps), A given (the map's exact Jacobian, StepMap.jacobian) or differenced too; response:
    the first `steps` indicator changes of a unit disturbance."""
    from ..checks import positive, whole
    x = np.asarray(x, dtype=np.float64)
    # (a string failed in int(), 1.5 disturbances were 1, a NaN or 0 eps gave NaN matrices)
    d, m = x.size, whole("disturbances", disturbances, 1)
    eps = positive("eps", eps, "the disturbance's finite-difference step")
    hx = eps if eps_x is None else positive("eps_x", eps_x, "the state's finite-difference step")
    steps = whole("steps", steps, 1)
    zero = np.zeros(m)

    def at(xx, e):
        y, g = step(xx, e)
        return np.asarray(y, dtype=np.float64), np.atleast_1d(np.asarray(g, dtype=np.float64))

    p = at(x, zero)[1].size          # (the indicators' count)
    B, D = np.zeros((d, m)), np.zeros((p, m))
    for j in range(m):
        e = np.zeros(m)
        e[j] = eps
        (yp, gp), (ym, gm) = at(x, e), at(x, -e)
        B[:, j], D[:, j] = (yp - ym) / (2 * eps), (gp - gm) / (2 * eps)
    C = np.zeros((p, d))
    Ad = np.zeros((d, d))
    for i in range(d):
        dx = np.zeros(d)
        dx[i] = hx
        (yp, gp), (ym, gm) = at(x + dx, zero), at(x - dx, zero)
        C[:, i] = (gp - gm) / (2 * hx)
        Ad[:, i] = (yp - ym) / (2 * hx)
    A = Ad if A is None else _as_matrix(A, d, d, "A")
    return GaitSensitivity(gait_sensitivity_norm(A, B, C, D), A, B, C, D,
                           impulse_response(A, B, C, D, steps))
