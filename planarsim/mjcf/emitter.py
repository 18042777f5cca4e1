"""The plain description of an MJCF file (description.py) to ModelBuilder calls: the plane of
motion (plane.py), the builder and the ground (world.py), rigid bodies of the MJCF bodies welded together with their mass
properties (mass.py) and shapes (collisions.py), pins, sliders and a free root's
coordinates, the fluid, the ground and the motors."""
from __future__ import annotations

import math

import numpy as np

from .collisions import Collisions
from .description import Description
from .mass import fluid_box, inertia_3d, uses_inertial
from .options import check_filterparent
from .plane import PlaneMap
from .result import ActuatorMap, JointMap, MJCFModel, RigidBody
from .walls import wall_shapes
from .world import ground_plane, make_builder
from .xml_tree import element_error


class Emitter:
    """One description's ModelBuilder calls (emit()), in the plane of its hinges shifted by
    `offset` [m]; `collide`: None (MuJoCo's contype/conaffinity) or the names of the geoms
    that collide."""

    def __init__(self, desc: Description, offset, collide):
        self.desc = desc
        self.report = desc.report
        self.bodies = desc.bodies
        self.map = PlaneMap(desc.bodies, offset, self.fail)
        self.collide = None if collide is None else frozenset(collide)
        self.flags = desc.flags
        if not self.flags.contact:            # <flag contact|constraint="disable">
            self.collide = frozenset()
        self.free_bodies = []                 # bodies with a free root's slides and hinge

    def fail(self, node, msg):
        raise element_error(self.desc.source, node, msg)

    def emit(self, builder_kw, builder) -> MJCFModel:
        self.ground = ground_plane(self.desc.world, self.map, self.report, self.fail)
        builder = make_builder(self.desc.option, self.map, self.ground, self.report, builder_kw,
                               builder)
        out = self.bodies_and_joints(builder)
        check_filterparent(self)              # <flag filterparent="disable">
        for motor in self.desc.motors:
            self.motor(motor, out)
        return out

    # rigid bodies -----------------------------------------------------------------------------
    def group(self):
        """Assign each MJCF body to a planarsim rigid body (None: welded to the world) and
        collect the joints that link them: pins, sliders and free roots."""
        self.rigid, self.links, self.free, self.body_map = [], [], (), {}
        self.translating = set()      # rigid bodies that translate only (two slides, no hinge)
        for b in self.bodies:
            parent_rid = b.parent.rid if b.parent is not None else None
            if not b.joints:
                b.rid = parent_rid
                if b.rid is not None:
                    self.body_map[b.name] = b.rid
                    self.rigid[b.rid].mjcf_bodies.append(b.name)
                continue
            b.rid = len(self.rigid)
            self.rigid.append(RigidBody(b.name, mjcf_bodies=[b.name]))
            self.body_map[b.name] = b.rid
            kinds = sorted(j["type"] for j in b.joints)
            if kinds == ["hinge"]:
                self.links.append(("pin", b.joints[0], parent_rid, b.rid))
            elif kinds == ["slide"]:
                self.links.append(("slider", b.joints[0], parent_rid, b.rid))
            elif kinds in (["hinge", "slide", "slide"], ["slide", "slide"]) and parent_rid is None:
                s = [j["axis"] for j in b.joints if j["type"] == "slide"]
                if abs(abs(np.cross(s[0], s[1]) @ self.map.ccw) - 1) > 1e-9:
                    self.fail(b.node, "the root's two slides must be orthogonal (each its own "
                                      "coordinate of the plane; MuJoCo's armature and limits act "
                                      "on each)")
                self.free_root(b)
                if "hinge" not in kinds:
                    self.translating.add(b.name)
            else:
                self.fail(b.node, f"joints {kinds} on one body are not supported: use one hinge, "
                                  f"one slide, or (a root) two slides spanning the plane, with or "
                                  f"without a hinge")

    def free_root(self, b):
        """Two slides (and a hinge) on a root: a body free in the plane, each joint a free
        coordinate (ModelBuilder.add_free_coordinate: its limits, spring-damper, armature and
        motor act, nothing is constrained). Without a hinge the body translates only: a point
        mass. MuJoCo composes the joints in file order: the slides must come before the hinge
        (they then move the hinge's anchor)."""
        types = [j["type"] for j in b.joints]
        if "hinge" in types and types.index("hinge") != len(types) - 1:
            self.fail(b.joints[types.index("hinge")]["node"],
                      "a free root's hinge must follow its two slides (MuJoCo turns the body "
                      "about the hinge after the slides moved it)")
        self.free += tuple(j["name"] for j in b.joints)
        self.free_bodies.append(b)

    def parts(self):
        """Mass [kg], in-plane COM [m], own inertia about the normal [kg m^2] and the shape of
        every geom (and <inertial>) of every rigid body; static geoms go to self.static."""
        m, self.static = self.map, []
        # the world's own geoms too (a static geom directly under <worldbody> collides)
        for b in [self.desc.world] + self.bodies:
            use_inertial = uses_inertial(self.desc.inertiafromgeom, b)
            if self.desc.inertiafromgeom == "true":
                for i in b.inertials:
                    self.report.ignore("<inertial> (inertiafromgeom='true')", i["node"].line)
            for g in b.geoms:
                shape = m.shape(g)
                if g["kind"] == "plane":
                    if b.rid is not None:
                        self.fail(g["node"], "a plane must belong to the world")
                    continue
                if b.rid is None:
                    self.static.append((g, shape))
                    continue
                mass = 0.0 if use_inertial else g["mass"]
                self.rigid[b.rid].parts.append((mass, m.plane(g["pos"]), mass * m.own_inertia(g),
                                                shape, g["name"], g))
            if use_inertial and b.rid is not None:
                for i in b.inertials:
                    self.rigid[b.rid].parts.append((i["mass"], m.plane(i["pos"]),
                                                    m.normal_inertia(i["tensor"]), None, "", i))
        self.static += wall_shapes(self.desc.world, m, self.report)   # planes that are walls

    def scale_total_mass(self):
        """<compiler settotalmass>: scale every mass and inertia so the bodies total it [kg]."""
        self.mass_scale = 1.0
        if self.desc.settotalmass is None:
            return
        total = sum(p[0] for rb in self.rigid for p in rb.parts)
        total += sum(g["mass"] for g, _ in self.static)
        f = self.mass_scale = self.desc.settotalmass / total
        for rb in self.rigid:
            rb.parts = [(m * f, x, i * f, *rest) for m, x, i, *rest in rb.parts]

    # build ------------------------------------------------------------------------------------
    def bodies_and_joints(self, builder) -> MJCFModel:
        self.group()
        self.parts()
        if not self.rigid:
            self.fail(self.desc.root, "no body with a joint: nothing moves")
        self.scale_total_mass()
        shapes_of = Collisions(self.rigid, self.static, self.ground, self.collide, self.report,
                               self.fail)
        ids = []
        for rb in self.rigid:
            m = np.array([p[0] for p in rb.parts])
            if not rb.parts or not m.sum() > 0:
                self.fail(self.desc.root, f"body {rb.name!r} has no mass (give its geoms mass or "
                                          f"density, or an <inertial>)")
            x = np.array([p[1] for p in rb.parts])
            rb.mass = float(m.sum())
            rb.com = (m[:, None] * x).sum(0) / rb.mass
            d2 = ((x - rb.com) ** 2).sum(1)
            rb.inertia = float(sum(p[2] for p in rb.parts) + (m * d2).sum())
            shapes = [shapes_of.body_shape(s, g, rb.com) for _, _, _, s, _, g in rb.parts if s is not None]
            if rb.name in self.translating:
                ids.append(self.point_body(builder, rb, shapes))
            else:
                ids.append(builder.add_body(rb.name, mass=rb.mass, inertia=rb.inertia,
                                            pos=tuple(rb.com), shapes=shapes))
        for g, s in self.static:
            shapes_of.world_shape(builder, g, s)
        shapes_of.self_collisions(self.bodies)
        out = MJCFModel(builder=builder, body={k: ids[v] for k, v in self.body_map.items()},
                        pin={}, rigid={ids[i]: rb for i, rb in enumerate(self.rigid)},
                        root=ids[0], name=self.desc.name, free_joints=self.free,
                        plane=self.map.name, report=self.report)
        for kind, j, parent, child in self.links:
            a = None if parent is None else ids[parent]
            if kind == "pin":
                pid = self.add_pin(builder, j, a, ids[child])
                out.pin[j["name"]] = pid
                out.joint[j["name"]] = JointMap("pin", pid, self.map.sign(j), j["ref"])
            else:
                out.joint[j["name"]] = JointMap("slider", self.add_slider(builder, j, a, ids[child]),
                                                1.0, j["ref"])
        # a free root's coordinates after the links (the links keep pin ids 0..)
        for b in self.free_bodies:
            self.free_coordinates(builder, b, ids[b.rid], out)
        self.fluid(builder, ids)
        for b in self.bodies:
            if b.rid is not None:
                mass, com, _ = inertia_3d(b, self.desc.inertiafromgeom, self.mass_scale)
                out.com[b.name] = self.map.plane(com if mass > 0 else b.pos)
        out.joint = {j["name"]: out.joint[j["name"]] for b in self.bodies for j in b.joints}  # file order
        return out

    def joint_terms(self, j):
        """Limits, stiffness, damping and rest value of a hinge or slide in planarsim's sign:
        (limit (lo, hi) or None, k, c, rest)."""
        sign = self.map.sign(j) if j["type"] == "hinge" else 1.0
        ref, rng = j["ref"], j["range"]
        limit = None
        if rng is not None:
            limit = tuple(sorted((sign * (rng[0] - ref), sign * (rng[1] - ref))))
        rest = sign * (j["springref"] - ref) + 0.0   # no -0.0
        return limit, j["stiffness"], j["damping"], rest

    def armature(self, j):
        """Joint armature [kg m^2 or kg]; 0, reported, where the caller dropped it."""
        if j["armature_dropped"]:
            self.report.drop("joint armature", j["node"].line)
        return j["armature"]

    def add_pin(self, builder, j, a, b):
        """A hinge -> ModelBuilder.add_pin at the joint's world position (armature [kg m^2]
        to add_pin(armature=...), frictionloss [N m] to add_pin(frictionloss=...))."""
        limit, k, c, rest = self.joint_terms(j)
        return builder.add_pin(j["name"], a, b, anchor_world=tuple(self.map.plane(j["pos"])),
                               limit=limit, stiffness=k, damping=c, rest_angle=rest,
                               armature=self.armature(j), frictionloss=j["frictionloss"])

    def add_slider(self, builder, j, a, b):
        """A slide between bodies -> ModelBuilder.add_slider (axis: unit in-plane direction;
        limit [m]; stiffness [N/m], damping [N s/m]; armature [kg]; frictionloss [N])."""
        limit, k, c, rest = self.joint_terms(j)
        ax = j["axis"]
        return builder.add_slider(j["name"], a, b, axis=(ax[self.map.i1], ax[self.map.i2]),
                                  anchor_world=tuple(self.map.plane(j["pos"])), limit=limit,
                                  stiffness=k, damping=c, rest=rest, armature=self.armature(j),
                                  frictionloss=j["frictionloss"])

    def free_coordinates(self, builder, b, body, out):
        """A free root's joints -> ModelBuilder.add_free_coordinate, each about the hinge's
        anchor, which the slides move."""
        hinge = [j for j in b.joints if j["type"] == "hinge"]
        anchor = tuple(float(x) for x in self.map.plane((hinge or b.joints)[0]["pos"]))
        for j in b.joints:
            limit, k, c, rest = self.joint_terms(j)
            kind = j["type"]
            axis = (2,) if kind == "hinge" else self.map.in_plane(j["axis"])
            pid = builder.add_free_coordinate(
                j["name"], body, kind=kind, axis=(1.0, 0.0) if kind == "hinge" else axis,
                anchor_world=anchor, limit=limit, stiffness=k, damping=c, rest=rest,
                armature=self.armature(j), frictionloss=j["frictionloss"])
            out.joint[j["name"]] = JointMap("free", body,
                                            self.map.sign(j) if kind == "hinge" else 1.0,
                                            j["ref"], axis, anchor, pin=pid)

    def point_body(self, builder, rb, shapes):
        """A body that translates only (a root with two slides, no hinge): a point mass. Its
        geoms must be drawn only and be one sphere at its centre (the drawn disk)."""
        ok = len(shapes) == 1 and shapes[0][0] == "circle" and not shapes[0][-1].get("collide")
        if not ok or np.hypot(*shapes[0][1]) > 1e-9:
            g = rb.parts[0][5]
            self.fail(g["node"], f"body {rb.name!r} translates without turning (two slides, no "
                                 f"hinge): it becomes a point mass, so its geoms must be one "
                                 f"sphere at its centre that collides with nothing")
        return builder.add_point_mass(rb.name, rb.mass, pos=tuple(rb.com), radius=shapes[0][2])

    def fluid(self, builder, ids):
        """<option viscosity density>: MuJoCo's inertia-box fluid model on every MJCF body
        with mass (mass.fluid_box), one principal axis along the plane's normal."""
        fluid = self.desc.option.get("fluid")
        if not fluid:
            return
        m = self.map
        for b in self.bodies:
            if b.rid is None or b.name in self.translating:
                if b.rid is not None and (b.geoms or b.inertials):
                    self.fail(b.node, "fluid forces on a body that translates only (a point "
                                      "mass) are not supported")
                continue
            mass, com, T = inertia_3d(b, self.desc.inertiafromgeom, self.mass_scale)
            if not mass > 1e-15:
                continue
            found = fluid_box(mass, T, m.normal, m.i1, m.i2)
            if found is None:
                self.fail(b.node, "fluid forces need one principal axis of the body's inertia "
                                  "normal to the plane of motion")
            box, angle = found
            rb = self.rigid[b.rid]
            builder.add_fluid_box(ids[b.rid], box, viscosity=fluid["viscosity"],
                                  density=fluid["density"], local=tuple(m.plane(com) - rb.com),
                                  angle=angle)

    # actuators --------------------------------------------------------------------------------
    def motor(self, motor, out: MJCFModel):
        """A <motor> -> a pin (or slider) motor on each joint of its transmission whose
        coefficient is not 0, its input gear * coef * ctrl in the joint's sign, saturated to
        that gain times its range (named the motor's name, or "motor:joint" where it drives
        several)."""
        lo, hi = motor.ctrl
        b = out.builder
        drives = [(j, c) for j, c in motor.moment if c != 0.0]
        ids, gains = [], []
        for joint, coef in drives:
            jm = out.joint[joint]
            gain = motor.gear * coef * jm.sign
            limit = (tuple(sorted((gain * lo, gain * hi))) if math.isfinite(lo)
                     else (-math.inf, math.inf))
            add_motor = b.add_pin_motor if jm.angular else b.add_slider_motor
            name = motor.name if len(drives) == 1 else f"{motor.name}:{joint}"
            ids.append(add_motor(name, jm.coordinate, limit=limit))
            gains.append(gain)
        out.actuator[motor.name] = ActuatorMap(tuple(ids), tuple(j for j, _ in drives),
                                               tuple(gains), motor.ctrl, motor.tendon)
