"""Plain numpy versions of the engine's kernels: slow, obvious, one formula each, written from
the physics and not from the compiled code. tests/planarsim/test_reference_kernels.py checks
the compiled kernels against them on random inputs (hypothesis).

  world_point, pin_error, rod_error, limit_errors, point_gap   constraint functions of q
  jacobian                      their derivative by central differences
  inverse_mass                  W, the block-diagonal inverse mass matrix
  delassus                      A = J W J^T
  coulomb_solutions             every solution of a small contact problem with Coulomb friction,
                                by trying every combination of contact modes
  coulomb_violations            how far an answer misses Coulomb's rules
"""
from __future__ import annotations

import itertools
import math

import numpy as np

# row kinds of the compiled rows (planarsim/kernels/constraints/rows.py)
PIN_X, PIN_Y, ROD, LIMIT_LO, LIMIT_HI, CONTACT_N, CONTACT_T = range(7)


# constraint functions -------------------------------------------------------------------------
def world_point(q, body, local):
    """World position [m] of the point `local` [m] fixed in `body` (-1: the world frame)."""
    if body < 0:
        return np.asarray(local, dtype=float)
    x, y, th = q[body]
    c, s = math.cos(th), math.sin(th)
    return np.array([x + c * local[0] - s * local[1], y + s * local[0] + c * local[1]])


def pin_error(a, q, j):
    """p_b - p_a [m] of pin j's two anchors (a: ModelArrays)."""
    return (world_point(q, a.pin_body[j, 1], a.pin_anchor[j, 1])
            - world_point(q, a.pin_body[j, 0], a.pin_anchor[j, 0]))


def rod_error(a, q, j):
    """|p_b - p_a| - L [m] of rod j."""
    d = (world_point(q, a.rod_body[j, 1], a.rod_anchor[j, 1])
         - world_point(q, a.rod_body[j, 0], a.rod_anchor[j, 0]))
    return float(np.hypot(*d)) - float(a.rod_length[j])


def limit_errors(a, q, j):
    """(angle - lower, upper - angle) [rad] of pin j's limits (>= 0 inside them)."""
    ba, bb = a.pin_body[j]
    angle = q[bb, 2] - a.pin_ref[j] - (q[ba, 2] if ba >= 0 else 0.0)
    return angle - a.pin_limit[j, 0], a.pin_limit[j, 1] - angle


def point_gap(a, q, i, normal, ground):
    """Distance [m] of point contact i above a straight ground through `ground` with unit
    `normal` (flat or sloped terrain: the exact gap)."""
    p = world_point(q, a.contact_body[i], a.contact_local[i])
    return float(np.dot(normal, p - ground))


def jacobian(f, q, eps=1e-6):
    """d f / d q by central differences: (len(f(q)), n_body * 3), q (n_body, 3)."""
    q = np.asarray(q, dtype=float)
    f0 = np.atleast_1d(f(q))
    out = np.zeros((len(f0), q.size))
    for k in range(q.size):
        dq = np.zeros(q.size)
        dq[k] = eps
        out[:, k] = (np.atleast_1d(f(q + dq.reshape(q.shape))) - np.atleast_1d(f(q - dq.reshape(q.shape)))) / (2 * eps)
    return out


# the velocity stage ----------------------------------------------------------------------------
def inverse_mass(a):
    """W = M^-1 (n_body * 3 square): 1/m, 1/m, 1/I per body."""
    return np.diag(np.stack([a.body_inv_mass, a.body_inv_mass, a.body_inv_inertia], axis=1).ravel())


def delassus(J, W):
    """A = J W J^T: the change of the rows' velocities per unit impulse."""
    return J @ W @ J.T


def _mode_equations(A, b, kinds, mu_of_row, modes):
    """The linear equations of one choice of modes: rows of (A | b) for w = A x + b = 0 and of
    (I | 0) for x = 0, friction tied to its normal. Returns (E, e) with E x = e."""
    n = len(b)
    E, e = [], []
    unit = np.eye(n)
    for r in range(n):
        kind, mode = kinds[r], modes[r]
        if kind in (PIN_X, PIN_Y, ROD) or mode == "hold":
            E.append(A[r])
            e.append(-b[r])
        elif mode == "free":
            E.append(unit[r])
            e.append(0.0)
        elif mode in ("slide+", "slide-"):   # tangent row: x_t = -s mu x_n (slip s = +-1)
            s = 1.0 if mode == "slide+" else -1.0
            E.append(unit[r] + s * mu_of_row[r] * unit[r - 1])
            e.append(0.0)
    return np.array(E), np.array(e)


def coulomb_violations(A, b, kinds, mu_of_row, x, scale=1.0):
    """Largest miss [N s or m/s] of Coulomb's and the joints' rules by impulses x:
    joints w = 0; unilateral rows x >= 0, w >= 0, x w = 0; a contact's tangent row
    |x_t| <= mu x_n, w_t = 0 inside the cone, x_t = -mu x_n sign(w_t) when it slips."""
    w = A @ x + b
    worst = 0.0
    for r, kind in enumerate(kinds):
        if kind in (PIN_X, PIN_Y, ROD):
            worst = max(worst, abs(w[r]))
        elif kind == CONTACT_T:
            bound = mu_of_row[r] * x[r - 1]
            worst = max(worst, abs(x[r]) - bound)
            if abs(w[r]) > 1e-9 * scale:      # slipping: friction at the edge, opposing
                worst = max(worst, abs(x[r] + math.copysign(bound, w[r])))
        else:
            worst = max(worst, -x[r], -w[r], abs(x[r] * w[r]) / scale)
    return worst


def coulomb_solutions(A, b, kinds, mu_of_row, tol=1e-9):
    """Every solution of the contact problem (A, b) found by trying each combination of modes:
    a unilateral row free or holding, a tangent row holding or slipping either way (free with
    its normal). Where a mode's equations are singular the least-squares answer is tried (a
    redundant load has many answers, and this finds one of them at most). Returns a list of x."""
    n = len(b)
    choices = []
    for r, kind in enumerate(kinds):
        if kind in (PIN_X, PIN_Y, ROD):
            choices.append(("hold",))
        elif kind == CONTACT_T:
            choices.append(("hold", "slide+", "slide-", "free"))
        else:
            choices.append(("hold", "free"))
    scale = 1.0 + float(np.abs(b).max(initial=0.0))
    found = []
    for modes in itertools.product(*choices):
        # a tangent row is free exactly when its normal row is
        if any(kinds[r] == CONTACT_T and (modes[r] == "free") != (modes[r - 1] == "free")
               for r in range(n)):
            continue
        E, e = _mode_equations(A, b, kinds, mu_of_row, modes)
        x = np.linalg.lstsq(E, e, rcond=None)[0]
        if np.abs(E @ x - e).max(initial=0.0) > tol * scale:
            continue
        if coulomb_violations(A, b, kinds, mu_of_row, x, scale) <= tol * scale * (1.0 + np.abs(x).max()):
            found.append(x)
    return found


def hinge_turn_gain(a, q, j):
    """1 / [kg m^2]: how fast a torque on hinge j turns its angle (theta_b - theta_a) from rest,
    with the hinge's own pin holding its two bodies and each body's hinges to the world
    holding it, nothing else: the Schur complement g W g^T - g W G^T (G W G^T)^+ G W g^T,
    G those pins' rows (by differences of pin_error), g the angle's row."""
    W = inverse_mass(a)
    ba, bb = (int(b) for b in a.pin_body[j])
    pins = [j] + [p for p in range(len(a.pin_kind)) if p != j and a.pin_kind[p] == 0
                  and min(a.pin_body[p]) < 0 and max(a.pin_body[p]) in (ba, bb)]
    G = np.vstack([jacobian(lambda x, p=p: pin_error(a, x.reshape(q.shape), p), q) for p in pins])
    g = np.zeros(q.size)
    g[3 * bb + 2] = 1.0
    if ba >= 0:
        g[3 * ba + 2] = -1.0
    c = G @ W @ g
    return float(g @ W @ g - c @ np.linalg.pinv(G @ W @ G.T, rcond=1e-10) @ c)
