"""What load_mjcf returns: the builder with the model added, how MJCF names map onto it, each
rigid body's mass properties and the report of what was not turned into physics."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..builder import ModelBuilder


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
    """An MJCF <motor>, one entry of an environment's action: the planarsim actuators it
    drives, one per joint its transmission moves (its joint, or each joint of its fixed
    tendon whose coefficient is not 0). Actuator ids[k] on MJCF joint joints[k] takes the
    input gains[k] * ctrl [N m or N] (gain = gear * coef, the pin's sign included), ctrl
    clamped to ctrlrange first. id, joint and gear: those of its only actuator."""
    ids: tuple
    joints: tuple
    gains: tuple
    ctrlrange: tuple = (-math.inf, math.inf)
    tendon: str | None = None

    def _only(self, what):
        if len(self.ids) != 1:
            raise ValueError(f"the motor on tendon {self.tendon!r} drives {len(self.ids)} "
                             f"joints {list(self.joints)}: read ids, joints and gains, not {what}")
        return 0

    @property
    def id(self) -> int:
        return self.ids[self._only("id")]

    @property
    def joint(self) -> str:
        return self.joints[self._only("joint")]

    @property
    def gear(self) -> float:
        return self.gains[self._only("gear")]

    @property
    def target(self) -> str:
        """What it pulls on, for messages: its joint's name or "tendon 'name'"."""
        return f"tendon {self.tendon!r}" if self.tendon is not None else self.joints[0]


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
    actuator : MJCF motor name (or its joint's or tendon's) -> ActuatorMap (ids, joints,
              gains, ctrlrange, tendon)
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
