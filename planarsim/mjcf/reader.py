"""MJCF elements to the plain description of description.py: <compiler>, <option>, <default>
classes, the body tree with its joints, geoms and inertials (frames composed into the
world's, defaults resolved, values checked) and the motors. Nothing here knows planarsim's
plane of motion or its ModelBuilder (emitter.py does)."""
from __future__ import annotations

import math

import numpy as np

from ..errors import ModelError
from .description import Body3D, Description, Motor, Tendon
from .geoms import BodyPartsReader
from .include import origin
from .options import Flags, joint_frictionloss, read_flags
from .plane import vec
from .schema import CHILDREN, DEFAULT_GRAVITY, DEFAULT_TIMESTEP, DROPPABLE, EMPTY_ONLY, IGNORED_ELEMENTS
from .xml_tree import Node

_OTHER_ACTUATORS = ("general", "position", "velocity", "intvelocity", "damper", "cylinder",
                    "muscle", "adhesion")


class Reader(BodyPartsReader):
    """One file's elements read into a Description (read()); its bodies' geoms and
    inertials by BodyPartsReader."""

    def __init__(self, root: Node, source: str, drop=()):
        super().__init__(source)
        self.root = root
        self.inertiafromgeom = "auto"
        self.settotalmass = None
        self.option = {}
        self.flags = Flags()                  # <option><flag> (options.read_flags)
        bad = sorted(set(drop) - set(DROPPABLE))
        if bad:
            raise ModelError(f"load_mjcf: drop={sorted(drop)} names {bad}; it may name {DROPPABLE}")
        self.drop = frozenset(drop)

    # top level ------------------------------------------------------------------------------
    def read(self) -> Description:
        root = self.root
        if root.tag != "mujoco":
            self.fail(root, "the root element must be <mujoco>")
        self.vet(root, root.attrib)
        worldbody, actuators, tendons = None, [], []
        for node in root.children:      # compiler first: it sets the angle unit for the rest
            if node.tag == "compiler":
                self.compiler(node)
        for node in root.children:
            if node.tag in ("compiler",):
                continue
            if node.tag == "option":
                self.options(node)
            elif node.tag == "default":
                self.defaults(node, parent="main", top=True)
            elif node.tag == "worldbody":
                if worldbody is not None:
                    self.fail(node, "only one <worldbody> is allowed")
                worldbody = node
            elif node.tag == "actuator":
                actuators.append(node)
            elif node.tag == "tendon":
                tendons.append(node)
            else:
                self.elsewhere(node, "mujoco")
        if worldbody is None:
            self.fail(root, "<worldbody> is missing")
        world = Body3D(worldbody, "world", None, np.zeros(3), np.eye(3))
        self.bodies = []
        self.walk_children(worldbody, world, "main")
        joints = {j["name"] for b in self.bodies for j in b.joints}
        self.tendons = {}
        for node in tendons:
            self.tendon_section(node, joints)
        motors = [m for node in actuators for m in self.motors(node, joints)]
        return Description(self.src, root, root.attrib.get("model", "mjcf"), world, self.bodies,
                           motors, self.option, self.inertiafromgeom, self.settotalmass,
                           self.report, self.flags, self.tendons)

    def elsewhere(self, node, parent):
        """An element the loader does not read: ignored and reported when it only draws,
        senses or tunes; otherwise a ModelError naming it."""
        if node.tag in IGNORED_ELEMENTS:
            # an included file's elements are reported with its name
            self.report.ignore(f"<{node.tag}>{origin(node)}", node.line)
            return
        if node.tag in EMPTY_ONLY:
            kids = [c for c in node.children if not (node.tag == "contact" and c.tag == "exclude")]
            if kids:
                self.fail(kids[0], f"<{kids[0].tag}> inside <{node.tag}>: {EMPTY_ONLY[node.tag]} "
                                   f"change physics and are not supported")
            for c in node.children:
                self.report.ignore(f"<{node.tag}><{c.tag}>", c.line)
            if not node.children:
                self.report.ignore(f"<{node.tag}> (empty)", node.line)
            return
        if node.tag == "freejoint":
            self.fail(node, "a free joint leaves the plane; use two slides and a hinge")
        self.fail(node, f"element <{node.tag}> is not supported inside <{parent}> "
                        f"(read: {sorted(CHILDREN.get(parent, set()))}; ignored: "
                        f"{sorted(IGNORED_ELEMENTS)})")

    def compiler(self, node):
        eff = dict(node.attrib)
        self.vet(node, eff)
        angle = eff.get("angle", "degree")
        if angle not in ("degree", "radian"):
            self.fail(node, f"angle={angle!r} must be 'degree' or 'radian'")
        self.angle_scale = math.pi / 180.0 if angle == "degree" else 1.0
        coord = eff.get("coordinate", "local")
        if coord not in ("local", "global"):
            self.fail(node, f"coordinate={coord!r} must be 'local' or 'global'")
        self.global_coords = coord == "global"
        self.inertiafromgeom = self.flag(node, eff, "inertiafromgeom")
        seq = eff.get("eulerseq", "xyz")
        if len(seq) != 3 or any(c not in "xyzXYZ" for c in seq):
            self.fail(node, f"eulerseq={seq!r} must be three of x, y, z, X, Y, Z")
        self.eulerseq = seq
        if "settotalmass" in eff:
            total = self.scalar(node, eff, "settotalmass", -1.0)
            self.settotalmass = total if total > 0 else None

    def options(self, node):
        eff = dict(node.attrib)
        self.vet(node, eff)
        self.option["timestep"] = self.scalar(node, eff, "timestep", DEFAULT_TIMESTEP)
        if not self.option["timestep"] > 0:
            self.fail(node, f"timestep={self.option['timestep']} must be > 0")
        self.option["gravity"] = self.floats(node, eff, "gravity", 3, default=DEFAULT_GRAVITY)
        fluid = {k: self.scalar(node, eff, k, 0.0) for k in ("viscosity", "density")}
        if any(v < 0 for v in fluid.values()):
            self.fail(node, f"viscosity={fluid['viscosity']} and density={fluid['density']} "
                            f"must be >= 0")
        if any(fluid.values()):
            what = ", ".join(f"{k}={v}" for k, v in fluid.items() if v)
            if "fluid" in self.drop:
                self.report.drop(f"option {what} (fluid forces)", node.line)
            else:
                self.option["fluid"] = fluid
        read_flags(self, node)                # <flag> children (gravity, contact, ...)

    def defaults(self, node, parent, top=False):
        """<default class=...>: attributes per element tag, inherited by nested classes."""
        extra = sorted(set(node.attrib) - {"class"})
        if extra:
            self.fail(node, f"attribute(s) {extra} not supported on <default>")
        name = node.attrib.get("class", "main" if top else None)
        if name is None:
            self.fail(node, "a nested <default> needs class=")
        if not top and name in self.classes:
            self.fail(node, f"class={name!r} is defined twice")
        table = self.classes["main"] if top else {t: dict(a) for t, a in self.classes[parent].items()}
        self.classes[name] = table
        for c in node.children:
            if c.tag == "default":
                self.defaults(c, name)
            elif c.tag in ("joint", "geom", "inertial", "tendon"):
                table.setdefault(c.tag, {}).update(c.attrib)
            elif c.tag in ("motor", "general"):
                table.setdefault("motor", {}).update(c.attrib)
            else:
                self.report.ignore(f"<default><{c.tag}>", c.line)

    # bodies, joints, geoms --------------------------------------------------------------------
    def walk_children(self, node, body: Body3D, cls):
        for c in node.children:
            if c.tag == "body":
                self.walk(c, body, cls)
            elif c.tag == "geom":
                body.geoms.append(self.geom(c, self.effective(c, cls), body))
            elif c.tag == "joint" and node.tag == "body":
                body.joints.append(self.joint(c, self.effective(c, cls), body))
            elif c.tag == "inertial" and node.tag == "body":
                body.inertials.append(self.inertial(c, body))
            else:
                self.elsewhere(c, node.tag)

    def walk(self, node, parent: Body3D, cls):
        eff = dict(node.attrib)
        self.vet(node, eff)
        name = eff.get("name") or f"body@{node.line}"
        if any(b.name == name for b in self.bodies):
            self.fail(node, f"duplicate body name {name!r}")
        pos, R = self.frame(node, eff, parent.pos, parent.R)
        body = Body3D(node, name, parent, pos, R)
        parent.children.append(body)
        self.bodies.append(body)
        self.walk_children(node, body, eff.get("childclass", cls))
        if "childclass" in eff and eff["childclass"] not in self.classes:
            self.fail(node, f"childclass={eff['childclass']!r} is not defined")

    def joint(self, j, eff, body):
        kind = eff.get("type", "hinge")
        if kind in ("free", "ball"):
            self.fail(j, f"type={kind!r} leaves the plane; use slides and a hinge")
        if kind not in ("hinge", "slide"):
            self.fail(j, f"type={kind!r} must be 'hinge' or 'slide'")
        a = self.floats(j, eff, "axis", 3, default=(0.0, 0.0, 1.0))
        if not np.linalg.norm(a) > 0:
            self.fail(j, f"axis={vec(a)} must be non-zero")
        a = a / np.linalg.norm(a)
        p = self.floats(j, eff, "pos", 3, default=(0.0, 0.0, 0.0))
        if not self.global_coords:
            a, p = body.R @ a, body.pos + body.R @ p
        friction = joint_frictionloss(self, j, eff)   # [N m or N]; 0 where off
        return dict(node=j, eff=eff, type=kind, axis=a, pos=p, frictionloss=friction,
                    name=eff.get("name") or f"joint@{j.line}", **self.joint_values(j, eff, kind))

    def joint_values(self, node, eff, kind):
        """ref, range (where limited), stiffness, damping, springref (in radians for a hinge)
        and armature (0 where the caller dropped it, drop={"armature"}: armature_dropped)."""
        s = self.angle_scale if kind == "hinge" else 1.0
        ref = self.scalar(node, eff, "ref", 0.0) * s
        rng = None
        # <flag limit|constraint="disable">: no joint is limited
        v = self.flag(node, eff, "limited") if self.flags.limit else "false"
        if v == "true" or (v == "auto" and "range" in eff):
            rng = self.floats(node, eff, "range", 2) * s
            if rng[0] > rng[1]:
                self.fail(node, f"range={vec(rng / s)} has lower > upper")
        k = self.scalar(node, eff, "stiffness", 0.0)
        c = self.scalar(node, eff, "damping", 0.0)
        if k < 0 or c < 0:
            self.fail(node, f"stiffness={k} and damping={c} must be >= 0")
        k, c = self.flags.passive(k, c)       # <flag spring|damper="disable">
        springref = self.scalar(node, eff, "springref", 0.0) * s
        armature = self.scalar(node, eff, "armature", 0.0)
        if armature < 0:
            self.fail(node, f"armature={armature} must be >= 0")
        dropped = armature != 0.0 and "armature" in self.drop
        return dict(ref=ref, range=rng, stiffness=k, damping=c, springref=springref,
                    armature=0.0 if dropped else armature, armature_dropped=dropped)

    # tendons ----------------------------------------------------------------------------------
    def tendon_section(self, node, joints):
        """A <tendon> section's fixed tendons into self.tendons (each joint one of `joints`);
        a spatial tendon, or a fixed one whose limits, spring, damper, friction or armature
        would act, is a ModelError."""
        self.vet(node, node.attrib)
        if not node.children:
            self.report.ignore("<tendon> (empty)", node.line)
        for t in node.children:
            if t.tag == "spatial":
                self.fail(t, "spatial tendons (routed through sites and wrapping geoms) are not "
                             "supported; a fixed tendon (a sum of joint values) is")
            if t.tag != "fixed":
                self.elsewhere(t, "tendon")
                continue
            eff = self.effective(t, tag="tendon")      # (checked against ATTRIBUTES["fixed"])
            v = self.flag(t, eff, "limited") if self.flags.limit else "false"
            if v == "true" or (v == "auto" and "range" in eff):
                self.fail(t, f"limited={eff.get('limited', 'auto')!r} with range="
                             f"{eff.get('range', '0 0')!r}: tendon limits are not supported")
            if "range" in eff:
                self.report.ignore("fixed range (not limited)", t.line)
            name = eff.get("name") or f"tendon@{t.line}"
            if name in self.tendons:
                self.fail(t, f"duplicate tendon name {name!r}")
            path = []
            for j in t.children:
                if j.tag != "joint":
                    self.elsewhere(j, "fixed")
                    continue
                self.vet(j, j.attrib, "tendon joint")
                jname = j.attrib.get("joint")
                if jname not in joints:
                    self.fail(j, f"joint={jname!r} names no joint of the model")
                if any(jname == p[0] for p in path):
                    self.fail(j, f"joint={jname!r} is already in tendon {name!r}")
                path.append((jname, float(self.floats(j, j.attrib, "coef", 1)[0])))
            if not path:
                self.fail(t, f"tendon {name!r} has no <joint>: its path cannot be empty")
            self.tendons[name] = Tendon(t, name, tuple(path))

    # actuators --------------------------------------------------------------------------------
    def motors(self, node, joints):
        """The <motor>s of an <actuator> (each on one of `joints` or on a fixed tendon);
        others are ModelErrors."""
        out = []
        for a in node.children:
            if a.tag != "motor":
                if a.tag in _OTHER_ACTUATORS:
                    self.fail(a, f"<{a.tag}> actuators are not supported (only <motor>)")
                self.elsewhere(a, "actuator")
                continue
            eff = self.effective(a, tag="motor")
            for key in ("site", "body", "jointinparent"):
                if key in eff:
                    self.fail(a, f"a motor on a {key} is not supported (only joint= or tendon=)")
            if ("joint" in eff) == ("tendon" in eff):
                self.fail(a, "a motor needs exactly one of joint= and tendon=")
            tname = eff.get("tendon")
            if tname is not None and tname not in self.tendons:
                self.fail(a, f"tendon={tname!r} names no fixed tendon of the model "
                             f"({sorted(self.tendons)})")
            jname = eff.get("joint")
            if tname is None and jname not in joints:
                self.fail(a, f"joint={jname!r} names no joint of the model")
            gear = self.floats(a, eff, "gear", (1, 6), default=(1.0,))
            if np.any(gear[1:] != 0):
                self.fail(a, f"gear={vec(gear)}: only the first component acts on a joint")
            lo, hi = -math.inf, math.inf
            for rng, lim in (("ctrlrange", "ctrllimited"), ("forcerange", "forcelimited")):
                v = self.flag(a, eff, lim)
                if v == "true" or (v == "auto" and rng in eff):
                    r = self.floats(a, eff, rng, 2)
                    if r[0] > r[1]:
                        self.fail(a, f"{rng}={vec(r)} has lower > upper")
                    lo, hi = max(lo, r[0]), min(hi, r[1])
            moment = self.tendons[tname].path if tname is not None else ((jname, 1.0),)
            out.append(Motor(a, eff.get("name") or tname or jname, moment, float(gear[0]),
                             (lo, hi), tname))
        return out
