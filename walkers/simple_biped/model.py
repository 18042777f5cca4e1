"""The Simple Biped model (Kelly 2014, section 3): three point masses joined by actuators.

Bodies: ``hip`` (hip_mass) and ``foot0``, ``foot1`` (foot_mass each); the legs are massless.
Actuators (index order is used by the controller):
    0 ``leg0``  axial force hip -> foot0 [N], + pushes apart, |u| <= leg_force_max
    1 ``leg1``  axial force hip -> foot1 [N]
    2 ``hip``   hip torque [N m] between leg0 (a) and leg1 (b), + turns leg1 counter-clockwise
                relative to leg0, |u| <= hip_torque_max (realised as forces on the point masses)
Contacts: point contacts ``foot0``, ``foot1`` on the foot masses (continuous collision, friction
mu). No ankle torque. The hip carries no contact: only the feet can touch the ground, and a hip
lower than fall_height above the ground ends a run as a fall.
Initial pose: standing, feet stand_width apart on the ground around x0, hip stand_height above
their mean height.
"""
from __future__ import annotations

import planarsim as ps
from planarsim.terrain import Terrain

from .params import SimpleBipedParams


# [l0] radius of the feet's disks against shapes (the ground meets the foot's centre)
FOOT_RADIUS = 0.01


def build(params: SimpleBipedParams | None = None, terrain: Terrain | None = None,
          dt: float = 1e-3, x0: float = 0.0, extras=None):
    """Model of the Simple Biped standing at x0 [m] on `terrain` (default flat).
    extras(builder), if given, adds bodies and shapes after the walker's own (stairs of
    static boxes, obstacles): each foot is a disk of FOOT_RADIUS l0 that touches their shapes
    (the ground through its own point contact)."""
    p = params if params is not None else SimpleBipedParams()
    terrain = terrain if terrain is not None else ps.terrain.flat()
    l0 = p.leg_length
    half = 0.5 * p.stand_width * l0
    xf = (x0 - half, x0 + half)
    yf = tuple(float(terrain.height(x)) for x in xf)
    b = ps.ModelBuilder(dt=dt, terrain=terrain)
    hip = b.add_point_mass("hip", p.hip_mass, pos=(x0, 0.5 * (yf[0] + yf[1]) + p.stand_height * l0),
                           radius=0.08 * l0)
    feet = [b.add_point_mass(f"foot{i}", p.foot_mass, pos=(xf[i], yf[i]), radius=0.03 * l0)
            for i in range(2)]
    for i, foot in enumerate(feet):
        b.add_axial(f"leg{i}", hip, foot, limit=(-p.leg_force_max, p.leg_force_max))
    b.add_hip_torque("hip", hip, feet[0], feet[1], limit=(-p.hip_torque_max, p.hip_torque_max))
    for i, foot in enumerate(feet):
        b.add_point_contact(f"foot{i}", foot, mu=p.mu)
    for foot in feet:
        b.add_shape(foot, "circle", (0.0, 0.0), FOOT_RADIUS * l0, mu=p.mu, ground=False)
    if extras is not None:
        extras(b)
    # legs are massless lines hip-foot: drawn from meta["segments"] (pairs of body ids)
    return b.compile(walker="simple-biped", segments=((hip, feet[0]), (hip, feet[1])))
