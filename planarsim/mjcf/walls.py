"""The world's planes that are walls.

MuJoCo's plane is a half-space: solid behind its normal (its size only draws it). A world
plane whose normal lies in the plane of motion, other than the ground (the one facing
straight up, which becomes flat terrain), is a static wall (plane.is_wall): a box fixed in
the world whose face lies on the plane, WALL_DEPTH deep behind it and 2 WALL_HALF_LENGTH
long along it, colliding by MuJoCo's contype/conaffinity rule with the bodies' geoms
(dm_control's reacher and point_mass arenas; a ceiling; an incline in the plane of motion).
A plane whose normal leaves the plane of motion without being normal to it stays a
ModelError (world.ground_plane).
"""
from __future__ import annotations

import math

import numpy as np

from .plane import is_wall
from .world import world_geoms

WALL_DEPTH = 1.0            # [m] a wall's box behind its plane
WALL_HALF_LENGTH = 100.0    # [m] a wall's box along its plane, each side of the plane's pos


def wall_shapes(world, plane_map, report) -> list:
    """(geom, ('box', centre, length, depth, angle)) for every wall of the world (`world`:
    the description's world body; `plane_map`: the PlaneMap; `report`: the LoadReport, which
    notes each wall)."""
    out, m = [], plane_map
    for g in world_geoms(world):
        if g["kind"] != "plane" or not is_wall(m, g):
            continue
        n3 = g["R"][:, 2]
        n = np.array([n3[m.i1], n3[m.i2]])
        n /= np.hypot(*n)
        centre = m.plane(g["pos"]) - 0.5 * WALL_DEPTH * n
        t = np.array([-n[1], n[0]])          # along the wall: the box's width axis
        angle = math.atan2(t[1], t[0])
        report.note(f"plane {g['name'] or g['node'].line!r} (normal {tuple(float(x) for x in np.round(n, 12))} "
                    f"in the plane of motion) is a wall: where it collides with a body's geom, a static "
                    f"box {WALL_DEPTH} m deep and {2 * WALL_HALF_LENGTH} m long behind it")
        out.append((g, ("box", centre, 2 * WALL_HALF_LENGTH, WALL_DEPTH, angle)))
    return out
