"""Which geoms collide, and with what: the caller's ``collide`` names, else MuJoCo's
contype/conaffinity filter; the shapes add_body and add_shape take."""
from __future__ import annotations

import numpy as np

from .schema import COLLIDES, DRAWN


def mj_pair(a, b) -> bool:
    """MuJoCo's filter: two geoms may touch when contype of one meets conaffinity of the other."""
    return bool((a["contype"] & b["conaffinity"]) or (b["contype"] & a["conaffinity"]))


class Collisions:
    """The collision options of a model's geoms. rigid: the RigidBody list (their parts'
    geoms, with a shape or None); static: (geom, shape) of the world's geoms; ground:
    (plane geom, height) or None; collide: None or the names of the geoms that collide;
    report: the LoadReport; fail(node, message) raises."""

    def __init__(self, rigid, static, ground, collide, report, fail):
        self.rigid, self.static, self.ground = rigid, static, ground
        self.collide, self.report, self.fail = collide, report, fail

    def body_geoms(self):
        return [p[5] for rb in self.rigid for p in rb.parts if p[3] is not None]

    def body_shape(self, s, g, com):
        """A shape tuple for add_body: relative to the COM, with add_shape's options."""
        how = self.collision(g)
        if s[0] == "circle":
            return ("circle", tuple(s[1] - com), s[2], how)
        if s[0] == "capsule":
            return ("capsule", tuple(s[1] - com), tuple(s[2] - com), s[3], how)
        if s[0] == "box":
            angle = () if s[4] == 0.0 else (s[4],)
            return ("box", tuple(s[1] - com), s[2], s[3], *angle, how)
        if len(s) > 2 and how.get("collide"):
            self.fail(g["node"], "an ellipsoid that collides is not supported (only drawn ones)")
        return ("polygon", [tuple(v - com) for v in s[1]], how)

    def collision(self, g):
        """add_shape options of a body geom: the caller's ``collide`` names, else MuJoCo's
        contype/conaffinity (ground contact with the ground plane, friction the larger of
        the two, none where both have condim 1)."""
        if self.collide is not None:
            return COLLIDES if g["name"] in self.collide else DRAWN
        ground = self.ground is not None and mj_pair(g, self.ground[0])
        others = [h for h, _ in self.static] + self.body_geoms()
        if not ground and not any(mj_pair(g, h) for h in others if h is not g):
            return dict(DRAWN)
        mu = g["mu"]
        if ground:
            plane = self.ground[0]
            mu = 0.0 if max(g["condim"], plane["condim"]) == 1 else max(mu, plane["mu"])
        return dict(collide=True, ground=ground, mu=mu, category=g["contype"],
                    mask=g["conaffinity"], name=g["name"] or None)

    def world_shape(self, builder, g, s):
        """A static geom that collides with some body geom -> a world shape; else ignored."""
        if self.collide is not None or not any(mj_pair(g, h) for h in self.body_geoms()):
            self.report.ignore("world geom that collides with nothing", g["node"].line)
            return
        if s[0] == "polygon" and len(s) > 2:
            self.fail(g["node"], "an ellipsoid that collides is not supported")
        params = [tuple(p) if isinstance(p, np.ndarray) else p for p in s[1:]]
        if s[0] == "polygon":
            params = [[tuple(v) for v in s[1]]]
        builder.add_shape(None, s[0], *params, mu=g["mu"], category=g["contype"],
                          mask=g["conaffinity"], name=g["name"] or None)

    def self_collisions(self, bodies):
        """Note pairs of one tree that MuJoCo may collide (not parent and child) and planarsim
        does not (bodies linked by joints never collide here)."""
        if self.collide is not None:
            return

        def tree_of(b):               # the first body below the world (or what is welded to it)
            while b.parent is not None and b.parent.rid is not None:
                b = b.parent
            return b.name
        parent = {b.rid: (b.parent.rid if b.parent is not None else None)
                  for b in bodies if b.joints}
        geoms = [(rid, p[5]) for rid, rb in enumerate(self.rigid) for p in rb.parts if p[3] is not None]
        # bodies of separate trees (joined only through the world) do collide in planarsim
        tree = {b.rid: tree_of(b) for b in bodies if b.rid is not None}
        for i, (ra, ga) in enumerate(geoms):
            for rb_, gb in geoms[i + 1:]:
                if ra == rb_ or parent.get(ra) == rb_ or parent.get(rb_) == ra:
                    continue
                if tree[ra] != tree[rb_]:
                    continue
                if mj_pair(ga, gb):
                    self.report.note(f"geoms {ga['name'] or ga['node'].line!r} and "
                                     f"{gb['name'] or gb['node'].line!r} may touch in MuJoCo; "
                                     f"planarsim's bodies linked by joints do not collide")
