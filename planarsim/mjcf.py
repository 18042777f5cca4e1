"""Loader for the planar subset of MJCF (MuJoCo XML) used by 2D characters such as SIMBICON's.

Supported (everything else is a ``ModelError`` naming the element and its line):

* ``<mujoco model>``, ``<compiler angle="degree|radian" coordinate="global">`` (global
  coordinates only), ``<default>`` with ``<joint>`` / ``<geom>`` attribute defaults,
  ``<worldbody>`` holding one root ``<body>``.
* ``<body name>`` nested to any depth. A body without a joint is welded to its parent: its
  geoms' mass and inertia are merged into the parent's rigid body.
* ``<joint type="slide|hinge" axis pos range limited stiffness damping armature=0>``. The root
  body either has two slide joints spanning the x-z plane plus a hinge about y ("free in the
  plane", no pin), or a single hinge (pinned to the world). Every other body has at most one
  hinge about +-y, which becomes ``add_pin`` with its limits (radians) and passive
  stiffness [N m/rad] / damping [N m s/rad].
* ``<geom type="capsule|box|sphere" size pos fromto mass density>``.

Plane mapping: MJCF (x, y, z) -> planarsim (x, y) = (x_mjcf, z_mjcf); the MJCF y coordinate is
dropped (left and right legs overlap in the plane). A hinge about +y turns x toward -z, which
is clockwise in our plane, so a pin angle is ``-axis_y * (MJCF joint angle)`` and a range
[lo, hi] about +y becomes [-hi, -lo].

Mass properties per rigid body, about the axis normal to the plane (MJCF y):
  sphere  I = 2/5 m r^2
  box     I = m (a^2 + c^2) / 3           (half sizes a along x, c along z)
  capsule cylinder (length L, radius r) plus two hemispheres, mass split by volume:
          I_perp = m_c (r^2/4 + L^2/12) + 2 m_h (83/320 r^2 + (L/2 + 3r/8)^2)
          I_axis = m_c r^2/2 + 2 m_h (2/5 r^2); I_y = I_perp + (I_axis - I_perp) (axis . y)^2
then the parallel-axis theorem with in-plane offsets (x, z) from the body COM.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from xml.parsers import expat

import numpy as np

from .builder import ModelBuilder
from .errors import ModelError

_ALLOWED = {
    "mujoco": {"model"},
    "compiler": {"angle", "coordinate"},
    "default": set(),
    "worldbody": set(),
    "body": {"name"},
    "joint": {"name", "type", "axis", "pos", "range", "limited", "stiffness", "damping", "armature"},
    "geom": {"name", "type", "size", "pos", "fromto", "mass", "density"},
}
_CHILDREN = {
    "mujoco": {"compiler", "default", "worldbody"},
    "compiler": set(),
    "default": {"joint", "geom"},
    "worldbody": {"body"},
    "body": {"joint", "geom", "body"},
    "joint": set(),
    "geom": set(),
}
DEFAULT_DENSITY = 1000.0  # [kg/m^3] MuJoCo's default geom density
DRAWN = {"collide": False}  # add_shape's options for a geom that is only drawn
COLLIDES = {"collide": True}


@dataclass
class Node:
    """One XML element with the line it starts on."""
    tag: str
    attrib: dict
    line: int
    children: list = field(default_factory=list)


def parse_xml(text: str, source: str = "<string>") -> Node:
    """Parse XML into Nodes that remember their line numbers (expat)."""
    parser = expat.ParserCreate()
    stack, root = [], []

    def start(tag, attrs):
        node = Node(tag, dict(attrs), parser.CurrentLineNumber)
        (stack[-1].children if stack else root).append(node)
        stack.append(node)

    def end(tag):
        stack.pop()

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    try:
        parser.Parse(text, True)
    except expat.ExpatError as e:
        raise ModelError(f"{source}:{e.lineno}: malformed XML: {expat.ErrorString(e.code)} "
                         f"(line {e.lineno}, column {e.offset})") from None
    return root[0]


@dataclass
class RigidBody:
    """A planarsim rigid body assembled from one MJCF body and the bodies welded to it."""
    name: str
    mass: float = 0.0                       # [kg]
    com: np.ndarray = None                  # (2,) world COM [m]
    inertia: float = 0.0                    # about the COM [kg m^2]
    parts: list = field(default_factory=list)   # (mass, (x, y), I_own, shape, name) per geom
    mjcf_bodies: list = field(default_factory=list)


@dataclass
class MJCFModel:
    """Result of :func:`load_mjcf`.

    builder : ModelBuilder with bodies and pins added (add actuators/contacts, then compile())
    body    : MJCF body name -> planarsim body id (welded bodies map to their rigid parent)
    pin     : MJCF hinge name -> planarsim pin id
    rigid   : planarsim body id -> RigidBody (mass [kg], com (2,) [m], inertia [kg m^2])
    root    : planarsim id of the root body
    free_joints : names of the root's planar joints (slides + hinge) that became "free"
    """
    builder: ModelBuilder
    body: dict
    pin: dict
    rigid: dict
    root: int
    name: str = "mjcf"
    free_joints: tuple = ()

    def compile(self, **meta):
        return self.builder.compile(**meta)


class _Loader:
    def __init__(self, root: Node, source: str):
        self.src = source
        self.root = root
        self.angle_scale = math.pi / 180.0   # MuJoCo's default compiler angle is degrees
        self.defaults = {"joint": {}, "geom": {}}

    # errors and attribute parsing -----------------------------------------------------------
    def fail(self, node, msg):
        raise ModelError(f"{self.src}:{node.line}: <{node.tag}"
                         f"{' name=' + repr(node.attrib['name']) if 'name' in node.attrib else ''}> "
                         f"(line {node.line}): {msg}")

    def check(self, node):
        if node.tag not in _ALLOWED:
            self.fail(node, f"element <{node.tag}> is not supported by the planar MJCF loader "
                            f"(supported: {sorted(_ALLOWED)})")
        bad = sorted(set(node.attrib) - _ALLOWED[node.tag])
        if bad:
            self.fail(node, f"attribute(s) {bad} not supported on <{node.tag}> "
                            f"(supported: {sorted(_ALLOWED[node.tag])})")
        for c in node.children:
            if c.tag not in _CHILDREN[node.tag]:
                self.fail(c, f"element <{c.tag}> is not supported inside <{node.tag}> "
                             f"(allowed: {sorted(_CHILDREN[node.tag]) or 'none'})")

    def attr(self, node, key, default=None):
        if key in node.attrib:
            return node.attrib[key]
        return self.defaults.get(node.tag, {}).get(key, default)

    def floats(self, node, key, n=None, default=None):
        raw = self.attr(node, key)
        if raw is None:
            if default is None:
                self.fail(node, f"attribute {key!r} is required")
            return np.asarray(default, dtype=np.float64)
        try:
            vals = np.array([float(t) for t in raw.split()], dtype=np.float64)
        except ValueError:
            self.fail(node, f"{key}={raw!r} must be numbers separated by spaces")
        if n is not None and vals.size not in ((n,) if isinstance(n, int) else n):
            self.fail(node, f"{key}={raw!r} must have {n} number(s), got {vals.size}")
        if not np.all(np.isfinite(vals)):
            self.fail(node, f"{key}={raw!r} must be finite")
        return vals

    # top level ------------------------------------------------------------------------------
    def load(self, builder, offset) -> MJCFModel:
        root = self.root
        if root.tag != "mujoco":
            self.fail(root, "the root element must be <mujoco>")
        self.check(root)
        worldbody = None
        for node in root.children:
            self.check(node)
            if node.tag == "compiler":
                self.compiler(node)
            elif node.tag == "default":
                for d in node.children:
                    self.check(d)
                    self.defaults[d.tag].update(d.attrib)
            elif worldbody is None:
                worldbody = node
            else:
                self.fail(node, "only one <worldbody> is allowed")
        if worldbody is None or len(worldbody.children) != 1:
            self.fail(worldbody or root, "<worldbody> must hold exactly one root <body>")
        self.offset = np.asarray(offset, dtype=np.float64)
        self.rigid, self.body_map, self.pins = [], {}, []
        self.walk(worldbody.children[0], parent=None)
        return self.emit(builder, root.attrib.get("model", "mjcf"))

    def compiler(self, node):
        angle = node.attrib.get("angle", "degree")
        if angle not in ("degree", "radian"):
            self.fail(node, f"angle={angle!r} must be 'degree' or 'radian'")
        self.angle_scale = math.pi / 180.0 if angle == "degree" else 1.0
        coord = node.attrib.get("coordinate", "global")
        if coord != "global":
            self.fail(node, f"coordinate={coord!r} is not supported; only 'global' coordinates")

    def plane(self, vec3):
        """MJCF (x, y, z) -> planarsim (x, y) = (x, z) + offset [m]."""
        return np.array([vec3[0], vec3[2]]) + self.offset

    # bodies, joints, geoms --------------------------------------------------------------------
    def walk(self, node, parent):
        self.check(node)
        name = node.attrib.get("name") or f"body@{node.line}"
        if name in self.body_map:
            self.fail(node, f"duplicate body name {name!r}")
        joints = [c for c in node.children if c.tag == "joint"]
        for j in joints:
            self.check(j)
        if parent is None:
            rid = self.new_rigid(name)
            self.root_joints(node, joints, rid)
        elif not joints:
            rid = parent                      # welded: merge into the parent's rigid body
        else:
            if len(joints) != 1 or self.attr(joints[0], "type", "hinge") != "hinge":
                self.fail(joints[0], "a non-root body must have at most one joint, a hinge")
            rid = self.new_rigid(name)
            self.pins.append(self.hinge(joints[0], parent, rid))
        self.body_map[name] = rid
        self.rigid[rid].mjcf_bodies.append(name)
        for c in node.children:
            if c.tag == "geom":
                self.check(c)
                self.rigid[rid].parts.append(self.geom(c) + (c.attrib.get("name", ""),))
            elif c.tag == "body":
                self.walk(c, rid)

    def new_rigid(self, name):
        self.rigid.append(RigidBody(name))
        return len(self.rigid) - 1

    def axis(self, j):
        a = self.floats(j, "axis", 3, default=(0.0, 0.0, 1.0))
        n = np.linalg.norm(a)
        if not n > 0:
            self.fail(j, f"axis={tuple(a)} must be non-zero")
        return a / n

    def passive(self, j):
        armature = float(self.floats(j, "armature", 1, default=(0.0,))[0])
        if armature != 0.0:
            self.fail(j, f"armature={armature} is not supported (must be 0)")
        k = float(self.floats(j, "stiffness", 1, default=(0.0,))[0])
        c = float(self.floats(j, "damping", 1, default=(0.0,))[0])
        if k < 0 or c < 0:
            self.fail(j, f"stiffness={k} and damping={c} must be >= 0")
        return k, c

    def root_joints(self, node, joints, rid):
        kinds = sorted(self.attr(j, "type", "hinge") for j in joints)
        if kinds == ["hinge", "slide", "slide"]:
            slides = [self.axis(j) for j in joints if self.attr(j, "type", "hinge") == "slide"]
            hinge = [j for j in joints if self.attr(j, "type", "hinge") == "hinge"][0]
            a = self.axis(hinge)
            span = np.cross(slides[0], slides[1])
            if abs(abs(a[1]) - 1) > 1e-9 or any(abs(s[1]) > 1e-9 for s in slides) or np.linalg.norm(span) < 1e-9:
                self.fail(node, "the root's joints must be two slides spanning the x-z plane and a "
                                "hinge about y (free in the plane)")
            for j in joints:
                k, c = self.passive(j)
                if k or c or self.limited(j):
                    self.fail(j, "stiffness, damping or limits on the root's planar joints are not "
                                 "supported")
            self.free = tuple(j.attrib.get("name", "") for j in joints)
            self.root_pin = None
        elif kinds == ["hinge"]:
            self.free = ()
            self.root_pin = self.hinge(joints[0], None, rid)
        else:
            self.fail(node, f"root body joints {kinds} unsupported: use slide x + slide z + hinge y "
                            f"(free in the plane) or one hinge (pinned to the world)")

    def limited(self, j):
        lim = self.attr(j, "limited", "auto")
        if lim not in ("true", "false", "auto"):
            self.fail(j, f"limited={lim!r} must be true, false or auto")
        return lim == "true" or (lim == "auto" and self.attr(j, "range") is not None)

    def hinge(self, j, parent, child):
        a = self.axis(j)
        if abs(abs(a[1]) - 1.0) > 1e-9:
            self.fail(j, f"hinge axis={tuple(j.attrib.get('axis', '0 0 1').split())} must be "
                         f"(0, +-1, 0): normal to the x-z plane")
        sign = -float(np.sign(a[1]))      # pin angle = sign * MJCF angle
        pos = self.plane(self.floats(j, "pos", 3, default=(0.0, 0.0, 0.0)))
        limit = None
        if self.limited(j):
            rng = self.floats(j, "range", 2) * self.angle_scale
            if rng[0] > rng[1]:
                self.fail(j, f"range={tuple(rng / self.angle_scale)} has lower > upper")
            limit = tuple(sorted((sign * rng[0], sign * rng[1])))
        k, c = self.passive(j)
        name = j.attrib.get("name") or f"joint@{j.line}"
        return dict(name=name, parent=parent, child=child, pos=pos, limit=limit, k=k, c=c, node=j)

    def geom(self, g):
        kind = self.attr(g, "type", "sphere")
        size = self.floats(g, "size", (1, 2, 3))
        if np.any(size <= 0):
            self.fail(g, f"size={tuple(size)} must be > 0")
        if kind == "sphere":
            r = size[0]
            vol = 4 / 3 * math.pi * r ** 3
            center = self.floats(g, "pos", 3, default=(0.0, 0.0, 0.0))
            i_unit, shape = 0.4 * r * r, ("circle", r)
        elif kind == "box":
            if size.size != 3:
                self.fail(g, f"box size={tuple(size)} must be three half-lengths")
            if "fromto" in g.attrib:
                self.fail(g, "fromto on a box is not supported; use pos and size")
            vol = 8 * size[0] * size[1] * size[2]
            center = self.floats(g, "pos", 3, default=(0.0, 0.0, 0.0))
            i_unit, shape = (size[0] ** 2 + size[2] ** 2) / 3, ("box", 2 * size[0], 2 * size[2])
        elif kind == "capsule":
            r = size[0]
            if "fromto" not in g.attrib:
                self.fail(g, "a capsule needs fromto (pos + half-length is not supported)")
            ft = self.floats(g, "fromto", 6)
            p0, p1 = ft[:3], ft[3:]
            L = float(np.linalg.norm(p1 - p0))
            if not L > 0:
                self.fail(g, "fromto end points must differ")
            vol_c, vol_h = math.pi * r * r * L, 4 / 3 * math.pi * r ** 3
            vol = vol_c + vol_h
            fc, fh = vol_c / vol, vol_h / vol
            i_perp = fc * (r * r / 4 + L * L / 12) + fh * (83 / 320 * r * r + (L / 2 + 3 * r / 8) ** 2)
            i_axis = fc * r * r / 2 + fh * 0.4 * r * r
            ay = (p1 - p0)[1] / L
            i_unit = i_perp + (i_axis - i_perp) * ay * ay
            center = 0.5 * (p0 + p1)
            shape = ("capsule", self.plane(p0), self.plane(p1), r)
        else:
            self.fail(g, f"geom type={kind!r} is not supported (capsule, box or sphere)")
        if "mass" in g.attrib or "mass" in self.defaults["geom"]:
            mass = float(self.floats(g, "mass", 1)[0])
        else:
            mass = float(self.floats(g, "density", 1, default=(DEFAULT_DENSITY,))[0]) * vol
        if not mass > 0:
            self.fail(g, f"mass={mass} must be > 0")
        return mass, self.plane(center), mass * i_unit, shape

    # build ------------------------------------------------------------------------------------
    def emit(self, builder, model_name) -> MJCFModel:
        ids = []
        for rb in self.rigid:
            if not rb.parts:
                self.fail(self.root, f"body {rb.name!r} has no geom with mass")
            m = np.array([p[0] for p in rb.parts])
            x = np.array([p[1] for p in rb.parts])
            rb.mass = float(m.sum())
            rb.com = (m[:, None] * x).sum(0) / rb.mass
            d2 = ((x - rb.com) ** 2).sum(1)
            rb.inertia = float(sum(p[2] for p in rb.parts) + (m * d2).sum())
            shapes = []
            for _, c, _, s, geom_name in rb.parts:
                # drawn only unless named in collide: the model touches the ground through
                # its own contact points
                how = COLLIDES if geom_name in self.collide else DRAWN
                if s[0] == "circle":
                    shapes.append(("circle", tuple(c - rb.com), s[1], how))
                elif s[0] == "box":
                    shapes.append(("box", tuple(c - rb.com), s[1], s[2], how))
                else:
                    shapes.append(("capsule", tuple(s[1] - rb.com), tuple(s[2] - rb.com), s[3],
                                   how))
            ids.append(builder.add_body(rb.name, mass=rb.mass, inertia=rb.inertia,
                                        pos=tuple(rb.com), shapes=shapes))
        pins = {}
        if self.root_pin is not None:
            self.pins.insert(0, self.root_pin)
        for p in self.pins:
            a = None if p["parent"] is None else ids[p["parent"]]
            pins[p["name"]] = builder.add_pin(p["name"], a, ids[p["child"]], anchor_world=tuple(p["pos"]),
                                              limit=p["limit"], stiffness=p["k"], damping=p["c"])
        return MJCFModel(builder=builder, body={k: ids[v] for k, v in self.body_map.items()},
                         pin=pins, rigid={ids[i]: rb for i, rb in enumerate(self.rigid)},
                         root=ids[0], name=model_name, free_joints=self.free)


def load_mjcf(source, builder: ModelBuilder | None = None, offset=(0.0, 0.0), collide=(),
              **builder_kw) -> MJCFModel:
    """Load a planar MJCF character.

    source : path to an .xml file, or the XML text itself (a string starting with '<')
    builder : add to this ModelBuilder (default: a new one from ``builder_kw``: dt, gravity,
        terrain)
    offset : (2,) [m] translation of the whole character in the plane (e.g. to stand it on
        the ground)
    collide : names of the geoms that collide (with the ground and other bodies' shapes); the
        others are drawn only (the character touches the ground through contacts added to the
        builder)

    Returns an MJCFModel (builder, name maps, per-body mass properties). Raises ModelError
    naming the element and line for malformed or unsupported input.
    """
    if isinstance(source, (str, Path)) and not str(source).lstrip().startswith("<"):
        path = Path(source)
        try:
            text = path.read_text()
        except OSError as e:
            raise ModelError(f"cannot read MJCF file {str(path)!r}: {e.strerror}") from None
        name = str(path)
    else:
        text, name = str(source), "<string>"
    root = parse_xml(text, name)
    b = builder if builder is not None else ModelBuilder(**builder_kw)
    loader = _Loader(root, name)
    loader.collide = frozenset(collide)
    out = loader.load(b, offset)
    known = {p[4] for rb in loader.rigid for p in rb.parts}
    unknown = sorted(loader.collide - known)
    if unknown:
        raise ModelError(f"{name}: collide names geoms {unknown} that the file does not have; "
                         f"its named geoms: {sorted(n for n in known if n)}")
    return out
