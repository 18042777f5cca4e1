"""The planar quadruped (A1-like robot dog) on the public builder.

Bodies:   0 torso; leg i (0 FL, 1 FR, 2 RL, 3 RR): thigh 1 + 2i, calf 2 + 2i.
Pins:     hip of leg i = 2i (torso -> thigh), knee of leg i = 2i + 1 (thigh -> calf), with the
          A1's joint limits; pin angles as in params.py (ref_angle 0: absolute-angle differences).
Motors:   actuator j drives pin j (same order), torque [N m] saturated at +-torque_limit.
Contacts: foot i = a full-circle arc contact of radius foot_radius centred at the calf tip.
          Only the feet touch the ground (no torso or knee contacts): a torso below
          fall_height ends a run as a fall.
Left and right legs of one end share the hip point and overlap in the plane, like Ranger's
inner and outer legs; the diagonal pairs are (FL, RR) and (FR, RL) (PAIR below).
Build pose: standing, torso level at stand_height above the mean ground height under the hips,
every foot straight below its hip, resting on the ground.
"""
from __future__ import annotations

import math

import planarsim as ps
from planarsim.terrain import Terrain, flat

from .params import QuadrupedParams
from .puppet import leg_ik

# the walker's shapes touch what a scene adds (extras), not the ground: its feet are its
# contacts; its own parts never collide with each other (one mechanism)
OFF_GROUND = {"ground": False}

LEG_NAMES = ("FL", "FR", "RL", "RR")
N_LEG = 4
HIP_SIGN = (1, 1, -1, -1)        # hip at x = HIP_SIGN[i] * hip_x in the torso frame
PAIR = (0, 1, 1, 0)              # diagonal pair of each leg: (FL, RR) = 0, (FR, RL) = 1
BODY_TORSO = 0


def thigh_body(i: int) -> int:
    return 1 + 2 * i


def calf_body(i: int) -> int:
    return 2 + 2 * i


def hip_pin(i: int) -> int:
    return 2 * i


def knee_pin(i: int) -> int:
    return 2 * i + 1


def _dir(phi):
    return math.sin(phi), -math.cos(phi)


def foot_rest_height(p: QuadrupedParams, terrain: Terrain, x: float) -> float:
    """Height [m] of the centre of a round foot resting on the terrain near x: r / cos(slope)
    above the ground (exact on a constant slope)."""
    return float(terrain.height(x)) + p.foot_radius * math.sqrt(1.0 + float(terrain.slope(x)) ** 2)


def standing_angles(p: QuadrupedParams, drop: float | None = None):
    """Hip and knee angles [rad] with the foot centre straight below the hip, `drop` below it
    [m] (default stand_height - foot_radius)."""
    drop = p.stand_height - p.foot_radius if drop is None else drop
    q1, q2, flag = leg_ik(0.0, -drop, p.thigh_length, p.calf_length,
                          p.hip_lower, p.hip_upper, p.knee_lower, p.knee_upper)
    if flag:
        raise ValueError(f"QuadrupedParams: standing pose unreachable on this terrain (IK flag {flag}, "
                         f"hip {drop:.3f} m above the foot centre)")
    return q1, q2


def build(params: QuadrupedParams | None = None, terrain: Terrain | None = None, dt: float = 1e-3,
          x0: float = 0.0, extras=None) -> ps.Model:
    """Model of the quadruped standing with its torso COM above x0 [m] on `terrain`.
    extras(builder), if given, adds bodies and shapes after the walker's own (a box to push,
    an obstacle): the torso's box and the legs' capsules collide with their shapes (not with
    the ground: the feet are the dog's contacts)."""
    p = params if params is not None else QuadrupedParams()
    terrain = terrain if terrain is not None else flat()
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, -9.81), terrain=terrain)
    hips_x = [x0 + HIP_SIGN[i] * p.hip_x for i in range(N_LEG)]
    ty = 0.5 * (float(terrain.height(hips_x[0])) + float(terrain.height(hips_x[2]))) + p.stand_height
    b.add_body("torso", mass=p.torso_mass, inertia=p.torso_inertia, pos=(x0, ty), angle=0.0,
               shapes=[("box", (0.0, 0.0), p.torso_length, p.torso_height, OFF_GROUND)])
    l1, l2 = p.thigh_length, p.calf_length
    width = (0.018, 0.012)          # drawing: left legs a little thicker than right ones
    knees = []
    for i, name in enumerate(LEG_NAMES):
        hx, hy = hips_x[i], ty
        q1, q2 = standing_angles(p, hy - foot_rest_height(p, terrain, hx))
        d1, d12 = _dir(q1), _dir(q1 + q2)
        kx, ky = hx + l1 * d1[0], hy + l1 * d1[1]
        knees.append((kx, ky))
        w = width[i % 2]
        b.add_body(f"{name}_thigh", mass=p.thigh_mass, inertia=p.thigh_inertia + p.armature,
                   pos=(hx + p.thigh_com * d1[0], hy + p.thigh_com * d1[1]), angle=q1,
                   shapes=[("capsule", (0.0, p.thigh_com), (0.0, p.thigh_com - l1), w, OFF_GROUND)])
        b.add_body(f"{name}_calf", mass=p.calf_mass, inertia=p.calf_inertia + p.armature,
                   pos=(kx + p.calf_com * d12[0], ky + p.calf_com * d12[1]), angle=q1 + q2,
                   shapes=[("capsule", (0.0, p.calf_com), (0.0, p.calf_com - l2), 0.7 * w, OFF_GROUND)])
    for i, name in enumerate(LEG_NAMES):
        b.add_pin(f"{name}_hip", BODY_TORSO, thigh_body(i), anchor_world=(hips_x[i], ty), ref_angle=0.0,
                  limit=(p.hip_lower, p.hip_upper))
        b.add_pin(f"{name}_knee", thigh_body(i), calf_body(i), anchor_world=knees[i], ref_angle=0.0,
                  limit=(p.knee_lower, p.knee_upper))
    for i, name in enumerate(LEG_NAMES):
        for joint in ("hip", "knee"):
            b.add_pin_motor(f"{name}_{joint}_motor", f"{name}_{joint}",
                            limit=(-p.torque_limit, p.torque_limit))
    for i, name in enumerate(LEG_NAMES):
        b.add_arc_contact(f"{name}_foot", calf_body(i), center=(0.0, p.calf_com - l2),
                          radius=p.foot_radius, mu=p.friction)
    if extras is not None:
        extras(b)
    return b.compile(walker="quadruped")
