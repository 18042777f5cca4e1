"""The kinematic puppet of the 2023 robot-dog post: analytic two-link inverse kinematics of a leg and the
puppet's joint angles from foot targets and a torso pose (compiled).

Leg geometry (params.py convention): a segment at absolute angle phi points along
d(phi) = (sin phi, -cos phi). With hip angle q1 (thigh relative to the torso) and knee angle
q2 (calf relative to the thigh), the foot centre relative to the hip, in the torso frame, is

    f(q1, q2) = l1 d(q1) + l2 d(q1 + q2)                                   (FK)

Inverse (knee behind the hip-foot line, q2 > 0, as the A1's):
    D^2 = x^2 + y^2,   cos q2 = (D^2 - l1^2 - l2^2) / (2 l1 l2)
    q1 = atan2(x, -y) - atan2(l2 sin q2, l1 + l2 cos q2)                  (IK)
Reach: D in [D(knee_upper), D(knee_lower)], D(q) = sqrt(l1^2 + l2^2 + 2 l1 l2 cos q).
A target outside (by more than REACH_TOL, rounding) is moved along its ray from the hip to the nearest reachable distance
(straight down if it is at the hip) and reported in a flag; a hip angle beyond its limit (by
more than ANGLE_TOL) is clamped and reported. Flags (bits): IK_FAR 1, IK_NEAR 2, IK_HIP_LIMIT 4, IK_NOT_FINITE 8.
A non-finite target gives the leg's folded-under pose with IK_NOT_FINITE; the result is never NaN.
Lengths [m], angles [rad].
"""
from __future__ import annotations

import math

import numpy as np

from planarsim.compiled import jit

IK_OK, IK_FAR, IK_NEAR, IK_HIP_LIMIT, IK_NOT_FINITE = 0, 1, 2, 4, 8
REACH_TOL = 1e-12   # [m]
ANGLE_TOL = 1e-12   # [rad]


@jit
def leg_fk(q1, q2, l1, l2):
    """Foot centre (x, y) relative to the hip in the torso frame [m] (FK above)."""
    a = q1 + q2
    return l1 * math.sin(q1) + l2 * math.sin(a), -l1 * math.cos(q1) - l2 * math.cos(a)


@jit
def leg_ik(x, y, l1, l2, hip_lo, hip_hi, knee_lo, knee_hi):
    """Joint angles (q1, q2) [rad] putting the foot centre at (x, y) [m] relative to the hip
    (torso frame), and the flag word (0: exact)."""
    flag = IK_OK
    if not (math.isfinite(x) and math.isfinite(y)):
        return min(max(0.0, hip_lo), hip_hi), knee_hi, IK_NOT_FINITE
    d_far = math.sqrt(l1 * l1 + l2 * l2 + 2.0 * l1 * l2 * math.cos(knee_lo))
    d_near = math.sqrt(l1 * l1 + l2 * l2 + 2.0 * l1 * l2 * math.cos(knee_hi))
    d = math.sqrt(x * x + y * y)
    # a target within REACH_TOL of the boundary (rounding) is moved but not flagged
    if d > d_far:
        if d > d_far + REACH_TOL:
            flag |= IK_FAR
        x, y, d = x * d_far / d, y * d_far / d, d_far
    elif d < d_near:
        if d < d_near - REACH_TOL:
            flag |= IK_NEAR
        if d > 1e-12:
            x, y = x * d_near / d, y * d_near / d
        else:
            x, y = 0.0, -d_near
        d = d_near
    c = (d * d - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)
    c = min(max(c, -1.0), 1.0)
    q2 = math.atan2(math.sqrt(1.0 - c * c), c)
    q2 = min(max(q2, knee_lo), knee_hi)   # rounding only: d is inside the reach
    s2 = math.sin(q2)
    q1 = math.atan2(x, -y) - math.atan2(l2 * s2, l1 + l2 * math.cos(q2))
    # the same direction may come out one turn off the limits' branch (a hip angle at a limit
    # may land a rounding error beyond it after the turn: ANGLE_TOL, as below)
    if q1 > hip_hi and q1 - 2.0 * math.pi >= hip_lo - ANGLE_TOL:
        q1 -= 2.0 * math.pi
    elif q1 < hip_lo and q1 + 2.0 * math.pi <= hip_hi + ANGLE_TOL:
        q1 += 2.0 * math.pi
    if q1 > hip_hi:
        if q1 > hip_hi + ANGLE_TOL:
            flag |= IK_HIP_LIMIT
        q1 = hip_hi
    elif q1 < hip_lo:
        if q1 < hip_lo - ANGLE_TOL:
            flag |= IK_HIP_LIMIT
        q1 = hip_lo
    return q1, q2, flag


@jit
def hip_world(tx, ty, th, hip_dx):
    """World position of a hip pin at torso-frame offset (hip_dx, 0) [m] of a torso at
    (tx, ty, th) [m, m, rad]."""
    return tx + math.cos(th) * hip_dx, ty + math.sin(th) * hip_dx


@jit
def leg_angles_for(foot_x, foot_y, tx, ty, th, hip_dx, l1, l2, hip_lo, hip_hi, knee_lo, knee_hi):
    """The puppet's leg: joint angles (q1, q2, flag) that put the foot centre at the world point
    (foot_x, foot_y) [m] for a torso at (tx, ty, th)."""
    hx, hy = hip_world(tx, ty, th, hip_dx)
    dx, dy = foot_x - hx, foot_y - hy
    c, s = math.cos(th), math.sin(th)
    return leg_ik(c * dx + s * dy, -s * dx + c * dy, l1, l2, hip_lo, hip_hi, knee_lo, knee_hi)


@jit
def pose_puppet(tx, ty, th, feet, hip_dx, l1, l2, hip_lo, hip_hi, knee_lo, knee_hi, q_out, flags_out):
    """Pose the whole puppet: feet (n_leg, 2) world foot-centre targets [m], torso pose
    (tx, ty, th), hip offsets hip_dx (n_leg,) [m]. Writes q_out (n_leg, 2) = (hip, knee) [rad]
    and flags_out (n_leg,). Returns the OR of all flags."""
    all_flags = 0
    for i in range(feet.shape[0]):
        q1, q2, f = leg_angles_for(feet[i, 0], feet[i, 1], tx, ty, th, hip_dx[i], l1, l2,
                                   hip_lo, hip_hi, knee_lo, knee_hi)
        q_out[i, 0] = q1
        q_out[i, 1] = q2
        flags_out[i] = f
        all_flags |= f
    return all_flags


def puppet_pose(params, torso_pose, feet):
    """Python front end: joint angles (n_leg, 2) [rad] and IK flags (n_leg,) of the puppet with
    the torso at torso_pose (x, y, pitch) [m, m, rad] and foot centres at feet (n_leg, 2) [m]."""
    from .model import HIP_SIGN
    feet = np.ascontiguousarray(feet, dtype=np.float64).reshape(-1, 2)
    if feet.shape[0] != len(HIP_SIGN):
        raise ValueError(f"feet must hold {len(HIP_SIGN)} foot targets (FL, FR, RL, RR), got {feet.shape[0]}")
    tx, ty, th = (float(v) for v in torso_pose)
    q = np.zeros((feet.shape[0], 2))
    flags = np.zeros(feet.shape[0], dtype=np.int64)
    hip_dx = np.array(HIP_SIGN, dtype=np.float64) * params.hip_x
    pose_puppet(tx, ty, th, feet, hip_dx, params.thigh_length, params.calf_length, params.hip_lower,
                params.hip_upper, params.knee_lower, params.knee_upper, q, flags)
    return q, flags
