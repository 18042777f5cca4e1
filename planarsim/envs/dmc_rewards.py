"""The dm_control tasks' rewards compiled: each domain's reward (dmc.py's ``_reward_<domain>``)
as a kernel of the readings' values array, the task's parameters as floats and the last
control, the same arithmetic in the same order, so that it gives the Python reward's float bit
for bit (tests/planarsim/test_dmc_rewards.py checks it over random values).

A domain's kernel reads x, its plan's values in the order the plan writes them (``names``
below says which; ``reward_params`` checks a plan against them), and p, the floats
``reward_params`` makes of the task's parameters: each tolerance as [lower, upper, margin,
scale] (rewards.tolerance_terms) where its bounds are parameters, else the sigmoid's scale.
``task_reward`` picks the domain's kernel by its code; ``reward_of_values`` calls it from
Python.
"""
from __future__ import annotations

import numpy as np

from ..compile import jit, kernel
from .rewards import (GAUSSIAN, LINEAR, LONG_TAIL, QUADRATIC, numpy_mean, tolerance_at,
                      tolerance_terms)

INF = float("inf")

# domain codes (task_reward's `code`)
CHEETAH, WALKER, HOPPER, ACROBOT, CARTPOLE, PENDULUM, REACHER, POINT_MASS, SWIMMER, FINGER = range(10)

# numpy_mean's exact range: no domain averages more controls or poles
MAX_MEAN = 128


@kernel
def _tolerance(x, p, i, kind):
    """tolerance_at of x with the terms p[i:i + 4] (lower, upper, margin, scale)."""
    return tolerance_at(x, p[i], p[i + 1], p[i + 2], kind, p[i + 3])


@kernel
def _small_control(ctrl, i, scale):
    """dm_control's tolerance(control i, margin=1, value_at_margin=0, sigmoid='quadratic')."""
    return tolerance_at(ctrl[i], 0.0, 0.0, 1.0, QUADRATIC, scale)


@kernel
def _mean_small_control(ctrl, n, scale, scratch):
    """np.mean of the first n controls' _small_control (scratch: n floats of room)."""
    for i in range(n):
        scratch[i] = _small_control(ctrl, i, scale)
    return numpy_mean(scratch, n)


@kernel
def cheetah_reward(x, p, ctrl, scratch):
    """x: speed [m/s]; p: the run tolerance's terms."""
    return _tolerance(x[0], p, 0, LINEAR)


@kernel
def walker_reward(x, p, ctrl, scratch):
    """x: height [m], upright (torso zz), speed [m/s]; p: standing's terms, move speed
    [m/s], moving's terms."""
    standing = _tolerance(x[0], p, 0, GAUSSIAN)
    upright = (1 + x[1]) / 2
    stand_reward = (3 * standing + upright) / 4
    if p[4] == 0:
        return stand_reward
    move_reward = _tolerance(x[2], p, 5, LINEAR)
    return stand_reward * (5 * move_reward + 1) / 6


@kernel
def hopper_reward(x, p, ctrl, scratch):
    """x: height [m], speed [m/s]; p: standing's terms, hop speed [m/s], hopping's terms,
    the small control's scale."""
    standing = _tolerance(x[0], p, 0, GAUSSIAN)
    if p[4] != 0:
        hopping = _tolerance(x[1], p, 5, LINEAR)
        return standing * hopping
    small_control = _mean_small_control(ctrl, ctrl.shape[0], p[9], scratch)
    return standing * (small_control + 4) / 5


@kernel
def acrobot_reward(x, p, ctrl, scratch):
    """x: distance [m], target radius [m]; p: the gaussian's scale."""
    return tolerance_at(x[0], 0.0, x[1], 1.0, GAUSSIAN, p[0])


@kernel
def cartpole_reward(x, p, ctrl, scratch):
    """x: each pole's cos, slider [m], the joint rates after the slider's; p: poles, the
    centred gaussian's scale, the small control's, the small velocity gaussian's."""
    poles = int(p[0])
    for i in range(poles):
        scratch[i] = (x[i] + 1) / 2
    upright = numpy_mean(scratch, poles)
    centered = (1 + tolerance_at(x[poles], 0.0, 0.0, 2.0, GAUSSIAN, p[1])) / 2
    small_control = (4 + _small_control(ctrl, 0, p[2])) / 5
    least = tolerance_at(x[poles + 1], 0.0, 0.0, 5.0, GAUSSIAN, p[3])
    for i in range(poles + 2, x.shape[0]):          # (Python's min: the first of the least)
        t = tolerance_at(x[i], 0.0, 0.0, 5.0, GAUSSIAN, p[3])
        if t < least:
            least = t
    small_velocity = (1 + least) / 2
    return upright * small_control * small_velocity * centered


@kernel
def pendulum_reward(x, p, ctrl, scratch):
    """x: the pole's cos; p: the bound's terms."""
    return _tolerance(x[0], p, 0, GAUSSIAN)


@kernel
def reacher_reward(x, p, ctrl, scratch):
    """x: distance [m], the radii's sum [m]."""
    return tolerance_at(x[0], 0.0, x[1], 0.0, GAUSSIAN, 0.0)


@kernel
def point_mass_reward(x, p, ctrl, scratch):
    """x: distance [m], target size [m]; p: the gaussian's scale, the small control's."""
    size = x[1]
    near_target = tolerance_at(x[0], 0.0, size, size, GAUSSIAN, p[0])
    small_control = (_mean_small_control(ctrl, ctrl.shape[0], p[1], scratch) + 4) / 5
    return near_target * small_control


@kernel
def swimmer_reward(x, p, ctrl, scratch):
    """x: distance [m], target size [m]; p: the long tail's scale."""
    size = x[1]
    return tolerance_at(x[0], 0.0, size, 5 * size, LONG_TAIL, p[0])


@kernel
def finger_reward(x, p, ctrl, scratch):
    """x: hinge rate [rad/s], distance to the target [m]; p: turn (1) or spin (0), the spin
    rate [rad/s]."""
    if p[0] == 0:
        return 1.0 if x[0] <= -p[1] else 0.0
    return 1.0 if x[1] <= 0 else 0.0


@kernel
def task_reward(code, x, p, ctrl, scratch):
    """The reward of domain `code` (this module's codes) from its values x, parameters p,
    last control ctrl (as given, not clamped); scratch: room for max(controls, poles)
    floats."""
    if code == CHEETAH:
        return cheetah_reward(x, p, ctrl, scratch)
    if code == WALKER:
        return walker_reward(x, p, ctrl, scratch)
    if code == HOPPER:
        return hopper_reward(x, p, ctrl, scratch)
    if code == ACROBOT:
        return acrobot_reward(x, p, ctrl, scratch)
    if code == CARTPOLE:
        return cartpole_reward(x, p, ctrl, scratch)
    if code == PENDULUM:
        return pendulum_reward(x, p, ctrl, scratch)
    if code == REACHER:
        return reacher_reward(x, p, ctrl, scratch)
    if code == POINT_MASS:
        return point_mass_reward(x, p, ctrl, scratch)
    if code == SWIMMER:
        return swimmer_reward(x, p, ctrl, scratch)
    return finger_reward(x, p, ctrl, scratch)


@jit
def reward_of_values(code, x, p, ctrl, scratch):
    """task_reward from Python (tests: against the Python reward)."""
    return task_reward(code, x, p, ctrl, scratch)


# --- the parameters, from Python --------------------------------------------------------

def _scale(kind, value_at_margin=0.1):
    return tolerance_terms((0.0, 0.0), 1.0, kind, value_at_margin)[3]


def _cartpole_names(names):
    poles = sum(1 for n in names if n.startswith("cos"))
    return ([f"cos{i}" for i in range(poles)] + ["slider"]
            + [f"qvel{i}" for i in range(1, len(names) - poles)]), poles


def _params(domain, p, names):
    """(the value names the domain's kernel reads, in order; its p)."""
    if domain == "cheetah":
        return ["speed"], tolerance_terms((p["run_speed"], INF), p["run_speed"], "linear", 0)
    if domain == "walker":
        move = p["move_speed"]
        return ["height", "upright", "speed"], (
            tolerance_terms((p["stand_height"], INF), p["stand_height"] / 2)
            + [float(move)]
            + (tolerance_terms((move, INF), move / 2, "linear", 0.5) if move else [0.0] * 4))
    if domain == "hopper":
        hop = p["hop_speed"]
        return ["height", "speed"], (
            tolerance_terms((p["stand_height"], 2)) + [float(hop)]
            + (tolerance_terms((hop, INF), hop / 2, "linear", 0.5) if hop else [0.0] * 4)
            + [_scale("quadratic", 0)])
    if domain == "acrobot":
        return ["distance", "radius"], [_scale("gaussian")]
    if domain == "cartpole":
        order, poles = _cartpole_names(names)
        return order, [float(poles), _scale("gaussian"), _scale("quadratic", 0),
                       _scale("gaussian")]
    if domain == "pendulum":
        return ["cos"], tolerance_terms((np.cos(np.deg2rad(p["angle_bound"])), 1))
    if domain == "reacher":
        return ["distance", "radii"], [0.0]
    if domain == "point_mass":
        return ["distance", "target_size"], [_scale("gaussian"), _scale("quadratic", 0)]
    if domain == "swimmer":
        return ["distance", "target_size"], [_scale("long_tail")]
    if domain == "finger":
        turn = p["target_radius"] is not None
        return ["hinge_velocity", "dist_to_target"], [float(turn), float(p["spin_velocity"])]
    raise NotImplementedError(f"no compiled reward for dm_control domain {domain!r}")


CODES = {"cheetah": CHEETAH, "walker": WALKER, "hopper": HOPPER, "acrobot": ACROBOT,
         "cartpole": CARTPOLE, "pendulum": PENDULUM, "reacher": REACHER,
         "point_mass": POINT_MASS, "swimmer": SWIMMER, "finger": FINGER}


def reward_params(domain: str, params: dict, names, n_controls: int):
    """(code, p as a float64 array, scratch floats needed) of domain `domain`'s compiled
    reward for task parameters `params`, checked against `names`, the value names of its
    plan (the kernel reads them by position)."""
    order, p = _params(domain, params, list(names))
    if list(names) != order:
        raise RuntimeError(f"dmc {domain}: the plan's reward values {list(names)} are not the "
                           f"compiled reward's {order}")
    room = max(n_controls, sum(1 for n in names if n.startswith("cos")), 1)
    if room > MAX_MEAN:
        raise NotImplementedError(f"dmc {domain}: {room} entries in a mean; the compiled "
                                  f"reward averages at most {MAX_MEAN} bit for bit")
    return CODES[domain], np.array(p, np.float64), room
