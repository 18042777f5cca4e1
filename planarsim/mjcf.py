"""Loader for planar MJCF (MuJoCo XML): characters that move in one plane, as MuJoCo's
ecosystem writes them (gymnasium's eight planar models, Hopper to Swimmer and Reacher; the
SIMBICON character).

What is read (see ``ATTRIBUTES`` for every attribute and what becomes of it):

* ``<compiler angle coordinate="local|global" inertiafromgeom settotalmass eulerseq>``:
  MuJoCo's default local frames (a body's ``pos``/orientation are in its parent's frame, its
  joints' and geoms' in its own) or the older global form (everything in the world's frame).
* ``<option timestep gravity viscosity density>``: timestep -> the model's dt [s]; gravity
  [m/s^2] -> the model's gravity, its component along the plane's normal dropped (the
  joints carry it: a planar model cannot move that way); a fluid (viscosity or density
  non-zero) -> MuJoCo's inertia-box drag on every body (ModelBuilder.add_fluid_box), unless
  ``drop`` names "fluid".
* ``<default>`` with nested classes, ``class`` and ``childclass``.
* ``<body pos quat axisangle euler zaxis xyaxes>``; a body without joints is welded to its
  parent (its geoms join the parent's rigid body, or the world's).
* ``<joint type="hinge|slide" pos axis ref range limited stiffness damping springref armature>``.
  A root body with two slides spanning the plane and a hinge about its normal is free in the
  plane, each joint a free coordinate (``add_free_coordinate``: limits, springs, dampers,
  armature and motors act on it, nothing is constrained); without the hinge it translates
  only (a point mass: reacher's target). One hinge pins a body to its parent (``add_pin``,
  limits [rad], passive stiffness [N m/rad] toward springref, damping [N m s/rad], armature
  [kg m^2]); one slide is a slider (``add_slider``); ``drop={"armature"}`` loads without
  armature (reported).
* ``<geom type="sphere|capsule|cylinder|box|ellipsoid|plane" size pos orientation fromto
  mass density friction contype conaffinity condim>``: mass properties as MuJoCo's compiler
  computes them (planarsim.mjcf_frames), shapes that collide by MuJoCo's contype/conaffinity
  rule; a plane in the world whose normal is the plane's "up" becomes flat terrain.
* ``<inertial pos mass diaginertia fullinertia orientation>`` (with inertiafromgeom auto/false).
* ``<actuator><motor joint gear ctrlrange ctrllimited forcerange forcelimited>``: a pin motor
  (a body torque or force on a free root's joints) whose torque input [N m] is
  ``gear * ctrl`` in the pin's sign (``MJCFModel.actuator[name].gear``), saturated to
  gear * ctrlrange.
* ``<include file>`` (planarsim.mjcf_include: on disk or from ``assets``), ``<option><flag>``
  (planarsim.mjcf_options: gravity, contact, limit, constraint, spring, damper, frictionloss
  honoured; flags without physics reported; the rest a ModelError), planes whose normal lies
  in the plane of motion as static walls and the plane of motion of a slides-only model
  (planarsim.mjcf_plane).

Purely visual or solver-tuning elements and attributes (rgba, material, asset, visual, light,
camera, site, solref, margin, integrator, ...) are ignored and listed in ``MJCFModel.report``;
anything else that changes physics and is not supported (tendons, equality constraints, a
joint leaving the plane) is a ModelError naming the element and its line.

Plane mapping. The plane of motion is the one normal to the hinges: MJCF y (x-z plane, the
walkers: planarsim (x, y) = (x_mjcf, z_mjcf)) or MJCF z (x-y plane, swimmer and reacher:
(x, y) = (x_mjcf, y_mjcf)). The coordinate along the normal is dropped (left and right legs
overlap). A hinge about the unit axis a turns by its MJCF angle about a; the plane's
counter-clockwise normal is e1 x e2 (-y for x-z, +z for x-y), so the pin angle is
``sign * (q - ref)`` with sign = a . (e1 x e2) and q the MJCF joint value (``ref`` at the
file's pose), and a range [lo, hi] becomes sorted(sign * ([lo, hi] - ref)).

Mass properties per rigid body about the plane's normal: each geom's principal inertia
turned into the world (I_n = sum_i I_i (R^T n)_i^2), then the parallel-axis theorem with
in-plane offsets from the body's COM.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from xml.parsers import expat

import numpy as np

from .builder import ModelBuilder
from .errors import ModelError
from . import mjcf_frames as F
from . import mjcf_include, mjcf_options, mjcf_plane   # hooks: includes, <option><flag>, plane
from .terrain import flat

DEFAULT_DENSITY = 1000.0  # [kg/m^3] MuJoCo's default geom density
DEFAULT_TIMESTEP = 0.002  # [s] MuJoCo's default option timestep
DEFAULT_GRAVITY = (0.0, 0.0, -9.81)  # [m/s^2] MuJoCo's default option gravity
DEFAULT_FRICTION = (1.0, 0.005, 0.0001)  # MuJoCo's default geom friction (slide, spin, roll)
DRAWN = {"collide": False}  # add_shape's options for a geom that is only drawn
COLLIDES = {"collide": True}
AXIS_TOL = 1e-9  # how far a unit joint axis may lean from the plane's normal (or into it)
DROPPABLE = ("armature", "fluid")  # physics the caller may choose to load without

# Per element: attributes it reads ("use"), ignores and reports ("ignore"), and accepts only
# at MuJoCo's default value ("default": value; any other value changes physics this loader
# does not model, a ModelError). Any attribute not listed is a ModelError.
_ORIENT = {"quat", "axisangle", "euler", "zaxis", "xyaxes"}
ATTRIBUTES = {
    "mujoco": dict(use={"model"}),
    "compiler": dict(
        use={"angle", "coordinate", "inertiafromgeom", "settotalmass", "eulerseq", "autolimits"},
        ignore={"meshdir", "texturedir", "assetdir", "discardvisual", "strippath", "fusestatic",
                "convexhull", "usethread", "saveinertial", "alignfree"},
        default={"boundmass": "0", "boundinertia": "0", "balanceinertia": "false"}),
    "option": dict(
        use={"timestep", "gravity", "viscosity", "density"},
        ignore={"integrator", "cone", "impratio", "tolerance", "iterations", "ls_iterations",
                "ls_tolerance", "solver", "noslip_iterations", "noslip_tolerance",
                "ccd_iterations", "ccd_tolerance", "mpr_iterations", "mpr_tolerance",
                "sdf_iterations", "sdf_initpoints", "jacobian", "apirate", "magnetic",
                "o_margin", "o_solref", "o_solimp", "o_friction", "collision",
                "actuatorgroupdisable"},
        default={"wind": "0 0 0"}),
    "body": dict(use={"name", "childclass", "pos"} | _ORIENT, ignore={"user"},
                 default={"mocap": "false", "gravcomp": "0"}),
    "joint": dict(
        use={"name", "class", "type", "pos", "axis", "range", "limited", "stiffness", "damping",
             "armature", "ref", "springref", "frictionloss"},
        ignore={"group", "margin", "solreflimit", "solimplimit", "solreffriction",
                "solimpfriction", "user"},
        default={"springdamper": "0 0", "actuatorfrclimited": "auto",
                 "actuatorgravcomp": "false"}),
    "geom": dict(
        use={"name", "class", "type", "size", "pos", "fromto", "mass", "density", "friction",
             "contype", "conaffinity", "condim"} | _ORIENT,
        ignore={"rgba", "material", "group", "margin", "gap", "solimp", "solref", "solmix",
                "priority", "user"},
        default={"shellinertia": "false", "fluidshape": "none", "fitscale": "1"}),
    "inertial": dict(use={"pos", "mass", "diaginertia", "fullinertia"} | _ORIENT),
    "motor": dict(
        use={"name", "class", "joint", "gear", "ctrlrange", "ctrllimited", "forcerange",
             "forcelimited"},
        ignore={"group", "user", "lengthrange", "actdim"},
        default={"actlimited": "auto", "actrange": "0 0"}),
}
# elements read by the loader, per parent
_CHILDREN = {
    "mujoco": {"compiler", "option", "default", "worldbody", "actuator"},
    "worldbody": {"body", "geom"},
    "body": {"body", "geom", "joint", "inertial"},
    "actuator": {"motor"},
}
# elements ignored (and reported) wherever they appear: drawing, cameras, sensing, bookkeeping
_IGNORED_ELEMENTS = {"size", "visual", "statistic", "custom", "asset", "keyframe", "sensor",
                     "light", "camera", "site", "extension", "exclude"}
# elements that are ignored when empty (a declaration with nothing in it) and a ModelError
# otherwise: each changes physics this loader does not model
_EMPTY_ONLY = {"tendon": "tendons", "equality": "equality constraints", "contact": "explicit contact pairs"}
SUPPORTED_GEOMS = ("sphere", "capsule", "cylinder", "box", "ellipsoid", "plane")


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
    inertia: float = 0.0                    # about the COM, normal to the plane [kg m^2]
    parts: list = field(default_factory=list)   # (mass, (x, y), I_own, shape, name, geom)
    mjcf_bodies: list = field(default_factory=list)


@dataclass
class JointMap:
    """How an MJCF joint maps onto planarsim: kind 'pin' (id: pin id), 'free' (id: the root
    body; axis: a slide's in-plane direction, or (2,) for the hinge; pin: its free coordinate
    in the pin table, ModelBuilder.add_free_coordinate) or 'slider' (id: pin id).
    The MJCF joint value is q = ref + sign * (planarsim coordinate). anchor: for a free
    root's joints, the point the hinge turns about, which the slides move, at the file's
    pose [m]."""
    kind: str
    id: int
    sign: float = 1.0
    ref: float = 0.0
    axis: tuple = ()
    anchor: tuple = ()
    pin: int = -1

    @property
    def coordinate(self) -> int:
        """Its row in the model's pin table (pins, sliders and free coordinates alike)."""
        return self.pin if self.kind == "free" else self.id

    @property
    def angular(self) -> bool:
        """Its coordinate is an angle [rad] (a hinge), not a slide [m]."""
        return self.kind == "pin" or (self.kind == "free" and self.axis == (2,))


@dataclass
class ActuatorMap:
    """A <motor>: planarsim actuator id, its MJCF joint, and gear: the actuator's input
    [N m or N] is ``gear * ctrl`` (the pin's sign included), saturated to ctrlrange * gear."""
    id: int
    joint: str
    gear: float
    ctrlrange: tuple = (-math.inf, math.inf)


@dataclass
class LoadReport:
    """What the loader did not turn into physics.

    ignored : "what" -> lines: visual, solver-tuning and bookkeeping elements and attributes
        (e.g. "<light>", "geom rgba", "option integrator")
    dropped : "what" -> lines: physics left out because ``drop`` asked for it (e.g. armature)
    notes : sentences on approximations the mapping makes (gravity along the normal, self
        collisions planarsim does not model, ...)
    """
    ignored: dict = field(default_factory=dict)
    dropped: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)

    def ignore(self, what: str, line: int):
        self.ignored.setdefault(what, []).append(line)

    def drop(self, what: str, line: int):
        self.dropped.setdefault(what, []).append(line)

    def note(self, text: str):
        if text not in self.notes:
            self.notes.append(text)

    def __str__(self):
        def lines(d):
            return [f"  {k} (line{'s' if len(v) > 1 else ''} {', '.join(map(str, sorted(set(v))))})"
                    for k, v in sorted(d.items())]
        out = ["ignored:"] + (lines(self.ignored) or ["  nothing"])
        if self.dropped:
            out += ["dropped (changes physics):"] + lines(self.dropped)
        if self.notes:
            out += ["notes:"] + [f"  {n}" for n in self.notes]
        return "\n".join(out)


@dataclass
class MJCFModel:
    """Result of :func:`load_mjcf`.

    builder : ModelBuilder with bodies, pins and motors added (add contacts, then compile())
    body    : MJCF body name -> planarsim body id (welded bodies map to their rigid parent;
              bodies welded to the world are absent)
    pin     : MJCF hinge name -> planarsim pin id
    rigid   : planarsim body id -> RigidBody (mass [kg], com (2,) [m], inertia [kg m^2])
    root    : planarsim id of the first root body
    free_joints : names of the root's planar joints (slides + hinge) that became "free"
    joint   : MJCF joint name -> JointMap (kind, id, sign, ref)
    actuator : MJCF motor name (or its joint's) -> ActuatorMap (id, joint, gear, ctrlrange)
    plane   : "x-z" or "x-y": the MJCF plane the model moves in
    report  : LoadReport: what was ignored, dropped or approximated
    com     : MJCF body name -> its own centre of mass in the plane at the file's pose [m]
              (the body's origin where it has no mass), for bodies that move
    """
    builder: ModelBuilder
    body: dict
    pin: dict
    rigid: dict
    root: int
    name: str = "mjcf"
    free_joints: tuple = ()
    joint: dict = field(default_factory=dict)
    actuator: dict = field(default_factory=dict)
    plane: str = "x-z"
    report: LoadReport = field(default_factory=LoadReport)
    com: dict = field(default_factory=dict)

    def compile(self, **meta):
        return self.builder.compile(**meta)


@dataclass
class Body3D:
    """An MJCF body at the file's pose: world position [m], rotation (columns: its axes)."""
    node: Node
    name: str
    parent: "Body3D | None"
    pos: np.ndarray
    R: np.ndarray
    joints: list = field(default_factory=list)      # dicts: node, eff, type, pos, axis
    geoms: list = field(default_factory=list)       # dicts: node, eff, kind, pos, R, ...
    inertials: list = field(default_factory=list)   # dicts: node, mass, pos, I_n
    children: list = field(default_factory=list)
    rid: int | None = None                          # planarsim rigid body (None: the world)


def _num(text):
    return [float(t) for t in str(text).split()]


def _vec(v):
    """A vector as a tuple of plain floats for messages."""
    return tuple(float(x) + 0.0 for x in np.round(v, 12))


def _mj_pair(a, b) -> bool:
    """MuJoCo's filter: two geoms may touch when contype of one meets conaffinity of the other."""
    return bool((a["contype"] & b["conaffinity"]) or (b["contype"] & a["conaffinity"]))


class _Loader:
    def __init__(self, root: Node, source: str, drop=()):
        self.src = source
        self.root = root
        self.angle_scale = math.pi / 180.0   # MuJoCo's default compiler angle is degrees
        self.eulerseq = "xyz"
        self.global_coords = False
        self.inertiafromgeom = "auto"
        self.settotalmass = None
        self.option = {}
        self.classes = {"main": {}}           # class -> tag -> attributes
        self.report = LoadReport()
        self.free_bodies = []                 # bodies with a free root's slides and hinge
        self.flags = mjcf_options.Flags()     # hook: <option><flag> (mjcf_options.read_flags)
        bad = sorted(set(drop) - set(DROPPABLE))
        if bad:
            raise ModelError(f"load_mjcf: drop={sorted(drop)} names {bad}; it may name {DROPPABLE}")
        self.drop = frozenset(drop)

    # errors and attributes --------------------------------------------------------------------
    def fail(self, node, msg):
        src = getattr(node, "file", None) or self.src     # hook: a node from an included file
        raise ModelError(f"{src}:{node.line}: <{node.tag}"
                         f"{' name=' + repr(node.attrib['name']) if 'name' in node.attrib else ''}> "
                         f"(line {node.line}): {msg}")

    def effective(self, node, cls="main", tag=None):
        """The node's attributes over its class's defaults (class attribute, else the
        inherited childclass, else 'main'); checks each against ATTRIBUTES."""
        cls = node.attrib.get("class", cls)
        if cls not in self.classes:
            self.fail(node, f"class={cls!r} is not defined by any <default class=...>")
        eff = dict(self.classes[cls].get(tag or node.tag, {}))
        eff.update(node.attrib)
        eff.pop("class", None)
        self.vet(node, eff)
        return eff

    def vet(self, node, eff):
        rules = ATTRIBUTES[node.tag]
        use, ignore, default = rules.get("use", set()), rules.get("ignore", set()), rules.get("default", {})
        for key in sorted(eff):
            if key in use:
                continue
            if key in ignore:
                self.report.ignore(f"{node.tag} {key}{mjcf_include.origin(node)}", node.line)
            elif key in default:
                if not self.same(eff[key], default[key]):
                    self.fail(node, f"{key}={eff[key]!r} changes physics this loader does not "
                                    f"model (only {default[key]!r} is supported)")
            else:
                self.fail(node, f"attribute(s) [{key!r}] not supported on <{node.tag}> "
                                f"(read: {sorted(use)}; ignored: {sorted(ignore)})")

    @staticmethod
    def same(a, b):
        try:
            return np.allclose(_num(a), _num(b), rtol=0, atol=0) and len(_num(a)) == len(_num(b))
        except ValueError:
            return str(a).strip() == str(b).strip()

    def floats(self, node, eff, key, n=None, default=None):
        raw = eff.get(key)
        if raw is None:
            if default is None:
                self.fail(node, f"attribute {key!r} is required")
            return np.asarray(default, dtype=np.float64)
        try:
            vals = np.array(_num(raw), dtype=np.float64)
        except ValueError:
            self.fail(node, f"{key}={raw!r} must be numbers separated by spaces")
        if n is not None and vals.size not in ((n,) if isinstance(n, int) else n):
            self.fail(node, f"{key}={raw!r} must have {n} number(s), got {vals.size}")
        if not np.all(np.isfinite(vals)):
            self.fail(node, f"{key}={raw!r} must be finite")
        return vals

    def scalar(self, node, eff, key, default):
        return float(self.floats(node, eff, key, 1, default=(default,))[0])

    def flag(self, node, eff, key, default="auto", allowed=("true", "false", "auto")):
        v = eff.get(key, default)
        if v not in allowed:
            self.fail(node, f"{key}={v!r} must be one of {allowed}")
        return v

    def orientation(self, node, eff) -> np.ndarray:
        """Rotation of an element's frame from quat | axisangle | euler | zaxis | xyaxes."""
        given = [k for k in ("quat", "axisangle", "euler", "zaxis", "xyaxes") if k in eff]
        if len(given) > 1:
            self.fail(node, f"orientation given twice: {given}")
        if not given:
            return np.eye(3)
        k = given[0]
        v = self.floats(node, eff, k, {"quat": 4, "axisangle": 4, "euler": 3, "zaxis": 3,
                                       "xyaxes": 6}[k])
        if k != "euler" and not np.linalg.norm(v[:3] if k != "quat" else v) > 0:
            self.fail(node, f"{k}={tuple(v)} must be non-zero")
        if k == "quat":
            return F.quat_matrix(v)
        if k == "axisangle":
            return F.axis_angle_matrix(v[:3], v[3] * self.angle_scale)
        if k == "euler":
            return F.euler_matrix(v * self.angle_scale, self.eulerseq)
        if k == "zaxis":
            return F.zaxis_matrix(v)
        return F.xyaxes_matrix(v)

    def frame(self, node, eff, parent_pos, parent_R):
        """World position [m] and rotation of an element given in its parent's frame (local
        coordinates) or in the world's (global)."""
        pos = self.floats(node, eff, "pos", 3, default=(0.0, 0.0, 0.0))
        R = self.orientation(node, eff)
        if self.global_coords:
            return pos, R
        return parent_pos + parent_R @ pos, parent_R @ R

    # top level ------------------------------------------------------------------------------
    def load(self, builder_kw, builder, offset, collide) -> MJCFModel:
        root = self.root
        if root.tag != "mujoco":
            self.fail(root, "the root element must be <mujoco>")
        self.vet(root, root.attrib)
        worldbody, actuators = None, []
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
            else:
                self.elsewhere(node, "mujoco")
        if worldbody is None:
            self.fail(root, "<worldbody> is missing")
        self.offset = np.asarray(offset, dtype=np.float64)
        world = Body3D(worldbody, "world", None, np.zeros(3), np.eye(3))
        self.bodies = []
        self.walk_children(worldbody, world, "main")
        self.choose_plane()
        self.world = world
        self.collide = None if collide is None else frozenset(collide)
        if not self.flags.contact:            # hook: <flag contact|constraint="disable">
            self.collide = frozenset()
        b = self.builder(builder_kw, builder)
        out = self.emit(b, root.attrib.get("model", "mjcf"))
        mjcf_options.check_filterparent(self)   # hook: <flag filterparent="disable">
        for node in actuators:
            self.actuators(node, out)
        return out

    def elsewhere(self, node, parent):
        """An element the loader does not read: ignored and reported when it only draws,
        senses or tunes; otherwise a ModelError naming it."""
        if node.tag in _IGNORED_ELEMENTS:
            # hook: an included file's elements are reported with its name
            self.report.ignore(f"<{node.tag}>{mjcf_include.origin(node)}", node.line)
            return
        if node.tag in _EMPTY_ONLY:
            kids = [c for c in node.children if not (node.tag == "contact" and c.tag == "exclude")]
            if kids:
                self.fail(kids[0], f"<{kids[0].tag}> inside <{node.tag}>: {_EMPTY_ONLY[node.tag]} "
                                   f"change physics and are not supported")
            for c in node.children:
                self.report.ignore(f"<{node.tag}><{c.tag}>", c.line)
            if not node.children:
                self.report.ignore(f"<{node.tag}> (empty)", node.line)
            return
        if node.tag == "freejoint":
            self.fail(node, "a free joint leaves the plane; use two slides and a hinge")
        self.fail(node, f"element <{node.tag}> is not supported inside <{parent}> "
                        f"(read: {sorted(_CHILDREN.get(parent, set()))}; ignored: "
                        f"{sorted(_IGNORED_ELEMENTS)})")

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
        self.option_line = node.line
        mjcf_options.read_flags(self, node)   # hook: <flag> children (gravity, contact, ...)

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
            elif c.tag in ("joint", "geom", "inertial"):
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
            self.fail(j, f"axis={tuple(a)} must be non-zero")
        a = a / np.linalg.norm(a)
        p = self.floats(j, eff, "pos", 3, default=(0.0, 0.0, 0.0))
        if not self.global_coords:
            a, p = body.R @ a, body.pos + body.R @ p
        mjcf_options.check_frictionloss(self, j, eff)   # hook: 0, or a ModelError naming it
        return dict(node=j, eff=eff, type=kind, axis=a, pos=p,
                    name=eff.get("name") or f"joint@{j.line}")

    def geom(self, g, eff, body):
        """World pose, size and mass of one geom (see planarsim.mjcf_frames)."""
        kind = eff.get("type", "sphere")
        if kind not in SUPPORTED_GEOMS:
            self.fail(g, f"type={kind!r} is not supported ({', '.join(SUPPORTED_GEOMS)})")
        if kind == "plane":
            pos, R = self.frame(g, eff, body.pos, body.R)
            return dict(node=g, eff=eff, kind=kind, pos=pos, R=R, mass=0.0, name=eff.get("name", ""),
                        **self.contact_params(g, eff))
        size = self.floats(g, eff, "size", (1, 2, 3))
        if np.any(size <= 0):
            self.fail(g, f"size={tuple(float(x) for x in size)} must be > 0")
        need = {"sphere": 1, "capsule": 1 if "fromto" in eff else 2,
                "cylinder": 1 if "fromto" in eff else 2, "box": 2 if "fromto" in eff else 3,
                "ellipsoid": 2 if "fromto" in eff else 3}[kind]
        if size.size < need:
            self.fail(g, f"{kind} size={tuple(float(x) for x in size)} needs {need} number(s)")
        if "fromto" in eff and kind != "sphere":
            ft = self.floats(g, eff, "fromto", 6)
            p0, p1 = ft[:3], ft[3:]
            if not self.global_coords:
                p0, p1 = body.pos + body.R @ p0, body.pos + body.R @ p1
            half = 0.5 * float(np.linalg.norm(p1 - p0))
            if not half > 0:
                self.fail(g, "fromto end points must differ")
            pos, R, ends = 0.5 * (p0 + p1), F.zaxis_matrix(p1 - p0), (p0, p1)
            dims = (size[0], half) if kind in ("capsule", "cylinder") else (size[0], size[1], half)
        else:
            pos, R = self.frame(g, eff, body.pos, body.R)
            dims = tuple(size[:need])
            ends = (pos - dims[-1] * R[:, 2], pos + dims[-1] * R[:, 2])
        vol, unit = F.unit_inertia(kind, dims)
        if "mass" in eff:
            mass = self.scalar(g, eff, "mass", 0.0)
            if mass < 0:
                self.fail(g, f"mass={mass} must be > 0 (or 0 for a massless geom)")
        else:
            density = self.scalar(g, eff, "density", DEFAULT_DENSITY)
            if density < 0:
                self.fail(g, f"density={density} must be >= 0")
            mass = density * vol
        return dict(node=g, eff=eff, kind=kind, pos=pos, R=R, dims=dims, unit=unit, mass=mass, ends=ends,
                    name=eff.get("name", ""), **self.contact_params(g, eff))

    def contact_params(self, g, eff):
        """contype, conaffinity (bits), condim and sliding friction of a geom."""
        out = {}
        for key in ("contype", "conaffinity"):
            v = eff.get(key, "1")
            if not v.strip().isdigit():
                self.fail(g, f"{key}={v!r} must be a non-negative integer (bits)")
            out[key] = int(v)
        out["condim"] = int(self.scalar(g, eff, "condim", 3))
        if out["condim"] not in (1, 3, 4, 6):
            self.fail(g, f"condim={out['condim']} must be 1, 3, 4 or 6")
        fr = self.floats(g, eff, "friction", (1, 2, 3), default=DEFAULT_FRICTION)
        if fr[0] < 0:
            self.fail(g, f"friction={tuple(fr)} must be >= 0")
        out["mu"] = float(fr[0])
        return out

    def inertial(self, node, body):
        eff = dict(node.attrib)
        self.vet(node, eff)
        pos, R = self.frame(node, eff, body.pos, body.R)
        mass = self.scalar(node, eff, "mass", -1.0)
        if not mass > 0:
            self.fail(node, f"mass={mass} must be > 0")
        if "fullinertia" in eff:
            f6 = self.floats(node, eff, "fullinertia", 6)
            tensor = np.array([[f6[0], f6[3], f6[4]], [f6[3], f6[1], f6[5]], [f6[4], f6[5], f6[2]]])
            tensor = R @ tensor @ R.T
        else:
            d = self.floats(node, eff, "diaginertia", 3)
            tensor = R @ np.diag(d) @ R.T
        return dict(node=node, mass=mass, pos=pos, tensor=tensor)

    # the plane of motion ----------------------------------------------------------------------
    def choose_plane(self):
        """The plane normal to the hinges (MJCF y -> x-z, z -> x-y; x-z without hinges); every
        hinge must be normal to it and every slide in it."""
        joints = [j for b in self.bodies for j in b.joints]
        hinges = [j for j in joints if j["type"] == "hinge"]
        # hook: from the hinges, else from the slides (a point mass on x and y slides)
        normal = mjcf_plane.normal_from_joints(hinges, [j for j in joints if j["type"] == "slide"])
        self.i1, self.i2 = (0, 2) if normal == 1 else (0, 1)
        self.normal = normal
        self.plane_name = "x-z" if normal == 1 else "x-y"
        self.ccw = np.cross(np.eye(3)[self.i1], np.eye(3)[self.i2])   # -y or +z
        want = "(0, +-1, 0)" if normal == 1 else "(0, 0, +-1)"
        for j in joints:
            a = j["axis"]
            if j["type"] == "hinge" and abs(abs(a[normal]) - 1) > AXIS_TOL:
                self.fail(j["node"], f"hinge axis={_vec(a)} is not normal to the "
                                     f"{self.plane_name} plane of motion: it must be {want}; a "
                                     f"joint leaving the plane is not supported")
            if j["type"] == "slide" and abs(a[normal]) > AXIS_TOL:
                self.fail(j["node"], f"slide axis={_vec(a)} leaves the "
                                     f"{self.plane_name} plane of motion")

    def plane(self, p) -> np.ndarray:
        """World point (x, y, z) -> planarsim (x, y) [m], shifted by the offset."""
        return np.array([p[self.i1], p[self.i2]]) + self.offset

    def sign(self, j) -> float:
        """+1 when the MJCF joint turns (hinge) counter-clockwise in planarsim's plane."""
        return float(np.sign(j["axis"] @ self.ccw))

    def builder(self, builder_kw, builder):
        """A ModelBuilder with the file's timestep and in-plane gravity (caller's builder or
        builder_kw win, noted in the report), and flat terrain from a ground plane."""
        dt = self.option.get("timestep", DEFAULT_TIMESTEP)
        g3 = np.asarray(self.option.get("gravity", DEFAULT_GRAVITY), dtype=np.float64)
        g = (float(g3[self.i1]), float(g3[self.i2]))
        if g3[self.normal] != 0:
            self.report.note(f"gravity along the plane's normal ({g3[self.normal]} m/s^2) is "
                             f"carried by the joints: the model cannot move that way")
        self.ground = self.ground_plane()
        if builder is not None:
            if builder.dt != dt or tuple(np.asarray(builder.gravity, float)) != g:
                self.report.note(f"the caller's builder keeps dt={builder.dt} s and gravity="
                                 f"{tuple(builder.gravity)}; the file has dt={dt} s, gravity={g}")
            if self.ground is not None:
                self.report.note("the caller's builder keeps its terrain; the file's ground plane "
                                 "is not applied")
            return builder
        kw = dict(dt=dt, gravity=g)
        if self.ground is not None:
            kw["terrain"] = flat(self.ground[1])
        for k, v in builder_kw.items():
            if k in kw and k != "terrain":
                self.report.note(f"{k}={v} given to load_mjcf overrides the file's {kw[k]}")
            kw[k] = v
        return ModelBuilder(**kw)

    def ground_plane(self):
        """(geom, height [m]) of the world's plane that faces up in the plane of motion, or
        None. Planes parallel to the plane of motion are ignored (they meet nothing)."""
        found = None
        for g in self.world_geoms():
            if g["kind"] != "plane":
                continue
            n = g["R"][:, 2]
            if abs(abs(n[self.normal]) - 1) <= AXIS_TOL:
                self.report.ignore("geom plane parallel to the plane of motion", g["node"].line)
                continue
            if mjcf_plane.is_wall(self, g):   # hook: a wall, a static box (parts())
                continue
            if abs(n[self.i2] - 1) > AXIS_TOL:
                self.fail(g["node"], f"a plane whose normal {_vec(n)} is not the "
                                     f"plane of motion's up is not supported")
            if found is not None:
                self.fail(g["node"], "a second ground plane is not supported")
            found = (g, float(self.plane(g["pos"])[1]))
        return found

    def world_geoms(self):
        """Geoms of the world and of the bodies welded to it (no joint on the way)."""
        out, stack = [], [self.world]
        while stack:
            b = stack.pop()
            out += b.geoms
            stack += [c for c in b.children if not c.joints]
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
                if abs(abs(np.cross(s[0], s[1]) @ self.ccw) - 1) > 1e-9:
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

    def limited(self, j):
        if not self.flags.limit:              # hook: <flag limit|constraint="disable">
            return False
        v = self.flag(j["node"], j["eff"], "limited")
        return v == "true" or (v == "auto" and "range" in j["eff"])

    def armature(self, j):
        """Joint armature [kg m^2 or kg]; 0 (reported) where the caller dropped it
        (drop={"armature"})."""
        a = self.scalar(j["node"], j["eff"], "armature", 0.0)
        if a != 0.0 and "armature" in self.drop:
            self.report.drop("joint armature", j["node"].line)
            return 0.0
        return a

    def parts(self):
        """Mass [kg], in-plane COM [m], own inertia about the normal [kg m^2] and the shape of
        every geom (and <inertial>) of every rigid body; static geoms go to self.static."""
        n = np.eye(3)[self.normal]
        self.static = []
        # hook: the world's own geoms too (they were left out: a static geom directly under
        # <worldbody> never collided)
        for b in [self.world] + self.bodies:
            use_inertial = self.uses_inertial(b)
            if self.inertiafromgeom == "true":
                for i in b.inertials:
                    self.report.ignore("<inertial> (inertiafromgeom='true')", i["node"].line)
            for g in b.geoms:
                shape = self.shape(g)
                if g["kind"] == "plane":
                    if b.rid is not None:
                        self.fail(g["node"], "a plane must belong to the world")
                    continue
                if b.rid is None:
                    self.static.append((g, shape))
                    continue
                mass = 0.0 if use_inertial else g["mass"]
                self.rigid[b.rid].parts.append((mass, self.plane(g["pos"]), mass * self.own_inertia(g, n),
                                                shape, g["name"], g))
            if use_inertial and b.rid is not None:
                for i in b.inertials:
                    self.rigid[b.rid].parts.append((i["mass"], self.plane(i["pos"]),
                                                    float(n @ i["tensor"] @ n), None, "", i))
        self.static += mjcf_plane.wall_shapes(self)   # hook: planes that are walls

    def own_inertia(self, g, n) -> float:
        """Inertia per unit mass [m^2] about the normal through the geom's centre."""
        if g["kind"] in ("capsule", "cylinder", "sphere"):
            i_perp, i_axis = g["unit"][0], g["unit"][2]
            ay = g["R"][self.normal, 2]         # axis . n
            return i_perp + (i_axis - i_perp) * ay * ay
        return F.inertia_about(g["unit"], g["R"], n)

    def shape(self, g):
        """The geom's silhouette in the plane (world coordinates [m], offset applied):
        ('circle', c, r) | ('capsule', p0, p1, r) | ('box', c, w, h, angle) | ('polygon', vs)."""
        kind, R, c = g["kind"], g["R"], self.plane(g["pos"])
        if kind == "plane":
            return None
        nz = abs(R[self.normal, 2])               # geom z axis . plane normal
        if kind == "sphere":
            return ("circle", c, g["dims"][0])
        if kind == "capsule":
            r = g["dims"][0]
            p0, p1 = (self.plane(e) for e in g["ends"])
            if np.hypot(*(p1 - p0)) < 1e-12:
                return ("circle", c, r)
            return ("capsule", p0, p1, r)
        if kind == "cylinder":
            r, h = g["dims"]
            if abs(nz - 1) <= AXIS_TOL:
                return ("circle", c, r)
            if nz <= AXIS_TOL:
                u = R[:, 2]
                return ("box", c, 2 * h, 2 * r, math.atan2(u[self.i2], u[self.i1]))
            self.fail(g["node"], "a cylinder tilted out of the plane has no planar shape here")
        half = np.asarray(g["dims"][:3] if kind == "box" else g["dims"], dtype=np.float64)
        along = [k for k in range(3) if abs(abs(R[self.normal, k]) - 1) <= AXIS_TOL]
        if kind == "ellipsoid":
            if not along:
                self.fail(g["node"], "an ellipsoid tilted out of the plane has no planar shape here")
            k1, k2 = [k for k in range(3) if k != along[0]]
            ts = np.linspace(0, 2 * math.pi, 24, endpoint=False)
            pts = [self.plane(g["pos"] + half[k1] * math.cos(t) * R[:, k1]
                              + half[k2] * math.sin(t) * R[:, k2]) for t in ts]
            return ("polygon", pts, "approximate")
        if along:
            k1, k2 = [k for k in range(3) if k != along[0]]
            u = R[:, k1]
            return ("box", c, 2 * half[k1], 2 * half[k2], math.atan2(u[self.i2], u[self.i1]))
        corners = [self.plane(g["pos"] + R @ (half * np.array(s)))
                   for s in np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).T.reshape(-1, 3)]
        return ("polygon", _hull(corners))

    # build ------------------------------------------------------------------------------------
    def emit(self, builder, model_name) -> MJCFModel:
        self.group()
        self.parts()
        if not self.rigid:
            self.fail(self.root, "no body with a joint: nothing moves")
        self.scale_total_mass()
        ids = []
        for rb in self.rigid:
            m = np.array([p[0] for p in rb.parts])
            if not rb.parts or not m.sum() > 0:
                self.fail(self.root, f"body {rb.name!r} has no mass (give its geoms mass or "
                                     f"density, or an <inertial>)")
            x = np.array([p[1] for p in rb.parts])
            rb.mass = float(m.sum())
            rb.com = (m[:, None] * x).sum(0) / rb.mass
            d2 = ((x - rb.com) ** 2).sum(1)
            rb.inertia = float(sum(p[2] for p in rb.parts) + (m * d2).sum())
            shapes = [self.body_shape(s, g, rb.com) for _, _, _, s, _, g in rb.parts if s is not None]
            if rb.name in self.translating:
                ids.append(self.point_body(builder, rb, shapes))
            else:
                ids.append(builder.add_body(rb.name, mass=rb.mass, inertia=rb.inertia,
                                            pos=tuple(rb.com), shapes=shapes))
        for g, s in self.static:
            self.world_shape(builder, g, s)
        self.self_collisions()
        out = MJCFModel(builder=builder, body={k: ids[v] for k, v in self.body_map.items()},
                        pin={}, rigid={ids[i]: rb for i, rb in enumerate(self.rigid)},
                        root=ids[0], name=model_name, free_joints=self.free,
                        plane=self.plane_name, report=self.report)
        for kind, j, parent, child in self.links:
            a = None if parent is None else ids[parent]
            if kind == "pin":
                pid = self.add_pin(builder, j, a, ids[child])
                out.pin[j["name"]] = pid
                out.joint[j["name"]] = JointMap("pin", pid, self.sign(j), self.ref(j))
            else:
                out.joint[j["name"]] = JointMap("slider", self.add_slider(builder, j, a, ids[child]),
                                                1.0, self.ref(j))
        # a free root's coordinates after the links (the links keep pin ids 0..)
        for b in self.free_bodies:
            hinge = [j for j in b.joints if j["type"] == "hinge"]
            # the slides move the hinge's anchor (the point the body turns about)
            anchor = tuple(float(x) for x in self.plane((hinge or b.joints)[0]["pos"]))
            for j in b.joints:
                limit, k, c, rest = self.joint_terms(j)
                arm = self.armature(j)
                kind = j["type"]
                a = j["axis"]
                axis = (2,) if kind == "hinge" else (float(a[self.i1]), float(a[self.i2]))
                pid = builder.add_free_coordinate(
                    j["name"], ids[b.rid], kind=kind, axis=(1.0, 0.0) if kind == "hinge" else axis,
                    anchor_world=anchor, limit=limit, stiffness=k, damping=c, rest=rest,
                    armature=arm)
                out.joint[j["name"]] = JointMap("free", ids[b.rid],
                                                self.sign(j) if kind == "hinge" else 1.0,
                                                self.ref(j), axis, anchor, pin=pid)
        self.fluid(builder, ids)
        for b in self.bodies:
            if b.rid is not None:
                mass, com, _ = self.inertia_3d(b)
                out.com[b.name] = self.plane(com if mass > 0 else b.pos)
        out.joint = {j["name"]: out.joint[j["name"]] for b in self.bodies for j in b.joints}  # file order
        return out

    def ref(self, j):
        """The joint's value at the file's pose (rad for a hinge, m for a slide)."""
        s = self.angle_scale if j["type"] == "hinge" else 1.0
        return self.scalar(j["node"], j["eff"], "ref", 0.0) * s

    def joint_terms(self, j):
        """Limits, stiffness, damping and rest value of a hinge or slide in planarsim's sign:
        (limit (lo, hi) or None, k, c, rest)."""
        node, eff = j["node"], j["eff"]
        s = self.angle_scale if j["type"] == "hinge" else 1.0
        sign = self.sign(j) if j["type"] == "hinge" else 1.0
        ref = self.ref(j)
        limit = None
        if self.limited(j):
            rng = self.floats(node, eff, "range", 2) * s
            if rng[0] > rng[1]:
                self.fail(node, f"range={tuple(rng / s)} has lower > upper")
            limit = tuple(sorted((sign * (rng[0] - ref), sign * (rng[1] - ref))))
        k = self.scalar(node, eff, "stiffness", 0.0)
        c = self.scalar(node, eff, "damping", 0.0)
        if k < 0 or c < 0:
            self.fail(node, f"stiffness={k} and damping={c} must be >= 0")
        k, c = self.flags.passive(k, c)       # hook: <flag spring|damper="disable">
        rest = sign * (self.scalar(node, eff, "springref", 0.0) * s - ref) + 0.0   # no -0.0
        return limit, k, c, rest

    def add_pin(self, builder, j, a, b):
        """A hinge -> ModelBuilder.add_pin at the joint's world position (armature [kg m^2]
        to add_pin(armature=...))."""
        limit, k, c, rest = self.joint_terms(j)
        return builder.add_pin(j["name"], a, b, anchor_world=tuple(self.plane(j["pos"])),
                               limit=limit, stiffness=k, damping=c, rest_angle=rest,
                               armature=self.armature(j))

    def add_slider(self, builder, j, a, b):
        """A slide between bodies -> ModelBuilder.add_slider (axis: unit in-plane direction;
        limit [m]; stiffness [N/m], damping [N s/m]; armature [kg])."""
        limit, k, c, rest = self.joint_terms(j)
        ax = j["axis"]
        return builder.add_slider(j["name"], a, b, axis=(ax[self.i1], ax[self.i2]),
                                  anchor_world=tuple(self.plane(j["pos"])), limit=limit,
                                  stiffness=k, damping=c, rest=rest,
                                  armature=self.armature(j))

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
        with mass: the box of the body's own mass and principal inertia about its COM
        (sides sqrt(6 (I_j + I_k - I_i) / m)), one principal axis along the plane's normal."""
        fluid = self.option.get("fluid")
        if not fluid:
            return
        for b in self.bodies:
            if b.rid is None or b.name in self.translating:
                if b.rid is not None and (b.geoms or b.inertials):
                    self.fail(b.node, "fluid forces on a body that translates only (a point "
                                      "mass) are not supported")
                continue
            mass, com, T = self.inertia_3d(b)
            if not mass > 1e-15:
                continue
            n, i1, i2 = self.normal, self.i1, self.i2
            if abs(T[n, i1]) + abs(T[n, i2]) > 1e-9 * max(np.trace(T), 1e-300):
                self.fail(b.node, "fluid forces need one principal axis of the body's inertia "
                                  "normal to the plane of motion")
            w, e = np.linalg.eigh(np.array([[T[i1, i1], T[i1, i2]], [T[i1, i2], T[i2, i2]]]))
            moments = (w[0], w[1], T[n, n])
            box = [math.sqrt(max(1e-15, moments[(k + 1) % 3] + moments[(k + 2) % 3] - moments[k])
                             / mass * 6.0) for k in range(3)]
            rb = self.rigid[b.rid]
            builder.add_fluid_box(ids[b.rid], box, viscosity=fluid["viscosity"],
                                  density=fluid["density"], local=tuple(self.plane(com) - rb.com),
                                  angle=math.atan2(e[1, 0], e[0, 0]))

    def uses_inertial(self, b) -> bool:
        """Body b's mass comes from its <inertial> elements, not its geoms (the compiler's
        inertiafromgeom: "false" always, "auto" where the body has an <inertial>)."""
        return self.inertiafromgeom == "false" or (self.inertiafromgeom == "auto"
                                                   and bool(b.inertials))

    def inertia_3d(self, b):
        """Mass [kg], COM (3,) [m] and inertia tensor (3, 3) about it [kg m^2] of MJCF body b
        alone, in world axes at the file's pose (as MuJoCo's body_mass, body_ipos, body_inertia)."""
        use_inertial = self.uses_inertial(b)
        items = ([(i["mass"], i["pos"], i["tensor"]) for i in b.inertials] if use_inertial else
                 [(g["mass"], g["pos"], g["mass"] * g["R"] @ np.diag(g["unit"]) @ g["R"].T)
                  for g in b.geoms if g["kind"] != "plane"])
        f = self.mass_scale
        mass = sum(m for m, _, _ in items) * f
        if not mass > 0:
            return 0.0, np.zeros(3), np.zeros((3, 3))
        com = sum(m * np.asarray(p) for m, p, _ in items) * f / mass
        T = np.zeros((3, 3))
        for m, p, I in items:
            r = np.asarray(p) - com
            T += f * (I + m * (r @ r * np.eye(3) - np.outer(r, r)))
        return mass, com, T

    def scale_total_mass(self):
        """<compiler settotalmass>: scale every mass and inertia so the bodies total it [kg]."""
        self.mass_scale = 1.0
        if self.settotalmass is None:
            return
        total = sum(p[0] for rb in self.rigid for p in rb.parts)
        total += sum(g["mass"] for g, _ in self.static)
        f = self.mass_scale = self.settotalmass / total
        for rb in self.rigid:
            rb.parts = [(m * f, x, i * f, *rest) for m, x, i, *rest in rb.parts]

    # collision shapes ---------------------------------------------------------------------
    def body_shape(self, s, g, com):
        """A shape tuple for add_body: relative to the COM, with add_shape's options."""
        how = self.collision(g)
        if s[0] == "circle":
            return ("circle", tuple(s[1] - com), s[2], how)
        if s[0] == "capsule":
            return ("capsule", tuple(s[1] - com), tuple(s[2] - com), s[3], how)
        if s[0] == "box":
            angle = () if s[4] == 0.0 else (s[4],)
            return ("box", tuple(s[1] - com), s[2], s[3], *angle, how)
        if len(s) > 2 and how.get("collide"):
            self.fail(g["node"], "an ellipsoid that collides is not supported (only drawn ones)")
        return ("polygon", [tuple(v - com) for v in s[1]], how)

    def collision(self, g):
        """add_shape options of a body geom: the caller's ``collide`` names, else MuJoCo's
        contype/conaffinity (ground contact with the ground plane, friction the larger of
        the two, none where both have condim 1)."""
        if self.collide is not None:
            return COLLIDES if g["name"] in self.collide else DRAWN
        ground = self.ground is not None and _mj_pair(g, self.ground[0])
        others = [h for h, _ in self.static] + [p[5] for rb in self.rigid for p in rb.parts
                                                 if p[3] is not None]
        if not ground and not any(_mj_pair(g, h) for h in others if h is not g):
            return dict(DRAWN)
        mu = g["mu"]
        if ground:
            plane = self.ground[0]
            mu = 0.0 if max(g["condim"], plane["condim"]) == 1 else max(mu, plane["mu"])
        return dict(collide=True, ground=ground, mu=mu, category=g["contype"],
                    mask=g["conaffinity"], name=g["name"] or None)

    def world_shape(self, builder, g, s):
        """A static geom that collides with some body geom -> a world shape; else ignored."""
        bodies = [p[5] for rb in self.rigid for p in rb.parts if p[3] is not None]
        if self.collide is not None or not any(_mj_pair(g, h) for h in bodies):
            self.report.ignore("world geom that collides with nothing", g["node"].line)
            return
        if s[0] == "polygon" and len(s) > 2:
            self.fail(g["node"], "an ellipsoid that collides is not supported")
        params = [tuple(p) if isinstance(p, np.ndarray) else p for p in s[1:]]
        if s[0] == "polygon":
            params = [[tuple(v) for v in s[1]]]
        builder.add_shape(None, s[0], *params, mu=g["mu"], category=g["contype"],
                          mask=g["conaffinity"], name=g["name"] or None)

    def self_collisions(self):
        """Note pairs of one tree that MuJoCo may collide (not parent and child) and planarsim
        does not (bodies linked by joints never collide here)."""
        if self.collide is not None:
            return

        def tree_of(b):               # the first body below the world (or what is welded to it)
            while b.parent is not None and b.parent.rid is not None:
                b = b.parent
            return b.name
        parent = {b.rid: (b.parent.rid if b.parent is not None else None)
                  for b in self.bodies if b.joints}
        geoms = [(rid, p[5]) for rid, rb in enumerate(self.rigid) for p in rb.parts if p[3] is not None]
        # fix: bodies of separate trees (joined only through the world) do collide in planarsim
        tree = {b.rid: tree_of(b) for b in self.bodies if b.rid is not None}
        for i, (ra, ga) in enumerate(geoms):
            for rb_, gb in geoms[i + 1:]:
                if ra == rb_ or parent.get(ra) == rb_ or parent.get(rb_) == ra:
                    continue
                if tree[ra] != tree[rb_]:
                    continue
                if _mj_pair(ga, gb):
                    self.report.note(f"geoms {ga['name'] or ga['node'].line!r} and "
                                     f"{gb['name'] or gb['node'].line!r} may touch in MuJoCo; "
                                     f"planarsim's bodies linked by joints do not collide")

    # actuators --------------------------------------------------------------------------------
    def actuators(self, node, out: MJCFModel):
        for a in node.children:
            if a.tag != "motor":
                if a.tag in ("general", "position", "velocity", "intvelocity", "damper",
                             "cylinder", "muscle", "adhesion"):
                    self.fail(a, f"<{a.tag}> actuators are not supported (only <motor>)")
                self.elsewhere(a, "actuator")
                continue
            eff = self.effective(a, tag="motor")
            for key in ("tendon", "site", "body", "jointinparent"):
                if key in eff:
                    self.fail(a, f"a motor on a {key} is not supported (only joint=)")
            jname = eff.get("joint")
            if jname is None or jname not in out.joint:
                self.fail(a, f"joint={jname!r} names no joint of the model")
            jm = out.joint[jname]
            gear = self.floats(a, eff, "gear", (1, 6), default=(1.0,))
            if np.any(gear[1:] != 0):
                self.fail(a, f"gear={tuple(gear)}: only the first component acts on a joint")
            signed = float(gear[0]) * jm.sign
            lo, hi = -math.inf, math.inf
            for rng, lim in (("ctrlrange", "ctrllimited"), ("forcerange", "forcelimited")):
                v = self.flag(a, eff, lim)
                if v == "true" or (v == "auto" and rng in eff):
                    r = self.floats(a, eff, rng, 2)
                    if r[0] > r[1]:
                        self.fail(a, f"{rng}={tuple(r)} has lower > upper")
                    lo, hi = max(lo, r[0]), min(hi, r[1])
            ctrl = (lo, hi)
            limit = tuple(sorted((signed * lo, signed * hi))) if math.isfinite(lo) else (-math.inf, math.inf)
            name = eff.get("name") or jname
            b = out.builder
            add_motor = b.add_pin_motor if jm.angular else b.add_slider_motor
            aid = add_motor(name, jm.coordinate, limit=limit)
            out.actuator[name] = ActuatorMap(aid, jname, signed, ctrl)


def _hull(points) -> list:
    """Convex hull (counter-clockwise) of 2D points (monotone chain)."""
    pts = sorted({(round(float(p[0]), 12), round(float(p[1]), 12)) for p in points})

    def half(seq):
        out = []
        for p in seq:
            while len(out) >= 2 and ((out[-1][0] - out[-2][0]) * (p[1] - out[-2][1])
                                     - (out[-1][1] - out[-2][1]) * (p[0] - out[-2][0])) <= 0:
                out.pop()
            out.append(p)
        return out[:-1]
    return half(pts) + half(pts[::-1])


def load_mjcf(source, builder: ModelBuilder | None = None, offset=(0.0, 0.0), collide=None,
              drop=(), assets=None, **builder_kw) -> MJCFModel:
    """Load a planar MJCF model (see the module's docstring for what is read).

    source : path to an .xml file, or the XML text itself (a string starting with '<', or
        UTF-8 bytes)
    builder : add to this ModelBuilder (it keeps its dt, gravity and terrain); default: a new
        one with the file's timestep [s], in-plane gravity [m/s^2] and ground plane (flat
        terrain), overridden by ``builder_kw`` (dt, gravity, terrain)
    offset : (2,) [m] translation of the whole file (bodies, world geoms, ground plane) in
        the plane
    collide : None: geoms collide by MuJoCo's contype/conaffinity; or names of the geoms that
        collide (with the ground and other bodies' shapes), the others drawn only
    drop : physics to load without instead of a ModelError: "armature", "fluid" (reported)
    assets : dict file name -> bytes or str, as mujoco.MjModel.from_xml_string takes it:
        where ``<include file=...>`` looks first (then on disk: next to the main file, then
        next to the including file, as MuJoCo; see planarsim.mjcf_include)

    Returns an MJCFModel (builder, name maps, per-body mass properties, ``report`` of what
    was ignored). Raises ModelError naming the element and line for malformed or unsupported
    input.
    """
    if isinstance(source, (bytes, bytearray)):   # hook: XML text as bytes (dm_control's swimmer)
        source = mjcf_include.decode(source, "load_mjcf: the XML source")
    if isinstance(source, (str, Path)) and not str(source).strip():
        raise ModelError("load_mjcf: the source is empty (give an MJCF file's path or its XML text)")
    if isinstance(source, (str, Path)) and not str(source).lstrip().startswith("<"):
        path = Path(source)
        try:
            text = path.read_text()
        except OSError as e:
            raise ModelError(f"cannot read MJCF file {str(path)!r}: {e.strerror}") from None
        name, base_dir = str(path), path.parent
    else:
        text, name, base_dir = str(source), "<string>", None
    root = parse_xml(text, name)
    # hook: <include file=...> replaced by the included files' elements
    root = mjcf_include.resolve_includes(root, name, base_dir, assets, parse_xml)
    loader = _Loader(root, name, drop)
    out = loader.load(builder_kw, builder, offset, collide)
    if collide is not None:
        known = {p[4] for rb in loader.rigid for p in rb.parts}
        unknown = sorted(frozenset(collide) - known)
        if unknown:
            raise ModelError(f"{name}: collide names geoms {unknown} that the file does not have; "
                             f"its named geoms: {sorted(n for n in known if n)}")
    return out
