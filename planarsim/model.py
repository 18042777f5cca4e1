"""Model: the immutable, validated description of a planar mechanism.

A ``Model`` comes only from ``ModelBuilder.compile()``. Kernels see ``model.arrays``, a
``ModelArrays`` NamedTuple of read-only numpy arrays named ``<entity>_<quantity>``.
Every body has three coordinates (x [m], y [m], theta [rad]); a point mass is a body whose
inverse inertia is zero, so its angle never changes and it takes no torque.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

# actuator kinds
ACT_PIN_TORQUE = 0   # torque tau on body b, -tau on body a, at a pin [N m]
ACT_AXIAL = 1        # force along the line a->b between two anchors, + pushes apart [N]
ACT_HIP_TORQUE = 2   # torque between two point-mass legs about a hip point mass [N m]
ACT_BODY_FORCE = 3   # force along a fixed world direction at the body origin [N]
ACT_BODY_TORQUE = 4  # torque on one body [N m]
ACT_SLIDER_FORCE = 5  # force along a slider's axis: +f on body b, -f on body a [N]
from .kernels.codes import (JOINT_FREE_BIT, JOINT_FREE_HINGE, JOINT_FREE_SLIDE,  # noqa: E402,F401
                           JOINT_HINGE, JOINT_SLIDE_BIT, JOINT_SLIDER)  # (pin_kind)


class ModelArrays(NamedTuple):
    """Flat arrays for the kernels (SI units). Shapes use n_body, n_pin, n_rod, n_contact, n_act."""
    dt: float                       # step size [s]
    n_shape_pair: int               # pairs of shapes that may touch (two contacts each)
    gravity: np.ndarray             # (2,) [m/s^2]
    body_mass: np.ndarray           # (n_body,) [kg]
    body_inertia: np.ndarray        # (n_body,) about the COM [kg m^2]; 0 for point masses
    body_inv_mass: np.ndarray       # (n_body,) [1/kg]
    body_inv_inertia: np.ndarray    # (n_body,) [1/(kg m^2)]; 0 for point masses
    pin_body: np.ndarray            # (n_pin, 2) int: body a, body b (-1 = world)
    pin_anchor: np.ndarray          # (n_pin, 2, 2) local anchor on a and b (world coords for -1) [m]
    pin_ref: np.ndarray             # (n_pin,) pin angle = theta_b - theta_a - ref [rad]
    pin_limit: np.ndarray           # (n_pin, 2) lower, upper pin angle [rad] (+-inf: none)
    pin_stiffness: np.ndarray       # (n_pin,) passive spring [N m/rad]
    pin_damping: np.ndarray         # (n_pin,) passive damper [N m s/rad]
    pin_rest: np.ndarray            # (n_pin,) spring rest angle [rad] (slider: position [m])
    pin_kind: np.ndarray            # (n_pin,) int JOINT_HINGE | JOINT_SLIDER | JOINT_FREE_HINGE |
                                    #   JOINT_FREE_SLIDE (a free body's coordinate: measured as a
                                    #   hinge's or slider's, no constraint rows). A slider keeps its
                                    #   two bodies' relative angle (theta_b - theta_a - ref = 0)
                                    #   and anchor b on the line through anchor a along pin_axis;
                                    #   its coordinate is the slide s = d.(p_b - p_a) [m], which
                                    #   pin_limit, pin_stiffness [N/m], pin_damping [N s/m] and
                                    #   pin_rest [m] then refer to
    pin_axis: np.ndarray            # (n_pin, 2) a slider's unit axis d in body a's frame (world
                                    #   if a = -1); (0, 0) for a hinge
    pin_armature: np.ndarray        # (n_pin,) reflected rotor inertia on the joint coordinate
                                    #   [kg m^2 hinge, kg slider] (kernels/constraints/soft.py)
    pin_frictionloss: np.ndarray    # (n_pin,) dry friction on the joint coordinate, MuJoCo's
                                    #   frictionloss [N m hinge, N slider]
                                    #   (kernels/constraints/joint_friction.py)
    rod_body: np.ndarray            # (n_rod, 2) int
    rod_anchor: np.ndarray          # (n_rod, 2, 2) local anchors [m]
    rod_length: np.ndarray          # (n_rod,) [m]
    contact_body: np.ndarray        # (n_contact,) int
    contact_kind: np.ndarray        # (n_contact,) CONTACT_POINT or CONTACT_ARC
    contact_local: np.ndarray       # (n_contact, 2) point, or arc centre, in the body frame [m]
    contact_radius: np.ndarray      # (n_contact,) arc radius [m] (0 for points)
    contact_span: np.ndarray        # (n_contact, 2) body-frame angle range of the sole [rad]
    contact_span_dir: np.ndarray    # (n_contact, 4) cos, sin of the span's start, of its end
    contact_mu: np.ndarray          # (n_contact,) Coulomb friction coefficient [-]
    contact_ccd: np.ndarray         # (n_contact,) 1: continuous collision (point on point mass)
    contact_vert_adr: np.ndarray    # (n_contact,) first fallback vertex (heel, toe, ...)
    contact_vert_num: np.ndarray    # (n_contact,) number of fallback vertices
    contact_other: np.ndarray       # (n_contact,) int the second body of a shape pair (-1: the
                                    #   world's shape; -1 for every contact with the ground)
    contact_pair: np.ndarray        # (n_contact, 3) int a pair's shapes (a on contact_body, b on
                                    #   contact_other) and its slot 0 | 1; -1 for ground contacts
    contact_restitution: np.ndarray  # (n_contact,) coefficient of restitution [-] (0: plastic)
    vert_local: np.ndarray          # (n_vert, 2) fallback vertices in the body frame [m]
    act_kind: np.ndarray            # (n_act,) ACT_* kind
    act_body: np.ndarray            # (n_act, 3) int bodies (a, b, c) as the kind needs; -1 unused
    act_ref: np.ndarray             # (n_act,) pin index for ACT_PIN_TORQUE, else -1
    act_anchor: np.ndarray          # (n_act, 2, 2) local anchors for ACT_AXIAL [m]
    act_dir: np.ndarray             # (n_act, 2) world direction for ACT_BODY_FORCE
    act_range: np.ndarray           # (n_act, 2) saturation [min, max] [N or N m]
    fluid_body: np.ndarray          # (n_fluid,) int body of each fluid-drag box (kernels/dynamics/fluid.py)
    fluid_coef: np.ndarray          # (n_fluid, 8) local centre x, y [m], angle of its first
                                    #   in-plane axis in the body frame [rad], linear [N s/m] and
                                    #   angular [N m s] viscous coefficients, quadratic [kg/m]
                                    #   along both in-plane axes, angular quadratic [kg m^2]
    terrain_coef: np.ndarray        # (3 + 3K,) see kernels/geometry/terrain.py
    shape_body: np.ndarray          # (n_shape,) int body of each colliding shape (-1: the world)
    shape_vert_adr: np.ndarray      # (n_shape,) int first core vertex (planarsim/shapes.py)
    shape_vert_num: np.ndarray      # (n_shape,) int core vertices: 1 circle, 2 capsule, >= 3 polygon
    shape_radius: np.ndarray        # (n_shape,) radius around the core [m]
    shape_bound: np.ndarray         # (n_shape, 5) bounding circle: centre (local) and radius [m];
                                    #   width [m] and a turn's lever [m] (shapes.shape_bounds)
    core_vert: np.ndarray           # (n_core, 2) core vertices in the shape's frame [m]
    core_norm: np.ndarray           # (n_core, 2) outward unit normal of the edge from each vertex
    core_cover: np.ndarray          # (n_core, 8) 1 where the edge from that vertex is a world
                                    #   shape's face covered by others; the vertex's normal
                                    #   cone (q; concave flag; p); the shares of the edge
                                    #   covered from its start and to its end
                                    #   (builder.covered_edges)


@dataclass(frozen=True)
class Shape:
    """Drawing geometry fixed to a body (local frame, metres; body -1: the world, world
    coordinates). kind: capsule | box | circle | polygon | arc."""
    body: int
    kind: str
    params: tuple


@dataclass(frozen=True)
class Model:
    """Immutable model: names, initial state, drawing shapes and the kernel arrays."""
    arrays: ModelArrays
    body_names: tuple
    pin_names: tuple
    rod_names: tuple
    contact_names: tuple
    act_names: tuple
    q0: np.ndarray                  # (n_body, 3) initial positions [m, m, rad]
    v0: np.ndarray                  # (n_body, 3) initial velocities [m/s, m/s, rad/s]
    shapes: tuple = ()
    terrain: object = None          # the ground's Terrain; None: no ground (ModelBuilder(ground=None))
    meta: dict = field(default_factory=dict)
    shape_names: tuple = ()         # how messages name each colliding shape (its kind, index,
                                    #   name= and body), in the order of shape_body

    # counts
    @property
    def n_body(self): return len(self.body_names)
    @property
    def n_pin(self): return len(self.pin_names)
    @property
    def n_rod(self): return len(self.rod_names)
    @property
    def n_contact(self): return len(self.contact_names)
    @property
    def n_act(self): return len(self.act_names)
    @property
    def n_shape(self): return int(self.arrays.shape_body.shape[0])
    @property
    def dt(self): return self.arrays.dt
    @property
    def total_mass(self): return float(self.arrays.body_mass.sum())

    # lookups
    def _find(self, names, kind, name):
        try:
            return names.index(name)
        except ValueError:
            raise KeyError(f"no {kind} named {name!r}; have {list(names)}") from None

    def body(self, name: str) -> int:
        return self._find(self.body_names, "body", name)

    def pin(self, name: str) -> int:
        return self._find(self.pin_names, "pin", name)

    def rod(self, name: str) -> int:
        return self._find(self.rod_names, "rod", name)

    def contact(self, name: str) -> int:
        return self._find(self.contact_names, "contact", name)

    def actuator(self, name: str) -> int:
        return self._find(self.act_names, "actuator", name)

    def is_point(self, body: int) -> bool:
        return self.arrays.body_inv_inertia[body] == 0.0 and self.arrays.body_inertia[body] == 0.0

    def summary(self) -> str:
        return (f"Model: {self.n_body} bodies, {self.n_pin} pins, {self.n_rod} rods, "
                f"{self.n_contact} contacts, {self.n_act} actuators, dt={self.dt:g} s, "
                f"mass={self.total_mass:g} kg")
