"""Mass properties of an MJCF body as MuJoCo's compiler computes them (from its geoms or its
<inertial>), and the box of MuJoCo's inertia-box fluid model."""
from __future__ import annotations

import math

import numpy as np


def uses_inertial(inertiafromgeom: str, b) -> bool:
    """Body b's mass comes from its <inertial> elements, not its geoms (the compiler's
    inertiafromgeom: "false" always, "auto" where the body has an <inertial>)."""
    return inertiafromgeom == "false" or (inertiafromgeom == "auto" and bool(b.inertials))


def inertia_3d(b, inertiafromgeom: str, scale: float):
    """Mass [kg], COM (3,) [m] and inertia tensor (3, 3) about it [kg m^2] of MJCF body b
    alone, in world axes at the file's pose (as MuJoCo's body_mass, body_ipos, body_inertia),
    every mass scaled by `scale` (<compiler settotalmass>)."""
    items = ([(i["mass"], i["pos"], i["tensor"]) for i in b.inertials]
             if uses_inertial(inertiafromgeom, b) else
             [(g["mass"], g["pos"], g["mass"] * g["R"] @ np.diag(g["unit"]) @ g["R"].T)
              for g in b.geoms if g["kind"] != "plane"])
    f = scale
    mass = sum(m for m, _, _ in items) * f
    if not mass > 0:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    com = sum(m * np.asarray(p) for m, p, _ in items) * f / mass
    T = np.zeros((3, 3))
    for m, p, I in items:
        r = np.asarray(p) - com
        T += f * (I + m * (r @ r * np.eye(3) - np.outer(r, r)))
    return mass, com, T


def fluid_box(mass, T, normal, i1, i2):
    """MuJoCo's inertia box of a body of `mass` [kg] and inertia tensor T about its COM:
    sides [m] (sqrt(6 (I_j + I_k - I_i) / m)), the normal's last, and the angle [rad] of its
    first principal axis in the plane; None where no principal axis is normal to the plane
    (axes i1, i2 in the plane, `normal` along its normal)."""
    n = normal
    if abs(T[n, i1]) + abs(T[n, i2]) > 1e-9 * max(np.trace(T), 1e-300):
        return None
    w, e = np.linalg.eigh(np.array([[T[i1, i1], T[i1, i2]], [T[i1, i2], T[i2, i2]]]))
    moments = (w[0], w[1], T[n, n])
    box = [math.sqrt(max(1e-15, moments[(k + 1) % 3] + moments[(k + 2) % 3] - moments[k])
                     / mass * 6.0) for k in range(3)]
    return box, math.atan2(e[1, 0], e[0, 0])
