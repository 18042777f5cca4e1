"""Rotations and geom mass properties for the MJCF loader (planarsim.mjcf).

Rotations are 3x3 matrices R whose columns are a frame's axes in its parent's frame, built
from MJCF's orientation forms: ``quat`` (w x y z), ``axisangle`` (x y z angle), ``euler``
(three angles about the axes named by the compiler's ``eulerseq``; a lowercase letter turns
about the rotated frame's axis, an uppercase one about the fixed frame's), ``zaxis`` (the
smallest rotation taking +z to the vector) and ``xyaxes`` (the x axis and a vector in the x-y
plane). Angles are radians here; the loader converts degrees.

Geom mass properties as MuJoCo's compiler computes them from a geom's shape (uniform density,
solid): volume [m^3] and the principal inertia per unit mass [m^2] about the geom's own axes
(x, y, z; capsules and cylinders lie along z):

  sphere     r                V = 4/3 pi r^3          I = 2/5 r^2 (each axis)
  capsule    r, half length h  cylinder of length 2h plus two hemispheres, mass split by volume:
             I_z = f_c r^2/2 + f_h 2/5 r^2
             I_x = f_c (r^2/4 + h^2/3) + f_h (83/320 r^2 + (h + 3r/8)^2)
  cylinder   r, h             V = 2 pi r^2 h          I_z = r^2/2, I_x = r^2/4 + h^2/3
  box        half sizes a b c V = 8abc                I_x = (b^2 + c^2)/3 (and cyclic)
  ellipsoid  radii a b c      V = 4/3 pi abc          I_x = (b^2 + c^2)/5 (and cyclic)
"""
from __future__ import annotations

import math

import numpy as np


def quat_matrix(q) -> np.ndarray:
    """Rotation matrix of the quaternion (w, x, y, z) (normalised here)."""
    q = np.asarray(q, dtype=np.float64)
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def axis_angle_matrix(axis, angle) -> np.ndarray:
    """Rotation by `angle` [rad] about `axis` (normalised here), right-handed."""
    a = np.asarray(axis, dtype=np.float64)
    a = a / np.linalg.norm(a)
    half = 0.5 * angle
    return quat_matrix((math.cos(half), *(math.sin(half) * a)))


def euler_matrix(angles, seq: str) -> np.ndarray:
    """Rotation of three angles [rad] about the axes of `seq` (e.g. 'xyz': intrinsic, each
    about the rotated frame's axis; 'XYZ': extrinsic, about the fixed frame's)."""
    R = np.eye(3)
    for ch, ang in zip(seq, angles):
        Ri = axis_angle_matrix(np.eye(3)["xyz".index(ch.lower())], ang)
        R = R @ Ri if ch.islower() else Ri @ R
    return R


def zaxis_matrix(z) -> np.ndarray:
    """The smallest rotation taking +z to the direction of `z`."""
    z = np.asarray(z, dtype=np.float64)
    z = z / np.linalg.norm(z)
    c = float(z[2])
    axis = np.array([-z[1], z[0], 0.0])            # +z x z
    s = float(np.linalg.norm(axis))
    if s < 1e-15:
        return np.eye(3) if c > 0 else np.diag([1.0, -1.0, -1.0])
    return axis_angle_matrix(axis, math.atan2(s, c))


def xyaxes_matrix(v) -> np.ndarray:
    """Frame from its x axis v[:3] and a vector v[3:] in its x-y plane (Gram-Schmidt)."""
    v = np.asarray(v, dtype=np.float64)
    x = v[:3] / np.linalg.norm(v[:3])
    y = v[3:] - (v[3:] @ x) * x
    y = y / np.linalg.norm(y)
    return np.column_stack([x, y, np.cross(x, y)])


def capsule_unit_inertia(r: float, h: float) -> tuple[float, float, float]:
    """Volume [m^3], perpendicular and axial inertia per unit mass [m^2] of a solid capsule of
    radius r and half length h [m] (cylinder 2h long plus two hemispheres)."""
    L = 2.0 * h
    vol_c, vol_h = math.pi * r * r * L, 4 / 3 * math.pi * r ** 3
    vol = vol_c + vol_h
    fc, fh = vol_c / vol, vol_h / vol
    i_perp = fc * (r * r / 4 + L * L / 12) + fh * (83 / 320 * r * r + (L / 2 + 3 * r / 8) ** 2)
    i_axis = fc * r * r / 2 + fh * 0.4 * r * r
    return vol, i_perp, i_axis


def unit_inertia(kind: str, size) -> tuple[float, np.ndarray]:
    """Volume [m^3] and principal inertia per unit mass (3,) [m^2] about the geom's axes
    (see the module's docstring); size: r | (r, h) | half sizes (a, b, c) | radii [m]."""
    s = np.asarray(size, dtype=np.float64)
    if kind == "sphere":
        r = s[0]
        return 4 / 3 * math.pi * r ** 3, np.full(3, 0.4 * r * r)
    if kind == "capsule":
        vol, i_perp, i_axis = capsule_unit_inertia(s[0], s[1])
        return vol, np.array([i_perp, i_perp, i_axis])
    if kind == "cylinder":
        r, h = s[0], s[1]
        i_perp = r * r / 4 + h * h / 3
        return 2 * math.pi * r * r * h, np.array([i_perp, i_perp, r * r / 2])
    a, b, c = s[:3]
    if kind == "box":
        return 8 * a * b * c, np.array([b * b + c * c, a * a + c * c, a * a + b * b]) / 3
    if kind == "ellipsoid":
        return 4 / 3 * math.pi * a * b * c, np.array([b * b + c * c, a * a + c * c, a * a + b * b]) / 5
    raise ValueError(kind)


def inertia_about(principal, R, n) -> float:
    """Inertia [kg m^2 or per unit mass] about the unit world direction n of a body whose
    principal inertia `principal` (3,) lies along the columns of R."""
    c = R.T @ n
    return float(principal[0] * c[0] ** 2 + principal[1] * c[1] ** 2 + principal[2] * c[2] ** 2)
