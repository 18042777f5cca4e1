"""Named benchmark scenes (each peer engine builds the same ones), shared with tests and examples."""
from __future__ import annotations

import math

import numpy as np

import planarsim as ps
from planarsim import terrain

G = 9.81
# the shapes only draw these scenes: their contacts are added one by one
DRAWN = {"collide": False}


def chain(n_links=4, dt=1e-3, length=0.5, mass=1.0):
    """Pendulum chain: N thin rods 0.5 m, 1 kg, pinned end to end, link 0 to the world, all
    horizontal at rest."""
    b = ps.ModelBuilder(dt=dt)
    prev = None
    for i in range(n_links):
        body = b.add_body(f"link{i}", mass=mass, inertia=mass * length ** 2 / 12,
                          pos=((i + 0.5) * length, 0.0),
                          shapes=[("capsule", (-length / 2, 0.0), (length / 2, 0.0), 0.02, DRAWN)])
        b.add_pin(f"pin{i}", prev, body, anchor_world=(i * length, 0.0))
        prev = body
    return b.compile()


def rod_drop(dt=1e-3):
    """A 1 m x 0.05 m, 1 kg box, horizontal, bottom face 0.5 m above flat ground."""
    b = ps.ModelBuilder(dt=dt)
    rod = b.add_body("rod", mass=1.0, inertia=(1.0 + 0.05 ** 2) / 12, pos=(0.0, 0.525))
    b.add_box_contacts("rod", rod, (0.0, 0.0), 1.0, 0.05, mu=1.0)
    return b.compile()


def boxes_on_hills(n=10, dt=1e-3):
    """Ten 0.4 x 0.2 m boxes resting on sine hills (a contact-heavy scene: 40 contacts)."""
    ter = terrain.hills([0.1], [4.0], [0.0])
    b = ps.ModelBuilder(dt=dt, terrain=ter)
    for i in range(n):
        x = 1.3 * i
        # 2 cm above the ground under its centre and its corners (in a trough the corners'
        # ground is the higher: a box set by its centre alone would start inside the hill)
        ground = float(np.max(ter.height(np.array([x - 0.2, x, x + 0.2]))))
        box = b.add_body(f"box{i}", mass=3.0, inertia=3.0 * (0.16 + 0.04) / 12,
                         pos=(x, ground + 0.12))
        b.add_box_contacts(f"box{i}", box, (0.0, 0.0), 0.4, 0.2, mu=1.0)
    return b.compile()


def biped_collapse(dt=1e-3):
    """The planar 7-link biped collapsing onto flat ground (no actuators)."""
    b = ps.ModelBuilder(dt=dt)
    def box_inertia(m, w, h):
        return m * (w * w + h * h) / 12
    # joint angles (hip, knee, ankle) per leg; world angle of each segment accumulates them
    legs = {"L": (0.25, -0.5, 0.25), "R": (0.05, -0.30, 0.25)}
    hip_y = 0.05 + 0.45 + 0.45 + 0.001 + 0.05  # rough standing height; recomputed below
    segs = {}
    # compute the pose from the ankle-flat condition: place hips so the lowest foot is 1 mm up
    poses = {}
    lowest = math.inf
    for side, (qh, qk, qa) in legs.items():
        th_thigh = qh
        th_shin = qh + qk
        th_foot = th_shin + qa
        hip = (0.0, 0.0)
        knee = (hip[0] + 0.45 * math.sin(th_thigh), hip[1] - 0.45 * math.cos(th_thigh))
        ankle = (knee[0] + 0.45 * math.sin(th_shin), knee[1] - 0.45 * math.cos(th_shin))
        c, s = math.cos(th_foot), math.sin(th_foot)
        foot_c = (ankle[0] + c * 0.05 + s * 0.025, ankle[1] + s * 0.05 - c * 0.025)
        for dx in (-0.1, 0.1):
            for dy in (-0.025, 0.025):
                lowest = min(lowest, foot_c[1] + s * dx + c * dy)
        poses[side] = (th_thigh, th_shin, th_foot, hip, knee, ankle, foot_c)
    lift = 0.001 - lowest
    torso = b.add_body("torso", 15.0, box_inertia(15.0, 0.2, 0.8), pos=(0.0, lift + 0.4),
                       shapes=[("box", (0.0, 0.0), 0.2, 0.8, 0.0, DRAWN)])
    b.add_box_contacts("torso_c", torso, (0.0, 0.0), 0.2, 0.8)
    for side, (tt, ts, tf, hip, knee, ankle, foot_c) in poses.items():
        def mid(p, q):
            return ((p[0] + q[0]) / 2, (p[1] + q[1]) / 2 + lift)
        thigh = b.add_body(f"thigh_{side}", 7.0, box_inertia(7.0, 0.08, 0.45), pos=mid(hip, knee), angle=tt,
                           shapes=[("box", (0.0, 0.0), 0.08, 0.45, 0.0, DRAWN)])
        shin = b.add_body(f"shin_{side}", 5.0, box_inertia(5.0, 0.08, 0.45), pos=mid(knee, ankle), angle=ts,
                          shapes=[("box", (0.0, 0.0), 0.08, 0.45, 0.0, DRAWN)])
        foot = b.add_body(f"foot_{side}", 1.0, box_inertia(1.0, 0.2, 0.05),
                          pos=(foot_c[0], foot_c[1] + lift), angle=tf,
                          shapes=[("box", (0.0, 0.0), 0.2, 0.05, 0.0, DRAWN)])
        b.add_pin(f"hip_{side}", torso, thigh, anchor_world=(hip[0], hip[1] + lift))
        b.add_pin(f"knee_{side}", thigh, shin, anchor_world=(knee[0], knee[1] + lift))
        b.add_pin(f"ankle_{side}", shin, foot, anchor_world=(ankle[0], ankle[1] + lift))
        for body, (w, h) in ((thigh, (0.08, 0.45)), (shin, (0.08, 0.45)), (foot, (0.2, 0.05))):
            b.add_box_contacts(f"{b._bodies[body]['name']}_c", body, (0.0, 0.0), w, h)
    return b.compile()


SCENES = {
    "chain2": (lambda: chain(2), 5000),
    "chain4": (lambda: chain(4), 5000),
    "chain8": (lambda: chain(8), 5000),
    "chain16": (lambda: chain(16), 5000),
    "chain32": (lambda: chain(32), 5000),
    "chain64": (lambda: chain(64), 5000),
    "rod_drop": (rod_drop, 2000),
    "boxes_on_hills": (boxes_on_hills, 2000),
    "biped_collapse": (biped_collapse, 3000),
}


# ---- shapes that collide -------------------------------------------------------------------
BOX_W, BOX_H = 0.4, 0.2     # [m]


def _box(b, name, x, y, mass=1.0, mu=0.6, angle=0.0):
    return b.add_body(name, mass, mass * (BOX_W ** 2 + BOX_H ** 2) / 12, pos=(x, y), angle=angle,
                      shapes=[("box", (0.0, 0.0), BOX_W, BOX_H, {"mu": mu})])


def box_column(n=10, dt=1e-3):
    """N boxes 0.4 x 0.2 m, 1 kg, stacked at rest on flat ground."""
    b = ps.ModelBuilder(dt=dt)
    for k in range(n):
        _box(b, f"box{k}", 0.0, BOX_H / 2 + k * BOX_H)
    return b.compile()


def box_pyramid(dt=1e-3):
    """20 boxes in rows of 6, 5, 4, 3, 2, at rest on flat ground (2 cm between neighbours)."""
    b = ps.ModelBuilder(dt=dt)
    k = 0
    for level, n in enumerate((6, 5, 4, 3, 2)):
        for j in range(n):
            _box(b, f"box{k}", (j - (n - 1) / 2) * (BOX_W + 0.02), BOX_H / 2 + level * BOX_H)
            k += 1
    return b.compile()


def box_piles(piles=5, n=10, dt=1e-3):
    """`piles` separate columns of n boxes, 1 m apart (separate islands)."""
    b = ps.ModelBuilder(dt=dt)
    for p in range(piles):
        for k in range(n):
            _box(b, f"box{p}_{k}", 1.0 * p, BOX_H / 2 + k * BOX_H)
    return b.compile()


def box_drop(dt=1e-3, piles=1):
    """Ten boxes dropped from 0.5-4.1 m, tilted and offset, onto each other and the ground;
    `piles` such drops 3 m apart (separate islands). 0.4 m apart: tilted by up to 0.6 rad a
    box reaches 0.195 m above and below its centre, so none starts inside another."""
    b = ps.ModelBuilder(dt=dt)
    for p in range(piles):
        for k in range(10):
            name = f"box{k}" if piles == 1 else f"box{p}_{k}"
            _box(b, name, 3.0 * p + 0.07 * ((k * 37) % 7 - 3), 0.5 + 0.4 * k,
                 angle=0.3 * ((k * 53) % 5 - 2))
    return b.compile()


# the box columns all run the same 2 s (their first steps settle the stack, one level per
# linear solve: a shorter run would weigh that start more at larger N)
SCENES.update({
    "box_column5": (lambda: box_column(5), 2000),
    "box_column10": (lambda: box_column(10), 2000),
    "box_column20": (lambda: box_column(20), 2000),
    "box_column40": (lambda: box_column(40), 2000),
    "box_pyramid": (box_pyramid, 1000),
    "box_piles": (box_piles, 1000),
    "box_drop": (box_drop, 2000),
    "box_drops5": (lambda: box_drop(piles=5), 2000),
})
