"""The plain description of an MJCF file that the reader (reader.py) makes and the emitter
(emitter.py) turns into ModelBuilder calls: bodies, joints, geoms, inertials and motors in
the world's frame at the file's pose, every attribute's class defaults resolved, every value
checked and in SI units (angles in radians). Nothing here knows planarsim's plane or
builder."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .options import Flags
from .result import LoadReport
from .xml_tree import Node


@dataclass
class Body3D:
    """An MJCF body at the file's pose: world position [m], rotation (columns: its axes).

    joints: dicts of node, eff (its attributes over its class's defaults), type ("hinge" or
        "slide"), name, axis (3,) unit and pos (3,) [m] in the world, ref (its value at the
        file's pose [rad or m]), range ((lo, hi) where limited, else None), stiffness,
        damping, springref [rad or m] and armature (0 where dropped: armature_dropped, which
        the emitter reports as it adds the joint)
    geoms: dicts of node, eff, kind, name, pos (3,) [m], R (3, 3), mass [kg], contype,
        conaffinity, condim, mu; all but planes: dims (half sizes [m]), unit (principal
        inertia per unit mass [m^2]) and ends (its axis' end points [m])
    inertials: dicts of node, mass [kg], pos (3,) [m], tensor (3, 3) [kg m^2] in world axes
    """
    node: Node
    name: str
    parent: "Body3D | None"
    pos: np.ndarray
    R: np.ndarray
    joints: list = field(default_factory=list)
    geoms: list = field(default_factory=list)
    inertials: list = field(default_factory=list)
    children: list = field(default_factory=list)
    rid: int | None = None                          # planarsim rigid body (None: the world)


@dataclass
class Tendon:
    """A fixed tendon: its length L = sum coef * q over its joints [m or rad], `path` the
    (joint name, coef) pairs in file order."""
    node: Node
    name: str
    path: tuple


@dataclass
class Motor:
    """A <motor>: its name (its joint's or tendon's where it has none), gear (the first
    component), the range (lo, hi) its control is saturated to (ctrlrange and forcerange),
    and its transmission: `moment`, the (joint name, coef) pairs its force gear * ctrl acts
    on as generalized force coef * gear * ctrl (((joint, 1.0),) for a motor on a joint; a
    fixed tendon's path for one on a tendon, named by `tendon`)."""
    node: Node
    name: str
    moment: tuple
    gear: float
    ctrl: tuple
    tendon: str | None = None


@dataclass
class Description:
    """An MJCF file as the reader found it (see the module's docstring).

    option: timestep [s], gravity (3,) [m/s^2] and, unless dropped, fluid (viscosity,
        density; gravity zeroed and fluid dropped as <option><flag> says); inertiafromgeom:
        "true", "false" or "auto"; settotalmass [kg] or None
    flags: what <option><flag> switched off (options.Flags)
    tendons: name -> Tendon (the fixed tendons, read for the motors on them)
    world: the world body (its geoms, and its child bodies); bodies: every other body, in
        file order (a parent before its children)
    """
    source: str
    root: Node
    name: str
    world: Body3D
    bodies: list
    motors: list
    option: dict
    inertiafromgeom: str
    settotalmass: float | None
    report: LoadReport
    flags: Flags = field(default_factory=Flags)
    tendons: dict = field(default_factory=dict)
