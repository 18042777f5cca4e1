"""The MJCF loader's plane of motion and the world's planes that are walls.

Plane of motion. The hinges' axes choose it (MJCF y -> the x-z plane, z -> x-y). A model
without hinges moves on its slides: a slide with a y component puts it in the x-y plane
(point_mass: slides along x and y), otherwise the x-z plane (a cart on an x slide).

Walls. MuJoCo's plane is a half-space: solid behind its normal (its size only draws it). A
world plane whose normal lies in the plane of motion, other than the ground (the one facing
straight up, which becomes flat terrain), is a static wall: a box fixed in the world whose
face lies on the plane, WALL_DEPTH deep behind it and 2 WALL_HALF_LENGTH long along it,
colliding by MuJoCo's contype/conaffinity rule with the bodies' geoms (dm_control's reacher
and point_mass arenas; a ceiling; an incline in the plane of motion). A plane whose normal
leaves the plane of motion without being normal to it stays a ModelError.
"""
from __future__ import annotations

import math

import numpy as np

WALL_DEPTH = 1.0            # [m] a wall's box behind its plane
WALL_HALF_LENGTH = 100.0    # [m] a wall's box along its plane, each side of the plane's pos
AXIS_TOL = 1e-9


def normal_from_joints(hinges, slides) -> int:
    """The MJCF axis normal to the plane of motion: 1 (y: the x-z plane) or 2 (z: x-y)."""
    if hinges:
        return 2 if abs(abs(hinges[0]["axis"][2]) - 1) <= AXIS_TOL else 1
    return 2 if any(abs(j["axis"][1]) > AXIS_TOL for j in slides) else 1


def is_wall(loader, g) -> bool:
    """A world plane whose normal lies in the plane of motion and is not the ground's up."""
    n = g["R"][:, 2]
    in_plane = abs(n[loader.normal]) <= AXIS_TOL
    return in_plane and abs(n[loader.i2] - 1) > AXIS_TOL


def wall_shapes(loader) -> list:
    """(geom, ('box', centre, length, depth, angle)) for every wall of the world."""
    out = []
    for g in loader.world_geoms():
        if g["kind"] != "plane" or not is_wall(loader, g):
            continue
        n3 = g["R"][:, 2]
        n = np.array([n3[loader.i1], n3[loader.i2]])
        n /= np.hypot(*n)
        centre = loader.plane(g["pos"]) - 0.5 * WALL_DEPTH * n
        t = np.array([-n[1], n[0]])          # along the wall: the box's width axis
        angle = math.atan2(t[1], t[0])
        loader.report.note(f"plane {g['name'] or g['node'].line!r} (normal {tuple(float(x) for x in np.round(n, 12))} "
                           f"in the plane of motion) is a wall: where it collides with a body's geom, a static "
                           f"box {WALL_DEPTH} m deep and {2 * WALL_HALF_LENGTH} m long behind it")
        out.append((g, ("box", centre, 2 * WALL_HALF_LENGTH, WALL_DEPTH, angle)))
    return out
