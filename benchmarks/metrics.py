"""Engine-neutral description of a benchmark scene, and the accuracy figures computed from
recorded poses so that every engine (planarsim and its peers) is judged by the same code.

A `SceneSpec` is read off the planarsim model of the scene (scenes.py): body masses,
inertias and start poses, the boxes given by each body's four corner contacts, and the pins
with their local anchors. Peers build their native scene from it (peers/mujoco_peer.py,
peers/pymunk_peer.py, peers/box2d_peer.py), so the initial conditions are identical by construction.

Recorded runs are arrays in planarsim's conventions: q (K, n_body, 3) = centre of mass x, y [m]
and angle theta [rad, counter-clockwise]; v (K, n_body, 3) = COM velocity [m/s] and angular
velocity [rad/s]. Frame 0 is the start state.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from benchmarks.scenes import G

#: episode of the timing runs and of the accuracy runs per scene kind [s] (scenes.py; a
#: family of sizes, chainN or box_columnN, by its prefix: scene_seconds)
ACCURACY_SECONDS = {"chain": 10.0, "biped_collapse": 3.0, "rod_drop": 2.0, "box_column": 10.0,
                    "box_pyramid": 10.0, "box_piles": 10.0}
#: scenes that the peers build (the chains N = 2..64, the biped collapse, the rod drop, the
#: box columns N = 5..40, the 20-box pyramid and five 10-box piles, whose boxes collide with
#: each other)
PEER_SCENES = ("chain2", "chain4", "chain8", "chain16", "chain32", "chain64", "biped_collapse", "rod_drop",
               "box_column5", "box_column10", "box_column20", "box_column40", "box_pyramid", "box_piles")


def scene_seconds(name: str) -> float:
    """The accuracy run's length [s] of peer scene `name` (ACCURACY_SECONDS, sizes by prefix)."""
    for family in ("chain", "box_column"):
        if name.startswith(family):
            return ACCURACY_SECONDS[family]
    return ACCURACY_SECONDS[name]


@dataclass(frozen=True)
class SceneSpec:
    """One benchmark scene in engine-neutral form (SI units, planarsim conventions).

    mass, inertia : (n_body,) [kg], [kg m^2] about the COM
    q0 : (n_body, 3) start poses (COM x, y [m], angle [rad]); the bodies start at rest
    box : (n_body, 2) width, height [m] of a box centred on the COM (nan: no collision shape)
    pin_body : (n_pin, 2) int body a, body b (-1: world)
    pin_anchor : (n_pin, 2, 2) local anchors on a and b (world coordinates for -1) [m]
    ground : True when a flat ground at y = 0 is present (friction 1, restitution 0)
    bodies_collide : the boxes collide with each other (stacks); else only with the ground
    """
    name: str
    dt: float
    mass: np.ndarray
    inertia: np.ndarray
    q0: np.ndarray
    box: np.ndarray
    pin_body: np.ndarray
    pin_anchor: np.ndarray
    ground: bool
    seconds: float
    energy_scale: float
    bodies_collide: bool = False

    @property
    def n_body(self) -> int:
        return len(self.mass)

    @property
    def kind(self) -> str:
        return "chain" if self.name.startswith("chain") else self.name


def spec_from_model(name: str, model, seconds: float) -> SceneSpec:
    """Read a SceneSpec off a planarsim Model built by scenes.py (boxes from the corner
    contacts of each body; energy scale of the bench scenes for chains, else the potential
    energy of the start pose above the lowest body point)."""
    a = model.arrays
    nb = model.n_body
    box = np.full((nb, 2), np.nan)
    pair = a.contact_kind == 2          # a shape pair's contacts: the boxes touch each other
    for body in range(nb):
        pts = a.contact_local[(a.contact_body == body) & ~pair]
        if len(pts) == 4:
            if np.abs(pts.mean(axis=0)).max() > 1e-12:
                raise ValueError(f"scene {name!r}: box of body {model.body_names[body]!r} is not centred on its COM")
            box[body] = pts.max(axis=0) - pts.min(axis=0)
        elif len(pts):
            raise ValueError(f"scene {name!r}: body {model.body_names[body]!r} has {len(pts)} contacts, "
                             "peers only build boxes (4 corner contacts)")
    if name.startswith("chain"):
        length = 2.0 * float(np.hypot(*a.pin_anchor[0, 1]))  # link 0 hangs from its end
        scale = G * length * float(sum(a.body_mass[i] * (i + 0.5) for i in range(nb)))
    else:
        scale = float(np.sum(a.body_mass * model.q0[:, 1]) * G)
    return SceneSpec(name=name, dt=float(a.dt), mass=a.body_mass.copy(), inertia=a.body_inertia.copy(),
                     q0=model.q0.copy(), box=box, pin_body=a.pin_body.copy(), pin_anchor=a.pin_anchor.copy(),
                     ground=bool(len(a.contact_body)), seconds=seconds, energy_scale=scale,
                     bodies_collide=bool(pair.any()))


def world_points(q, body, local):
    """World position (K, 2) of the body-frame point `local` of `body` in frames q (K, nb, 3);
    body -1 means the world (local is then already a world point)."""
    if body < 0:
        return np.broadcast_to(np.asarray(local, float), (q.shape[0], 2))
    c, s = np.cos(q[:, body, 2]), np.sin(q[:, body, 2])
    lx, ly = local
    return np.stack([q[:, body, 0] + c * lx - s * ly, q[:, body, 1] + s * lx + c * ly], axis=1)


def pin_separation(spec: SceneSpec, q) -> float:
    """Largest distance between the two attachment points of any pin over the frames [m]."""
    worst = 0.0
    for j in range(len(spec.pin_body)):
        pa = world_points(q, spec.pin_body[j, 0], spec.pin_anchor[j, 0])
        pb = world_points(q, spec.pin_body[j, 1], spec.pin_anchor[j, 1])
        worst = max(worst, float(np.max(np.hypot(*(pb - pa).T))))
    return worst


def lowest_point(spec: SceneSpec, q) -> np.ndarray:
    """(K,) height of the lowest box corner of any body above the ground y = 0 [m]."""
    low = np.full(q.shape[0], np.inf)
    for body in range(spec.n_body):
        w, h = spec.box[body]
        if np.isnan(w):
            continue
        for dx in (-w / 2, w / 2):
            for dy in (-h / 2, h / 2):
                low = np.minimum(low, world_points(q, body, (dx, dy))[:, 1])
    return low


def kinetic(mass, inertia, v) -> np.ndarray:
    """(K,) kinetic energy [J] of velocities v (K, n_body, 3) (or () of one frame (n_body, 3))
    of bodies of `mass` [kg] and `inertia` [kg m^2] (n_body,)."""
    return 0.5 * np.sum(mass * (v[..., 0] ** 2 + v[..., 1] ** 2) + inertia * v[..., 2] ** 2, axis=-1)


def energy(spec: SceneSpec, q, v) -> np.ndarray:
    """(K,) kinetic + gravitational potential energy [J]."""
    return kinetic(spec.mass, spec.inertia, v) + G * np.sum(spec.mass * q[..., 1], axis=-1)


def accuracy(spec: SceneSpec, q, v) -> dict:
    """Accuracy figures of a recorded run (frame 0 = start, frames every dt).

    pin_error_m: largest pin separation; energy_drift: (E_end - E_0) / scale (signed) and
    energy_err_max: max |E - E_0| / scale (the scene's energy scale); penetration_m: largest
    depth of a box corner below the ground; rest_gap_m: lowest corner height at the end
    (positive: the body hovers). Rod drop adds impact_speed, rebound_speed [m/s] and
    time_to_rest [s] (all speeds of any point below 1 cm/s from then on; nan if never).
    """
    out = {"pin_error_m": pin_separation(spec, q) if len(spec.pin_body) else math.nan}
    e = energy(spec, q, v)
    out["energy_drift"] = float((e[-1] - e[0]) / spec.energy_scale)
    out["energy_err_max"] = float(np.max(np.abs(e - e[0])) / spec.energy_scale)
    if spec.ground:
        low = lowest_point(spec, q)
        out["penetration_m"] = float(max(0.0, -np.min(low)))
        out["rest_gap_m"] = float(low[-1])
    if spec.bodies_collide:
        # stacks start at rest, touching: any move is a sink or a slide (a stack's accuracy)
        out["stack_drift_m"] = float(np.max(np.hypot(q[..., 0] - q[0, :, 0], q[..., 1] - q[0, :, 1])))
    if spec.name == "rod_drop":
        vy = v[:, 0, 1]
        k_impact = int(np.argmin(vy))
        out["impact_speed"] = float(-vy[k_impact])
        out["rebound_speed"] = float(max(0.0, np.max(vy[k_impact:])))
        half = float(np.nanmax(spec.box[0])) / 2
        moving = np.maximum(np.hypot(v[:, 0, 0], v[:, 0, 1]), np.abs(v[:, 0, 2]) * half) > 0.01
        moving[:k_impact] = True
        last = np.nonzero(moving)[0]
        k_rest = int(last[-1]) + 1 if len(last) else 0
        out["time_to_rest"] = k_rest * spec.dt if k_rest < len(vy) else math.nan
    return out
