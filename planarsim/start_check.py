"""Where a run starts: no body or contact may start below the ground.

The step lifts a contact found below the ground onto it (the position projection), so a body
built 1 m inside a hill would jump to the surface in the first step with no word. A simulator
(planarsim.Simulator, a walker's run) refuses that start instead: a ModelError naming the
contact, its body and how deep it is, unless the caller allows it.

Depths are measured here in plain numpy from the model's terrain (not by the compiled
contact search): a point's depth along the ground's normal at its x, an arc sole's and a
straight side's deepest sample (every 0.5 degrees of arc, 200 points of a side), which is
exact to far below the tolerance.
"""
from __future__ import annotations

import numpy as np

from .errors import ModelError
from .kernels.codes import CONTACT_ARC, CONTACT_EDGE, CONTACT_POINT
from .terrain import from_coef

START_TOLERANCE = 1e-3   # [m] a contact may start this far below the ground (rounding, a foot
                         #   set on hills by hand), no further
ARC_SAMPLES = 721        # points on a full circle (0.5 degree apart)
EDGE_SAMPLES = 201       # points along a straight side


def _world(q, b, local):
    """World points of body b at configuration q, local (n, 2) [m]."""
    x, y, th = q[b]
    c, s = np.cos(th), np.sin(th)
    local = np.atleast_2d(local)
    return np.stack([x + c * local[:, 0] - s * local[:, 1], y + s * local[:, 0] + c * local[:, 1]], axis=1)


def _depth(terrain, pts) -> np.ndarray:
    """Depth [m] of world points below the ground along its normal (negative: above)."""
    h = terrain.height(pts[:, 0])
    d = terrain.slope(pts[:, 0])
    return (h - pts[:, 1]) / np.sqrt(1.0 + d * d)


def _contact_local_points(model, i) -> tuple:
    """(local points (n, 2) [m], radius grown around them [m]) sampling contact i's surface."""
    a = model.arrays
    kind = int(a.contact_kind[i])
    local = np.asarray(a.contact_local[i], dtype=np.float64)
    r = float(a.contact_radius[i])
    adr, num = int(a.contact_vert_adr[i]), int(a.contact_vert_num[i])
    verts = np.asarray(a.vert_local[adr:adr + num], dtype=np.float64).reshape(num, 2)
    if kind == CONTACT_POINT:
        return local[None, :], 0.0
    if kind == CONTACT_ARC:
        a0, a1 = a.contact_span[i]
        n = max(2, int(np.ceil(ARC_SAMPLES * (a1 - a0) / (2 * np.pi))))
        ang = np.linspace(a0, a1, n)
        arc = local + r * np.stack([np.cos(ang), np.sin(ang)], axis=1)
        return np.vstack([arc, verts]), 0.0
    if kind == CONTACT_EDGE:
        u = np.linspace(0.0, 1.0, EDGE_SAMPLES)[:, None]
        return local + u * (verts[0] - local), r
    return np.zeros((0, 2)), 0.0     # a pair of shapes: not the ground's


def contact_depths(model, q, enabled=None) -> list:
    """[(contact index, depth [m], x [m])] of every enabled ground contact at configuration q
    (n_body, 3): how far its deepest point is below the ground (negative: clear by that
    much) and where."""
    out = []
    q = np.asarray(q, dtype=np.float64)
    ground = from_coef(model.arrays.terrain_coef, "ground")
    for i in range(model.n_contact):
        if enabled is not None and not enabled[i]:
            continue
        local, grow = _contact_local_points(model, i)
        if not len(local):
            continue
        pts = _world(q, int(model.arrays.contact_body[i]), local)
        depth = _depth(ground, pts) + grow
        k = int(np.argmax(depth))
        out.append((i, float(depth[k]), float(pts[k, 0])))
    return out


def below_ground(model, state, tolerance: float = START_TOLERANCE, who: str = "simulator"):
    """(how many contacts start more than `tolerance` [m] below the ground at `state`, a
    sentence naming the deepest: its body, depth and x; '' when none)."""
    deep = [c for c in contact_depths(model, state.q, state.contact_enabled) if c[1] > tolerance]
    if not deep:
        return 0, ""
    i, depth, x = max(deep, key=lambda c: c[1])
    b = int(model.arrays.contact_body[i])
    more = len(deep) - 1
    others = f" (and {more} more contact{'s' if more > 1 else ''})" if more else ""
    return len(deep), (f"{who}: contact {model.contact_names[i]!r} ({i}) of body "
                       f"{model.body_names[b]!r} ({b}) starts {depth:.4g} m below the ground at "
                       f"x={x:.4g} m{others}, more than {tolerance:g} m")


def check_start(model, state, tolerance: float = START_TOLERANCE, who: str = "simulator") -> None:
    """ModelError naming the deepest contact that starts more than `tolerance` [m] below the
    ground at `state` (its body, depth and x), else nothing."""
    count, said = below_ground(model, state, tolerance, who)
    if count:
        raise ModelError(f"{said}; the first step would move it to the surface. Build the body "
                         f"higher (its pos), or pass allow_below_ground=True to start it there")
