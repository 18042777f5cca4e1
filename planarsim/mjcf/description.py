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
class Motor:
    """A <motor>: its name (its joint's where it has none), joint, gear (the first component)
    and the range (lo, hi) its control is saturated to (ctrlrange and forcerange)."""
    node: Node
    name: str
    joint: str
    gear: float
    ctrl: tuple


@dataclass
class Description:
    """An MJCF file as the reader found it (see the module's docstring).

    option: timestep [s], gravity (3,) [m/s^2] and, unless dropped, fluid (viscosity,
        density; gravity zeroed and fluid dropped as <option><flag> says); inertiafromgeom:
        "true", "false" or "auto"; settotalmass [kg] or None
    flags: what <option><flag> switched off (options.Flags)
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
