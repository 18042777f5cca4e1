"""Builders of the passive walkers, written only against planarsim's public ModelBuilder.

All three walk down a plane of slope gamma toward +x: the terrain is
``planarsim.terrain.slope(-degrees(gamma))`` and gravity is vertical. Slope frame: tangent
t = (cos g, -sin g) (downhill), normal n = (sin g, cos g). Leg angles theta are measured from
the slope normal, counter-clockwise, so a stance leg leaning back (hip behind the foot) has
theta > 0 and theta decreases during a step (Garcia et al.'s convention).

Bodies and contacts
-------------------
simplest walker : hip (point mass M), foot_a / foot_b (point masses beta M), rods leg_a / leg_b;
                  point contacts foot_a / foot_b (continuous collision).
compass gait    : hip (point mass mH), leg_a / leg_b rigid bodies (mass m, COM at a from the
                  foot) pinned to the hip; point contacts foot_a / foot_b at the leg ends.
rimless wheel   : hub rigid body (M, M k^2) with point contacts spoke0..spoke{N-1} at the ends
                  of N spokes of length l (massless, drawn as capsules).
"""
from __future__ import annotations

import math

import numpy as np

import planarsim as ps
from planarsim import terrain as ps_terrain

from .params import CompassParams, RimlessParams, SimplestParams

# the shapes only draw the walker: its feet are its contacts
DRAWN = {"collide": False}

FEET = ("foot_a", "foot_b")


def slope_frame(gamma: float):
    """Unit tangent t (downhill, toward +x) and normal n of a plane of slope gamma [rad]."""
    t = np.array([math.cos(gamma), -math.sin(gamma)])
    n = np.array([math.sin(gamma), math.cos(gamma)])
    return t, n


def slope_terrain(gamma: float):
    return ps_terrain.slope(-math.degrees(gamma))


def leg_up(theta: float, gamma: float) -> np.ndarray:
    """World unit vector from foot to hip of a leg at angle theta from the slope normal."""
    t, n = slope_frame(gamma)
    return -math.sin(theta) * t + math.cos(theta) * n


def build_simplest(p: SimplestParams = SimplestParams(), dt: float = 1e-3, terrain=None,
                   theta0: float = 0.2, phi0: float = 0.4) -> ps.Model:
    """Simplest walking model; build pose: foot_a at the origin at stance angle theta0 [rad],
    swing leg at phi0 [rad] from the stance leg."""
    terrain = slope_terrain(p.slope) if terrain is None else terrain
    l = p.leg_length
    hip = l * leg_up(theta0, p.slope)
    foot_b = hip - l * leg_up(theta0 - phi0, p.slope)
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, -p.gravity), terrain=terrain)
    h = b.add_point_mass("hip", p.hip_mass, pos=hip, radius=0.06 * l)
    fa = b.add_point_mass("foot_a", p.foot_mass_ratio * p.hip_mass, pos=(0.0, 0.0), radius=0.02 * l)
    fb = b.add_point_mass("foot_b", p.foot_mass_ratio * p.hip_mass, pos=foot_b, radius=0.02 * l)
    b.add_rod("leg_a", h, fa, length=l)
    b.add_rod("leg_b", h, fb, length=l)
    b.add_point_contact("foot_a", fa, mu=p.mu)
    b.add_point_contact("foot_b", fb, mu=p.mu)
    return b.compile(walker="simplest-walker", slope=p.slope)


def build_compass(p: CompassParams = CompassParams(), dt: float = 1e-3, terrain=None,
                  theta0: float = 0.2, phi0: float = 0.4) -> ps.Model:
    """Compass gait; leg bodies have local frames with the foot at (0, -a) and the hip at (0, b);
    body angle = leg angle from the slope normal - gamma."""
    terrain = slope_terrain(p.slope) if terrain is None else terrain
    l, a = p.leg_length, p.com_from_foot
    bl = l - a
    k = p.leg_gyration if p.leg_gyration > 0 else 1e-3
    hip = l * leg_up(theta0, p.slope)
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, -p.gravity), terrain=terrain)
    h = b.add_point_mass("hip", p.hip_mass, pos=hip, radius=0.06 * l)
    for name, foot, th in (("leg_a", "foot_a", theta0), ("leg_b", "foot_b", theta0 - phi0)):
        up = leg_up(th, p.slope)
        angle = math.atan2(-up[0], up[1])
        com = hip - bl * up
        leg = b.add_body(name, p.leg_mass, p.leg_mass * k * k, pos=com, angle=angle,
                         shapes=[("capsule", (0.0, -a), (0.0, bl), 0.02 * l, DRAWN)])
        b.add_pin(f"hip_{name}", h, leg, anchor_world=hip)
        b.add_point_contact(foot, leg, local=(0.0, -a), mu=p.mu)
    return b.compile(walker="compass-gait", slope=p.slope)


def build_rimless(p: RimlessParams = RimlessParams(), dt: float = 1e-3, terrain=None) -> ps.Model:
    """Rimless wheel standing on spoke0 at the origin, leaning back by alpha (just after a
    touchdown); spoke i points along the hub angle + 2 pi i / N from the hub's local -y."""
    terrain = slope_terrain(p.slope) if terrain is None else terrain
    l, n_sp = p.spoke_length, p.n_spokes
    alpha = p.half_angle
    centre = l * leg_up(alpha, p.slope)
    # local -y of the hub points from the centre to spoke0's foot
    up = leg_up(alpha, p.slope)
    hub_angle = math.atan2(-up[0], up[1])
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, -p.gravity), terrain=terrain)
    shapes = [("circle", (0.0, 0.0), 0.08 * l, DRAWN)]
    feet = []
    for i in range(n_sp):
        ang = 2.0 * math.pi * i / n_sp
        foot = (l * math.sin(ang), -l * math.cos(ang))
        shapes.append(("capsule", (0.0, 0.0), foot, 0.01 * l, DRAWN))
        feet.append(foot)
    hub = b.add_body("hub", p.hub_mass, p.hub_mass * p.hub_gyration ** 2, pos=centre, angle=hub_angle,
                     shapes=shapes)
    for i, foot in enumerate(feet):
        b.add_point_contact(f"spoke{i}", hub, local=foot, mu=p.mu)
    return b.compile(walker="rimless-wheel", slope=p.slope)
