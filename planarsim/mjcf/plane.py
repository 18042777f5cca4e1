"""The plane of motion: which MJCF plane the model moves in (the one normal to its hinges),
how a world point maps into it, which way a joint turns in it and the silhouette of a geom
in it."""
from __future__ import annotations

import math

import numpy as np

from .. import mjcf_frames as F
from .schema import AXIS_TOL


def vec(v):
    """A vector as a tuple of plain floats for messages."""
    return tuple(float(x) + 0.0 for x in np.round(v, 12))


def normal_from_joints(hinges, slides) -> int:
    """The MJCF axis normal to the plane of motion: 1 (y: the x-z plane) or 2 (z: x-y). The
    hinges' axes choose it; a model without hinges moves on its slides: a slide with a y
    component puts it in the x-y plane (point_mass: slides along x and y), otherwise the
    x-z plane (a cart on an x slide)."""
    if hinges:
        return 2 if abs(abs(hinges[0]["axis"][2]) - 1) <= AXIS_TOL else 1
    return 2 if any(abs(j["axis"][1]) > AXIS_TOL for j in slides) else 1


def is_wall(plane_map, g) -> bool:
    """A world plane whose normal lies in the plane of motion and is not the ground's up
    (walls.py makes it a static box)."""
    n = g["R"][:, 2]
    in_plane = abs(n[plane_map.normal]) <= AXIS_TOL
    return in_plane and abs(n[plane_map.i2] - 1) > AXIS_TOL


class PlaneMap:
    """The plane normal to the hinges of `bodies` (MJCF y -> x-z, z -> x-y; without hinges
    x-y where a slide has a y component, else x-z: normal_from_joints), shifted by `offset` (2,) [m]; every hinge must be normal to it and every slide
    in it (else fail(node, message) raises)."""

    def __init__(self, bodies, offset, fail):
        self.fail = fail
        self.offset = np.asarray(offset, dtype=np.float64)
        joints = [j for b in bodies for j in b.joints]
        hinges = [j for j in joints if j["type"] == "hinge"]
        # from the hinges, else from the slides (a point mass on x and y slides)
        normal = normal_from_joints(hinges, [j for j in joints if j["type"] == "slide"])
        self.i1, self.i2 = (0, 2) if normal == 1 else (0, 1)
        self.normal = normal
        self.name = "x-z" if normal == 1 else "x-y"
        self.ccw = np.cross(np.eye(3)[self.i1], np.eye(3)[self.i2])   # -y or +z
        want = "(0, +-1, 0)" if normal == 1 else "(0, 0, +-1)"
        for j in joints:
            a = j["axis"]
            if j["type"] == "hinge" and abs(abs(a[normal]) - 1) > AXIS_TOL:
                fail(j["node"], f"hinge axis={vec(a)} is not normal to the "
                                f"{self.name} plane of motion: it must be {want}; a "
                                f"joint leaving the plane is not supported")
            if j["type"] == "slide" and abs(a[normal]) > AXIS_TOL:
                fail(j["node"], f"slide axis={vec(a)} leaves the "
                                f"{self.name} plane of motion")

    def plane(self, p) -> np.ndarray:
        """World point (x, y, z) -> planarsim (x, y) [m], shifted by the offset."""
        return np.array([p[self.i1], p[self.i2]]) + self.offset

    def sign(self, j) -> float:
        """+1 when the MJCF joint turns (hinge) counter-clockwise in planarsim's plane."""
        return float(np.sign(j["axis"] @ self.ccw))

    def in_plane(self, v) -> tuple:
        """The in-plane components of world vector v."""
        return (float(v[self.i1]), float(v[self.i2]))

    def own_inertia(self, g) -> float:
        """Inertia per unit mass [m^2] about the normal through the geom's centre."""
        n = np.eye(3)[self.normal]
        if g["kind"] in ("capsule", "cylinder", "sphere"):
            i_perp, i_axis = g["unit"][0], g["unit"][2]
            ay = g["R"][self.normal, 2]         # axis . n
            return i_perp + (i_axis - i_perp) * ay * ay
        return F.inertia_about(g["unit"], g["R"], n)

    def normal_inertia(self, tensor) -> float:
        """An inertia tensor's moment about the plane's normal [kg m^2]."""
        n = np.eye(3)[self.normal]
        return float(n @ tensor @ n)

    def shape(self, g):
        """The geom's silhouette in the plane (world coordinates [m], offset applied):
        ('circle', c, r) | ('capsule', p0, p1, r) | ('box', c, w, h, angle) | ('polygon', vs)."""
        kind, R, c = g["kind"], g["R"], self.plane(g["pos"])
        if kind == "plane":
            return None
        nz = abs(R[self.normal, 2])               # geom z axis . plane normal
        if kind == "sphere":
            return ("circle", c, g["dims"][0])
        if kind == "capsule":
            r = g["dims"][0]
            p0, p1 = (self.plane(e) for e in g["ends"])
            if np.hypot(*(p1 - p0)) < 1e-12:
                return ("circle", c, r)
            return ("capsule", p0, p1, r)
        if kind == "cylinder":
            r, h = g["dims"]
            if abs(nz - 1) <= AXIS_TOL:
                return ("circle", c, r)
            if nz <= AXIS_TOL:
                u = R[:, 2]
                return ("box", c, 2 * h, 2 * r, math.atan2(u[self.i2], u[self.i1]))
            self.fail(g["node"], "a cylinder tilted out of the plane has no planar shape here")
        half = np.asarray(g["dims"][:3] if kind == "box" else g["dims"], dtype=np.float64)
        along = [k for k in range(3) if abs(abs(R[self.normal, k]) - 1) <= AXIS_TOL]
        if kind == "ellipsoid":
            if not along:
                self.fail(g["node"], "an ellipsoid tilted out of the plane has no planar shape here")
            k1, k2 = [k for k in range(3) if k != along[0]]
            ts = np.linspace(0, 2 * math.pi, 24, endpoint=False)
            pts = [self.plane(g["pos"] + half[k1] * math.cos(t) * R[:, k1]
                              + half[k2] * math.sin(t) * R[:, k2]) for t in ts]
            return ("polygon", pts, "approximate")
        if along:
            k1, k2 = [k for k in range(3) if k != along[0]]
            u = R[:, k1]
            return ("box", c, 2 * half[k1], 2 * half[k2], math.atan2(u[self.i2], u[self.i1]))
        corners = [self.plane(g["pos"] + R @ (half * np.array(s)))
                   for s in np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).T.reshape(-1, 3)]
        return ("polygon", hull(corners))


def hull(points) -> list:
    """Convex hull (counter-clockwise) of 2D points (monotone chain)."""
    pts = sorted({(round(float(p[0]), 12), round(float(p[1]), 12)) for p in points})

    def half(seq):
        out = []
        for p in seq:
            while len(out) >= 2 and ((out[-1][0] - out[-2][0]) * (p[1] - out[-2][1])
                                     - (out[-1][1] - out[-2][1]) * (p[0] - out[-2][0])) <= 0:
                out.pop()
            out.append(p)
        return out[:-1]
    return half(pts) + half(pts[::-1])
