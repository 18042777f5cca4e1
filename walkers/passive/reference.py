"""Independent references for the passive walkers (no planarsim inside): the reduced ODEs of
the simplest walking model and Goswami et al.'s compass gait integrated with scipy, and the
rimless wheel in closed form. (The compass gait's equations are given with its code below.)

Simplest walking model (Garcia, Chatterjee, Ruina, Coleman 1998, beta -> 0), dimensionless
time t sqrt(g / l):
    theta'' = sin(theta - gamma)
    phi''   = sin(theta - gamma) + sin(phi) (theta'^2 - cos(theta - gamma))
Heel strike when phi - 2 theta crosses 0 upward with theta < 0 (the crossing near mid-stance
is the scuff the model ignores). Impact (plastic, angular momentum about the new foot) and
relabelling:
    theta+ = -theta-,  theta'+ = cos(2 theta-) theta'-,  phi+ = -2 theta-,
    phi'+ = cos(2 theta-) (1 - cos(2 theta-)) theta'-

Rimless wheel (hub of mass M and inertia I about its centre, N massless spokes of length l,
alpha = pi / N, slope gamma). Angular momentum about the new contact is conserved at impact:
    (I + M l^2) w+ = (I + M l^2 cos 2 alpha) w-      => w+ = eta w-,
    eta = (I + M l^2 cos 2 alpha) / (I + M l^2)        (point-mass hub: eta = cos 2 alpha)
Between impacts energy is conserved; the hub drops by 2 l sin(alpha) sin(gamma), so
    w-^2 = w+^2 + 4 M g l sin(alpha) sin(gamma) / (I + M l^2)
and the fixed point is w-*^2 = 4 M g l sin(alpha) sin(gamma) / ((I + M l^2)(1 - eta^2)),
w+* = eta w-*. The step period is the time to rotate the spoke from -alpha to +alpha about the
vertical offset gamma (a quadrature of the energy integral); speed = 2 l sin(alpha) / period.
"""
from __future__ import annotations

import math

import numpy as np

GARCIA_GAMMA = 0.009
# Garcia et al. 1998, stable (long-period) gait at gamma = 0.009: theta*, theta_dot* after
# heel strike (dimensionless); phi* = 2 theta*, phi_dot* from the impact law.
GARCIA_THETA = 0.20031090049
GARCIA_THETA_DOT = -0.19983247291


def simplest_rhs(t, y, gamma):
    th, thd, ph, phd = y
    a = math.sin(th - gamma)
    return [thd, a, phd, a + math.sin(ph) * (thd * thd - math.cos(th - gamma))]


def simplest_heel_strike(y):
    """Impact and relabelling: state just before -> just after heel strike."""
    th, thd = y[0], y[1]
    c = math.cos(2.0 * th)
    return np.array([-th, c * thd, -2.0 * th, c * (1.0 - c) * thd])


def simplest_step(x, gamma, rtol=1e-12, atol=1e-13, t_max=10.0):
    """One step of the reduced model: (x after heel strike) -> (next x, step period [-],
    dense solution)."""
    from scipy.integrate import solve_ivp

    def strike(t, y, gamma):
        return y[2] - 2.0 * y[0]
    strike.direction = 1.0
    sol = solve_ivp(simplest_rhs, (0.0, t_max), np.asarray(x, float), args=(gamma,), events=strike,
                    rtol=rtol, atol=atol, dense_output=True, method="DOP853")
    for te, ye in zip(sol.t_events[0], sol.y_events[0]):
        if ye[0] < 0.0:
            return simplest_heel_strike(ye), float(te), sol
    raise RuntimeError(f"simplest walker: no heel strike within {t_max} from x={x}")


def simplest_map(gamma):
    """The reduced model's step map x -> next x at slope gamma [rad], for planarsim.analysis
    (a step without heel strike, a fall, raises StepMapError)."""
    return _as_map(lambda x: simplest_step(x, gamma))


def simplest_fixed_point(gamma=GARCIA_GAMMA, x0=None, tol=1e-12):
    """Newton fixed point of the reduced model's stride map.

    Returns dict(x (4,), period [-], multipliers (4,) largest modulus first, jacobian)."""
    from planarsim.analysis import find_fixed_point
    if x0 is None:
        th = GARCIA_THETA
        x0 = simplest_heel_strike([-th, GARCIA_THETA_DOT / math.cos(2 * th)])
    fp = find_fixed_point(lambda x: simplest_step(x, gamma)[0], x0, tol=tol, eps=1e-7)
    if not fp.converged:
        raise RuntimeError(f"reference fixed point did not converge: residual {fp.residual:g}")
    return dict(x=fp.x, period=simplest_step(fp.x, gamma)[1], multipliers=fp.multipliers,
                jacobian=fp.jacobian)


def rimless_fixed_point(slope, n_spokes, spoke_length=1.0, hub_mass=1.0, hub_inertia=0.0,
                        gravity=9.81):
    """Closed-form steady gait of the rimless wheel (see the module docstring).

    Returns dict(omega_after, omega_before [rad/s, magnitudes], eta, period [s], speed [m/s],
    step_length [m]). Raises ValueError if the steady wheel cannot pass over its spoke."""
    from scipy.integrate import quad
    M, l, g, I = hub_mass, spoke_length, gravity, hub_inertia
    alpha = math.pi / n_spokes
    J = I + M * l * l
    eta = (I + M * l * l * math.cos(2 * alpha)) / J
    w_before = math.sqrt(4 * M * g * l * math.sin(alpha) * math.sin(slope) / (J * (1 - eta * eta)))
    w_after = eta * w_before
    # energy integral: spoke angle psi from the vertical runs from -(alpha - gamma) to alpha + gamma
    c = 2 * M * g * l / J

    def rate(psi):
        return math.sqrt(w_after ** 2 + c * (math.cos(alpha - slope) - math.cos(psi)))
    if w_after ** 2 <= c * (1 - math.cos(alpha - slope)):
        raise ValueError("rimless wheel: the steady gait does not pass over the vertical "
                         f"(slope {slope} rad too small for {n_spokes} spokes)")
    period = quad(lambda psi: 1.0 / rate(psi), -(alpha - slope), alpha + slope,
                  epsabs=1e-13, epsrel=1e-12, limit=200)[0]
    step = 2 * l * math.sin(alpha)
    return dict(omega_after=w_after, omega_before=w_before, eta=eta, period=period,
                speed=step / period, step_length=step)


# compass gait --------------------------------------------------------------------------------
# Goswami, Thuilot & Espiau (1998): point-mass hip mH, two legs of mass m (COM at a from the
# foot, b = l - a from the hip, inertia m r^2 about the COM), slope gamma. Absolute leg angles
# from the slope normal (counter-clockwise, > 0 leaning back): stance th1, swing th2; the unit
# vector from foot to hip is up(th) = -sin(th) t + cos(th) n. Stance foot at the origin:
#     stance COM a up(th1), hip l up(th1), swing COM l up(th1) - b up(th2).
# Lagrangian (D = th1 - th2, I = m r^2):
#     T = 1/2 [m a^2 + (mH + m) l^2 + I] th1'^2 + 1/2 (m b^2 + I) th2'^2 - m l b cos(D) th1' th2'
#     V = g [(m a + (mH + m) l) cos(th1 - gamma) - m b cos(th2 - gamma)]
# Swing phase, M(q) q'' + C(q, q') q' + G(q) = 0:
#     M = [[m a^2 + (mH + m) l^2 + I, -m l b cos D], [-m l b cos D, m b^2 + I]]
#     C q' = [-m l b sin(D) th2'^2, m l b sin(D) th1'^2]
#     G = [-(m a + (mH + m) l) g sin(th1 - gamma), m b g sin(th2 - gamma)]
# Heel strike: the swing foot's height along n, l (cos th1 - cos th2), reaches 0 going down
# with the swing foot ahead of the stance foot (th2 > th1); the crossing at mid-stance (the
# scuff) is ignored, as in the engine. Impact (plastic, no slip, the trailing foot leaves
# without impulse): the angular momentum of the whole walker about the new stance foot and
# that of the old stance leg about the hip are conserved; then the legs swap labels.
# Section coordinates as the engine's (walkers.passive.gait): just after heel strike,
# x = (theta = th1, theta_dot [rad/s], phi = th1 - th2, phi_dot [rad/s]).

def _compass_consts(p):
    r = p.leg_gyration if p.leg_gyration > 0 else 1e-3     # as walkers.passive.model.build_compass
    return (p.hip_mass, p.leg_mass, p.leg_length, p.com_from_foot,
            p.leg_length - p.com_from_foot, p.leg_mass * r * r, p.gravity, p.slope)


def compass_rhs(t, y, c, lib=math):
    """Swing-phase ODE: y = (th1, th2, th1' , th2') [rad, rad/s] -> y' (c: _compass_consts;
    lib: the module of sin and cos, cmath for a complex step)."""
    mH, m, l, a, b, I, g, gam = c
    th1, th2, w1, w2 = y
    D = th1 - th2
    cD, sD = lib.cos(D), lib.sin(D)
    M11, M12, M22 = m * a * a + (mH + m) * l * l + I, -m * l * b * cD, m * b * b + I
    r1 = m * l * b * sD * w2 * w2 + (m * a + (mH + m) * l) * g * lib.sin(th1 - gam)
    r2 = -m * l * b * sD * w1 * w1 - m * b * g * lib.sin(th2 - gam)
    det = M11 * M22 - M12 * M12
    return [w1, w2, (M22 * r1 - M12 * r2) / det, (M11 * r2 - M12 * r1) / det]


def _up(th):
    """Foot-to-hip unit vector in slope (t, n) coordinates, and its derivative in th."""
    return np.array([-math.sin(th), math.cos(th)]), np.array([-math.cos(th), -math.sin(th)])


def compass_parts(y, c):
    """The walker's masses from kinematics alone, stance foot at the origin, slope (t, n)
    coordinates: list of (mass [kg], inertia [kg m^2], position [m], velocity [m/s],
    angular rate [rad/s]) for the stance leg, the hip and the swing leg."""
    mH, m, l, a, b, I, g, gam = c
    th1, th2, w1, w2 = y
    u1, du1 = _up(th1)
    u2, du2 = _up(th2)
    return [(m, I, a * u1, a * w1 * du1, w1),
            (mH, 0.0, l * u1, l * w1 * du1, 0.0),
            (m, I, l * u1 - b * u2, l * w1 * du1 - b * w2 * du2, w2)]


def compass_energy(y, c):
    """Mechanical energy [J] computed from compass_parts (independent of the ODE's M, C, G)."""
    g, gam = c[6], c[7]
    gvec = g * np.array([math.sin(gam), -math.cos(gam)])   # gravity in slope coordinates
    return sum(0.5 * mi * (v @ v) + 0.5 * Ii * w * w - mi * (gvec @ r) for mi, Ii, r, v, w in
               compass_parts(y, c))


def _cross2(a, b):
    return a[0] * b[1] - a[1] * b[0]


def compass_momenta(y, c, point):
    """(angular momentum of the whole walker about `point`, of the stance leg about the hip)
    [kg m^2/s], from compass_parts."""
    parts = compass_parts(y, c)
    hip = parts[1][2]
    H = sum(mi * _cross2(r - point, v) + Ii * w for mi, Ii, r, v, w in parts)
    mi, Ii, r, v, w = parts[0]
    return H, mi * _cross2(r - hip, v) + Ii * w


def compass_heel_strike(y, c):
    """Impact and relabelling: y = (th1, th2, th1', th2') just before heel strike -> just
    after (new stance = old swing leg). Solves the two momentum balances, linear in the new
    rates, by evaluating them at unit rates."""
    th1, th2 = y[0], y[1]
    foot = compass_parts([th1, th2, 0.0, 0.0], c)[1][2] - c[2] * _up(th2)[0]   # new stance foot
    H_total_minus, H_leg_minus = compass_momenta(y, c, foot)
    # after: new stance foot at the origin, new labels (th2, th1); momenta linear in the rates
    A = np.empty((2, 2))
    for j in range(2):
        e = [th2, th1, float(j == 0), float(j == 1)]
        Ht, _ = compass_momenta(e, c, np.zeros(2))
        parts = compass_parts(e, c)
        mi, Ii, r, v, w = parts[2]                     # new swing leg = old stance leg
        A[0, j], A[1, j] = Ht, mi * _cross2(r - parts[1][2], v) + Ii * w
    w = np.linalg.solve(A, [H_total_minus, H_leg_minus])
    return np.array([th2, th1, w[0], w[1]])


def _to_section(y):
    return np.array([y[0], y[2], y[0] - y[1], y[2] - y[3]])


def _from_section(x):
    return np.array([x[0], x[0] - x[2], x[1], x[1] - x[3]])


def compass_step(x, p, rtol=1e-12, atol=1e-13, t_max=10.0, consts=None):
    """One step of the compass gait: section state x (theta, theta_dot [rad/s], phi,
    phi_dot [rad/s]) just after heel strike -> (next x, step period [s], step length [m],
    y(t) -> (th1, th2, th1', th2') over the step). p: CompassParams (or consts: the tuple of
    _compass_consts, p then unused).

    The strike event is terminal; at a crossing that is not a heel strike (the scuff at
    mid-stance) the integration restarts from the crossing."""
    from scipy.integrate import solve_ivp
    c = _compass_consts(p) if consts is None else consts

    def strike(t, y, c):
        return math.cos(y[0]) - math.cos(y[1])          # swing-foot height / l
    strike.direction = -1.0
    strike.terminal = True
    t0, y0, segs = 0.0, _from_section(x), []
    while t0 < t_max:
        sol = solve_ivp(compass_rhs, (t0, t_max), y0, args=(c,), events=strike, rtol=rtol,
                        atol=atol, dense_output=True, method="DOP853")
        segs.append((sol.t[-1], sol.sol))
        if sol.status != 1:
            break
        te, ye = float(sol.t_events[0][-1]), sol.y_events[0][-1]
        if ye[1] > ye[0] and te > 0.0:
            step = c[2] * (math.sin(ye[1]) - math.sin(ye[0]))

            def y_of_t(t):
                return next(s for t_end, s in segs if t <= t_end)(t)
            return _to_section(compass_heel_strike(ye, c)), te, step, y_of_t
        # restart 1 us past the crossing (integrated without events) so that it is not
        # found again
        past = solve_ivp(compass_rhs, (te, te + 1e-6), ye, args=(c,), rtol=rtol, atol=atol,
                         dense_output=True, method="DOP853")
        segs.append((past.t[-1], past.sol))
        t0, y0 = float(past.t[-1]), past.y[:, -1]
    raise RuntimeError(f"compass gait: no heel strike within {t_max} s from x={x}")


def _rhs_jacobian(y, c):
    """d compass_rhs / dy (4, 4) at y, by the complex step (exact to rounding)."""
    import cmath
    J = np.empty((4, 4))
    for k in range(4):
        yk = np.asarray(y, dtype=complex).copy()
        yk[k] += 1e-20j
        J[:, k] = np.array(compass_rhs(0.0, yk, c, cmath)).imag / 1e-20
    return J


def compass_step_jacobian(x, p=None, rtol=1e-12, atol=1e-13, consts=None):
    """(next x, d next x / dx (4, 4)) of compass_step from the variational equations: the
    swing phase's state transition matrix Phi' = (df/dy) Phi integrated with the state up to
    the heel strike time te (DOP853 at rtol), the event-time term (I - f g^T / (g . f)) at the
    strike (g the gradient of the swing foot's height cos th1 - cos th2, f the flow there:
    the saltation of a moving event time), then the impact map's derivative (Richardson's
    extrapolation of centred differences, 1e-5 and 5e-6: error ~1e-11)."""
    from scipy.integrate import solve_ivp
    c = _compass_consts(p) if consts is None else consts
    xn, te, _, _ = compass_step(x, p, rtol, atol, consts=c)

    def augmented(t, z):
        y, Phi = z[:4], z[4:].reshape(4, 4)
        return np.concatenate([compass_rhs(t, y, c), (_rhs_jacobian(y, c) @ Phi).ravel()])
    T_from = np.array([[1.0, 0, 0, 0], [1.0, 0, -1.0, 0], [0, 1.0, 0, 0], [0, 1.0, 0, -1.0]])
    T_to = np.array([[1.0, 0, 0, 0], [0, 0, 1.0, 0], [1.0, -1.0, 0, 0], [0, 0, 1.0, -1.0]])
    z0 = np.concatenate([_from_section(x), np.eye(4).ravel()])
    sol = solve_ivp(augmented, (0.0, te), z0, rtol=rtol, atol=atol, method="DOP853")
    ye, Phi = sol.y[:4, -1], sol.y[4:, -1].reshape(4, 4)
    f = np.asarray(compass_rhs(te, ye, c))
    g = np.array([-math.sin(ye[0]), math.sin(ye[1]), 0.0, 0.0])
    event = np.eye(4) - np.outer(f, g) / (g @ f)

    def impact(e):
        D = np.empty((4, 4))
        for k in range(4):
            d = np.zeros(4)
            d[k] = e
            D[:, k] = (compass_heel_strike(ye + d, c) - compass_heel_strike(ye - d, c)) / (2 * e)
        return D
    H = (4.0 * impact(5e-6) - impact(1e-5)) / 3.0
    return xn, T_to @ H @ event @ Phi @ T_from


def simplest_feet_step_jacobian(x, p, rtol=1e-12, atol=1e-13):
    """(next x, d next x / dx) of simplest_feet_step (compass_step_jacobian's variational
    equations; rates in units of sqrt(g / l))."""
    k = math.sqrt(p.gravity / p.leg_length)
    S = np.diag([1.0, k, 1.0, k])
    xn, J = compass_step_jacobian(np.asarray(x, float) * np.diag(S), None, rtol, atol,
                                  consts=simplest_feet_consts(p))
    return xn / np.diag(S), np.linalg.solve(S, J @ S)


def _as_map(step):
    """The step map x -> step(x)[0] of a reference step function (a fall, which the step
    function raises as RuntimeError, raises StepMapError)."""
    from planarsim.analysis import StepMapError

    def f(x):
        try:
            return step(x)[0]
        except RuntimeError as e:
            raise StepMapError(str(e)) from None
    return f


def compass_map(p):
    """The reference compass gait's step map x -> next x (a fall raises StepMapError)."""
    return _as_map(lambda x: compass_step(x, p))


def compass_fixed_point(p=None, x0=None, tol=1e-12, eps=1e-6):
    """Newton fixed point of the reference compass gait's step map (p: CompassParams, default
    the defaults; x0: section state, default walkers.passive.compass_gait.default_start).
    Multipliers by central differences of step eps.

    Returns dict(x (4,), period [s], step_length [m], speed [m/s], multipliers (4,) largest
    modulus first, jacobian)."""
    from planarsim.analysis import find_fixed_point, floquet_multipliers
    from .params import CompassParams
    p = CompassParams() if p is None else p
    if x0 is None:
        from .compass_gait import default_start
        x0 = default_start(p)
    f = compass_map(p)
    fp = find_fixed_point(f, x0, tol=tol, eps=eps)
    if not fp.converged:
        raise RuntimeError(f"compass reference fixed point did not converge: residual {fp.residual:g}")
    _, period, step, _ = compass_step(fp.x, p)
    return dict(x=fp.x, period=period, step_length=step, speed=step / period,
                multipliers=floquet_multipliers(f, fp.x, eps=eps), jacobian=fp.jacobian)


# simplest walker with feet of finite mass ---------------------------------------------------
# The simplest walking model with foot mass ratio beta > 0 (walkers.passive.model.build_simplest:
# hip point mass M, point feet beta M on massless rods of length l) is the compass gait above
# with each leg's mass at its foot (a = 0, b = l) and no leg inertia (I = 0); its section
# coordinates are the engine's (rates in units of sqrt(g / l)).

def simplest_feet_consts(p):
    """_compass_consts of the simplest walker with SimplestParams p (feet of mass beta M)."""
    return (p.hip_mass, p.foot_mass_ratio * p.hip_mass, p.leg_length, 0.0, p.leg_length, 0.0,
            p.gravity, p.slope)


def simplest_feet_step(x, p, rtol=1e-12, atol=1e-13):
    """One step of the simplest walker with feet of mass beta M (SimplestParams p): section
    state x (theta, theta_dot, phi, phi_dot; rates in units of sqrt(g / l)) -> (next x,
    step period [s])."""
    k = math.sqrt(p.gravity / p.leg_length)
    scale = np.array([1.0, k, 1.0, k])
    xn, period, _, _ = compass_step(np.asarray(x, float) * scale, None, rtol, atol,
                                    consts=simplest_feet_consts(p))
    return xn / scale, period


def simplest_feet_map(p):
    """The step map of simplest_feet_step at SimplestParams p (a fall raises StepMapError)."""
    return _as_map(lambda x: simplest_feet_step(x, p))


class SimplestFeetFamily:
    """slope -> simplest_feet_map, for planarsim.analysis (MapPool, continue_branch), at foot
    mass ratio beta."""

    def __init__(self, beta: float):
        from .params import SimplestParams
        self.base = SimplestParams(foot_mass_ratio=beta)

    def __call__(self, slope):
        return simplest_feet_map(self.base.replace(slope=float(slope)))


def simplest_feet_doublings(beta, width=2e-4):
    """Slopes [rad] of the 1 -> 2 and 2 -> 4 period doublings of the simplest walker with foot
    mass ratio beta on the scipy reference (simplest_feet_step: DOP853 at rtol 1e-12). The
    doublings are found by continuation (planarsim.analysis, period-1 branch from the
    published gait at 0.009 rad to 0.0154, period-2 branch to 0.018), then each slope where
    det(J + I) = 0 by brentq (xtol 1e-12) within +-width of it: fixed points of P (P^2) by
    Newton to 1e-12, multipliers by central differences of step 1e-6. About 15 s."""
    from scipy.optimize import brentq
    from planarsim.analysis import (MapPool, continue_branch, find_fixed_point,
                                    floquet_multipliers, period_doubling_branch)
    fam = SimplestFeetFamily(beta)
    with MapPool(fam, workers=1) as pool:
        br = continue_branch(pool, simplest_fixed_point(0.009)["x"], 0.009, 0.0154, points=6,
                             param="slope")
        pd = br.first("period-doubling")
        b2 = period_doubling_branch(pool, pd, 0.0180, points=6, param="slope")
    pd2 = b2.first("period-doubling")
    if pd is None or pd2 is None:
        raise RuntimeError(f"reference (beta {beta}): doublings not found by continuation")
    start = {1: pd.x, 2: b2.points[0].x}      # Newton's start, then the last fixed point

    def det(p, period):
        f1 = fam(p)
        f = f1 if period == 1 else (lambda x: f1(f1(x)))
        fp = find_fixed_point(f, start[period], tol=1e-12, eps=1e-7)
        if not fp.converged:
            raise RuntimeError(f"reference fixed point at slope {p} did not converge")
        start[period] = fp.x
        return float(np.prod(1.0 + floquet_multipliers(f, fp.x, eps=1e-6)).real)
    return (brentq(lambda p: det(p, 1), pd.p - width, pd.p + width, xtol=1e-12),
            brentq(lambda p: det(p, 2), pd2.p - width, pd2.p + width, xtol=1e-12))
