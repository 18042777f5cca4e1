"""The DeepMind Control Suite's planar tasks as gymnasium environments on planarsim, with
dm_control's semantics: its model files (read from the installed dm_control package, which
is not imported), its rewards (``rewards.tolerance``, reimplemented), its observations (the
task's ``get_observation`` entries, each raveled, concatenated in order), its control step
(``_CONTROL_TIMESTEP`` where the domain sets one, else the model's timestep; the physics
steps n_sub_steps = control step / timestep times per action), its time limits (episode
steps = ceil(time limit / control step)) and its episode initialisation (the same draws from
a ``numpy.random.RandomState(seed)``, so that a seed starts the same state as
``suite.load(domain, task, task_kwargs={"random": seed})``; cheetah then settles 200 physics
steps on planarsim's engine; finger draws its joint angles again while two of planarsim's
colliding shapes overlap, where dm_control asks MuJoCo for a contact: the same geometry, so
the same draws, and a start that never overlaps).

One class, :class:`DMCEnv`; each domain is a few functions (its initialisation, its readings
and its reward, written as dm_control's ``Physics`` / ``Task`` methods are), each task a row
of ``TASKS`` (its domain and parameters: walker stand / walk / run differ by a target speed).
A domain's readings (its observation entries, then the values its reward reads) are a table
of operations (:mod:`.readout`) written at a reset and computed with the reward (each domain's
compiled from those values: dmc_rewards.py, the same float as its Python function here) by one
compiled call; in the fast compile mode that call also loads the action's commands and runs
the physics steps, so that an env step is one compiled call (dmc_step.py).
The quantities dm_control reads from MuJoCo's data (body frames ``xpos`` / ``xmat``, body
centres of mass ``xipos``, site and geom positions, the sensors ``subtreelinvel``,
``velocimeter``, ``gyro``, ``framepos``, ``jointpos``, ``jointvel``, ``touch``) are
computed from planarsim's body poses and velocities and the file's frames
(:class:`FileFrames`).

What differs from dm_control: the motion (planarsim's hard contacts and its integrator, not
MuJoCo's soft contacts and Euler / RK4), hence episodes beyond their first steps; and the
touch sensors (hopper's, finger's), which here are the normal force of planarsim's contacts
in the site's sphere or ellipsoid over the last physics step (impulse / timestep), not
MuJoCo's soft contact force of the current state (0 right after a reset). As in dm_control,
the reward's control terms read the action as given, the motors the action clamped to
ctrlrange.
"""
from __future__ import annotations

import collections
import importlib.util
import math
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field

import numpy as np
from gymnasium import spaces

from ..mjcf import parse_xml
from ..start_check import shape_overlaps
from ..checks import MAX_STEPS
from ..compile import FAST, MODE, TABLES
from ..kernels.checks.guards import GUARD_ROOM
from ..link.step import bind
from .core import PlanarMujocoEnv
from .dmc_rewards import reward_params
from .dmc_step import ACTION_REFUSED, DMCArrays, dmc_observe, dmc_step
from .readout import Readout, read

if TABLES:
    from ..compile.refs import TableHandle
from .rewards import tolerance

INF = float("inf")


# --- the suite's files --------------------------------------------------------------------

def find_suite_dir() -> str:
    """Directory of dm_control's suite model files (found without importing dm_control)."""
    spec = importlib.util.find_spec("dm_control")
    if spec is None or not spec.submodule_search_locations:
        raise ImportError("the DeepMind Control Suite's model files come with dm_control, which "
                          "is not installed (pip install dm_control); planarsim does not ship "
                          "them")
    return os.path.join(list(spec.submodule_search_locations)[0], "suite")


def common_assets(directory: str) -> dict:
    """The ./common/*.xml files the suite's models include, as load_mjcf's assets."""
    common = os.path.join(directory, "common")
    return {f"./common/{f}": open(os.path.join(common, f), "rb").read()
            for f in sorted(os.listdir(common)) if f.endswith(".xml")}


def with_joint_damping(text: str, damping: dict) -> str:
    """The model text with the named joints' damping [N m s/rad] replaced (as dm_control's
    tasks set model.dof_damping before their episodes)."""
    mjcf = ET.fromstring(text)
    for name, value in damping.items():
        joints = [j for j in mjcf.iter("joint") if j.get("name") == name]
        if len(joints) != 1:
            raise ValueError(f"joint damping: the model has {len(joints)} joints named {name!r}")
        joints[0].set("damping", repr(float(value)))
    return ET.tostring(mjcf, encoding="unicode")


def swimmer_xml(directory: str, n_bodies: int) -> str:
    """dm_control's swimmer with n_bodies bodies (suite/swimmer.py's _make_model, with the
    standard library's ElementTree)."""
    if n_bodies < 3:
        raise ValueError(f"swimmer: at least 3 bodies required, got {n_bodies}")
    mjcf = ET.fromstring(open(os.path.join(directory, "swimmer.xml")).read())
    head_body = mjcf.find("./worldbody/body")
    actuator = ET.SubElement(mjcf, "actuator")
    sensor = ET.SubElement(mjcf, "sensor")
    parent = head_body
    for i in range(n_bodies - 1):
        child = ET.Element("body", name=f"segment_{i}")
        child.set("pos", "0 .1 0")
        ET.SubElement(child, "geom", {"class": "visual", "name": f"visual_{i}"})
        ET.SubElement(child, "geom", {"class": "inertial", "name": f"inertial_{i}"})
        child.append(ET.Element("site", name=f"site_{i}"))
        limit = 360.0 / n_bodies
        child.append(ET.Element("joint", {"name": f"joint_{i}", "range": f"{-limit} {limit}"}))
        actuator.append(ET.Element("motor", name=f"motor_{i}", joint=f"joint_{i}"))
        sensor.append(ET.Element("velocimeter", name=f"velocimeter_{i}", site=f"site_{i}"))
        sensor.append(ET.Element("gyro", name=f"gyro_{i}", site=f"site_{i}"))
        parent.append(child)
        parent = child
    return ET.tostring(mjcf, encoding="unicode")


def _vec(text, n=3):
    v = [float(x) for x in text.split()]
    return np.array(v + [0.0] * (n - len(v)))


_ROTATIONS = ("quat", "axisangle", "euler", "xyaxes", "zaxis")


class FileFrames:
    """Frames of an MJCF file at its own pose (qpos0), for files whose bodies and sites carry
    positions only: each body's origin and parent, each site's and named geom's body,
    position and size (class defaults and childclass applied to sizes), the sensors in order
    (type, name, attributes). Positions are 3D world coordinates [m]. A site or geom may be
    rotated in its body (`rotated` names those): its position is read, but a reading of its
    orientation is refused (Readout.sensor)."""

    def __init__(self, text: str, source: str):
        root = parse_xml(text, source)
        self.source = source
        self.body = collections.OrderedDict()       # name -> (parent name or None, pos)
        self.site, self.geom = {}, {}               # name -> (body or None, pos, size)
        self.site_type = {}                         # site name -> "sphere", "ellipsoid", ...
        self.rotated = set()                        # ("site" or "geom", name) rotated in its body
        self.sensors = []                           # (type, name, attrib)
        self._defaults = {}
        for node in root.children:
            if node.tag == "default":
                self._read_defaults(node, "main", {})
        for node in root.children:
            if node.tag == "worldbody":
                self._walk(node, None, np.zeros(3), "main")
            elif node.tag == "sensor":
                self.sensors += [(s.tag, s.attrib.get("name", ""), s.attrib) for s in node.children]

    def _read_defaults(self, node, name, inherited):
        own = {tag: dict(a) for tag, a in inherited.items()}
        for ch in node.children:
            if ch.tag != "default":
                own.setdefault(ch.tag, {}).update(ch.attrib)
        self._defaults[name] = own
        for ch in node.children:
            if ch.tag == "default":
                self._read_defaults(ch, ch.attrib.get("class", name), own)

    def _attr(self, node, cls, key, default):
        if key in node.attrib:
            return node.attrib[key]
        return self._defaults.get(node.attrib.get("class", cls), {}).get(node.tag, {}).get(key, default)

    def _walk(self, node, body, pos, cls):
        for ch in node.children:
            if ch.tag == "body":
                name = ch.attrib.get("name")
                rot = sorted(set(ch.attrib) & set(_ROTATIONS))
                if rot:
                    raise NotImplementedError(f"{self.source}:{ch.line}: body {name!r} is rotated "
                                              f"({rot}); planarsim's dm_control tasks read frames "
                                              f"of unrotated bodies only")
                p = pos + _vec(ch.attrib.get("pos", "0 0 0"))
                self.body[name] = (body, p)
                self._walk(ch, name, p, ch.attrib.get("childclass", cls))
            elif ch.tag in ("site", "geom") and "name" in ch.attrib:
                if "fromto" in ch.attrib:
                    ft = _vec(ch.attrib["fromto"], 6)
                    local = (ft[:3] + ft[3:]) / 2
                else:
                    local = _vec(ch.attrib.get("pos", "0 0 0"))
                size = _vec(self._attr(ch, cls, "size", "0.005" if ch.tag == "site" else "0"))
                table = self.site if ch.tag == "site" else self.geom
                table[ch.attrib["name"]] = (body, pos + local, size)
                # (a fromto turns the frame to its axis as a rotation does)
                if any(self._attr(ch, cls, k, None) is not None
                       for k in _ROTATIONS + ("fromto",)):
                    self.rotated.add((ch.tag, ch.attrib["name"]))
                if ch.tag == "site":
                    self.site_type[ch.attrib["name"]] = self._attr(ch, cls, "type", "sphere")

    def subtree(self, name) -> list:
        """MJCF bodies in body `name`'s subtree (itself first)."""
        out = [name]
        for b, (parent, _) in self.body.items():
            if parent in out:
                out.append(b)
        return out


# --- the domains: dm_control's Physics / Task methods on planarsim ----------------------

def randomize_limited_and_rotational_joints(env, random, qpos):
    """dm_control.suite.utils.randomizers' rule, joint by joint in file order: a limited
    hinge or slide uniform in its range, an unlimited hinge uniform in [-pi, pi]."""
    for i in range(len(env.coords.names)):
        lo, hi = env.joint_range[i]
        if env.joint_limited[i]:
            qpos[i] = random.uniform(lo, hi)
        elif env.joint_angular[i]:
            qpos[i] = random.uniform(-np.pi, np.pi)


def _init_randomized(env, random, qpos, qvel, params):
    randomize_limited_and_rotational_joints(env, random, qpos)


def _init_cheetah(env, random, qpos, qvel, params):
    limited = env.joint_limited
    lower, upper = env.joint_range[limited].T
    qpos[limited] = random.uniform(lower, upper)
    env.settle = 200                   # physics steps without control before the episode


def _init_acrobot(env, random, qpos, qvel, params):
    qpos[[env.qindex("shoulder"), env.qindex("elbow")]] = random.uniform(-np.pi, np.pi, 2)


def _init_cartpole(env, random, qpos, qvel, params):
    nv = len(qvel)
    if params["swing_up"]:
        qpos[env.qindex("slider")] = .01 * random.randn()
        qpos[env.qindex("hinge_1")] = np.pi + .01 * random.randn()
        qpos[2:] = .1 * random.randn(nv - 2)
    else:
        qpos[env.qindex("slider")] = random.uniform(-.1, .1)
        qpos[1:] = random.uniform(-.034, .034, nv - 1)
    qvel[:] = 0.01 * random.randn(nv)


def _init_pendulum(env, random, qpos, qvel, params):
    qpos[env.qindex("hinge")] = random.uniform(-np.pi, np.pi)


def _init_reacher(env, random, qpos, qvel, params):
    env.geom_size_override["target"] = params["target_size"]
    randomize_limited_and_rotational_joints(env, random, qpos)
    angle = random.uniform(0, 2 * np.pi)
    radius = random.uniform(.05, .20)
    env.set_target(radius * np.sin(angle), radius * np.cos(angle))


def _init_swimmer(env, random, qpos, qvel, params):
    randomize_limited_and_rotational_joints(env, random, qpos)
    close_target = random.rand() < .2
    target_box = .3 if close_target else 2
    xpos, ypos = random.uniform(-target_box, target_box, size=2)
    env.set_target(xpos, ypos)


def set_random_joint_angles(env, random, qpos, max_attempts=1000):
    """dm_control finger's _set_random_joint_angles: the randomizers' draws, again until no
    two colliding shapes overlap (MuJoCo: no contact after the reset). The test is planarsim's
    exact gap of its colliding shapes (start_check.shape_overlaps: capsules and discs, the
    file's geoms in the plane), so the start is never inside the spinner and the draws are
    dm_control's."""
    zero = np.zeros(len(qpos))
    for _ in range(max_attempts):
        randomize_limited_and_rotational_joints(env, random, qpos)
        q, _ = env.coords.to_maximal(qpos, zero)
        if not shape_overlaps(env.sim_model, q):
            return
    raise RuntimeError(f"{env.task}: no collision-free joint angles in {max_attempts} draws")


def _init_finger(env, random, qpos, qvel, params):
    if params["target_radius"] is not None:        # turn: a target on the spinner's circle
        angle = random.uniform(-np.pi, np.pi)
        hinge = env.xpos("spinner")
        radius = env.geom_size("cap1").sum()
        env.set_target(hinge[0] + radius * np.sin(angle), hinge[2] + radius * np.cos(angle))
        env.site_size_override["target"] = params["target_radius"]
    set_random_joint_angles(env, random, qpos)


def _qpos_all(env, r, first=0):
    return [r.qpos(i) for i in range(first, len(env.coords.names))]


def _qvel_all(env, r):
    return [r.qvel(i) for i in range(len(env.coords.names))]


def _plan_position_velocity(env, r, first=1):
    """physics.data.qpos[first:] and physics.velocity()."""
    r.obs("position", *_qpos_all(env, r, first))
    r.obs("velocity", *_qvel_all(env, r))


def _plan_cheetah(env, r):
    _plan_position_velocity(env, r)
    r.value("speed", r.sensor("torso_subtreelinvel", 0))


def _reward_cheetah(x, p, ctrl):
    return tolerance(x["speed"], bounds=(p["run_speed"], INF), margin=p["run_speed"],
                     value_at_margin=0, sigmoid="linear")


def _plan_walker(env, r):
    r.obs("orientations", *[r.xmat(b, 0, j) for b in env.frames.body for j in (0, 2)])
    r.obs("height", r.point(2, r.body_origin("torso")), scalar=True)
    r.obs("velocity", *_qvel_all(env, r))
    r.value("height", r.point(2, r.body_origin("torso")))
    r.value("upright", r.xmat("torso", 2, 2))
    r.value("speed", r.sensor("torso_subtreelinvel", 0))


def _reward_walker(x, p, ctrl):
    standing = tolerance(x["height"], bounds=(p["stand_height"], INF),
                         margin=p["stand_height"] / 2)
    upright = (1 + x["upright"]) / 2
    stand_reward = (3 * standing + upright) / 4
    if p["move_speed"] == 0:
        return stand_reward
    move_reward = tolerance(x["speed"], bounds=(p["move_speed"], INF),
                            margin=p["move_speed"] / 2, value_at_margin=0.5, sigmoid="linear")
    return stand_reward * (5 * move_reward + 1) / 6


def _plan_hopper(env, r):
    _plan_position_velocity(env, r)
    r.obs("touch", *[r.sensor(s, log1p=True) for s in ("touch_toe", "touch_heel")])
    r.value("height", r.point(2, r.body_com("torso"), r.body_com("foot")))
    r.value("speed", r.sensor("torso_subtreelinvel", 0))


def _small_control(ctrl):
    """dm_control's tolerance(control, margin=1, value_at_margin=0, sigmoid='quadratic')
    of each control."""
    return [tolerance(float(c), margin=1, value_at_margin=0, sigmoid="quadratic") for c in ctrl]


def _reward_hopper(x, p, ctrl):
    standing = tolerance(x["height"], (p["stand_height"], 2))
    if p["hop_speed"]:
        hopping = tolerance(x["speed"], bounds=(p["hop_speed"], INF), margin=p["hop_speed"] / 2,
                            value_at_margin=0.5, sigmoid="linear")
        return standing * hopping
    small_control = np.mean(_small_control(ctrl))
    return standing * (small_control + 4) / 5


def _plan_acrobot(env, r):
    arms = ("upper_arm", "lower_arm")
    r.obs("orientations", *([r.xmat(b, 0, 2) for b in arms] + [r.xmat(b, 2, 2) for b in arms]))
    r.obs("velocity", *_qvel_all(env, r))
    r.value("distance", r.dist(r.site("target"), r.site("tip")))
    r.value("radius", r.const(env.frames.site["target"][2][0]))


def _reward_acrobot(x, p, ctrl):
    return tolerance(x["distance"], bounds=(0, x["radius"]), margin=1)


def _poles(env):
    return list(env.frames.body)[1:]        # dm_control's xmat[2:]: the bodies after the cart


def _plan_cartpole(env, r):
    poles = _poles(env)
    r.obs("position", r.qpos("slider"), *[r.xmat(b, i, 2) for b in poles for i in (2, 0)])
    r.obs("velocity", *_qvel_all(env, r))
    for i, b in enumerate(poles):
        r.value(f"cos{i}", r.xmat(b, 2, 2))
    r.value("slider", r.qpos("slider"))
    for i in range(1, len(env.coords.names)):
        r.value(f"qvel{i}", r.qvel(i))


def _reward_cartpole(x, p, ctrl):
    cosines = [v for k, v in x.items() if k.startswith("cos")]
    upright = np.mean([(c + 1) / 2 for c in cosines])
    centered = (1 + tolerance(x["slider"], margin=2)) / 2
    small_control = (4 + _small_control(ctrl[:1])[0]) / 5
    small_velocity = (1 + min(tolerance(v, margin=5) for k, v in x.items()
                              if k.startswith("qvel"))) / 2
    return upright * small_control * small_velocity * centered


def _plan_pendulum(env, r):
    r.obs("orientation", r.xmat("pole", 2, 2), r.xmat("pole", 0, 2))
    r.obs("velocity", r.qvel("hinge"))
    r.value("cos", r.xmat("pole", 2, 2))


def _reward_pendulum(x, p, ctrl):
    return tolerance(x["cos"], (np.cos(np.deg2rad(p["angle_bound"])), 1))


def _plan_reacher(env, r):
    r.obs("position", *_qpos_all(env, r))
    r.obs("to_target", *[r.point(k, r.geom("target"), r.geom("finger")) for k in (0, 1)])
    r.obs("velocity", *_qvel_all(env, r))
    r.value("distance", r.dist(r.geom("target"), r.geom("finger")))
    r.value("radii", r.const(env.geom_size("target")[0] + env.geom_size("finger")[0]))


def _reward_reacher(x, p, ctrl):
    return tolerance(x["distance"], (0, x["radii"]))


def _plan_point_mass(env, r):
    _plan_position_velocity(env, r, first=0)
    r.value("distance", r.dist(r.geom("target"), r.geom("pointmass")))
    r.value("target_size", r.const(env.geom_size("target")[0]))


def _reward_point_mass(x, p, ctrl):
    size = x["target_size"]
    near_target = tolerance(x["distance"], bounds=(0, size), margin=size)
    small_control = (np.mean(_small_control(ctrl)) + 4) / 5
    return near_target * small_control


def _plan_swimmer(env, r):
    r.obs("joints", *_qpos_all(env, r, 3))
    r.obs("to_target", *[r.point(k, r.geom("target"), r.geom("nose"), frame="head")
                         for k in (0, 1)])
    vel = []              # dm_control: sensordata[12:], (vx, vy) of each velocimeter, wz of a gyro
    for kind, name, _ in env.frames.sensors:
        if kind == "velocimeter":
            vel += [r.sensor(name, 0), r.sensor(name, 1)]
        elif kind == "gyro":
            vel.append(r.sensor(name, 2))
    r.obs("body_velocities", *vel)
    r.value("distance", r.dist(r.geom("target"), r.geom("nose")))
    r.value("target_size", r.const(env.geom_size("target")[0]))


def _reward_swimmer(x, p, ctrl):
    size = x["target_size"]
    return tolerance(x["distance"], bounds=(0, size), margin=5 * size, sigmoid="long_tail")


def _plan_finger(env, r):
    tip, spinner, target = (r.sensor_point(s) for s in ("tip", "spinner", "target"))
    r.obs("position", r.sensor("proximal"), r.sensor("distal"),
          *[r.point(k, tip, spinner) for k in (0, 2)])
    r.obs("velocity", *[r.sensor(s) for s in ("proximal_velocity", "distal_velocity",
                                              "hinge_velocity")])
    r.obs("touch", *[r.sensor(s, log1p=True) for s in ("touchtop", "touchbottom")])
    turn = env.params["target_radius"] is not None
    to_target = r.dist(target, tip, minus=env.site_size("target")[0])
    if turn:
        r.obs("target_position", *[r.point(k, target, spinner) for k in (0, 2)])
        r.obs("dist_to_target", to_target, scalar=True)
    r.value("hinge_velocity", r.sensor("hinge_velocity"))
    r.value("dist_to_target", to_target)


def _reward_finger(x, p, ctrl):
    if p["target_radius"] is None:          # spin: the hinge turning fast enough [rad/s]
        return float(x["hinge_velocity"] <= -p["spin_velocity"])
    return float(x["dist_to_target"] <= 0)


@dataclass(frozen=True)
class Domain:
    """A suite domain: its file, MuJoCo timestep [s] (the file's; checked at load),
    _DEFAULT_TIME_LIMIT [s], _CONTROL_TIMESTEP [s] (None: the timestep), and its functions
    init(env, random, qpos, qvel, params); plan(env, readout): its observation entries and
    the values its reward reads, as readout.Readout ops; reward(values, params, control): the
    reward from those values (a dict by name) and the last action;
    defaults: the task parameters its module sets as constants; step_options: StepOptions
    fields the domain's simulator takes."""
    xml: str
    timestep: float
    time_limit: float
    control_timestep: float | None
    init: callable
    plan: callable
    reward: callable
    defaults: dict = field(default_factory=dict)
    step_options: dict = field(default_factory=dict)

    @property
    def n_sub_steps(self) -> int:
        """dm_control.rl.control.compute_n_steps."""
        if self.control_timestep is None:
            return 1
        n = self.control_timestep / self.timestep
        if self.control_timestep < self.timestep or abs(n - round(n)) > 1e-8:
            raise ValueError(f"{self.xml}: control timestep {self.control_timestep} is not a whole "
                             f"multiple of the physics timestep {self.timestep}")
        return int(round(n))

    @property
    def episode_steps(self) -> int:
        """Steps until dm_control's step count reaches time_limit / control step."""
        return int(math.ceil(self.time_limit / (self.timestep * self.n_sub_steps)))


DOMAINS = {
    "cheetah": Domain("cheetah.xml", 0.01, 10, None, _init_cheetah, _plan_cheetah,
                      _reward_cheetah, dict(run_speed=10)),
    "walker": Domain("walker.xml", 0.0025, 25, .025, _init_randomized, _plan_walker,
                     _reward_walker, dict(stand_height=1.2)),
    "hopper": Domain("hopper.xml", 0.005, 20, .02, _init_randomized, _plan_hopper, _reward_hopper,
                     dict(stand_height=0.6)),
    "acrobot": Domain("acrobot.xml", 0.01, 10, None, _init_acrobot, _plan_acrobot, _reward_acrobot),
    "cartpole": Domain("cartpole.xml", 0.01, 10, None, _init_cartpole, _plan_cartpole,
                       _reward_cartpole),
    "pendulum": Domain("pendulum.xml", 0.02, 20, None, _init_pendulum, _plan_pendulum,
                       _reward_pendulum, dict(angle_bound=8)),
    "reacher": Domain("reacher.xml", 0.02, 20, None, _init_reacher, _plan_reacher, _reward_reacher),
    "swimmer": Domain("swimmer.xml", 0.002, 30, .03, _init_swimmer, _plan_swimmer,
                      _reward_swimmer),
    # a mass on two limited, damped slides, each pulled by a motor on a fixed tendon
    "point_mass": Domain("point_mass.xml", 0.02, 20, None, _init_randomized, _plan_point_mass,
                         _reward_point_mass),
    # a two-link finger and a spinner on a hinge with dry friction, no gravity. The motors
    # alone (30 N m on 0.0068 kg m^2) would turn the proximal link 0.44 rad in a step from
    # rest; its damping (2.5 N m s/rad, implicit as in MuJoCo's Euler) holds that to 0.09 rad,
    # within the motor guard (StepOptions.turn_limit), which counts the damper
    "finger": Domain("finger.xml", 0.01, 20, .02, _init_finger, _plan_finger, _reward_finger,
                     dict(target_radius=None, spin_velocity=15.0)),
}

# task -> (domain, parameters): dm_control's task functions' arguments
TASKS = {
    "cheetah-run": ("cheetah", {}),
    "walker-stand": ("walker", dict(move_speed=0)),
    "walker-walk": ("walker", dict(move_speed=1)),
    "walker-run": ("walker", dict(move_speed=8)),
    "hopper-stand": ("hopper", dict(hop_speed=0)),
    "hopper-hop": ("hopper", dict(hop_speed=2)),
    "acrobot-swingup": ("acrobot", {}),
    "cartpole-balance": ("cartpole", dict(swing_up=False)),
    "cartpole-swingup": ("cartpole", dict(swing_up=True)),
    "pendulum-swingup": ("pendulum", {}),
    "reacher-easy": ("reacher", dict(target_size=.05)),
    "reacher-hard": ("reacher", dict(target_size=.015)),
    "swimmer-swimmer6": ("swimmer", dict(n_bodies=6)),
    "point_mass-easy": ("point_mass", {}),
    "finger-spin": ("finger", dict(joint_damping={"hinge": .03})),
    "finger-turn_easy": ("finger", dict(target_radius=.07)),
    "finger-turn_hard": ("finger", dict(target_radius=.03)),
}

# the suite's other planar tasks, and why planarsim cannot run them (none left)
UNSUPPORTED = {}


def env_id(task: str) -> str:
    return f"planarsim/dmc-{task}-v0"


# --- the environment -----------------------------------------------------------------------

# sensors of one value (the rest are 3D)
_SCALAR_SENSORS = ("touch", "jointpos", "jointvel")

class DMCEnv(PlanarMujocoEnv):
    """A DeepMind Control Suite task (a key of TASKS, e.g. "walker-walk") on planarsim.

    obs: the task's observation entries flattened in dm_control's order (float64, unbounded);
    action: one control per actuator in its ctrlrange (float64, as dm_control's action_spec);
    reward: dm_control's ``get_reward`` of the state after the step; never terminates (the
    registered ids truncate at dm_control's time limit). reset(seed=s) draws the initial
    state as dm_control's task does from numpy.random.RandomState(s). ``env.params`` (the
    task's parameters: stand_height, move_speed, ...) are read by the reward at each reset.

    ``suite_dir``: where the suite's files are (default: the installed dm_control's);
    remaining keywords go to PlanarMujocoEnv (render_mode, width, height, load_mjcf's).
    """

    def __init__(self, task: str, suite_dir: str | None = None, **kw):
        if task in UNSUPPORTED:
            raise NotImplementedError(f"dm_control task {task!r} cannot run on planarsim: "
                                      f"{UNSUPPORTED[task]}")
        if task not in TASKS:
            raise ValueError(f"unknown dm_control task {task!r}; planarsim runs {sorted(TASKS)}")
        self.task = task
        domain_name, params = TASKS[task]
        self.domain = DOMAINS[domain_name]
        self.domain_name = domain_name
        self.params = {**self.domain.defaults, **params}
        directory = suite_dir or find_suite_dir()
        if domain_name == "swimmer":
            text = swimmer_xml(directory, self.params["n_bodies"])
            source = f"swimmer({self.params['n_bodies']})"
        else:
            source = os.path.join(directory, self.domain.xml)
            text = open(source).read()
        if self.params.get("joint_damping"):
            text = with_joint_damping(text, self.params["joint_damping"])
        self.frames = FileFrames(text, source)
        kw.setdefault("assets", common_assets(directory))
        PlanarMujocoEnv.__init__(self, text, self.domain.n_sub_steps, **kw)
        if abs(self.timestep - self.domain.timestep) > 1e-12:
            raise ValueError(f"{source}: the file's timestep is {self.timestep} s, planarsim's "
                             f"table of dm_control domains says {self.domain.timestep} s")
        if self.domain.step_options:
            self.sim.options = self.sim.options._replace(**self.domain.step_options)
        self.metadata = {"render_modes": ["rgb_array"], "render_fps": int(round(1.0 / self.dt))}
        self.action_space = spaces.Box(low=self._act_lo.copy(), high=self._act_hi.copy(),
                                       dtype=np.float64)
        self._setup_geometry()
        self._random = None
        self.settle = 0
        self._ctrl = np.zeros(len(self._act))
        self._q0 = np.array(self.sim_model.q0, float).reshape(-1, 3)     # (our own: writeable)
        self._readout = self._plan_key = None
        self._reset_state(np.random.RandomState(0))
        n = self._get_obs().size
        self.observation_space = spaces.Box(-np.inf, np.inf, (n,), np.float64)

    # the model's data as dm_control reads it --------------------------------------------
    @property
    def qpos(self):
        """MuJoCo's qpos of the current state."""
        return self.data.qpos

    @property
    def qvel(self):
        """MuJoCo's qvel of the current state."""
        return self.data.qvel

    def _setup_geometry(self):
        loaded, model = self.loaded, self.sim_model
        self.plane_axes = (0, 2) if loaded.plane == "x-z" else (0, 1)
        self.normal_axis = 1 if loaded.plane == "x-z" else 2
        # the plane's counter-clockwise rotation axis in 3D: -y for x-z, +z for x-y
        self.ccw_sign = -1.0 if loaded.plane == "x-z" else 1.0
        self.qindex = {n: i for i, n in enumerate(self.coords.names)}.__getitem__
        rng = []
        for jm in self.coords.jm:
            lim = model.arrays.pin_limit[jm.coordinate]
            rng.append(sorted(jm.ref + jm.sign * x for x in lim))
        self.joint_range = np.array(rng, float)
        self.joint_limited = np.isfinite(self.joint_range).all(axis=1)
        self.joint_angular = np.array([jm.angular for jm in self.coords.jm])
        self.geom_size_override, self.site_size_override = {}, {}
        self.target = None
        self._mass = np.asarray(model.arrays.body_mass, float)
        # the sensors by name, and what each reads that the file fixes (looked up once, not at
        # every step): a subtree's bodies and masses, a site's body and point
        self._sensors = {}
        for kind, name, attrib in self.frames.sensors:
            fixed = None
            if kind == "subtreelinvel":
                ids = sorted({self.loaded.body[b] for b in self.frames.subtree(attrib["body"])
                              if b in self.loaded.body})
                fixed = (ids, self._mass[ids], self._mass[ids].sum())
            elif kind in ("velocimeter", "gyro"):
                fixed = self.frames.site[attrib["site"]][:2]
            self._sensors[name] = (kind, attrib, fixed)

    def _rigid(self, body):
        if body not in self.loaded.body:
            raise KeyError(f"{self.task}: MJCF body {body!r} does not move (welded to the world) "
                           f"or is not in the file; moving bodies: {sorted(self.loaded.body)}")
        return self.loaded.body[body]

    def _to3(self, p2, file_point):
        out = np.array(file_point, float).copy()
        out[self.plane_axes[0]], out[self.plane_axes[1]] = p2
        return out

    def pos3(self, body, file_point):
        """World 3D position of a point fixed in MJCF body `body` (None: the world), given at
        the file's pose (its out-of-plane coordinate stays the file's)."""
        if body is None:
            return np.array(file_point, float)
        a, b = self.plane_axes
        return self._to3(self.point(body, (file_point[a], file_point[b])), file_point)

    def xpos(self, body):
        """MuJoCo's xpos: the body frame's origin."""
        return self.pos3(body, self.frames.body[body][1])

    def xipos(self, body):
        """MuJoCo's xipos: the body's own centre of mass."""
        com = self.loaded.com[body]
        p = self.frames.body[body][1].copy()
        p[self.plane_axes[0]], p[self.plane_axes[1]] = com
        return self.pos3(body, p)

    def angle(self, body):
        """The body's rotation from the file's pose, counter-clockwise in the plane [rad]."""
        b = self._rigid(body)
        return float(self.sim.state.q[b, 2] - self.sim_model.q0[b, 2])

    def xmat(self, body):
        """MuJoCo's xmat (3x3) of a body (its frame unrotated in the file)."""
        phi = self.ccw_sign * self.angle(body)
        c, s = math.cos(phi), math.sin(phi)
        if self.normal_axis == 1:        # rotation about +y by phi
            return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
        return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])

    def _xpos(self, table, name):
        """World position (3,) [m] of site or geom `name` of `table` (frames.site or
        frames.geom); the world's 'target' where the task moved it (set_target)."""
        body, p, _ = table[name]
        if body is None and self.target is not None and name == "target":
            p = self.target
        return self.pos3(body, p)

    @staticmethod
    def _size(table, override, name):
        """The size of site or geom `name` of `table`, its first entry as the task set it."""
        size = table[name][2].copy()
        if name in override:
            size[0] = override[name]
        return size

    def site_xpos(self, name):
        return self._xpos(self.frames.site, name)

    def site_size(self, name):
        return self._size(self.frames.site, self.site_size_override, name)

    def geom_xpos(self, name):
        return self._xpos(self.frames.geom, name)

    def geom_size(self, name):
        return self._size(self.frames.geom, self.geom_size_override, name)

    def set_target(self, x, y):
        """Move the world's 'target' (reacher's and swimmer's geom, finger's site) to (x, y)
        [m] in the model's plane, as dm_control's tasks set model.geom_pos / site_pos."""
        table = self.frames.geom if "target" in self.frames.geom else self.frames.site
        p = table["target"][1].copy()
        p[self.plane_axes[0]], p[self.plane_axes[1]] = x, y
        self.target = p
        self._readout = None              # (the readings' table holds the target's place)

    def set_control(self, action):
        """Set the control the reward reads (dm_control's physics.set_control), without
        stepping."""
        self._ctrl[:] = np.array(action, dtype=np.float64).reshape(len(self._act))

    def control(self):
        """dm_control's physics.control(): the last action as given (before the clamp)."""
        return self._ctrl.copy()

    def sensor(self, name):
        """A sensor of the file's <sensor> section, by name, as MuJoCo's sensordata gives it:
        subtreelinvel, velocimeter, gyro, framepos and frame x / y / z axis of a site, geom or
        body (3D), jointpos, jointvel, touch (a float). Read by the readings' own operations
        (readout.Readout)."""
        found = self._sensors.get(name)
        if found is None:
            raise KeyError(f"{self.task}: no sensor {name!r} in the file; it has "
                           f"{[s[1] for s in self.frames.sensors]}")
        r = Readout(self)
        scalar = found[0] in _SCALAR_SENSORS
        for axis in [None] if scalar else range(3):
            r.value(str(axis), r.sensor(name, axis))
        values = self._evaluate(r)
        return float(values[0]) if scalar else values

    def _evaluate(self, r):
        """The values of Readout r's table on the current state (one compiled call)."""
        st, ws, a = self.sim.state, self.sim.ws, self.sim_model.arrays
        out = np.zeros(r.n_obs + len(r.value_names))
        read(st.q, st.v, self._q0, self.data.qpos, self.data.qvel, self._ctrl,
             st.last_contact_impulse, a.contact_kind, a.contact_body, a.contact_local,
             a.contact_radius, ws.contact_bodies, ws.contact_refpt, *r.tables(), out)
        return out

    # the readings: observation and reward, one compiled call ------------------------------
    def _plan(self):
        """The task's readings as a table (readout.Readout), written at a reset or when the
        target moves, with the compiled reward's parameters (dmc_rewards.reward_params): the
        environment's arrays for dmc_observe (dmc_step.DMCArrays), bound at the next read."""
        # what a plan reads that a reset or set_target may change: the same as the last
        # plan's, the last table stands (most tasks draw no target: a reset writes nothing)
        key = (None if self.target is None else tuple(self.target.tolist()),
               sorted(self.geom_size_override.items()), sorted(self.site_size_override.items()))
        # the bound arrays stand while they are still this env's own (a batched vector env
        # gives each copy's commands a row of its array: envs/batched.py) and the reward's
        # parameters (self.params, read at each plan) fit them
        bound = getattr(self, "_arrays", None)
        if bound is not None and bound.u is not self._u:
            bound = None
        if key == self._plan_key and bound is not None:
            self._readout = self._planned
            if self._reward_params_into(bound, self._planned):
                return
        r = Readout(self)
        self.domain.plan(self, r)
        tables = r.tables()
        old = getattr(self, "_tables", None)
        self._plan_key, self._planned = key, r
        self._readout = r
        self._n_obs = r.n_obs
        if (bound is not None and old is not None
                and all(a.shape == b.shape for a, b in zip(old, tables))
                and self._reward_params_into(bound, r)):
            # the same table with new numbers (a target drawn, a size set): written into the
            # arrays the compiled call is bound to, which stays bound (binding it again, numba
            # typing its arguments, was most of a reset's time)
            for a, b in zip(old, tables):
                a[...] = b
            return
        self._tables = tables
        self._values = np.zeros(r.n_obs + len(r.value_names))
        self._obs_values = self._values[:r.n_obs]
        code, p, room = reward_params(self.domain_name, self.params, r.value_names,
                                      len(self._act))
        c, d = self.coords, self.data
        self._arrays = DMCArrays(
            self._q0, d.qpos, d.qvel, np.full((self.sim_model.n_body, 3), np.nan), c.pins,
            c.sign, c.ref, self._ctrl, self._act_lo, self._act_hi, self._drive_entry,
            self._drive_id, self._drive_gain, self._u, *tables, self._values, p,
            np.zeros(room), r.n_obs, code)
        self._table = TableHandle(self._arrays) if TABLES else self._arrays
        self._observe_call = self._step_call = self._observe_type = None

    def _reward_params_into(self, bound, readout) -> bool:
        """The compiled reward's parameters from self.params as they are now, written into
        the bound DMCArrays `bound`; False (nothing written) where they no longer fit it."""
        code, p, room = reward_params(self.domain_name, self.params, readout.value_names,
                                      len(self._act))
        if (code != bound.reward_code or p.shape != bound.reward_p.shape
                or room > bound.scratch.shape[0]):
            return False
        bound.reward_p[...] = p
        return True

    def _sim_table(self):
        """The simulator's StepArgs as compiled code takes it (its handle where TABLES)."""
        return self.sim._args if TABLES else self.sim._args.obj

    def _observe(self) -> float:
        """qpos, qvel, the readings (the observation's entries, then the reward's values, in
        self._values) and the reward of the current state: one compiled call
        (dmc_step.dmc_observe); returns the reward."""
        if self._readout is None:
            self._plan()
        sim = self._sim_table()
        call = self._observe_call
        if call is None or (MODE == FAST and sim.numba_type is not self._observe_type):
            call = self._observe_call = bind(dmc_observe, (sim, self._table))
            if MODE == FAST:      # and the whole env step (elsewhere Simulator.steps, then this)
                self._observe_type = sim.numba_type
                self._step_call = bind(dmc_step, (sim, self._table, self._ctrl, 1))
        return call(sim, self._table)

    def _read(self) -> np.ndarray:
        """The readings of the current state: the observation's entries, then the reward's
        values (one compiled call, with the reward: _observe)."""
        self._observe()
        return self._values

    def _reward_of(self, values) -> float:
        """The reward of the readings `values` and the last control, in Python (the domain's
        reward function: the compiled one's check)."""
        named = dict(zip(self._readout.value_names, values[self._n_obs:].tolist()))
        return float(self.domain.reward(named, self.params, self._ctrl))

    # gymnasium -----------------------------------------------------------------------------
    def observation(self) -> collections.OrderedDict:
        """The task's observation entries (dm_control's get_observation), by name."""
        values = self._read()
        return collections.OrderedDict(self._readout.entries(values))

    def _get_obs(self):
        return self._read()[:self._n_obs].copy()

    def reward(self) -> float:
        """dm_control's get_reward of the current state (and last control)."""
        return self._observe()

    def _reset_state(self, random):
        qpos, qvel = self.init_qpos.copy(), np.zeros(self.model.nv)
        self.settle = 0
        self.geom_size_override, self.site_size_override = {}, {}
        self.domain.init(self, random, qpos, qvel, self.params)
        self._ctrl[:] = 0.0
        self._readout = None              # (the target and sizes the init drew)
        self.set_state(qpos, qvel)
        if self.settle:
            self.sim.steps(self.settle, np.zeros(self.sim_model.n_act))
            self._sync()

    def reset_model(self):
        if self._random is None:
            self._random = np.random.RandomState(int(self.np_random.integers(2 ** 31)))
        self._reset_state(self._random)
        return self._get_obs()

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        if seed is not None:
            self._random = np.random.RandomState(seed)
        return super().reset(seed=seed, options=options)

    def step(self, action):
        a = np.asarray(action, dtype=np.float64)
        call, n = self._step_call, self.frame_skip
        if (call is not None and self._readout is not None and self._advanced is None
                and a.ndim == 1 and a.flags.c_contiguous and type(n) is int and 0 <= n <= MAX_STEPS
                and self.sim._args.numba_type is self._observe_type
                and self._arrays.u is self._u):
            # the fast compile mode: one compiled call (dmc_step.dmc_step)
            code, done, reward = call(self.sim._args, self._table, a, n)
            if code:
                reward = self._finish_step(a, n, code, done)
        else:
            self._advance(a, n)                    # (raises for an action of the wrong shape
            self._ctrl[:] = a                      # or with a NaN: the control stays)
            reward = self._observe()
        return self._obs_values.copy(), reward, False, False, {}

    def _finish_step(self, a, n, code, done):
        """The rest of a dmc_step that stopped with `code` after `done` physics steps: an
        action refused raises naming what is wrong; a step out of solve storage (GUARD_ROOM)
        grows it and the steps go on as Simulator.steps takes them; any other code raises
        SimulationDiverged. Returns the reward."""
        if code == ACTION_REFUSED:
            self.check_action(a)                   # (raises)
            raise AssertionError(f"dmc_step refused action {a.tolist()}")
        if code != GUARD_ROOM:
            self.sim._raise(code)
        self.sim._grow()
        self.sim._run_steps(self._u, n - done)
        self._ctrl[:] = a
        return self._observe()
