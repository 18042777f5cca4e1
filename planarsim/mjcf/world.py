"""The builder a file's model goes into (its timestep, in-plane gravity and ground) and the
world's ground plane."""
from __future__ import annotations

import numpy as np

from ..builder import ModelBuilder
from ..terrain import flat
from .plane import is_wall, vec
from .schema import AXIS_TOL, DEFAULT_GRAVITY, DEFAULT_TIMESTEP


def make_builder(option, plane_map, ground, report, builder_kw, builder):
    """A ModelBuilder with the file's timestep and in-plane gravity (<option>: `option`; the
    caller's builder or builder_kw win, noted in the report), and flat terrain from the
    ground plane `ground` ((geom, height) or None)."""
    dt = option.get("timestep", DEFAULT_TIMESTEP)
    g3 = np.asarray(option.get("gravity", DEFAULT_GRAVITY), dtype=np.float64)
    g = plane_map.in_plane(g3)
    if g3[plane_map.normal] != 0:
        report.note(f"gravity along the plane's normal ({g3[plane_map.normal]} m/s^2) is "
                    f"carried by the joints: the model cannot move that way")
    if builder is not None:
        if builder.dt != dt or tuple(np.asarray(builder.gravity, float)) != g:
            report.note(f"the caller's builder keeps dt={builder.dt} s and gravity="
                        f"{vec(builder.gravity)}; the file has dt={dt} s, gravity={g}")
        if ground is not None:
            report.note("the caller's builder keeps its terrain; the file's ground plane "
                        "is not applied")
        return builder
    kw = dict(dt=dt, gravity=g)
    if ground is not None:
        kw["terrain"] = flat(ground[1])
    for k, v in builder_kw.items():
        if k in kw and k != "terrain":
            report.note(f"{k}={v} given to load_mjcf overrides the file's {kw[k]}")
        kw[k] = v
    return ModelBuilder(**kw)


def ground_plane(world, plane_map, report, fail):
    """(geom, height [m]) of the world's plane that faces up in the plane of motion, or
    None. Planes parallel to the plane of motion are ignored (they meet nothing)."""
    found, m = None, plane_map
    for g in world_geoms(world):
        if g["kind"] != "plane":
            continue
        n = g["R"][:, 2]
        if abs(abs(n[m.normal]) - 1) <= AXIS_TOL:
            report.ignore("geom plane parallel to the plane of motion", g["node"].line)
            continue
        if is_wall(m, g):                     # a wall, a static box (walls.py)
            continue
        if abs(n[m.i2] - 1) > AXIS_TOL:
            fail(g["node"], f"a plane whose normal {vec(n)} is not the "
                            f"plane of motion's up is not supported")
        if found is not None:
            fail(g["node"], "a second ground plane is not supported")
        found = (g, float(m.plane(g["pos"])[1]))
    return found


def world_geoms(world):
    """Geoms of the world and of the bodies welded to it (no joint on the way)."""
    out, stack = [], [world]
    while stack:
        b = stack.pop()
        out += b.geoms
        stack += [c for c in b.children if not c.joints]
    return out
