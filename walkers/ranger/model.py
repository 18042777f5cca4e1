"""Ranger as four rigid bodies on the public builder (Kelly 2014, section 5).

Bodies: 0 outer leg, 1 inner leg, 2 outer foot, 3 inner foot (side s: leg s, foot 2 + s).
Pins:   0 hip (outer -> inner: angle = theta_inner - theta_outer), 1 + s ankle of side s
        (leg -> foot: angle = theta_foot - theta_leg). All pin angles are 0 with every body at
        angle 0 (legs vertical, feet level): ref_angle = 0.
Feet:   circular-arc soles (radius 0.2 m, centre 0.14 m above the ankle on a level foot) with
        the back corner and the top of Kelly's foot outline as fallback vertices; the arc ends
        are the heel and the toe. contact s is the sole of foot s.
Motors: 0 hip, 1 + s ankle of side s: pin torques [N m], saturated at the peak torques.
Springs: the parallel springs of ranger.md are passive pin springs.
Rotor inertia (light feet behind heavy legs): with rotor_on_foot = 1 the ankle
rotor's reflected inertia G^2 Jm (0.00185 kg m^2, as large as the foot's own 0.002) is added to
the foot body as an armature. Exact for the foot's rotation relative to a leg that does not
rotate; the error is the leg's angular velocity times G^2 Jm, against the leg's 0.45 kg m^2
(< 0.5 %). The hip rotor's G^2 Jm = 0.007 kg m^2 is 1.5 % of a leg's inertia and is left out.
"""
from __future__ import annotations

import math

import numpy as np

import planarsim as ps
from planarsim.terrain import flat

from .params import RangerParams

# the shapes only draw the walker: its feet are its contacts
DRAWN = {"collide": False}
# [m/s^2] the model's gravity, straight down (the controller's tables are made with the
# model's: Run passes model.arrays.gravity's magnitude)
GRAVITY = 9.81

OUTER, INNER = 0, 1
LEG = (0, 1)             # body of the leg of side s
FOOT = (2, 3)            # body of the foot of side s
ANKLE_PIN = (1, 2)       # pin of the ankle of side s


def foot_inertia_com(p: RangerParams) -> float:
    """Foot inertia about its COM incl. the reflected ankle rotor when rotor_on_foot [kg m^2]."""
    i_com = p.foot_inertia - p.foot_mass * (p.foot_com_x ** 2 + p.foot_com_y ** 2)
    return i_com + p.rotor_on_foot * p.ankle_gear ** 2 * p.rotor_inertia


def _pose_misfit(terrain, hip_x: float, x_rear: float, what: str) -> str:
    """The error text of a standing pose that does not fit: on flat ground the parameters are
    to blame, elsewhere the terrain's rise between the feet [m] is named too."""
    if not np.any(terrain.coef[2:]) and terrain.coef[1] == 0.0:
        return f"RangerParams: {what}"
    rise = float(terrain.height(0.0)) - float(terrain.height(x_rear))
    return (f"Ranger cannot stand at x = 0 on terrain {terrain.name!r}: the ground rises {rise:+.3f} m "
            f"from the rear foot to the front foot, and {what}. Ranger walks on flat ground "
            "(its controller has no terrain estimate)")


def standing_pose(p: RangerParams, terrain=None):
    """The STAND pose at rest with both feet on the ground: front (inner) leg at
    stand_front_angle with its foot level, rear (outer) leg at stand_rear_angle with its foot
    turned toe down on its sole until it touches. Every gait starts from it (WALK through the
    controller's START phase).
    Returns (hip_xy, leg angles (outer, inner), foot angles (outer, inner))."""
    terrain = terrain if terrain is not None else flat()
    pose = "stand"
    L, r, d = p.leg_length, p.sole_radius, p.sole_center_height
    th_front, th_rear = p.stand_front_angle, p.stand_rear_angle
    hip_x = -L * math.sin(th_front)                # front ankle at x = 0
    hip_y = float(terrain.height(0.0)) + (r - d) + L * math.cos(th_front)
    x_rear = hip_x + L * math.sin(th_rear)
    h_rear = hip_y - L * math.cos(th_rear) - float(terrain.height(x_rear))   # rear ankle height
    # lowest sole point of a foot turned by phi (toe down < 0): r - d cos(phi) below the ankle
    c = (r - h_rear) / d
    if not -1.0 < c <= 1.0 or h_rear < r - d - 1e-12:
        raise ValueError(_pose_misfit(terrain, hip_x, x_rear,
                                      f"{pose}_rear_angle={th_rear} and {pose}_front_angle={th_front} "
                                      f"put the rear ankle {h_rear:.3f} m above the ground; the foot "
                                      f"reaches {r - d:.3f}..{r:.3f} m"))
    phi_rear = -math.acos(min(c, 1.0))
    if -math.pi / 2 - phi_rear > p.sole_span_front:
        raise ValueError(_pose_misfit(terrain, hip_x, x_rear,
                                      f"the rear foot would need {phi_rear:.3f} rad toe down, past its toe"))
    return np.array([hip_x, hip_y]), (th_rear, th_front), (phi_rear, 0.0)


def build(p: RangerParams | None = None, terrain=None, dt: float = 1e-3, suspended: bool = False) -> ps.Model:
    """Compile the Ranger model in the STAND pose (see standing_pose).

    suspended : lift the robot 0.3 m and pin its hip to the world (a test stand; GUI test).
    """
    p = p if p is not None else RangerParams()
    terrain = terrain if terrain is not None else flat()
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, -GRAVITY), terrain=terrain)
    hip, angles, foot_angles = standing_pose(p, terrain)
    if suspended:
        hip = hip + np.array([0.0, 0.3])       # on the test stand the feet hang 0.3 m up
    L, c = p.leg_length, p.leg_com
    ankles = []
    for s, th in enumerate(angles):
        d = np.array([math.sin(th), -math.cos(th)])
        com = hip + c * d
        b.add_body(("outer_leg", "inner_leg")[s], mass=p.leg_mass, inertia=p.leg_inertia,
                   pos=tuple(com), angle=th,
                   shapes=[("capsule", (0.0, c), (0.0, c - L), 0.025 if s == 0 else 0.018, DRAWN)])
        ankles.append(hip + L * d)
    fx, fy = p.foot_com_x, p.foot_com_y
    i_foot = foot_inertia_com(p)
    if i_foot <= 0:
        raise ValueError(f"RangerParams: foot inertia about its COM {i_foot} <= 0; move the COM closer "
                         f"to the ankle or raise foot_inertia")
    for s in range(2):
        cf, sf = math.cos(foot_angles[s]), math.sin(foot_angles[s])
        b.add_body(("outer_foot", "inner_foot")[s], mass=p.foot_mass, inertia=i_foot,
                   pos=(ankles[s][0] + cf * fx - sf * fy, ankles[s][1] + sf * fx + cf * fy),
                   angle=foot_angles[s])
    b.add_pin("hip", LEG[OUTER], LEG[INNER], anchor_world=tuple(hip), ref_angle=0.0,
              stiffness=p.hip_spring, rest_angle=p.hip_spring_rest)
    for s in range(2):
        b.add_pin(("outer_ankle", "inner_ankle")[s], LEG[s], FOOT[s], anchor_world=tuple(ankles[s]),
                  ref_angle=0.0, stiffness=p.ankle_spring,
                  rest_angle=p.ankle_spring_rest - p.ankle_offset)
    for s in range(2):
        ax, ay = -fx, -fy                          # ankle in the foot frame
        verts = [(ax + p.foot_back_x, ay + p.foot_back_y), (ax + p.foot_top_x, ay + p.foot_top_y)]
        b.add_arc_contact(("outer_sole", "inner_sole")[s], FOOT[s], center=(ax, ay + p.sole_center_height),
                          radius=p.sole_radius, span=(p.sole_span_back, p.sole_span_front),
                          vertices=verts, mu=p.friction)
    b.add_pin_motor("hip_motor", "hip", limit=(-p.hip_torque_peak, p.hip_torque_peak))
    for s in range(2):
        b.add_pin_motor(("outer_ankle_motor", "inner_ankle_motor")[s], ANKLE_PIN[s] ,
                        limit=(-p.ankle_torque_peak, p.ankle_torque_peak))
    if suspended:
        b.add_pin("test_stand", None, LEG[OUTER], anchor_world=tuple(hip))
    return b.compile(walker="ranger")
