"""The SIMBICON character (Thachuk 2018, Table 2 / appendix A.1) loaded from its MJCF file.

``legs.xml`` (the thesis' MJCF character, shipped beside this file) goes through planarsim.mjcf: 7 rigid
bodies (torso with the hip spheres welded on; thigh + knee sphere; shin + ankle sphere; foot,
per side), 6 pins with the MJCF limits and passive stiffness/damping 5 N m/rad / 5 N m s/rad.
This module adds, with the public builder only:
  * a pin motor per joint, saturated at the params' torque limits;
  * the feet as box contacts (4 corners of the 0.3 x 0.15 m foot box, friction mu);
  * the start pose: the MJCF pose (legs straight, standing) raised so the soles touch y = 0.
The feet touch the ground through their corner contacts; the other geoms (torso, hip and knee
spheres, thigh and shin capsules) collide with it, so a fall leaves no part inside the ground;
``non_foot_clearance`` measures how close they come (the ankle spheres, which reach 2.5 cm
below the sole in the MJCF file, count as part of the foot, as in the thesis' contact test).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from planarsim import ModelBuilder
from planarsim.mjcf import load_mjcf
from planarsim.terrain import flat

from .params import SimbiconParams

XML = Path(__file__).resolve().parent / "legs.xml"
SIDES = ("right", "left")           # side 0 = right (swings first, Table 1), 1 = left
JOINTS = ("hip", "knee", "ankle")
_PIN_NAMES = {  # MJCF joint names of legs.xml per side (the file is not quite symmetric)
    "right": ("right_hip_to_right_thigh", "right_knee_to_right_shin", "right_ankle_to_right_foot"),
    "left": ("left_hip_to_left_thigh", "left_thigh_to_left_shin", "left_ankle_to_left_foot"),
}
# geoms that collide with the ground and with what a scene adds (a fall leaves no part inside
# the ground): all but the feet and the ankle spheres, which reach 2.5 cm below the sole (the
# feet's corner contacts hold the character up, as in the thesis' contact test)
COLLIDING_GEOMS = tuple(f"{side}_{part}_geom" for side in SIDES
                        for part in ("hip", "thigh", "knee", "shin")) + ("base",)
SOLE_DEPTH = 1.275   # [m] sole below the MJCF origin: foot box centre z = -1.2, half height 0.075
FOOT_BOX = (0.15, -1.2, 0.3, 0.15)   # MJCF foot box: centre x, z; width, height [m]


def build(params: SimbiconParams | None = None, terrain=None, dt: float = 1e-3):
    """Model of the character standing on `terrain` (default flat) at x = 0, its soles on the
    highest ground under them.

    Returns the compiled Model; ``model.meta`` holds the index maps the controller needs:
    torso, thigh[side], shin[side], foot[side], pin[side, joint], act[side, joint],
    contact[side, corner].
    """
    p = params if params is not None else SimbiconParams()
    terrain = terrain if terrain is not None else flat()
    # the soles rest on the highest ground under them (on hills the toe's ground may be
    # higher than the heel's: started at the heel's, the toe would begin below the ground)
    cx, _, w, _ = FOOT_BOX
    ground = float(max(terrain.height(x) for x in np.linspace(cx - w / 2, cx + w / 2, 9)))
    b = ModelBuilder(dt=dt, terrain=terrain)
    char = load_mjcf(XML, builder=b, offset=(0.0, ground + SOLE_DEPTH), collide=COLLIDING_GEOMS)
    limits = {"hip": p.hip_torque_max, "knee": p.knee_torque_max, "ankle": p.ankle_torque_max}
    pin = np.zeros((2, 3), np.int64)
    act = np.zeros((2, 3), np.int64)
    contact = np.zeros((2, 4), np.int64)
    for s, side in enumerate(SIDES):
        for j, joint in enumerate(JOINTS):
            pin[s, j] = char.pin[_PIN_NAMES[side][j]]
            tau = limits[joint]
            act[s, j] = b.add_pin_motor(f"{side}_{joint}", int(pin[s, j]), limit=(-tau, tau))
        foot = char.body[f"{side}_foot"]
        com = char.rigid[foot].com
        cx, cz, w, h = FOOT_BOX
        centre = (cx - com[0], cz + ground + SOLE_DEPTH - com[1])
        contact[s] = b.add_box_contacts(f"{side}_sole", foot, centre, w, h, mu=p.mu)
    meta = dict(walker="simbicon",
                torso=char.body["base"],
                thigh=np.array([char.body[f"{s}_thigh"] for s in SIDES]),
                shin=np.array([char.body[f"{s}_shin"] for s in SIDES]),
                foot=np.array([char.body[f"{s}_foot"] for s in SIDES]),
                pin=pin, act=act, contact=contact)
    return b.compile(**meta)


def start_state(model, lean: float = 0.0, speed: float = 0.0):
    """State at rest with both (straight) legs tilted forward by `lean` [rad] about the ankles,
    feet flat and the torso upright: the ankles are dorsiflexed by `lean`, the hips flexed by
    -lean, and the COM sits ahead of the ankles so the character starts to fall forward.
    `speed` [m/s] gives every body the same forward velocity (a walking start)."""
    from planarsim import make_state
    q = np.array(model.q0, dtype=np.float64)
    a = model.arrays
    c, s = np.cos(-lean), np.sin(-lean)
    rot = np.array([[c, -s], [s, c]])
    mt = model.meta
    hip = None
    for side in range(2):
        ankle_pin = mt["pin"][side, 2]
        ankle = model.q0[a.pin_body[ankle_pin, 1], :2] + a.pin_anchor[ankle_pin, 1]
        for body in (mt["thigh"][side], mt["shin"][side]):
            q[body, :2] = ankle + rot @ (model.q0[body, :2] - ankle)
            q[body, 2] = -lean
        hip_pin = mt["pin"][side, 0]
        hip = ankle + rot @ (model.q0[mt["torso"], :2] + a.pin_anchor[hip_pin, 0] - ankle)
    hip_pin = mt["pin"][0, 0]
    q[mt["torso"], :2] = hip - a.pin_anchor[hip_pin, 0]
    v = np.zeros_like(q)
    v[:, 0] = speed
    return make_state(model, q=q, v=v)


def non_foot_clearance(model, q) -> np.ndarray:
    """(K,) lowest height above the terrain [m] of every drawing shape that is not part of a
    foot (torso, hip and knee spheres, thigh and shin capsules) over frames q (K, n_body, 3).
    The ankle spheres belong to the foot. Negative: something other than a foot touched."""
    q = np.asarray(q)
    foot = set(int(i) for i in model.meta["foot"])
    shins = set(int(i) for i in model.meta["shin"])
    lowest = np.full(q.shape[0], np.inf)
    for shape in model.shapes:
        if shape.body in foot or shape.kind == "arc":
            continue
        x, y, th = q[:, shape.body, 0], q[:, shape.body, 1], q[:, shape.body, 2]
        c, s = np.cos(th), np.sin(th)
        if shape.kind == "circle":
            if shape.body in shins:
                continue          # the ankle sphere: part of the foot
            pts, r = [shape.params[0]], shape.params[1]
        elif shape.kind == "capsule":
            pts, r = [shape.params[0], shape.params[1]], shape.params[2]
        else:  # box
            (cx, cy), w, h = shape.params[0], shape.params[1], shape.params[2]
            pts, r = [(cx + sx * w / 2, cy + sy * h / 2) for sx in (-1, 1) for sy in (-1, 1)], 0.0
        for lx, ly in pts:
            px, py = x + c * lx - s * ly, y + s * lx + c * ly
            lowest = np.minimum(lowest, py - r - model.terrain.height(px))
    return lowest
