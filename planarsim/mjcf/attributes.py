"""Reading an MJCF element's attributes: over its class's defaults, each checked against
schema.ATTRIBUTES (read, ignored and reported, or only its default value accepted), as
numbers, flags and frames; a ModelError names the element and its line."""
from __future__ import annotations

import math

import numpy as np

from .. import mjcf_frames as F
from .include import origin
from .plane import vec
from .result import LoadReport
from .schema import ATTRIBUTES
from .xml_tree import element_error


def numbers(text):
    return [float(t) for t in str(text).split()]


class ElementReader:
    """The attributes of a file's elements: its <default> classes (class -> tag ->
    attributes), angle unit, Euler sequence and frames (local or global) from <compiler>,
    and the report of what it ignores."""

    def __init__(self, source: str):
        self.src = source
        self.angle_scale = math.pi / 180.0   # MuJoCo's default compiler angle is degrees
        self.eulerseq = "xyz"
        self.global_coords = False
        self.classes = {"main": {}}           # class -> tag -> attributes
        self.report = LoadReport()

    def fail(self, node, msg):
        raise element_error(self.src, node, msg)

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

    def vet(self, node, eff, kind=None):
        """Each attribute in eff read, ignored (reported) or at its default, by the rules of
        ATTRIBUTES[kind] (default: the node's tag); else a ModelError naming it."""
        rules = ATTRIBUTES[kind or node.tag]
        use, ignore, default = rules.get("use", set()), rules.get("ignore", set()), rules.get("default", {})
        for key in sorted(eff):
            if key in use:
                continue
            if key in ignore:
                self.report.ignore(f"{node.tag} {key}{origin(node)}", node.line)
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
            return np.allclose(numbers(a), numbers(b), rtol=0, atol=0) and len(numbers(a)) == len(numbers(b))
        except ValueError:
            return str(a).strip() == str(b).strip()

    def floats(self, node, eff, key, n=None, default=None):
        raw = eff.get(key)
        if raw is None:
            if default is None:
                self.fail(node, f"attribute {key!r} is required")
            return np.asarray(default, dtype=np.float64)
        try:
            vals = np.array(numbers(raw), dtype=np.float64)
        except ValueError:
            self.fail(node, f"{key}={raw!r} must be numbers separated by spaces")
        if n is not None and vals.size not in ((n,) if isinstance(n, int) else n):
            counts = " or ".join(map(str, (n,) if isinstance(n, int) else n))
            self.fail(node, f"{key}={raw!r} must have {counts} number(s), got {vals.size}")
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
            self.fail(node, f"{k}={vec(v)} must be non-zero")
        if k == "xyaxes" and not np.linalg.norm(np.cross(v[:3], v[3:])) > 0:
            self.fail(node, f"xyaxes={vec(v)}: its second vector must not be zero or parallel "
                            "to its first (the frame's x-y plane)")
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
