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
* ``<joint type="hinge|slide" pos axis ref range limited stiffness damping springref armature
  frictionloss>`` (frictionloss [N m or N]: planarsim's exact dry-friction row on the joint,
  kernels/constraints/joint_friction.py, where MuJoCo's is a soft constraint).
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
* ``<tendon><fixed><joint joint coef>`` and ``<motor tendon>``: a fixed tendon's length is
  sum coef_i q_i; a motor on it drives each joint whose coef is not 0 with gear * coef *
  ctrl (one planarsim motor each: ``MJCFModel.actuator[name].ids / joints / gains``). The
  tendon's limits, spring, damper, friction and armature, and spatial tendons, are
  ModelErrors.
* ``<include file>`` (include.py: on disk or from ``assets``), ``<option><flag>``
  (options.py: gravity, contact, limit, constraint, spring, damper, frictionloss
  honoured; flags without physics reported; the rest a ModelError), planes whose normal lies
  in the plane of motion as static walls (walls.py) and the plane of motion of a slides-only
  model (plane.py).

Purely visual or solver-tuning elements and attributes (rgba, material, asset, visual, light,
camera, site, solref, margin, integrator, ...) are ignored and listed in ``MJCFModel.report``;
anything else that changes physics and is not supported (spatial tendons, equality constraints, a
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

Layout, as MuJoCo keeps its XML reader apart from its model compiler: xml_tree.py (text to
elements with their lines), include.py (<include> elements replaced by the included files'
elements), reader.py with attributes.py (elements to a plain description,
description.py: bodies, joints, geoms, inertials and motors in the world's frame, defaults
resolved, values checked; options.py: <option><flag>) and emitter.py with plane.py, walls.py, mass.py
and collisions.py (the description to ModelBuilder calls in the plane of motion); schema.py lists what is read,
result.py what load_mjcf returns.
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..builder import ModelBuilder
from ..errors import ModelError, plain
from .description import Body3D, Description, Motor, Tendon
from .emitter import Emitter
from .include import decode, resolve_includes
from .reader import Reader
from .result import ActuatorMap, JointMap, LoadReport, MJCFModel, RigidBody
from .schema import (ATTRIBUTES, AXIS_TOL, COLLIDES, DEFAULT_DENSITY, DEFAULT_FRICTION,
                     DEFAULT_GRAVITY, DEFAULT_TIMESTEP, DRAWN, DROPPABLE, SUPPORTED_GEOMS)
from .xml_tree import Node, parse_xml

__all__ = ["load_mjcf", "MJCFModel", "JointMap", "ActuatorMap", "LoadReport", "RigidBody", "Body3D",
           "Description", "Motor", "Tendon", "Node", "parse_xml", "Reader", "Emitter", "ATTRIBUTES",
           "AXIS_TOL",
           "COLLIDES", "DEFAULT_DENSITY", "DEFAULT_FRICTION", "DEFAULT_GRAVITY", "DEFAULT_TIMESTEP",
           "DRAWN", "DROPPABLE", "SUPPORTED_GEOMS"]


def _names(collection) -> list:
    """The items of `collection` (a list of names), or [None] when it is not a collection."""
    try:
        return list(collection)
    except TypeError:
        return [None]


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
        next to the including file, as MuJoCo; see planarsim.mjcf.include)

    Returns an MJCFModel (builder, name maps, per-body mass properties, ``report`` of what
    was ignored). Raises ModelError naming the element and line for malformed or unsupported
    input.
    """
    if isinstance(source, os.PathLike):
        source = Path(source)
    if not isinstance(source, (str, Path, bytes, bytearray)):
        raise TypeError(f"load_mjcf: source={source!r} must be a path (str or pathlib.Path) to an "
                        "MJCF file, or its XML text (str or bytes)")
    if collide is not None and (isinstance(collide, (str, bytes))
                                or not all(isinstance(n, str) for n in _names(collide))):
        raise TypeError(f"load_mjcf: collide={collide!r} must be None or a list of geom names, "
                        "e.g. ['foot']")
    if isinstance(drop, (str, bytes)) or not all(isinstance(n, str) for n in _names(drop)):
        raise TypeError(f"load_mjcf: drop={drop!r} must be a list of names, e.g. ['armature']")
    if builder is not None and not isinstance(builder, ModelBuilder):
        raise TypeError(f"load_mjcf: builder={builder!r} must be a planarsim ModelBuilder "
                        "(or None: a new one from the file's option)")
    try:
        offset = np.asarray(offset, dtype=np.float64).reshape(2)
    except (TypeError, ValueError):
        raise ModelError(f"load_mjcf: offset={plain(offset)!r} must be a pair (x, y) [m]") from None
    if not np.all(np.isfinite(offset)):
        raise ModelError(f"load_mjcf: offset={tuple(offset.tolist())} must be finite")
    if isinstance(source, (bytes, bytearray)):   # XML text as bytes (dm_control's swimmer)
        source = decode(source, "load_mjcf: the XML source")
    if isinstance(source, str) and source.startswith("\ufeff"):
        source = source[1:]     # a byte order mark: the text, not a path starting with one
    if isinstance(source, (str, Path)) and not str(source).strip():
        raise ModelError("load_mjcf: the source is empty (give an MJCF file's path or its XML text)")
    if isinstance(source, (str, Path)) and not str(source).lstrip().startswith("<"):
        path = Path(source)
        try:
            text = path.read_bytes().decode("utf-8")
        except OSError as e:
            raise ModelError(f"cannot read MJCF file {str(path)!r}: {e.strerror}") from None
        except ValueError as e:     # (not UTF-8; a NUL in the path)
            what = (f"not UTF-8 text ({e.reason} at byte {e.start})"
                    if isinstance(e, UnicodeDecodeError) else str(e))
            raise ModelError(f"cannot read MJCF file {str(path)!r}: {what}") from None
        name, base_dir = str(path), path.parent
    else:
        text, name, base_dir = str(source), "<string>", None
    # <include file=...> replaced by the included files' elements
    root = resolve_includes(parse_xml(text, name), name, base_dir, assets, parse_xml)
    description = Reader(root, name, drop).read()
    emitter = Emitter(description, offset, collide)
    out = emitter.emit(builder_kw, builder)
    if collide is not None:
        known = {p[4] for rb in emitter.rigid for p in rb.parts}
        unknown = sorted(frozenset(collide) - known)
        if unknown:
            raise ModelError(f"{name}: collide names geoms {unknown} that the file does not have; "
                             f"its named geoms: {sorted(n for n in known if n)}")
    return out
