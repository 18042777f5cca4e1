"""Independent references for the passive walkers (no planarsim inside): the reduced ODEs of
the simplest walking model integrated with scipy, and the rimless wheel in closed form.

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
    from planarsim.analysis import StepMapError

    def f(x):
        try:
            return simplest_step(x, gamma)[0]
        except RuntimeError as e:
            raise StepMapError(str(e)) from None
    return f


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
