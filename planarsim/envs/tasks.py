"""gymnasium's planar v5 MuJoCo tasks on planarsim (see core.PlanarMujocoEnv for what differs).

Each class follows the gymnasium v5 environment of the same name (gymnasium/envs/mujoco/
<name>_v5.py): the same defaults, observation layout, reward terms and info keys,
termination, reset noise and frame skip.
"""
from __future__ import annotations

import numpy as np
from gymnasium import utils
from gymnasium.spaces import Box

from ..mjcf import parse_xml
from .core import PlanarMujocoEnv, gym_asset


class _Locomotion(PlanarMujocoEnv, utils.EzPickle):
    """Hopper, Walker2d and HalfCheetah: obs = qpos[1:] and qvel (clipped for some)."""
    clip_qvel = True

    def __init__(self, xml_file, frame_skip, forward_reward_weight, ctrl_cost_weight,
                 reset_noise_scale, exclude_current_positions_from_observation=True,
                 render_mode=None, **kw):
        self._forward_reward_weight = forward_reward_weight
        self._ctrl_cost_weight = ctrl_cost_weight
        self._reset_noise_scale = reset_noise_scale
        self._exclude = exclude_current_positions_from_observation
        PlanarMujocoEnv.__init__(self, xml_file, frame_skip, render_mode=render_mode, **kw)
        self.metadata = {"render_modes": ["rgb_array"], "render_fps": int(np.round(1.0 / self.dt))}
        n = self.model.nq + self.model.nv - int(self._exclude)
        self.observation_space = Box(low=-np.inf, high=np.inf, shape=(n,), dtype=np.float64)

    def control_cost(self, action):
        return self._ctrl_cost_weight * np.sum(np.square(action))

    def _get_obs(self):
        position = self.data.qpos.flatten()
        velocity = self.data.qvel.flatten()
        if self.clip_qvel:
            velocity = np.clip(velocity, -10, 10)
        if self._exclude:
            position = position[1:]
        return np.concatenate((position, velocity)).ravel()

    def reset_model(self):
        lo, hi = -self._reset_noise_scale, self._reset_noise_scale
        qpos = self.init_qpos + self.np_random.uniform(low=lo, high=hi, size=self.model.nq)
        qvel = self.init_qvel + self.np_random.uniform(low=lo, high=hi, size=self.model.nv)
        self.set_state(qpos, qvel)
        return self._get_obs()


class _Healthy(_Locomotion):
    """Hopper and Walker2d: forward + healthy reward - ctrl cost; terminates when unhealthy."""

    def __init__(self, xml_file, frame_skip=4, forward_reward_weight=1.0, ctrl_cost_weight=1e-3,
                 healthy_reward=1.0, terminate_when_unhealthy=True, reset_noise_scale=5e-3, **kw):
        self._healthy_reward = healthy_reward
        self._terminate_when_unhealthy = terminate_when_unhealthy
        _Locomotion.__init__(self, xml_file, frame_skip, forward_reward_weight, ctrl_cost_weight,
                             reset_noise_scale, **kw)

    @property
    def healthy_reward(self):
        return self.is_healthy * self._healthy_reward

    def step(self, action):
        x_before = self.data.qpos[0]
        self.do_simulation(action, self.frame_skip)
        x_after = self.data.qpos[0]
        x_velocity = (x_after - x_before) / self.dt
        observation = self._get_obs()
        forward_reward = self._forward_reward_weight * x_velocity
        healthy_reward = self.healthy_reward
        ctrl_cost = self.control_cost(action)
        reward = forward_reward + healthy_reward - ctrl_cost
        terminated = (not self.is_healthy) and self._terminate_when_unhealthy
        info = {"x_position": x_after, "z_distance_from_origin": self.data.qpos[1] - self.init_qpos[1],
                "x_velocity": x_velocity, "reward_forward": forward_reward,
                "reward_ctrl": -ctrl_cost, "reward_survive": healthy_reward}
        return observation, reward, terminated, False, info

    def _get_reset_info(self):
        return {"x_position": self.data.qpos[0],
                "z_distance_from_origin": self.data.qpos[1] - self.init_qpos[1]}


class Hopper(_Healthy):
    """gymnasium Hopper-v5 on planarsim (hopper.xml, frame_skip 4, dt 0.008 s)."""

    def __init__(self, xml_file="hopper.xml", frame_skip=4, forward_reward_weight=1.0,
                 ctrl_cost_weight=1e-3, healthy_reward=1.0, terminate_when_unhealthy=True,
                 healthy_state_range=(-100.0, 100.0), healthy_z_range=(0.7, float("inf")),
                 healthy_angle_range=(-0.2, 0.2), reset_noise_scale=5e-3,
                 exclude_current_positions_from_observation=True, render_mode=None, **kw):
        utils.EzPickle.__init__(self, xml_file, frame_skip, forward_reward_weight, ctrl_cost_weight,
                                healthy_reward, terminate_when_unhealthy, healthy_state_range,
                                healthy_z_range, healthy_angle_range, reset_noise_scale,
                                exclude_current_positions_from_observation, render_mode, **kw)
        self._healthy_state_range = healthy_state_range
        self._healthy_z_range = healthy_z_range
        self._healthy_angle_range = healthy_angle_range
        _Healthy.__init__(self, xml_file, frame_skip, forward_reward_weight, ctrl_cost_weight,
                          healthy_reward, terminate_when_unhealthy, reset_noise_scale,
                          exclude_current_positions_from_observation=exclude_current_positions_from_observation,
                          render_mode=render_mode, **kw)

    @property
    def is_healthy(self):
        z, angle = self.data.qpos[1:3]
        state = self.state_vector()[2:]
        lo, hi = self._healthy_state_range
        healthy_state = np.all(np.logical_and(lo < state, state < hi))
        healthy_z = self._healthy_z_range[0] < z < self._healthy_z_range[1]
        healthy_angle = self._healthy_angle_range[0] < angle < self._healthy_angle_range[1]
        return bool(healthy_state and healthy_z and healthy_angle)


class Walker2d(_Healthy):
    """gymnasium Walker2d-v5 on planarsim (walker2d_v5.xml, frame_skip 4, dt 0.008 s).
    Both legs move in one plane and only touch the floor (as in MuJoCo's file, whose geoms
    do not collide with each other)."""

    def __init__(self, xml_file="walker2d_v5.xml", frame_skip=4, forward_reward_weight=1.0,
                 ctrl_cost_weight=1e-3, healthy_reward=1.0, terminate_when_unhealthy=True,
                 healthy_z_range=(0.8, 2.0), healthy_angle_range=(-1.0, 1.0),
                 reset_noise_scale=5e-3, exclude_current_positions_from_observation=True,
                 render_mode=None, **kw):
        utils.EzPickle.__init__(self, xml_file, frame_skip, forward_reward_weight, ctrl_cost_weight,
                                healthy_reward, terminate_when_unhealthy, healthy_z_range,
                                healthy_angle_range, reset_noise_scale,
                                exclude_current_positions_from_observation, render_mode, **kw)
        self._healthy_z_range = healthy_z_range
        self._healthy_angle_range = healthy_angle_range
        _Healthy.__init__(self, xml_file, frame_skip, forward_reward_weight, ctrl_cost_weight,
                          healthy_reward, terminate_when_unhealthy, reset_noise_scale,
                          exclude_current_positions_from_observation=exclude_current_positions_from_observation,
                          render_mode=render_mode, **kw)

    @property
    def is_healthy(self):
        z, angle = self.data.qpos[1:3]
        return bool(self._healthy_z_range[0] < z < self._healthy_z_range[1]
                    and self._healthy_angle_range[0] < angle < self._healthy_angle_range[1])


class HalfCheetah(_Locomotion):
    """gymnasium HalfCheetah-v5 on planarsim (half_cheetah.xml, frame_skip 5, dt 0.05 s).
    Its observation does not clip qvel; reset adds Gaussian noise to qvel."""
    clip_qvel = False

    def __init__(self, xml_file="half_cheetah.xml", frame_skip=5, forward_reward_weight=1.0,
                 ctrl_cost_weight=0.1, reset_noise_scale=0.1,
                 exclude_current_positions_from_observation=True, render_mode=None, **kw):
        utils.EzPickle.__init__(self, xml_file, frame_skip, forward_reward_weight, ctrl_cost_weight,
                                reset_noise_scale, exclude_current_positions_from_observation,
                                render_mode, **kw)
        _Locomotion.__init__(self, xml_file, frame_skip, forward_reward_weight, ctrl_cost_weight,
                             reset_noise_scale, exclude_current_positions_from_observation,
                             render_mode=render_mode, **kw)

    def step(self, action):
        x_before = self.data.qpos[0]
        self.do_simulation(action, self.frame_skip)
        x_after = self.data.qpos[0]
        x_velocity = (x_after - x_before) / self.dt
        observation = self._get_obs()
        forward_reward = self._forward_reward_weight * x_velocity
        ctrl_cost = self.control_cost(action)
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


class InvertedPendulum(PlanarMujocoEnv, utils.EzPickle):
    """gymnasium InvertedPendulum-v5 on planarsim (inverted_pendulum.xml, frame_skip 2)."""

    def __init__(self, xml_file="inverted_pendulum.xml", frame_skip=2, reset_noise_scale=0.01,
                 render_mode=None, **kw):
        utils.EzPickle.__init__(self, xml_file, frame_skip, reset_noise_scale, render_mode, **kw)
        self._reset_noise_scale = reset_noise_scale
        PlanarMujocoEnv.__init__(self, xml_file, frame_skip,
                                 Box(low=-np.inf, high=np.inf, shape=(4,), dtype=np.float64),
                                 render_mode=render_mode, **kw)
        self.metadata = {"render_modes": ["rgb_array"], "render_fps": int(np.round(1.0 / self.dt))}

    def step(self, action):
        self.do_simulation(action, self.frame_skip)
        observation = self._get_obs()
        terminated = bool(not np.isfinite(observation).all() or (np.abs(observation[1]) > 0.2))
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
    root = parse_xml(open(path).read(), path)

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


class InvertedDoublePendulum(PlanarMujocoEnv, utils.EzPickle):
    """gymnasium InvertedDoublePendulum-v5 on planarsim (inverted_double_pendulum.xml,
    frame_skip 5). The last observation entry, MuJoCo's qfrc_constraint[0] (the constraint
    force on the cart's slide), is here the slider's limit impulse of the last step over the
    step length [N] (clipped to +-10); without a limit hit both are 0."""

    def __init__(self, xml_file="inverted_double_pendulum.xml", frame_skip=5, healthy_reward=10.0,
                 reset_noise_scale=0.1, render_mode=None, **kw):
        utils.EzPickle.__init__(self, xml_file, frame_skip, healthy_reward, reset_noise_scale,
                                render_mode, **kw)
        self._healthy_reward = healthy_reward
        self._reset_noise_scale = reset_noise_scale
        PlanarMujocoEnv.__init__(self, xml_file, frame_skip,
                                 Box(low=-np.inf, high=np.inf, shape=(9,), dtype=np.float64),
                                 render_mode=render_mode, **kw)
        self.metadata = {"render_modes": ["rgb_array"], "render_fps": int(np.round(1.0 / self.dt))}
        self._tip = _site(gym_asset(xml_file) if "/" not in xml_file else xml_file, "tip")
        self._slider = self.loaded.joint[self.coords.names[0]].id

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
