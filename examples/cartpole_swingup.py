"""Swing InvertedPendulum's cart-pole up from hanging and balance it, by iterative LQR on the
engine's exact step derivatives (planarsim.ilqr, planarsim.derivatives).

The model is gymnasium's inverted_pendulum.xml (a 10.5 kg cart on a rail pushed by up to
300 N, a 5 kg pole of 0.6 m, joint dampers of 1) with its joint limits taken out: the file
keeps the pole within 90 degrees of upright, and the swing passes through all angles. The
pole starts hanging at rest; iLQR finds the pushes over the horizon that bring it up and
hold it there: a cost on the pole's angle from upright (1 - cos theta), the cart's place and
the pushes, heavier at the end, solved over the whole horizon from the pushes of a rough
hand-written controller (energy pumping, then a PD catch near upright: hand_controller). The
result is then run closed-loop: each push is iLQR's plus its feedback gain times the
distance from the planned state.

    python examples/cartpole_swingup.py [--dt 0.02] [--horizon 4] [--iterations 60]

It reads the model from gymnasium's own files: pip install -e '.[gym]' first.
"""
import argparse
import os
import sys
import time

try:
    import gymnasium
except ImportError:     # (a plain install has no gymnasium: say what to install, not a traceback)
    sys.exit(f"{__file__}: needs gymnasium: pip install -e '.[gym]'")

import numpy as np

import planarsim as ps
from planarsim.ilqr import QuadraticCost, follow, ilqr
from planarsim.mjcf import load_mjcf

XML = os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets",
                   "inverted_pendulum.xml")
CART, POLE = 0, 1           # the bodies; x = (q.ravel(), v.ravel()), 3 entries a body
X_CART = 3 * CART           # the cart's place [m]
THETA = 3 * POLE + 2        # the pole's angle [rad] (0 upright)


def cart_pole(dt):
    """The cart-pole of inverted_pendulum.xml without its joint limits, at step dt [s]."""
    with open(XML) as f:
        xml = f.read()
    xml = xml.replace('<joint armature="0" damping="1" limited="true"/>',
                      '<joint armature="0" damping="1" limited="false"/>')
    xml = xml.replace(' range="-90 90"', "").replace('limited="true" name="slider"',
                                                     'limited="false" name="slider"')
    return load_mjcf(xml, dt=dt).compile()


def hanging(sim):
    """Put the pole hanging straight down from the cart, everything at rest."""
    s = sim.state.copy()
    anchor = sim.model.arrays.pin_anchor[1, 1]        # the hinge on the pole, in its frame
    s.q[POLE] = [anchor[0], anchor[1], np.pi]         # rotated by pi about the hinge at 0
    s.v[:] = 0.0
    sim.state = s


class SwingCost(QuadraticCost):
    """QuadraticCost on the cart's place and the speeds, and on the pole's angle
    w (1 - cos theta) instead of w theta^2 / 2 (its Hessian Gauss-Newton's, w cos^2(theta/2) / 2
    >= 0): the same near upright, bounded and periodic far from it. theta_w, theta_final: w per
    step and at the end."""

    def __init__(self, goal, Q, R, Q_final, theta_w, theta_final):
        super().__init__(goal, Q, R, Q_final)
        object.__setattr__(self, "theta_w", theta_w)
        object.__setattr__(self, "theta_final", theta_final)

    def _angle(self, x, w):
        th = x[THETA]
        return w * (1.0 - np.cos(th)), w * np.sin(th), 0.5 * w * np.cos(0.5 * th) ** 2

    def step_terms(self, x, u):
        l, lx, lu, lxx, luu, lux = super().step_terms(x, u)
        a, ax, axx = self._angle(x, self.theta_w)
        lx = lx.copy()
        lx[THETA] += ax
        lxx = lxx.copy()
        lxx[THETA, THETA] += axx
        return l + a, lx, lu, lxx, luu, lux

    def final_terms(self, x):
        l, lx, lxx = super().final_terms(x)
        a, ax, axx = self._angle(x, self.theta_final)
        lx = lx.copy()
        lx[THETA] += ax
        lxx = lxx.copy()
        lxx[THETA, THETA] += axx
        return l + a, lx, lxx


def cost(model, steps):
    """The swing-up's cost: per step 5 (1 - cos theta) + 5 x^2 + 0.1 (vx^2 + w^2) [per s] and
    1e-5 u^2; at the end 1000 ((1 - cos theta) + x^2) + 100 (vx^2 + w^2)."""
    h = model.dt
    n = 6 * model.n_body
    goal = np.zeros(n)
    goal[3 * POLE + 1] = -model.arrays.pin_anchor[1, 1][1]      # (the pole's centre up)
    Q = np.zeros((n, n))
    Qf = np.zeros((n, n))
    v = n // 2
    for i, w, wf in ((X_CART, 5.0, 1000.0), (v + X_CART, 0.1, 100.0), (v + THETA, 0.1, 100.0)):
        Q[i, i], Qf[i, i] = w * h, wf
    return SwingCost(goal, Q, 1e-5 * h * np.eye(model.n_act), Qf, 5.0 * h, 1000.0)


def upright_error(states):
    """The pole's angle from upright [rad], whichever way round it went up (in (-pi, pi])."""
    theta = states[:, THETA]
    return theta - 2.0 * np.pi * np.round(theta / (2.0 * np.pi))


def hand_controller(sim, steps, pump=100.0, catch=0.3):
    """A first guess (steps, 1) of pushes [N]: a hand-written controller run from the
    simulator's state (which it leaves as it was). Away from upright it pumps the swing's
    energy E = J w^2 / 2 + m g l (cos theta - 1) (0 upright) towards 0 by pushing the cart
    along w cos theta, pump * (-E) w cos theta [N] (energy shaping, Astrom and Furuta 2000),
    the first push 300 N to set the pole swinging, less a pull of the cart towards its start;
    within `catch` [rad] of upright a PD law on the angle and the cart holds the pole.
    Its gains are rough: iLQR does the rest."""
    model = sim.model
    a = model.arrays
    total = 1.0 / a.body_inv_mass[CART] + 1.0 / a.body_inv_mass[POLE]     # [kg]
    m = 1.0 / a.body_inv_mass[POLE]
    lever = float(np.hypot(*a.pin_anchor[1, 1]))      # [m] hinge to the pole's centre
    inertia = 1.0 / a.body_inv_inertia[POLE] + m * lever ** 2    # [kg m^2] about the hinge
    g = float(np.hypot(*a.gravity))                    # [m/s^2]
    lo, hi = a.act_range[0]
    start = sim.state.copy()
    us = np.zeros((steps, model.n_act))
    for k in range(steps):
        s = sim.state
        theta, w = s.q[POLE, 2], s.v[POLE, 2]
        x, vx = s.q[CART, 0], s.v[CART, 0]
        up = np.arctan2(np.sin(theta), np.cos(theta))
        if abs(up) < catch:
            u = total * (-40.0 * up - 8.0 * w + 2.0 * x + 3.0 * vx)
        elif k == 0:
            u = hi
        else:
            energy = 0.5 * inertia * w * w + m * g * lever * (np.cos(theta) - 1.0)
            u = -pump * energy * w * np.cos(theta) - total * 4.0 * (x + vx)
        us[k] = np.clip(u, lo, hi)
        sim.step(us[k])
    sim.state = start
    return us


def swing_up(dt=0.02, horizon=4.0, iterations=60):
    """(the ILQRResult, the closed-loop run's states (T + 1, n_x), the simulator, the first
    guess's commands) of the swing-up over `horizon` [s] at step dt [s]: iLQR over the whole
    horizon from the hand-written controller's pushes (hand_controller), which already
    swing the pole up and hold it. (From pushes pump sin(2 pi t / period) instead, the plan
    fell into local minima that spin the pole through upright, and which one depended on
    the period and on the step's rounding.)"""
    model = cart_pole(dt)
    sim = ps.Simulator(model)
    hanging(sim)
    steps = int(round(horizon / dt))
    guess = hand_controller(sim, steps)
    result = ilqr(sim, guess, cost(model, steps), iterations=iterations, tol=1e-9)
    run = follow(sim, result)
    return result, run, sim, guess


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--dt", type=float, default=0.02)
    ap.add_argument("--horizon", type=float, default=4.0)
    ap.add_argument("--iterations", type=int, default=60)
    args = ap.parse_args(argv)
    start = time.perf_counter()
    result, run, _, _ = swing_up(args.dt, args.horizon, args.iterations)
    last = upright_error(run[-int(round(1.0 / args.dt)):])
    print(f"iLQR: {len(result.costs) - 1} iterations in {time.perf_counter() - start:.1f} s, "
          f"cost over the horizon {result.costs[0]:.4g} (the hand-written controller's "
          f"pushes) -> {result.cost:.4g}")
    print(f"closed loop: the pole within {np.abs(last).max():.3g} rad of upright "
          f"over the last second, the cart within {np.abs(run[:, X_CART]).max():.2f} m of "
          f"its start, pushes up to {np.abs(result.us).max():.0f} N")
    return result, run


if __name__ == "__main__":
    main()
