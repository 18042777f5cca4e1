"""The base of planarsim's gymnasium environments: an MJCF model loaded by planarsim.mjcf,
stepped by planarsim, seen through MuJoCo's generalized coordinates (qpos, qvel).

Coordinates. planarsim keeps every rigid body's pose (x, y, angle) and velocity; MuJoCo keeps
joint values in file order. ``GeneralizedCoords`` maps between them through the loader's
JointMap: a hinge's MJCF value is ``ref + sign * (pin angle)`` (sign = -1 for a hinge about
+y in the x-z plane: MuJoCo's positive rotation about +y is clockwise in planarsim's plane),
a slide's ``ref + displacement along its axis``; a free root (two slides then a hinge, as
MuJoCo composes them) translates its hinge's anchor by the slides and turns about it; a root
with two slides and no hinge (reacher's target) only translates. Every MJCF joint is an entry
of the pin table (a free root's are free coordinates), so after each step (qpos, qvel) come
from that table in compiled code (``joint_values``); ``to_maximal`` (a reset's set_state) and
``from_maximal`` are the same map in Python, inverse and forward.
"""
from __future__ import annotations

import math
import os
from collections import namedtuple
from types import SimpleNamespace

import warnings

import numpy as np
import gymnasium
from gymnasium import spaces

from ..compiled import jit
from ..kernels.constraints.joints import joint_position_rate
from ..kernels.math2d import update_trig
from ..link.step import bind
from ..mjcf import load_mjcf
from ..model import JOINT_SLIDE_BIT
from ..sim import Simulator
from ..state import make_state


def gym_asset(name: str) -> str:
    """Path of gymnasium's MJCF file `name` (gymnasium ships them without mujoco)."""
    return os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets", name)


# the pin table's columns joint_values reads: handing numba these five arrays instead of the
# model's whole table (a hundred arrays, each typed at every call) makes the call about 10x
# cheaper, which an environment pays at every step
JointTable = namedtuple("JointTable", "pin_kind pin_body pin_axis pin_anchor pin_ref")


def _rot(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s], [s, c]])


def _cross(w, r):
    """omega x r in the plane."""
    return np.array([-w * r[1], w * r[0]])


@jit
def joint_values(m, q, v, cs, pins, sign, ref, qpos, qvel):
    """MuJoCo's qpos, qvel from planarsim's q, v (n_body, 3): every MJCF joint i is joint
    pins[i] of the pin table (a free root's slides and hinge are free coordinates), its value
    ref[i] + sign[i] * coordinate and its rate sign[i] * rate (cs: an (n_body, 3) buffer of
    the angles' cos / sin)."""
    update_trig(q, cs)
    for i in range(pins.shape[0]):
        x, rate = joint_position_rate(m, q, cs, v, pins[i])
        qpos[i] = ref[i] + sign[i] * x
        qvel[i] = sign[i] * rate


@jit
def set_commands(ctrl, lo, hi, entry, act_id, gain, u):
    """Each drive e (a planarsim actuator of action entry[e]): u[act_id[e]] = gain[e] * c,
    c = ctrl[entry[e]] clamped to [lo, hi] of that entry; False (u untouched) if an entry of
    ctrl is not finite."""
    for k in range(ctrl.shape[0]):
        if not math.isfinite(ctrl[k]):
            return False
    for e in range(act_id.shape[0]):
        k = entry[e]
        u[act_id[e]] = gain[e] * min(max(ctrl[k], lo[k]), hi[k])
    return True


@jit
def place_links(order, ref, sign, pin_body, pin_anchor, pin_ref, pin_kind, pin_axis, qpos, qvel,
                q, v):
    """q, v of each joint's body b from its body a (placed before it in `order`: rows of (MJCF
    joint index, pin index)) and the joint's qpos, qvel (a hinge: angle ref + sign x, a slide
    along the pin's axis turning with body a)."""
    for k in range(order.shape[0]):
        i = order[k, 0]
        j = order[k, 1]
        a = pin_body[j, 0]
        b = pin_body[j, 1]
        xa = q[a, 0] if a >= 0 else 0.0
        ya = q[a, 1] if a >= 0 else 0.0
        ta = q[a, 2] if a >= 0 else 0.0
        vxa = v[a, 0] if a >= 0 else 0.0
        vya = v[a, 1] if a >= 0 else 0.0
        wa = v[a, 2] if a >= 0 else 0.0
        c, s = math.cos(ta), math.sin(ta)
        px = xa + c * pin_anchor[j, 0, 0] - s * pin_anchor[j, 0, 1]
        py = ya + s * pin_anchor[j, 0, 0] + c * pin_anchor[j, 0, 1]
        vpx = vxa - wa * (py - ya)
        vpy = vya + wa * (px - xa)
        if pin_kind[j] & JOINT_SLIDE_BIT:
            th = ta + pin_ref[j]
            dx = c * pin_axis[j, 0] - s * pin_axis[j, 1]
            dy = s * pin_axis[j, 0] + c * pin_axis[j, 1]
            d = qpos[i] - ref[i]
            vpx += -wa * dy * d + dx * qvel[i]
            vpy += wa * dx * d + dy * qvel[i]
            px += dx * d
            py += dy * d
            w = wa
        else:
            th = ta + pin_ref[j] + sign[i] * (qpos[i] - ref[i])
            w = wa + sign[i] * qvel[i]
        cb, sb = math.cos(th), math.sin(th)
        cx = px - (cb * pin_anchor[j, 1, 0] - sb * pin_anchor[j, 1, 1])
        cy = py - (sb * pin_anchor[j, 1, 0] + cb * pin_anchor[j, 1, 1])
        q[b, 0] = cx
        q[b, 1] = cy
        q[b, 2] = th
        v[b, 0] = vpx - w * (cy - py)
        v[b, 1] = vpy + w * (cx - px)
        v[b, 2] = w


class GeneralizedCoords:
    """MuJoCo's (qpos, qvel) <-> planarsim's maximal (q, v) (n_body, 3) for a loaded model."""

    def __init__(self, loaded, model):
        self.names = list(loaded.joint)
        self.jm = [loaded.joint[n] for n in self.names]
        self.nq = len(self.names)
        self.n_body = model.n_body
        self.q0 = np.array(model.q0, float).reshape(-1, 3)
        a = model.arrays
        self.pin_body, self.pin_anchor = np.asarray(a.pin_body), np.asarray(a.pin_anchor)
        self.pin_ref, self.pin_kind = np.asarray(a.pin_ref), np.asarray(a.pin_kind)
        self.pin_axis = np.asarray(a.pin_axis)
        # free roots: body -> (slide indices, hinge index)
        self.free = {}
        for i, jm in enumerate(self.jm):
            if jm.kind == "free":
                slides, hinge = self.free.setdefault(jm.id, ([], [None]))
                if jm.axis == (2,):
                    hinge[0] = i
                else:
                    slides.append(i)
        self.links = [i for i, jm in enumerate(self.jm) if jm.kind != "free"]
        # the compiled map (joint_values): each joint's pin, sign and ref
        self.pins = np.array([jm.coordinate for jm in self.jm], np.int64)
        self.sign = np.array([jm.sign for jm in self.jm], float)
        self.ref = np.array([jm.ref for jm in self.jm], float)
        self._cs = np.full((self.n_body, 3), np.nan)
        a = model.arrays
        self._arrays = JointTable(a.pin_kind, a.pin_body, a.pin_axis, a.pin_anchor, a.pin_ref)

    def values(self, q, v, qpos=None, qvel=None):
        """The same as from_maximal, compiled (into qpos, qvel if given)."""
        qpos = np.empty(self.nq) if qpos is None else qpos
        qvel = np.empty(self.nq) if qvel is None else qvel
        joint_values(self._arrays, q, v, self._cs, self.pins, self.sign, self.ref, qpos, qvel)
        return qpos, qvel

    def values_into(self, q, v, qpos, qvel):
        """A callable of no arguments that writes values(q, v) into qpos, qvel: the compiled
        map bound once to these arrays (no type dispatch per call where the compile mode
        allows it; for arrays that stay the same objects, as a simulator's state does)."""
        args = (self._arrays, q, v, self._cs, self.pins, self.sign, self.ref, qpos, qvel)
        entry = bind(joint_values, args)
        return lambda: entry(*args)

    def _free_parts(self, body):
        """(slide indices, hinge index or None, (2, 2) slide axes as columns, anchor at the
        file's pose) of a free root."""
        slides, (h,) = self.free[body]
        A = np.array([self.jm[i].axis for i in slides], float).T
        return slides, h, A, np.array(self.jm[slides[0]].anchor, float)

    def _link_order(self):
        """The non-free joints (their indices) in an order in which each one's body a is
        placed before it (the world, a free root or an earlier joint's body b), made once."""
        order = getattr(self, "_order", None)
        if order is not None:
            return order
        placed = set(self.free) | {-1}
        pending, order = list(self.links), []
        while pending:
            ready = [i for i in pending if self.pin_body[self.jm[i].id][0] in placed]
            if not ready:
                raise RuntimeError(f"joints {[self.names[i] for i in pending]} hang from no body")
            for i in ready:
                order.append(i)
                placed.add(int(self.pin_body[self.jm[i].id][1]))
                pending.remove(i)
        self._order = np.array([(i, self.jm[i].id) for i in order], np.int64).reshape(-1, 2)
        self._link_ref = np.array([jm.ref for jm in self.jm], float)
        self._link_sign = np.array([jm.sign for jm in self.jm], float)
        return self._order

    def to_maximal(self, qpos, qvel):
        """(nq,), (nv,) MuJoCo values -> q, v (n_body, 3)."""
        qpos, qvel = np.asarray(qpos, float), np.asarray(qvel, float)
        q = np.full((self.n_body, 3), np.nan)
        v = np.full((self.n_body, 3), np.nan)
        for body in self.free:
            slides, h, A, A0 = self._free_parts(body)
            d = A @ np.array([qpos[i] - self.jm[i].ref for i in slides])
            phi = 0.0 if h is None else self.jm[h].sign * (qpos[h] - self.jm[h].ref)
            anchor = A0 + d
            c = anchor + _rot(phi) @ (self.q0[body, :2] - A0)
            w = 0.0 if h is None else self.jm[h].sign * qvel[h]
            q[body] = (c[0], c[1], self.q0[body, 2] + phi)
            v[body, :2] = A @ np.array([qvel[i] for i in slides]) + _cross(w, c - anchor)
            v[body, 2] = w
        order = self._link_order()
        place_links(order, self._link_ref, self._link_sign, self.pin_body, self.pin_anchor,
                    self.pin_ref, self.pin_kind, self.pin_axis, qpos, qvel, q, v)
        return q, v

    def from_maximal(self, q, v):
        """q, v (n_body, 3) -> MuJoCo's (qpos, qvel) (nq,), (nv,)."""
        q, v = np.asarray(q, float), np.asarray(v, float)
        qpos, qvel = np.zeros(self.nq), np.zeros(self.nq)
        for body in self.free:
            slides, h, A, A0 = self._free_parts(body)
            phi = q[body, 2] - self.q0[body, 2]
            anchor = q[body, :2] - _rot(phi) @ (self.q0[body, :2] - A0)
            d = np.linalg.solve(A, anchor - A0)
            vA = v[body, :2] - _cross(v[body, 2], q[body, :2] - anchor)
            ds = np.linalg.solve(A, vA)
            for k, i in enumerate(slides):
                qpos[i] = self.jm[i].ref + d[k]
                qvel[i] = ds[k]
            if h is not None:
                qpos[h] = self.jm[h].ref + self.jm[h].sign * phi
                qvel[h] = self.jm[h].sign * v[body, 2]
        for i in self.links:
            jm = self.jm[i]
            a, b = self.pin_body[jm.id]
            qa = q[a] if a >= 0 else np.zeros(3)
            va = v[a] if a >= 0 else np.zeros(3)
            if self.pin_kind[jm.id] & JOINT_SLIDE_BIT:
                la, lb = self.pin_anchor[jm.id]
                Ra = _rot(qa[2])
                Pa = qa[:2] + Ra @ la
                Pb = q[b, :2] + _rot(q[b, 2]) @ lb
                dw = Ra @ self.pin_axis[jm.id]
                vPa = va[:2] + _cross(va[2], Pa - qa[:2])
                vPb = v[b, :2] + _cross(v[b, 2], Pb - q[b, :2])
                qpos[i] = jm.ref + dw @ (Pb - Pa)
                qvel[i] = dw @ (vPb - vPa)
            else:
                qpos[i] = jm.ref + jm.sign * (q[b, 2] - qa[2] - self.pin_ref[jm.id])
                qvel[i] = jm.sign * (v[b, 2] - va[2])
        return qpos, qvel


# keywords an environment passes on to planarsim.mjcf.load_mjcf (and its ModelBuilder)
LOAD_KEYWORDS = frozenset({"offset", "collide", "drop", "dt", "gravity", "terrain", "ground",
                           "assets"})


class PlanarMujocoEnv(gymnasium.Env):
    """A gymnasium Env with MuJoCo's MujocoEnv interface (data.qpos / data.qvel, init_qpos,
    init_qvel, set_state, do_simulation, state_vector, dt = timestep * frame_skip) on planarsim.

    Differences from gymnasium's MuJoCo environments: contacts are planarsim's exact hard
    (complementarity) contacts with Coulomb friction, not MuJoCo's soft, slightly penetrating
    ones; only the collisions planarsim.mjcf loads are modelled (see its LoadReport, e.g. no
    self-collision beyond it); the integrator is planarsim's (semi-implicit, one velocity
    solve per step), not MuJoCo's; joint springs and dampers are implicit. Episodes therefore
    differ from MuJoCo's beyond the first contacts; observations use MuJoCo's layout exactly.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 30}

    def __init__(self, xml_file: str, frame_skip: int, observation_space=None,
                 render_mode: str | None = None, width: int = 480, height: int = 480, **load_kw):
        if isinstance(frame_skip, bool) or int(frame_skip) != frame_skip or frame_skip < 1:
            raise ValueError(f"{type(self).__name__}: frame_skip={frame_skip!r} must be a whole "
                             "number of physics steps per env step, at least 1")
        for key, size in (("width", width), ("height", height)):
            if isinstance(size, bool) or int(size) != size or size < 16:
                raise ValueError(f"{type(self).__name__}: {key}={size!r} must be a whole "
                                 "number of pixels, at least 16")
        unknown = sorted(set(load_kw) - LOAD_KEYWORDS)
        if unknown:
            raise TypeError(f"{type(self).__name__}: unknown keyword(s) {unknown}; it takes its "
                            f"task's own (gymnasium's v5 names), render_mode, width, height and "
                            f"the model loader's {sorted(LOAD_KEYWORDS)}")
        # an absolute path, the XML text itself, or the name of one of gymnasium's files
        path = (xml_file if os.path.isabs(xml_file) or xml_file.lstrip().startswith("<")
                else gym_asset(xml_file))
        self.loaded = load_mjcf(path, **load_kw)
        self.sim_model = self.loaded.compile()
        self.coords = GeneralizedCoords(self.loaded, self.sim_model)
        self.frame_skip = int(frame_skip)
        self.timestep = float(self.sim_model.arrays.dt)
        self._act = list(self.loaded.actuator.values())
        self.model = SimpleNamespace(nq=self.coords.nq, nv=self.coords.nq, nu=len(self._act))
        low = np.array([a.ctrlrange[0] for a in self._act], dtype=np.float32)
        high = np.array([a.ctrlrange[1] for a in self._act], dtype=np.float32)
        self.action_space = spaces.Box(low=low, high=high, dtype=np.float32)
        if observation_space is not None:
            self.observation_space = observation_space
        self.init_qpos, self.init_qvel = self.coords.from_maximal(self.sim_model.q0, self.sim_model.v0)
        self.data = SimpleNamespace(qpos=self.init_qpos.copy(), qvel=self.init_qvel.copy())
        self._u = np.zeros(self.sim_model.n_act)
        # the drives: each planarsim actuator, its action entry and its gain gear * coef
        self._drive_entry = np.array([k for k, a in enumerate(self._act) for _ in a.ids], np.int64)
        self._drive_id = np.array([i for a in self._act for i in a.ids], np.int64)
        self._drive_gain = np.array([g for a in self._act for g in a.gains], float)
        self._act_lo = np.array([a.ctrlrange[0] for a in self._act], float)
        self._act_hi = np.array([a.ctrlrange[1] for a in self._act], float)
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode={render_mode!r}: planarsim's environments render "
                             f"{self.metadata['render_modes']} only")
        self.render_mode = render_mode
        self.width, self.height = int(width), int(height)
        with warnings.catch_warnings():
            # a file may build a joint outside its limit (dm_control's hopper): every reset
            # puts a state of the task's in first
            warnings.filterwarnings("ignore", message=".*outside its limit")
            self.sim = Simulator(self.sim_model, None, make_state(self.sim_model))
        # the speed bound (StepOptions.speed_limit) is set once, from the file's pose at rest,
        # so that a reset only copies a state in (Simulator.start_over: microseconds)
        self.sim.options = self.sim.options

    @property
    def dt(self) -> float:
        return self.timestep * self.frame_skip

    # MuJoCo's MujocoEnv interface -------------------------------------------------------
    #: (state, callable): data.qpos, data.qvel written from that state (values_into)
    _sync_bound = (None, None)

    def _sync(self):
        """data.qpos and data.qvel from the simulator's state, written in place (as MuJoCo's
        MjData fields are) by one compiled call bound to the state's arrays."""
        st = self.sim.state
        bound, call = self._sync_bound
        if bound is not st:
            d = self.data
            d.qpos, d.qvel = np.array(d.qpos, float), np.array(d.qvel, float)   # arrays of our own
            call = self.coords.values_into(st.q, st.v, d.qpos, d.qvel)
            self._sync_bound = (st, call)
        call()

    def set_state(self, qpos, qvel):
        qpos, qvel = np.asarray(qpos, float), np.asarray(qvel, float)
        if qpos.shape != (self.model.nq,) or qvel.shape != (self.model.nv,):
            raise ValueError(f"set_state: qpos shape {qpos.shape} and qvel shape {qvel.shape} "
                             f"must be ({self.model.nq},) and ({self.model.nv},)")
        for name, x in (("qpos", qpos), ("qvel", qvel)):
            bad = np.flatnonzero(~np.isfinite(x))
            if bad.size:
                raise ValueError(f"set_state: {name}[{int(bad[0])}] = {x[bad[0]]} is not finite "
                                 f"({bad.size} of {x.size} entries NaN or infinite)")
        q, v = self.coords.to_maximal(qpos, qvel)
        # as a new simulator: no contact modes, warm starts or ground queries carry over.
        # Like MuJoCo's set_state, any pose is accepted (one below the floor is pushed out by
        # the first step)
        self.sim.start_over(q, v)
        self._sync()

    def check_action(self, action) -> np.ndarray:
        a = np.asarray(action, dtype=np.float64)
        if a.shape != self.action_space.shape:
            raise ValueError(f"action has shape {a.shape}; {type(self).__name__} takes shape "
                             f"{self.action_space.shape} (one control per actuator: "
                             f"{[x.target for x in self._act]})")
        if not np.all(np.isfinite(a)):
            raise ValueError(f"action {a.tolist()} has NaN or infinite entries")
        return a

    def load_commands(self, ctrl) -> bool:
        """The actuators' commands self._u from action `ctrl`: MuJoCo clamps ctrl to
        ctrlrange; each actuator's input is gear * coef * ctrl (one compiled call, which also
        says whether every entry was finite). False (self._u untouched) for an action of the
        wrong shape or with a NaN or infinite entry."""
        a = np.asarray(ctrl, dtype=np.float64)
        return a.shape == self.action_space.shape and set_commands(
            a, self._act_lo, self._act_hi, self._drive_entry, self._drive_id, self._drive_gain,
            self._u)

    #: frames the simulator has already advanced, under commands loaded from the action the
    #: next do_simulation is given (a batched vector step: planarsim.envs.batched), or None
    _advanced = None

    def do_simulation(self, ctrl, n_frames):
        self._advance(ctrl, n_frames)
        self._sync()

    def _advance(self, ctrl, n_frames):
        """do_simulation's physics: the commands of action `ctrl` and n_frames steps (or the
        steps a batched vector step already took), without writing qpos and qvel."""
        advanced, self._advanced = self._advanced, None
        if advanced is None:
            if not self.load_commands(ctrl):
                self.check_action(ctrl)        # (raises, naming what is wrong)
            self.sim.steps(int(n_frames), self._u)
        elif advanced != int(n_frames):
            raise RuntimeError(f"do_simulation({int(n_frames)} frames) after a batched step of "
                               f"{advanced} frames")

    def state_vector(self):
        return np.concatenate([self.data.qpos.flat, self.data.qvel.flat])

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        obs = self.reset_model()
        return obs, self._get_reset_info()

    def _get_reset_info(self):
        return {}

    def reset_model(self):  # pragma: no cover - each task defines it
        raise NotImplementedError

    def body_com(self, body: str) -> np.ndarray:
        """World (plane) position [m] of MJCF body `body`'s own centre of mass (MuJoCo's
        get_body_com, in the plane's two coordinates)."""
        return self.point(body, self.loaded.com[body])

    def point(self, body: str, local_mjcf) -> np.ndarray:
        """World (plane) position of a point fixed in MJCF body `body`, given at the file's
        pose in the plane's coordinates (e.g. a site's position)."""
        bid = self.loaded.body[body]
        x, y, angle = self.sim.state.q[bid]
        q0 = self.sim_model.q0[bid]
        dx, dy = float(local_mjcf[0]) - q0[0], float(local_mjcf[1]) - q0[1]
        c, s = math.cos(angle - q0[2]), math.sin(angle - q0[2])
        return np.array([x + c * dx - s * dy, y + s * dx + c * dy])

    # rendering ----------------------------------------------------------------------------
    def render(self):
        if self.render_mode is None:
            gymnasium.logger.warn("render() called without render_mode; pass render_mode='rgb_array'")
            return None
        # (imported here for start-up time: matplotlib only where an env renders)
        from ..render.draw import render_state
        import matplotlib.pyplot as plt
        dpi = 100
        fig, _ = render_state(self.sim_model, self.sim.state.q, size=(self.width / dpi, self.height / dpi),
                              dpi=dpi)
        fig.canvas.draw()
        img = np.asarray(fig.canvas.buffer_rgba())[..., :3].copy()
        plt.close(fig)
        return img

    def close(self):
        pass
