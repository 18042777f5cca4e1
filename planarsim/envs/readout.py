"""A dm_control task's observation and reward quantities in one compiled call per env step.

A task's readings (the entries of its observation, then the quantities its reward reads) are
written once, at a reset, as a table of operations (:class:`Readout`), each of which computes
one float from the state: a joint's qpos or qvel, a control, an entry of a body's rotation
matrix (MuJoCo's ``xmat``), a coordinate of the difference of two points fixed in bodies
(or in the world), optionally turned into a body's frame, the distance of two such points, a
point's velocity (a ``velocimeter``), a body's rate (a ``gyro``), a subtree's linear velocity
(``subtreelinvel``) and a site's ``touch`` (the normal force of the contacts in its sphere or
ellipsoid over the last physics step). ``read`` evaluates the whole table in one compiled
call; the environment binds it once to its arrays (no numba type dispatch per step).

Points are given in the model's plane, at the file's pose (qpos0), as the MJCF file places
them; a body's rotation is its angle from the file's pose (planarsim's q less q0).
"""
from __future__ import annotations

import math

import numpy as np

from ..compiled import jit
from ..kernels.codes import CONTACT_PAIR

# operation kinds (column 0 of the integer table)
OP_CONST = 0       # out = const
OP_QPOS = 1        # out = coef * qpos[k]
OP_QVEL = 2        # out = coef * qvel[k]
OP_CTRL = 3        # out = coef * ctrl[k]
OP_COS = 4         # out = coef * cos(angle of b1)
OP_SIN = 5         # out = coef * sin(angle of b1)
OP_POINT = 6       # out = coef * (P1 - P2)[k] + const, turned into b3's frame if b3 >= 0
OP_DIST = 7        # out = |P1 - P2| + const
OP_VEL = 8         # out = coef * (velocity of P1)[k], turned into b3's frame if b3 >= 0
OP_RATE = 9        # out = coef * omega of b1
OP_SUBTREE = 10    # out = sum(weight * v[id, k]) / const over ids[s:s+n]
OP_TOUCH = 11      # out = normal force [N] in the ellipse (radii x2, y2) about P1 of body b1
                   # (log1p of it if k == 1); const: the physics step [s]

# integer columns: kind, b1, b2, b3, k, s, n; float columns: x1, y1, x2, y2, coef, const
N_INT = 7
N_FLOAT = 6


@jit
def _angle(q, q0, b):
    return q[b, 2] - q0[b, 2]


@jit
def _point(q, q0, b, x, y):
    """World (plane) position [m] of the point (x, y) of body b at the file's pose (b < 0:
    the world's fixed point (x, y))."""
    if b < 0:
        return x, y
    c = math.cos(q[b, 2] - q0[b, 2])
    s = math.sin(q[b, 2] - q0[b, 2])
    dx = x - q0[b, 0]
    dy = y - q0[b, 1]
    return q[b, 0] + c * dx - s * dy, q[b, 1] + s * dx + c * dy


@jit
def _into_frame(q, q0, b, dx, dy):
    """(dx, dy) in body b's frame (turned back by its angle); unchanged for b < 0."""
    if b < 0:
        return dx, dy
    c = math.cos(q[b, 2] - q0[b, 2])
    s = math.sin(q[b, 2] - q0[b, 2])
    return c * dx + s * dy, c * dy - s * dx


@jit
def _touch(q, q0, b, cx, cy, r0, r1, dt, impulse, kind, body, local, radius, bodies, refpt):
    """Normal force [N] over the last step of body b's contacts whose point lies in the
    ellipse of radii (r0, r1) about (cx, cy) (file pose), axes the body's: a ground contact's
    point its lowest point (its foot arc's), a pair's the surface point on body b."""
    px, py = _point(q, q0, b, cx, cy)
    c = math.cos(q[b, 2])
    s = math.sin(q[b, 2])
    cr = math.cos(q[b, 2] - q0[b, 2])
    sr = math.sin(q[b, 2] - q0[b, 2])
    total = 0.0
    for k in range(impulse.shape[0]):
        if not impulse[k, 0] > 0.0:
            continue
        if kind[k] == CONTACT_PAIR:
            if bodies[k, 0] == b:
                side = 0
            elif bodies[k, 1] == b:
                side = 1
            else:
                continue
            lx = refpt[k, 2 * side]
            ly = refpt[k, 2 * side + 1]
            drop = 0.0
        elif body[k] == b:
            lx = local[k, 0]
            ly = local[k, 1]
            drop = radius[k]
        else:
            continue
        dx = q[b, 0] + c * lx - s * ly - px
        dy = q[b, 1] + s * lx + c * ly - drop - py
        u = cr * dx + sr * dy
        w = -sr * dx + cr * dy
        if (u / r0) ** 2 + (w / r1) ** 2 <= 1.0:
            total += impulse[k, 0] / dt
    return total


@jit
def read(q, v, q0, qpos, qvel, ctrl, impulse, kind, body, local, radius, bodies, refpt,
         ops_i, ops_f, ids, weights, out):
    """out[j] = operation j of the table (ops_i, ops_f) on the state (q, v; qpos, qvel its
    joint values; ctrl the last action; impulse the last step's contact impulses; kind, body,
    local, radius: the model's contact table; bodies, refpt: the workspace's pair contacts);
    ids, weights: the subtrees' bodies and masses."""
    for j in range(ops_i.shape[0]):
        op = ops_i[j, 0]
        b1 = ops_i[j, 1]
        b2 = ops_i[j, 2]
        b3 = ops_i[j, 3]
        k = ops_i[j, 4]
        x1 = ops_f[j, 0]
        y1 = ops_f[j, 1]
        x2 = ops_f[j, 2]
        y2 = ops_f[j, 3]
        coef = ops_f[j, 4]
        const = ops_f[j, 5]
        value = const
        if op == OP_QPOS:
            value = coef * qpos[k]
        elif op == OP_QVEL:
            value = coef * qvel[k]
        elif op == OP_CTRL:
            value = coef * ctrl[k]
        elif op == OP_COS:
            value = coef * math.cos(_angle(q, q0, b1))
        elif op == OP_SIN:
            value = coef * math.sin(_angle(q, q0, b1))
        elif op == OP_POINT or op == OP_DIST:
            ax, ay = _point(q, q0, b1, x1, y1)
            bx, by = _point(q, q0, b2, x2, y2)
            dx, dy = _into_frame(q, q0, b3, ax - bx, ay - by)
            if op == OP_DIST:
                value = math.sqrt(dx * dx + dy * dy) + const
            else:
                value = coef * (dx if k == 0 else dy) + const
        elif op == OP_VEL:
            px, py = _point(q, q0, b1, x1, y1)
            w = v[b1, 2]
            vx = v[b1, 0] - w * (py - q[b1, 1])
            vy = v[b1, 1] + w * (px - q[b1, 0])
            vx, vy = _into_frame(q, q0, b3, vx, vy)
            value = coef * (vx if k == 0 else vy)
        elif op == OP_RATE:
            value = coef * v[b1, 2]
        elif op == OP_SUBTREE:
            s = ops_i[j, 5]
            total = 0.0
            for i in range(s, s + ops_i[j, 6]):
                total += weights[i] * v[ids[i], k]
            value = total / const
        elif op == OP_TOUCH:
            value = _touch(q, q0, b1, x1, y1, x2, y2, const, impulse, kind, body, local,
                           radius, bodies, refpt)
            if k == 1:
                value = math.log1p(value)
        out[j] = value


# frame sensors read here: their objects, and the xmat column of each axis sensor
_FRAMES = ("site", "geom", "xbody", "body")
_AXES = {"framexaxis": 0, "frameyaxis": 1, "framezaxis": 2}
# sensors whose reading turns with their site's or geom's frame (its axes, or a velocity or
# size in it)
_TURNED = set(_AXES) | {"velocimeter", "gyro", "touch", "accelerometer", "framequat"}


class Readout:
    """The table of a task's readings, written by its domain's ``plan(env, readout)``:
    ``obs(name, *ops)`` appends an observation entry (its ops' values, in order),
    ``value(name, op)`` a quantity the reward reads. The op constructors (``qpos``, ``xmat``,
    ``point``, ``sensor``, ...) take MJCF names and return one op each.
    """

    def __init__(self, env):
        self.env = env
        self.rows_i, self.rows_f = [], []
        self.obs_names, self.obs_sizes = [], []
        self.value_names = []
        self.ids, self.weights = [], []
        self._ops = []

    # the table ---------------------------------------------------------------------------
    def obs(self, name, *ops, scalar=False):
        """An observation entry: its ops' values in order (a 0-d array if scalar)."""
        if self.value_names:
            raise RuntimeError("Readout: observation entries come before the reward's values")
        self.obs_names.append(name)
        self.obs_sizes.append(None if scalar else len(ops))
        self._ops += ops

    def value(self, name, op):
        self.value_names.append(name)
        self._ops.append(op)

    def tables(self):
        """(ops_i, ops_f, ids, weights) arrays of the table."""
        ops_i = np.array([o[0] for o in self._ops], np.int64).reshape(-1, N_INT)
        ops_f = np.array([o[1] for o in self._ops], np.float64).reshape(-1, N_FLOAT)
        ids = np.array(self.ids + [0], np.int64)
        weights = np.array(self.weights + [0.0], np.float64)
        return ops_i, ops_f, ids, weights

    @property
    def n_obs(self) -> int:
        return sum(1 if n is None else n for n in self.obs_sizes)

    def entries(self, values):
        """{name: array} of the observation entries in `values` (read's out)."""
        out, i = {}, 0
        for name, n in zip(self.obs_names, self.obs_sizes):
            out[name] = values[i].copy() if n is None else values[i:i + n].copy()
            i += 1 if n is None else n
        return out

    # ops ---------------------------------------------------------------------------------
    @staticmethod
    def _op(kind, b1=-1, b2=-1, b3=-1, k=0, s=0, n=0, x1=0.0, y1=0.0, x2=0.0, y2=0.0,
            coef=1.0, const=0.0):
        return (kind, b1, b2, b3, k, s, n), (x1, y1, x2, y2, coef, const)

    def _body(self, name):
        return -1 if name is None else self.env._rigid(name)

    def _plane(self, p3):
        a0, a1 = self.env.plane_axes
        return float(p3[a0]), float(p3[a1])

    def _axis(self, axis3):
        """The plane index (0, 1) of a 3D axis, or None for the plane's normal."""
        a0, a1 = self.env.plane_axes
        return {a0: 0, a1: 1}.get(axis3)

    def const(self, value):
        return self._op(OP_CONST, const=float(value))

    def qpos(self, joint):
        return self._op(OP_QPOS, k=self.env.qindex(joint) if isinstance(joint, str) else joint)

    def qvel(self, joint):
        return self._op(OP_QVEL, k=self.env.qindex(joint) if isinstance(joint, str) else joint)

    def ctrl(self, i):
        return self._op(OP_CTRL, k=i)

    def xmat(self, body, i, j):
        """MuJoCo's xmat[i, j] of a body (env.xmat's entries as ops)."""
        env = self.env
        b = self._body(body)
        n = env.normal_axis
        if i == n or j == n:
            return self.const(1.0 if i == j else 0.0)
        if i == j:
            return self._op(OP_COS, b)
        # the rotation by phi = ccw_sign * angle about the normal: [[c, -s], [s, c]] in the
        # plane's axes (a0, a1) for +z; about +y, (x, z) = (a0, a1) takes [[c, s], [-s, c]]
        upper = -1.0 if n == 2 else 1.0        # the sign of s in entry (a0, a1)
        first = (i, j) == (env.plane_axes[0], env.plane_axes[1])
        sign = upper if first else -upper
        return self._op(OP_SIN, b, coef=sign * env.ccw_sign)

    def point(self, axis3, a, b=(None, (0.0, 0.0, 0.0)), frame=None):
        """Coordinate axis3 (0, 1, 2) of point a - point b, turned into MJCF body `frame`'s
        axes if given; a point is (MJCF body or None, its 3D position at the file's pose).
        The plane's normal coordinate is a - b of the file's."""
        k = self._axis(axis3)
        if k is None:
            return self.const(a[1][axis3] - b[1][axis3])
        (x1, y1), (x2, y2) = self._plane(a[1]), self._plane(b[1])
        return self._op(OP_POINT, self._body(a[0]), self._body(b[0]), self._body(frame), k=k,
                        x1=x1, y1=y1, x2=x2, y2=y2)

    def dist(self, a, b, minus=0.0):
        """|point a - point b| - minus [m] (points in the plane; their normal coordinates
        equal, as every task's are)."""
        normal = self.env.normal_axis
        if abs(a[1][normal] - b[1][normal]) > 0.0:
            raise NotImplementedError(f"{self.env.task}: a distance across the plane")
        (x1, y1), (x2, y2) = self._plane(a[1]), self._plane(b[1])
        return self._op(OP_DIST, self._body(a[0]), self._body(b[0]), x1=x1, y1=y1, x2=x2,
                        y2=y2, const=-float(minus))

    # named places of the file
    def _place(self, table, name):
        """(body, 3D position) of a site or geom of `table`; the world's 'target' where the
        task moved it (env.set_target)."""
        body, p, _ = table[name]
        if body is None and self.env.target is not None and name == "target":
            p = self.env.target
        return body, p

    def site(self, name):
        return self._place(self.env.frames.site, name)

    def geom(self, name):
        return self._place(self.env.frames.geom, name)

    def body_origin(self, name):
        return name, self.env.frames.body[name][1]

    def body_com(self, name):
        env = self.env
        p = env.frames.body[name][1].copy()
        p[env.plane_axes[0]], p[env.plane_axes[1]] = env.loaded.com[name]
        return name, p

    def sensor_point(self, name):
        """The point a framepos sensor reads: (MJCF body or None, 3D position)."""
        kind, attrib, _ = self.env._sensors[name]
        if kind != "framepos" or attrib.get("objtype") not in _FRAMES:
            raise NotImplementedError(f"{self.env.task}: sensor {name!r} is not the framepos "
                                      f"of a site, geom or body")
        return self._frame_place(attrib)

    def _frame_place(self, attrib):
        """(MJCF body or None, 3D position) of a frame sensor's object."""
        obj, kind = attrib["objname"], attrib["objtype"]
        if kind == "site":
            return self.site(obj)
        if kind == "geom":
            return self.geom(obj)
        return self.body_origin(obj)

    def sensor(self, name, axis3=None, log1p=False):
        """An op reading the file's sensor `name` (axis3 for a 3D sensor), as env.sensor."""
        env = self.env
        kind, attrib, fixed = env._sensors[name]
        if "reftype" in attrib or "refname" in attrib:
            raise NotImplementedError(
                f"{env.frames.source}: sensor {name!r} (<{kind}>) is read relative to "
                f"{attrib.get('reftype', '?')} {attrib.get('refname', '?')!r}; planarsim's "
                f"dm_control tasks read frame sensors in the world frame only")
        if "site" in attrib:
            turned = ("site", attrib["site"])
        else:
            turned = (attrib.get("objtype"), attrib.get("objname"))
        # (a touch on a sphere reads the same at any rotation)
        sphere_touch = kind == "touch" and env.frames.site_type.get(turned[1]) == "sphere"
        if turned in env.frames.rotated and kind in _TURNED and not sphere_touch:
            raise NotImplementedError(
                f"{env.frames.source}: sensor {name!r} (<{kind}>) reads the frame of "
                f"{turned[0]} {turned[1]!r}, which is rotated in its body (or set by "
                f"fromto); planarsim's dm_control tasks read the orientation of unrotated "
                f"sites and geoms only")
        if kind in ("jointpos", "jointvel"):
            make = self.qpos if kind == "jointpos" else self.qvel
            return make(attrib["joint"])
        if kind == "framepos":
            return self.point(axis3, self.sensor_point(name))
        if kind in _AXES and attrib.get("objtype") in _FRAMES:
            # a column of the object's xmat (sites and geoms turn with their body: the
            # files' are unrotated in it)
            body = self._frame_place(attrib)[0]
            if body is None:
                return self.const(1.0 if axis3 == _AXES[kind] else 0.0)
            return self.xmat(body, axis3, _AXES[kind])
        if kind == "gyro":
            if axis3 != env.normal_axis:
                return self.const(0.0)
            return self._op(OP_RATE, self._body(fixed[0]), coef=env.ccw_sign)
        if kind == "velocimeter":
            k = self._axis(axis3)
            if k is None:
                return self.const(0.0)
            b = self._body(fixed[0])
            x, y = self._plane(fixed[1])
            return self._op(OP_VEL, b, b3=b, k=k, x1=x, y1=y)
        if kind == "subtreelinvel":
            k = self._axis(axis3)
            if k is None:
                return self.const(0.0)
            ids, masses, total = fixed
            start = len(self.ids)
            self.ids += list(ids)
            self.weights += [float(m) for m in masses]
            return self._op(OP_SUBTREE, k=k, s=start, n=len(ids), const=float(total))
        if kind == "touch":
            site = attrib["site"]
            body, p, size = env.frames.site[site]
            x, y = self._plane(p)
            a0, a1 = env.plane_axes
            sphere = env.frames.site_type[site] == "sphere"
            r0, r1 = (size[0], size[0]) if sphere else (size[a0], size[a1])
            return self._op(OP_TOUCH, self._body(body), k=int(log1p), x1=x, y1=y,
                            x2=float(r0), y2=float(r1), const=env.timestep)
        raise NotImplementedError(f"{env.task}: sensor {name!r} of type <{kind}> is not read")
