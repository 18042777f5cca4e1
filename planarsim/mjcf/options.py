"""MJCF ``<option><flag .../>``: MuJoCo's switches, mapped onto what planarsim models.

Flags with physics planarsim has (MuJoCo's default is "enable"; "disable" does this):

=============  ==================================================================
gravity        gravity is zero (the model's gravity (0, 0))
contact        no geom collides: every shape is drawn only (the ground and walls too)
limit          joint ranges are not enforced (the joints load without limits)
constraint     all of contact, limit and frictionloss (planarsim's joints themselves
               are its coordinates, not constraints, as MuJoCo's are)
frictionloss   joints' frictionloss is not applied (their dry friction rows are left out)
spring         joint stiffness is zero
damper         joint damping is zero (with spring also disabled: the fluid forces too,
               as MuJoCo's passive forces)
equality       nothing (the loader refuses equality constraints anyway)
filterparent   accepted where no parent and child body have geoms that may touch
               (planarsim's bodies linked by a joint never collide); else a ModelError
=============  ==================================================================

Flags without physics in planarsim (solver, collision pipeline, sensors, bookkeeping) are
accepted and listed in the load report's ``ignored``: warmstart, refsafe, sensor, midphase,
eulerdamp, autoreset, nativeccd, island, multiccd, and enabling energy, fwdinv,
invdiscrete, diagexact, speculative (and override where contacts are off).

Flags whose physics planarsim does not have are a ModelError naming the flag: clampctrl
and actuation disabled, override (contact parameters from <option o_...>), sleep and ipc
enabled.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

# MuJoCo's disable flags (default "enable") and enable flags (default "disable")
DISABLE = ("constraint", "equality", "frictionloss", "limit", "contact", "spring", "damper",
           "gravity", "clampctrl", "warmstart", "filterparent", "actuation", "refsafe", "sensor",
           "midphase", "eulerdamp", "autoreset", "nativeccd", "island", "multiccd")
ENABLE = ("override", "energy", "fwdinv", "invdiscrete", "sleep", "diagexact", "ipc",
          "speculative")
# switched away from MuJoCo's default: no physics in planarsim, reported as ignored
NO_PHYSICS = {"warmstart", "refsafe", "sensor", "midphase", "eulerdamp", "autoreset",
              "nativeccd", "island", "multiccd", "energy", "fwdinv", "invdiscrete", "diagexact",
              "speculative", "equality"}
# switched away from MuJoCo's default: physics planarsim does not model
REFUSED = {
    "clampctrl": "MuJoCo would then pass controls outside ctrlrange to the motors; planarsim's "
                 "motors saturate at gear * ctrlrange",
    "actuation": "MuJoCo would then apply no actuator force; planarsim's motors always act",
    "override": "MuJoCo would then take every contact's parameters (friction, margin, solref) "
                "from <option o_...>; planarsim uses each geom's friction",
    "sleep": "MuJoCo would then freeze bodies at rest; planarsim has no sleeping bodies",
    "ipc": "MuJoCo's IPC contact model has no planarsim equivalent",
}


@dataclass
class Flags:
    """What <option><flag> switched on or off (MuJoCo's defaults: everything on that has
    physics). flag_node: name -> the <flag> node that set it (for messages)."""
    gravity: bool = True
    contact: bool = True
    limit: bool = True
    frictionloss: bool = True
    spring: bool = True
    damper: bool = True
    filterparent: bool = True
    flag_node: dict = field(default_factory=dict)

    def passive(self, k: float, c: float):
        """(stiffness, damping) of a joint after the spring and damper flags."""
        return (k if self.spring else 0.0), (c if self.damper else 0.0)


def read_flags(loader, option_node):
    """Read the <flag> children of <option> into loader.flags (loader: the Reader; its flags,
    option, report, fail()) (ModelError for any other child,
    an unknown flag, a value other than enable/disable, or a flag planarsim cannot honour);
    apply the ones that change what <option> set: gravity (zeroed) and the fluid (dropped
    with both spring and damper disabled)."""
    flags = loader.flags
    for c in option_node.children:
        if c.tag != "flag":
            loader.fail(c, f"<{c.tag}> inside <option> is not supported (only <flag>)")
        for key in sorted(c.attrib):
            value = c.attrib[key].strip()
            if key not in DISABLE and key not in ENABLE:
                loader.fail(c, f"flag {key}={value!r} is not one of MuJoCo's flags "
                               f"({', '.join(DISABLE + ENABLE)})")
            if value not in ("enable", "disable"):
                loader.fail(c, f"flag {key}={value!r} must be 'enable' or 'disable'")
            default = "enable" if key in DISABLE else "disable"
            if value == default:
                continue
            flags.flag_node[key] = c
            if key == "override":
                continue                    # below: it matters only where contacts are on
            if key in REFUSED:
                loader.fail(c, f"flag {key}={value!r} is not supported: {REFUSED[key]}")
            if key in NO_PHYSICS:
                loader.report.ignore(f"option flag {key}={value!r}", c.line)
                continue
            if key == "constraint":
                flags.contact = flags.limit = flags.frictionloss = False
            elif key in ("gravity", "contact", "limit", "frictionloss", "spring", "damper",
                         "filterparent"):
                setattr(flags, key, False)
    if "override" in flags.flag_node:
        node = flags.flag_node["override"]
        if flags.contact:
            loader.fail(node, f"flag override='enable' is not supported: {REFUSED['override']}")
        loader.report.ignore("option flag override='enable' (contacts are off)", node.line)
    if not flags.gravity:
        loader.option["gravity"] = np.zeros(3)
        loader.report.note("gravity is off (<option><flag gravity='disable'>)")
    if not flags.contact:
        loader.report.note("contacts are off (<option><flag contact or constraint='disable'>): "
                           "every geom is drawn only")
    if not flags.limit:
        loader.report.note("joint limits are off (<option><flag limit or constraint='disable'>)")
    if not flags.spring:
        loader.report.note("joint springs are off (<option><flag spring='disable'>)")
    if not flags.damper:
        loader.report.note("joint dampers are off (<option><flag damper='disable'>)")
    if not (flags.spring or flags.damper) and loader.option.pop("fluid", None):
        loader.report.note("fluid forces are off (<option><flag spring and damper='disable'>)")


def joint_frictionloss(loader, node, eff):
    """(loader: the Reader) A hinge's or slide's frictionloss [N m or N] (MuJoCo's dry joint
    friction; planarsim's exact friction row, kernels/constraints/joint_friction.py); 0, reported as
    ignored, where <flag frictionloss> or <flag constraint> is disabled; a negative one is a
    ModelError naming the joint."""
    raw = eff.get("frictionloss")
    if raw is None:
        return 0.0
    value = loader.scalar(node, eff, "frictionloss", 0.0)
    if value == 0.0:
        return 0.0
    if value < 0:
        name = eff.get("name") or f"joint@{node.line}"
        loader.fail(node, f"joint {name!r} has frictionloss={value}: it must be >= 0")
    if not loader.flags.frictionloss:
        loader.report.ignore("joint frictionloss (<flag frictionloss or constraint='disable'>)",
                             node.line)
        return 0.0
    return value


def check_filterparent(loader):
    """(loader: the Emitter, after its bodies and joints; its flags, collide, rigid, bodies,
    report, fail()) <flag filterparent='disable'>: MuJoCo then lets a parent and child body collide;
    planarsim never collides bodies linked by a joint: a ModelError where such a pair's
    geoms may touch (contype/conaffinity), else nothing changes."""
    if loader.flags.filterparent or not loader.flags.contact or loader.collide is not None:
        return
    geoms = {}
    for rid, rb in enumerate(loader.rigid):
        geoms[rid] = [p[5] for p in rb.parts if p[3] is not None]
    for b in loader.bodies:
        if not b.joints or b.parent is None or b.parent.rid is None:
            continue
        for ga in geoms.get(b.rid, []):
            for gb in geoms.get(b.parent.rid, []):
                if (ga["contype"] & gb["conaffinity"]) or (gb["contype"] & ga["conaffinity"]):
                    loader.fail(loader.flags.flag_node["filterparent"],
                                f"flag filterparent='disable' lets geoms "
                                f"{ga['name'] or ga['node'].line!r} (body {b.name!r}) and "
                                f"{gb['name'] or gb['node'].line!r} (its parent "
                                f"{b.parent.name!r}) collide in MuJoCo; planarsim's bodies "
                                f"linked by a joint do not collide")
    loader.report.ignore("option flag filterparent='disable' (no parent and child geoms may "
                         "touch)", loader.flags.flag_node["filterparent"].line)
