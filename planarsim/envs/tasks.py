"""gymnasium's planar v5 MuJoCo tasks on planarsim (see core.PlanarMujocoEnv for what differs).

Each class follows the gymnasium v5 environment of the same name (gymnasium/envs/mujoco/
<name>_v5.py): the same defaults, observation layout, reward terms and info keys,
termination, reset noise and frame skip.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from gymnasium import utils
from gymnasium.spaces import Box

from ..checks import finite_number, flag, pair
from ..compiled import jit
from ..mjcf import parse_xml
from .core import PlanarMujocoEnv, gym_asset


@jit
def joined_finite(a, b, out):
    """out = a's entries then b's; returns whether every entry is finite (an observation and
    its check in one compiled call; compiled code allocates nothing)."""
    n = a.shape[0]
    finite = True
    for i in range(n):
        out[i] = a[i]
        finite = finite and math.isfinite(a[i])
    for i in range(b.shape[0]):
        out[n + i] = b[i]
        finite = finite and math.isfinite(b[i])
    return finite


@jit
def reacher_obs(q, q0, bodies, local, qpos, qvel, out):
    """Reacher's observation into out (cos and sin of the two arm angles, the target's qpos,
    the arm's qvel, fingertip - target); returns fingertip - target (x, y) [m]. bodies: the
    fingertip's and the target's body; local: their centres of mass at the file's pose."""
    vx = 0.0
    vy = 0.0
    for k in range(2):
        b = bodies[k]
        dx = local[k, 0] - q0[b, 0]
        dy = local[k, 1] - q0[b, 1]
        c = math.cos(q[b, 2] - q0[b, 2])
        s = math.sin(q[b, 2] - q0[b, 2])
        sign = 1.0 if k == 0 else -1.0            # the fingertip less the target
        vx += sign * (q[b, 0] + c * dx - s * dy)
        vy += sign * (q[b, 1] + s * dx + c * dy)
    out[0] = math.cos(qpos[0])
    out[1] = math.cos(qpos[1])
    out[2] = math.sin(qpos[0])
    out[3] = math.sin(qpos[1])
    n = 4
    for i in range(2, qpos.shape[0]):
        out[n] = qpos[i]
        n += 1
    out[n] = qvel[0]
    out[n + 1] = qvel[1]
    out[n + 2] = vx
    out[n + 3] = vy
    return vx, vy


def check_task_keywords(name, defaults, args) -> None:
    """ValueError naming the task, the keyword and its value where a task's keyword is not of
    its default's kind: a weight or reward (a float default) a finite number, a switch (a bool
    default) True or False, a range (a tuple default) a pair (low, high) with low < high
    (either may be infinite the other way). A NaN weight gave NaN rewards, a reversed range
    ended every episode at its first step, a string switch was read as True."""
    for key, default in defaults.items():
        value, said = args[key], f"{name}: {key}"
        if isinstance(default, bool):
            flag(said, value, ValueError)
        elif isinstance(default, float):
            finite_number(said, value)
        elif isinstance(default, tuple):
            pair(said, value, increasing=True)


class _Task(PlanarMujocoEnv, utils.EzPickle):
    """A task's keyword arguments and their defaults are its class's DEFAULTS (gymnasium's
    v5 defaults), each kept as the attribute "_" + name; any other keyword goes to
    PlanarMujocoEnv (render_mode, width, height) or load_mjcf. obs_size(): the observation's
    length."""
    DEFAULTS: dict = {}

    def __init__(self, **kw):
        args = {**self.DEFAULTS, **kw}
        check_task_keywords(type(self).__name__, self.DEFAULTS, args)
        noise = args.get("reset_noise_scale", 0.0)
        if not (isinstance(noise, (int, float)) and math.isfinite(noise) and noise >= 0):
            raise ValueError(f"{type(self).__name__}: reset_noise_scale={noise!r} must be a "
                             "finite number >= 0")
        utils.EzPickle.__init__(self, **args)
        for key in self.DEFAULTS:
            if key not in ("xml_file", "frame_skip"):
                setattr(self, "_" + key, args.pop(key))
        PlanarMujocoEnv.__init__(self, args.pop("xml_file"), args.pop("frame_skip"), **args)
        self.metadata = {"render_modes": ["rgb_array"], "render_fps": int(np.round(1.0 / self.dt))}
        self.observation_space = Box(low=-np.inf, high=np.inf, shape=(self.obs_size(),),
                                     dtype=np.float64)

    def obs_size(self) -> int:  # pragma: no cover - each task defines it
        raise NotImplementedError


class _Locomotion(_Task):
    """Hopper, Walker2d, HalfCheetah and Swimmer: obs = qpos without the first n_excluded
    (the root's position) and qvel (clipped to +-10 for some)."""
    clip_qvel = True
    n_excluded = 1

    @property
    def _exclude(self):
        return self._exclude_current_positions_from_observation

    def obs_size(self):
        return self.model.nq + self.model.nv - self.n_excluded * int(self._exclude)

    def control_cost(self, action):
        return self._ctrl_cost_weight * np.sum(np.square(action))

    def advance(self, action, n=1):
        """Simulate one env step; return the root's first n qpos after it, their velocity
        over the step, the observation, the forward reward (weight * x velocity) and the
        control cost."""
        before = self.data.qpos[:n].copy()
        self.do_simulation(action, self.frame_skip)
        after = self.data.qpos[:n].copy()
        velocity = (after - before) / self.dt
        return (after, velocity, self._get_obs(), self._forward_reward_weight * velocity[0],
                self.control_cost(action))

    def _get_obs(self):
        position = self.data.qpos.flatten()
        velocity = self.data.qvel.flatten()
        if self.clip_qvel:
            velocity = np.clip(velocity, -10, 10)
        if self._exclude:
            position = position[self.n_excluded:]
        return np.concatenate((position, velocity)).ravel()

    def reset_model(self):
        lo, hi = -self._reset_noise_scale, self._reset_noise_scale
        qpos = self.init_qpos + self.np_random.uniform(low=lo, high=hi, size=self.model.nq)
        qvel = self.init_qvel + self.np_random.uniform(low=lo, high=hi, size=self.model.nv)
        self.set_state(qpos, qvel)
        return self._get_obs()


_HEALTHY = dict(frame_skip=4, forward_reward_weight=1.0, ctrl_cost_weight=1e-3, healthy_reward=1.0,
                terminate_when_unhealthy=True, reset_noise_scale=5e-3,
                exclude_current_positions_from_observation=True)


class _Healthy(_Locomotion):
    """Hopper and Walker2d: forward + healthy reward - ctrl cost; terminates when unhealthy
    (z and the root's angle outside their ranges; Hopper also any state beyond its range)."""
    _healthy_state_range = None     # Hopper's DEFAULTS set it

    @property
    def healthy_reward(self):
        return self.is_healthy * self._healthy_reward

    @property
    def is_healthy(self):
        z, angle = self.data.qpos[1:3]
        healthy = (self._healthy_z_range[0] < z < self._healthy_z_range[1]
                   and self._healthy_angle_range[0] < angle < self._healthy_angle_range[1])
        state_range = self._healthy_state_range
        if state_range is not None:
            state = self.state_vector()[2:]
            healthy = healthy and bool(np.all((state_range[0] < state) & (state < state_range[1])))
        return bool(healthy)

    def step(self, action):
        (x_after,), (x_velocity,), observation, forward_reward, ctrl_cost = self.advance(action)
        healthy = self.is_healthy
        healthy_reward = healthy * self._healthy_reward
        reward = forward_reward + healthy_reward - ctrl_cost
        terminated = (not healthy) and self._terminate_when_unhealthy
        info = {"x_position": x_after, "z_distance_from_origin": self.data.qpos[1] - self.init_qpos[1],
                "x_velocity": x_velocity, "reward_forward": forward_reward,
                "reward_ctrl": -ctrl_cost, "reward_survive": healthy_reward}
        return observation, reward, terminated, False, info

    def _get_reset_info(self):
        return {"x_position": self.data.qpos[0],
                "z_distance_from_origin": self.data.qpos[1] - self.init_qpos[1]}


class Hopper(_Healthy):
    """gymnasium Hopper-v5 on planarsim (hopper.xml, frame_skip 4, dt 0.008 s)."""
    DEFAULTS = dict(xml_file="hopper.xml", **_HEALTHY, healthy_state_range=(-100.0, 100.0),
                    healthy_z_range=(0.7, float("inf")), healthy_angle_range=(-0.2, 0.2))


class Walker2d(_Healthy):
    """gymnasium Walker2d-v5 on planarsim (walker2d_v5.xml, frame_skip 4, dt 0.008 s).
    Both legs move in one plane and only touch the floor (as in MuJoCo's file, whose geoms
    do not collide with each other)."""
    DEFAULTS = dict(xml_file="walker2d_v5.xml", **_HEALTHY, healthy_z_range=(0.8, 2.0),
                    healthy_angle_range=(-1.0, 1.0))


class HalfCheetah(_Locomotion):
    """gymnasium HalfCheetah-v5 on planarsim (half_cheetah.xml, frame_skip 5, dt 0.05 s).
    Its observation does not clip qvel; reset adds Gaussian noise to qvel."""
    clip_qvel = False
    DEFAULTS = dict(xml_file="half_cheetah.xml", frame_skip=5, forward_reward_weight=1.0,
                    ctrl_cost_weight=0.1, reset_noise_scale=0.1,
                    exclude_current_positions_from_observation=True)

    def step(self, action):
        (x_after,), (x_velocity,), observation, forward_reward, ctrl_cost = self.advance(action)
        info = {"x_position": x_after, "x_velocity": x_velocity,
                "reward_forward": forward_reward, "reward_ctrl": -ctrl_cost}
        return observation, forward_reward - ctrl_cost, False, False, info

    def reset_model(self):
        s = self._reset_noise_scale
        qpos = self.init_qpos + self.np_random.uniform(low=-s, high=s, size=self.model.nq)
        qvel = self.init_qvel + s * self.np_random.standard_normal(self.model.nv)
        self.set_state(qpos, qvel)
        return self._get_obs()

    def _get_reset_info(self):
        return {"x_position": self.data.qpos[0]}


class Swimmer(_Locomotion):
    """gymnasium Swimmer-v5 on planarsim (swimmer.xml, frame_skip 4, dt 0.04 s): three links
    in the x-y plane, no gravity, MuJoCo's inertia-box drag (viscosity 0.1, density 4000;
    kernels/dynamics/fluid.py) and armature 0.1 on every joint, the root's included. Reward: the
    velocity of qpos[0] minus 1e-4 |action|^2. What differs: MuJoCo's file asks for RK4,
    planarsim steps it with its own first-order integrator (the drag explicit, as MuJoCo's
    Euler has it)."""
    clip_qvel = False
    n_excluded = 2
    DEFAULTS = dict(xml_file="swimmer.xml", frame_skip=4, forward_reward_weight=1.0,
                    ctrl_cost_weight=1e-4, reset_noise_scale=0.1,
                    exclude_current_positions_from_observation=True)

    def step(self, action):
        xy_after, (x_velocity, y_velocity), observation, forward_reward, ctrl_cost = \
            self.advance(action, 2)
        info = {"x_position": xy_after[0], "y_position": xy_after[1],
                "distance_from_origin": np.linalg.norm(xy_after, ord=2),
                "x_velocity": x_velocity, "y_velocity": y_velocity,
                "reward_forward": forward_reward, "reward_ctrl": -ctrl_cost}
        return observation, forward_reward - ctrl_cost, False, False, info

    def _get_reset_info(self):
        return {"x_position": self.data.qpos[0], "y_position": self.data.qpos[1],
                "distance_from_origin": np.linalg.norm(self.data.qpos[0:2], ord=2)}


class Reacher(_Task):
    """gymnasium Reacher-v5 on planarsim (reacher.xml, frame_skip 2, dt 0.02 s): a two-link
    arm in the x-y plane (no gravity; armature 1 and damping 1 on its hinges) reaching for a
    target that translates only (two slides: a point mass here). obs: cos and sin of the two
    arm angles, the target's qpos, the arm's qvel, fingertip - target (x, y); reward
    -|fingertip - target| - |action|^2 (the bodies lie at one height: the distance is the
    plane's). What differs: MuJoCo's file asks for RK4, planarsim steps it with its own
    first-order integrator."""

    DEFAULTS = dict(xml_file="reacher.xml", frame_skip=2, reward_dist_weight=1.0,
                    reward_control_weight=1.0)

    def __init__(self, **kw):
        _Task.__init__(self, **kw)
        self.goal = self.init_qpos[-2:].copy()
        # the fingertip's and the target's bodies and centres of mass, for reacher_obs
        self._ends = np.array([self.loaded.body[b] for b in ("fingertip", "target")], np.int64)
        self._ends_com = np.array([self.loaded.com[b][:2] for b in ("fingertip", "target")], float)
        self._q0 = np.ascontiguousarray(self.sim_model.q0, float).reshape(-1, 3)

    def obs_size(self):
        """cos and sin of the two arm angles, the other qpos, the arm's two qvel and fingertip -
        target: 10 for gymnasium's reacher.xml (reacher_obs writes this many)."""
        return self.model.nq + 6

    def _get_rew(self, action, vec=None):
        """(reward, its terms); vec: fingertip - target [m] if already measured."""
        if vec is None:
            vec = self.body_com("fingertip") - self.body_com("target")
        reward_dist = -math.hypot(vec[0], vec[1]) * self._reward_dist_weight
        reward_ctrl = -np.square(action).sum() * self._reward_control_weight
        return reward_dist + reward_ctrl, {"reward_dist": reward_dist, "reward_ctrl": reward_ctrl}

    def step(self, action):
        self.do_simulation(action, self.frame_skip)
        observation = np.empty(self.obs_size())
        vec = reacher_obs(self.sim.state.q, self._q0, self._ends, self._ends_com, self.data.qpos,
                          self.data.qvel, observation)
        reward, info = self._get_rew(action, vec)
        return observation, reward, False, False, info

    def reset_model(self):
        qpos = self.np_random.uniform(low=-0.1, high=0.1, size=self.model.nq) + self.init_qpos
        while True:
            self.goal = self.np_random.uniform(low=-0.2, high=0.2, size=2)
            if np.linalg.norm(self.goal) < 0.2:
                break
        qpos[-2:] = self.goal
        qvel = self.init_qvel + self.np_random.uniform(low=-0.005, high=0.005, size=self.model.nv)
        qvel[-2:] = 0
        self.set_state(qpos, qvel)
        return self._get_obs()

    def _get_obs(self):
        vec = self.body_com("fingertip") - self.body_com("target")
        theta = self.data.qpos[:2]
        return np.concatenate([np.cos(theta), np.sin(theta), self.data.qpos[2:],
                               self.data.qvel[:2], vec])


class InvertedPendulum(_Task):
    """gymnasium InvertedPendulum-v5 on planarsim (inverted_pendulum.xml, frame_skip 2)."""
    DEFAULTS = dict(xml_file="inverted_pendulum.xml", frame_skip=2, reset_noise_scale=0.01)

    def obs_size(self):
        """qpos then qvel: 4 for gymnasium's inverted_pendulum.xml (joined_finite writes this
        many)."""
        return self.model.nq + self.model.nv

    def step(self, action):
        self.do_simulation(action, self.frame_skip)
        observation = np.empty(self.obs_size())
        finite = joined_finite(self.data.qpos, self.data.qvel, observation)
        terminated = not finite or abs(observation[1]) > 0.2
        reward = int(not terminated)
        return observation, reward, terminated, False, {"reward_survive": reward}

    def reset_model(self):
        s = self._reset_noise_scale
        qpos = self.init_qpos + self.np_random.uniform(size=self.model.nq, low=-s, high=s)
        qvel = self.init_qvel + self.np_random.uniform(size=self.model.nv, low=-s, high=s)
        self.set_state(qpos, qvel)
        return self._get_obs()

    def _get_obs(self):
        return np.concatenate([self.data.qpos, self.data.qvel]).ravel()


def _site(path, name):
    """(MJCF body name, plane position at the file's pose) of site `name`, for files whose
    bodies carry positions only (local coordinates, no rotations)."""
    root = parse_xml(Path(path).read_text(), path)

    def walk(node, pos, body):
        for ch in node.children:
            if ch.tag in ("worldbody", "body"):
                if set(ch.attrib) & {"quat", "axisangle", "euler", "zaxis", "xyaxes"}:
                    raise NotImplementedError(f"{path}: site lookup through rotated bodies")
                p = pos + np.array([float(x) for x in ch.attrib.get("pos", "0 0 0").split()])
                found = walk(ch, p, ch.attrib.get("name", body))
                if found is not None:
                    return found
            elif ch.tag == "site" and ch.attrib.get("name") == name:
                return body, pos + np.array([float(x) for x in ch.attrib.get("pos", "0 0 0").split()])
        return None
    body, p = walk(root, np.zeros(3), None)
    return body, np.array([p[0], p[2]])


class InvertedDoublePendulum(_Task):
    """gymnasium InvertedDoublePendulum-v5 on planarsim (inverted_double_pendulum.xml,
    frame_skip 5). The last observation entry, MuJoCo's qfrc_constraint[0] (the constraint
    force on the cart's slide), is here the slider's limit impulse of the last step over the
    step length [N] (clipped to +-10); without a limit hit both are 0."""

    DEFAULTS = dict(xml_file="inverted_double_pendulum.xml", frame_skip=5, healthy_reward=10.0,
                    reset_noise_scale=0.1)

    def __init__(self, **kw):
        _Task.__init__(self, **kw)
        xml_file = kw.get("xml_file", self.DEFAULTS["xml_file"])
        self._tip = _site(gym_asset(xml_file) if "/" not in xml_file else xml_file, "tip")
        self._slider = self.loaded.joint[self.coords.names[0]].id

    def obs_size(self):
        return 9

    def tip(self):
        return self.point(*self._tip)

    def _cart_constraint_force(self):
        imp = self.sim.state.last_pin_impulse[self._slider]
        return (imp[2] - imp[3]) / self.timestep

    def step(self, action):
        self.do_simulation(action, self.frame_skip)
        x, y = self.tip()
        observation = self._get_obs()
        terminated = bool(y <= 1)
        v1, v2 = self.data.qvel[1:3]
        dist_penalty = 0.01 * x ** 2 + (y - 2) ** 2
        vel_penalty = 1e-3 * v1 ** 2 + 5e-3 * v2 ** 2
        alive_bonus = self._healthy_reward * int(not terminated)
        reward = alive_bonus - dist_penalty - vel_penalty
        info = {"reward_survive": alive_bonus, "distance_penalty": -dist_penalty,
                "velocity_penalty": -vel_penalty}
        return observation, reward, terminated, False, info

    def _get_obs(self):
        return np.concatenate([self.data.qpos[:1], np.sin(self.data.qpos[1:]),
                               np.cos(self.data.qpos[1:]), np.clip(self.data.qvel, -10, 10),
                               np.clip([self._cart_constraint_force()], -10, 10)]).ravel()

    def reset_model(self):
        s = self._reset_noise_scale
        self.set_state(self.init_qpos + self.np_random.uniform(low=-s, high=s, size=self.model.nq),
                       self.init_qvel + self.np_random.standard_normal(self.model.nv) * s)
        return self._get_obs()
