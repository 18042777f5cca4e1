"""The default step's equations in numpy, written so that complex numbers pass through them:
the exact derivative of a step by the complex step (planarsim.derivatives).

A `StepPlan` holds what one step decided at its real start (its contacts' modes and slips, the
commands' saturation, the Newton correction's number of passes, the energy bound's branch)
and the matrices that do not depend on the state there (the bodies' inverse masses with the
joints' rotors and dampers). `replica(plan, q0, v0, u)` then computes the step's end from a
batch of starts (B, 3 n) with those decisions held:

    v_lin = R v0 + h W_D (f(u) + f_spring(q0)),              q_pred = q0 + h v_lin,
    P W_D F^T lam = -b,     b_joint = c(q_pred) / h,     b_contact = c(q0)^+ / h + P v_lin,
    v_new = v_lin + W_D F^T lam,
    q <- q0 + h v_new, then the Newton passes G(q) W_A P^T mu = -c(q), q += W_A P^T mu,
    v += W_A P^T mu / h (joints and limits only) or W_A P^T kappa, G W_A P^T kappa =
    S (-c(q)) / h (S: 1 on the joints' and limits' rows, 0 on the contacts' normal rows,
    which move positions only),
    one more pass on the last factorisation where the engine takes one,
    v1 = v_new + k (v - v_new), k the energy bound's share (kernels/dynamics/integrate.py).

P holds the rows at q0: the joints' (a hinge's x and y, a slider's perpendicular and angle)
and the touching ground contacts' (a normal row: the gap of a point, or of a round sole's
centre less its radius; a sticking contact's tangent row: its material point's move along the
ground from where it was at q0); F is P but for a sliding contact's normal row, whose impulse
pushes along n - mu s t (Coulomb). These are the rows kernels/constraints/rows.py builds, in the same
arithmetic up to rounding. Every operation is analytic in the state (no abs, max or branch on
it: those are the plan's), so a start q0 + i e dq gives the directional derivative as the
imaginary part over e, exact to rounding (Squire and Trapp 1998: no difference is taken).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .kernels.constraints.rows import HELD_GAP
from .kernels.codes import JOINT_FREE_BIT, JOINT_HINGE, JOINT_SLIDE_BIT, JOINT_SLIDER
from .kernels.dynamics.integrate import DIVERGED_GROWTH, ROUNDING, STALLED_RATIO
from .kernels.checks.work import (CONSTRAINT_SHARE, CORRECTION_MOVE_FLOOR, RELATIVE_ROUNDING,
                                  SHAKE_REGIME, VELOCITY_FLOOR)


class ReplicaRefused(Exception):
    """The step is outside what the replica reproduces (the message says why)."""


@dataclass
class ContactPlan:
    """The touching ground contacts (on flat or sloped ground), as decided at the real start."""
    index: np.ndarray           # (k,) int the contacts' indices in the model
    body: np.ndarray            # (k,) int
    local: np.ndarray           # (k, 2) [m] the normal row's body point: a point, a sole's centre
    radius: np.ndarray          # (k,) [m] 0 for a point
    pinned: np.ndarray          # (k,) bool: sticking (a tangent row); else sliding
    mu_slip: np.ndarray         # (k,) mu s of a sliding contact (its friction along -s t)
    terrain: np.ndarray         # the terrain's coefficients (kernels/geometry/terrain.py)
    pair: np.ndarray | None = None   # (k, 8) int per shape pair's slot (-1 row: a ground
                                     # contact): ref body, inc body, ref shape, inc shape,
                                     # distance kind, ref index, inc index, clip (collide.py)
    normal: np.ndarray = field(default_factory=lambda: np.array([0.0, 1.0]))  # flat or sloped
    offset: float = 0.0         # [m] n . (any ground point) there
    point_mass: np.ndarray | None = None   # (k,) bool: on a body without rotational inertia
    model: object = None
    was_touching: np.ndarray | None = None  # (k,) bool: its mode at the step's start not free

    @property
    def count(self) -> int:
        return int(self.body.shape[0])


@dataclass
class StepPlan:
    """One step's decisions and state-independent matrices (module docstring)."""
    model: object
    h: float
    q0: np.ndarray              # (3 n,) the real start
    u: np.ndarray               # (n_act,) the real commands
    W_A: np.ndarray
    W_D: np.ndarray
    R: np.ndarray
    f0: np.ndarray              # applied forces at the real start and commands (no springs;
                                # not the actuators of `turning`)
    F: np.ndarray               # d f / d u (0 past a bound) of the others
    fs0: np.ndarray             # the joints' springs at q0
    K: np.ndarray               # d f_spring / dq
    f_alone0: np.ndarray        # the springs the step takes as forces (in ws.force), at q0
    K_force: np.ndarray
    rotors: np.ndarray          # the joints' rotors' inertia A (3 n, 3 n)
    held: np.ndarray            # the joints' rows that hold something (a free coordinate: none)
    turning: np.ndarray         # the actuators whose force turns with the bodies (axial, hip)
    u_held: np.ndarray          # (n_act,) bool: a command past its bound (held at it)
    contacts: ContactPlan
    limits: np.ndarray          # (k, 2) int: the active joint limits' [joint, side]
    order: np.ndarray           # the rows (joints' then contacts') in the engine's order
    iters: int
    tol: float
    pivot_tol: float = 1e-11            # StepOptions.pivot_tol, refine_pivot_tol
    refine_pivot_tol: float = 1e-7
    resting: bool = False       # a unilateral row starts on its surface (module docstring)
    v_lin: np.ndarray | None = None     # the first row's v_lin (derivatives checks it)
    passes: int | None = None   # Newton passes (None: decide, on the real run)
    extra_pass: bool | None = None
    bound: dict | None = None   # the energy bound's branch (None: decide)
    shake_whole: bool = False   # the engine kept the correction whole as SHAKE's (its regime)
    held_m: np.ndarray | None = None     # the mode rows held from the start (held_rows)
    lifted: np.ndarray | None = None     # the mode rows whose start is off their surface
    solved: np.ndarray | None = None     # the velocity solve's independent rows
    kept: np.ndarray | None = None       # the rows the correction keeps (none leaving)
    flip: tuple = ()            # rows whose leaving is judged the other way (derivatives.py)
    near: np.ndarray | None = None       # rows whose leaving is within rounding of its bound
    corrected: np.ndarray | None = None  # the correction's


# --- rows -------------------------------------------------------------------------------------
def _turn(q, b, local):
    """World arm R(theta_b) local (B, 2) of body b at q (B, n, 3); local (2,) or (B, 2)."""
    cs, sn = np.cos(q[:, b, 2]), np.sin(q[:, b, 2])
    lx, ly = (local[..., 0], local[..., 1])
    return np.stack([cs * lx - sn * ly, sn * lx + cs * ly], axis=-1)


def _cross(r, d):
    """z of r x d, r (B, 2), d (2,) or (B, 2)."""
    return r[..., 0] * d[..., 1] - r[..., 1] * d[..., 0]


def joint_rows(model, q, held):
    """(c (B, m), J (B, m, 3 n)) of the joints' held rows at q (B, n, 3): kernels/constraints/pin.py's
    hinge rows (anchor b minus anchor a) and kernels/constraints/slider.py's rows."""
    a = model.arrays
    B, n = q.shape[0], q.shape[1]
    c = np.zeros((B, 2 * model.n_pin), dtype=q.dtype)
    J = np.zeros((B, 2 * model.n_pin, 3 * n), dtype=q.dtype)
    hinges = np.flatnonzero(a.pin_kind == JOINT_HINGE)
    for e, sign in ((0, -1.0), (1, 1.0)) if hinges.size else ():
        # every hinge's end e at once (B, k): anchor b minus anchor a
        body = a.pin_body[hinges, e]
        world = hinges[body < 0]
        c[:, 2 * world] += sign * a.pin_anchor[world, e, 0]
        c[:, 2 * world + 1] += sign * a.pin_anchor[world, e, 1]
        j, b = hinges[body >= 0], body[body >= 0]
        cs, sn = np.cos(q[:, b, 2]), np.sin(q[:, b, 2])
        lx, ly = a.pin_anchor[j, e, 0], a.pin_anchor[j, e, 1]
        rx, ry = cs * lx - sn * ly, sn * lx + cs * ly
        c[:, 2 * j] += sign * (q[:, b, 0] + rx)
        c[:, 2 * j + 1] += sign * (q[:, b, 1] + ry)
        # (a hinge's two ends are two bodies: no index repeats within one end's assignment)
        J[:, 2 * j, 3 * b] += sign
        J[:, 2 * j + 1, 3 * b + 1] += sign
        J[:, 2 * j, 3 * b + 2] += -sign * ry
        J[:, 2 * j + 1, 3 * b + 2] += sign * rx
    for j in np.flatnonzero(a.pin_kind != JOINT_HINGE):
        kind = int(a.pin_kind[j])
        if kind & JOINT_FREE_BIT:
            continue
        ba, bb = int(a.pin_body[j, 0]), int(a.pin_body[j, 1])
        r = 2 * j
        if kind == JOINT_SLIDER:
            if ba >= 0:
                d = _turn(q, ba, np.asarray(a.pin_axis[j], dtype=float))
                pa = q[:, ba, :2] + _turn(q, ba, np.asarray(a.pin_anchor[j, 0], dtype=float))
            else:
                d = np.broadcast_to(np.asarray(a.pin_axis[j], dtype=float), (B, 2))
                pa = np.broadcast_to(np.asarray(a.pin_anchor[j, 0], dtype=float), (B, 2))
            nrm = np.stack([-d[:, 1], d[:, 0]], axis=-1)
            pb = q[:, bb, :2] + _turn(q, bb, np.asarray(a.pin_anchor[j, 1], dtype=float))
            c[:, r] = np.sum(nrm * (pb - pa), axis=-1)
            c[:, r + 1] = q[:, bb, 2] - a.pin_ref[j] - (q[:, ba, 2] if ba >= 0 else 0.0)
            J[:, r, 3 * bb:3 * bb + 2] += nrm
            J[:, r, 3 * bb + 2] += _cross(pb - q[:, bb, :2], nrm)
            J[:, r + 1, 3 * bb + 2] += 1.0
            if ba >= 0:
                J[:, r, 3 * ba:3 * ba + 2] -= nrm
                J[:, r, 3 * ba + 2] -= _cross(pb - q[:, ba, :2], nrm)
                J[:, r + 1, 3 * ba + 2] -= 1.0
        else:
            raise ReplicaRefused(f"joint {model.pin_names[j]!r} of kind {kind}")
    if not model.n_rod:
        return c[:, held], J[:, held]
    cr, Jr = rod_rows(model, q)
    return (np.concatenate([c[:, held], cr], axis=1),
            np.concatenate([J[:, held], Jr.astype(J.dtype)], axis=1))


def rod_rows(model, q):
    """(c (B, k), J (B, k, 3 n)) of the rods' rows at q (B, n, 3): kernels/constraints/rod.py's
    |p_b - p_a| - L along the unit vector a -> b (an end on the world: its anchor there)."""
    a = model.arrays
    B, n = q.shape[0], q.shape[1]
    c = np.zeros((B, model.n_rod), dtype=q.dtype)
    J = np.zeros((B, model.n_rod, 3 * n), dtype=q.dtype)
    for o in range(model.n_rod):
        ends = [(int(a.rod_body[o, e]), np.asarray(a.rod_anchor[o, e], dtype=float))
                for e in (0, 1)]
        pa, pb = (_world(q, body, local) for body, local in ends)
        d = pb - pa
        length = np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1])
        e = d / length[:, None]
        c[:, o] = length - a.rod_length[o]
        for (body, _), p, sign in zip(ends, (pa, pb), (-1.0, 1.0)):
            if body >= 0:
                J[:, o, 3 * body:3 * body + 2] += sign * e
                J[:, o, 3 * body + 2] += sign * _cross(p - q[:, body, :2], e)
    return c, J


def ground_point(cp, point):
    """(g (B, 2) [m], n (B, 2)) the ground point closest to `point` (B, 2) and the unit normal
    there (kernels/geometry/terrain.py closest_point). Flat or sloped ground: the foot of the
    perpendicular. Hills: the first row's (real) closest point found by the engine's own
    search, then Newton on (x - px) + (h(x) - py) h'(x) = 0 continued for every row from it
    (the rows differ from the first by a complex step only, so the root's derivative comes
    out exact: the implicit function theorem)."""
    coef = cp.terrain
    if coef[2] == 0.0:
        nrm = cp.normal
        gap = point @ nrm - cp.offset
        return point - gap[:, None] * nrm, np.broadcast_to(nrm, point.shape)
    from .kernels.geometry.terrain import closest_point
    px, py = point[:, 0], point[:, 1]
    x = np.full(point.shape[0], closest_point(coef, float(px[0].real), float(py[0].real))[0],
                dtype=point.dtype)
    for _ in range(HILLS_NEWTON):
        h, dh, ddh = _height_derivs(coef, x)
        x = x - ((x - px) + (h - py) * dh) / (1.0 + dh * dh + (h - py) * ddh)
    h, dh, _ = _height_derivs(coef, x)
    inv = 1.0 / np.sqrt(1.0 + dh * dh)
    return np.stack([x, h], axis=-1), np.stack([-dh * inv, inv], axis=-1)


#: Newton steps continued from the engine's closest point (the first is exact to rounding
#: for a complex step; the others only confirm it)
HILLS_NEWTON = 3


def _height_derivs(coef, x):
    """(h, h', h'') of the terrain at x (B,) (kernels/geometry/terrain.py height_derivs)."""
    h = coef[0] + coef[1] * x
    dh = coef[1] + 0.0 * x
    ddh = 0.0 * x
    for k in range(int(coef[2])):
        amp, w, phase = coef[3 + 3 * k], 2.0 * np.pi / coef[4 + 3 * k], coef[5 + 3 * k]
        arg = w * x + phase
        h = h + amp * np.sin(arg)
        dh = dh + amp * w * np.cos(arg)
        ddh = ddh - amp * w * w * np.sin(arg)
    return h, dh, ddh


def _perp_tangent(nrm):
    """The ground tangent t = (n_y, -n_x) (B, 2) of normals (B, 2)."""
    return np.stack([nrm[:, 1], -nrm[:, 0]], axis=-1)


def _world(q, body, local):
    """World point (B, 2) of body-frame point `local` ((2,) or (B, 2)) of body (the world's
    own coordinates for body < 0)."""
    if body < 0:
        return np.broadcast_to(local, (q.shape[0], 2)) + 0.0 * q[:, 0, :2]
    return q[:, body, :2] + _turn(q, body, local)


def _theta(q, body):
    """Body's angle (B,) [rad] (0 for the world, body < 0; q's dtype, so that a dual number's
    derivative parts carry through)."""
    if body < 0:
        return 0.0 * q[:, 0, 2]
    return q[:, body, 2]


def _local(q, body, point):
    """Body-frame coordinates (B, 2) of world point (B, 2) (unchanged for the world)."""
    if body < 0:
        return point
    return _unturn(q, body, point - q[:, body, :2])


def _unturn(q, body, vector):
    """World direction `vector` (B, 2) in body's frame (unchanged for the world)."""
    if body < 0:
        return vector
    th = q[:, body, 2]
    cs, sn = np.cos(th), np.sin(th)
    return np.stack([cs * vector[:, 0] + sn * vector[:, 1],
                     -sn * vector[:, 0] + cs * vector[:, 1]], axis=-1)


def _rotate_by(q, body, vector):
    """Body-frame direction `vector` (2,) in the world (B, 2)."""
    if body < 0:
        return np.broadcast_to(vector, (q.shape[0], 2)) + 0.0 * q[:, 0, :2]
    return _turn(q, body, vector)


def pair_point(model, pair, q0):
    """The manifold point of a shape pair's slot at q0 (kernels/geometry/collide.py, its features held:
    pair = ContactPlan.pair's row): (p: the incident core's point, g: the reference
    feature's point, n: the normal from the reference, gap), each (B, 2) or (B,). A FACE point
    is an incident vertex (clip none) or the incident edge crossing a side line of the
    reference edge (its start or end), g its foot on the reference edge's line; a DIST point
    is a vertex pair."""
    a = model.arrays
    ref, inc, s_ref, s_inc, dist, i_ref, i_inc, clip = (int(x) for x in pair)
    vr = a.core_vert[a.shape_vert_adr[s_ref]:a.shape_vert_adr[s_ref] + a.shape_vert_num[s_ref]]
    nr = a.core_norm[a.shape_vert_adr[s_ref]:a.shape_vert_adr[s_ref] + a.shape_vert_num[s_ref]]
    vi = a.core_vert[a.shape_vert_adr[s_inc]:a.shape_vert_adr[s_inc] + a.shape_vert_num[s_inc]]
    radii = a.shape_radius[s_ref] + a.shape_radius[s_inc]
    if dist:
        p = _world(q0, inc, vi[i_inc])
        g = _world(q0, ref, vr[i_ref])
        d = p - g
        length = np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1])
        return p, g, d / length[:, None], length - radii
    start = _world(q0, ref, vr[i_ref])
    n = _rotate_by(q0, ref, nr[i_ref])
    if clip == 0:
        p = _world(q0, inc, vi[i_inc])
    else:
        e0 = _world(q0, inc, vi[i_inc])
        e1 = _world(q0, inc, vi[(i_inc + 1) % vi.shape[0]])
        side = start if clip == 1 else _world(q0, ref, vr[(i_ref + 1) % vr.shape[0]])
        t = np.stack([-n[:, 1], n[:, 0]], axis=-1)
        frac = np.sum(t * (side - e0), axis=-1) / np.sum(t * (e1 - e0), axis=-1)
        p = e0 + frac[:, None] * (e1 - e0)
    depth = np.sum(n * (p - start), axis=-1)
    return p, p - depth[:, None] * n, n, depth - radii


def _pair_rows(model, cp, k, q, q0, c, J, F, r):
    """contact_rows' rows r (normal) and r + 1 (sticking: tangent) of shape pair slot k:
    kernels/geometry/pair.py pair_row with the features found at q0 (_store_point), acting on the
    reference body (-) and the incident body (+) at the incident surface point."""
    a = model.arrays
    ref, inc, s_ref, s_inc, dist = (int(x) for x in cp.pair[k, :5])
    r_ref, r_inc = a.shape_radius[s_ref], a.shape_radius[s_inc]
    p0, g0, n0, _ = pair_point(model, cp.pair[k], q0)
    anchor = _local(q0, inc, p0)                    # the incident core's point
    face_n = _unturn(q0, ref, n0)                   # the face's normal in its body's frame
    face_g = _local(q0, ref, g0)
    ref_pt = _local(q0, ref, g0 + r_ref * n0)
    inc_pt = _local(q0, inc, p0 - r_inc * n0)
    surface0 = p0 - r_inc * n0
    # at q
    p, g = _world(q, inc, anchor), _world(q, ref, face_g)
    if dist:
        d = p - g
        length = np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1])
        n = d / length[:, None]
        gap = length - r_ref - r_inc
    else:
        n = _turn(q, ref, face_n) if ref >= 0 else face_n
        gap = np.sum(n * (p - g), axis=-1) - r_ref - r_inc
    surface = p - r_inc * n

    def put(row, M, d, at, qq):
        for body, sign in ((ref, -1.0), (inc, 1.0)):
            if body < 0:
                continue
            M[:, row, 3 * body:3 * body + 2] += sign * d
            M[:, row, 3 * body + 2] += sign * _cross(at - qq[:, body, :2], d)

    c[:, r] = gap
    put(r, J, n, surface, q)
    t0 = _perp_tangent(n0)
    put(r, F, n0 - cp.mu_slip[k] * t0 if not cp.pinned[k] else n0, surface0, q0)
    if cp.pinned[k]:
        t = _perp_tangent(n)
        if not dist and r_inc > 0.0:
            # a round side rolls on the face: its surface point plus the arc it rolled
            # (pair.pair_row)
            c[:, r + 1] = (np.sum(t * (surface - _world(q, ref, ref_pt)), axis=-1)
                           + r_inc * ((_theta(q, inc) - _theta(q0, inc))
                                      - (_theta(q, ref) - _theta(q0, ref))))
        else:
            c[:, r + 1] = np.sum(t * (_world(q, inc, inc_pt) - _world(q, ref, ref_pt)),
                                 axis=-1)
        put(r + 1, J, t, surface, q)
        put(r + 1, F, t0, surface0, q0)


def contact_rows(cp, q, q0, n_coord):
    """(c (B, m), J (B, m, 3 n), F (B, m, 3 n)) of the touching contacts' rows at q, each
    contact's normal row then (sticking) its tangent row: the normal row the gap of its point
    (a round sole's centre, less the radius) along the normal at its closest ground point at
    q; the tangent row its material point's distance along the ground tangent at q0 from the
    ground point found at q0 (a round sole: its centre's, plus the arc r (theta - theta0) it
    rolled, the same at q0 as its material point's below the centre); F: the
    rows' impulse directions at q0 (J at q0 but a sliding contact's normal row, along
    n - mu s t at its point). Rows of kernels/geometry/contacts.py ground_row and rows.build_rows."""
    B = q.shape[0]
    n_rows = int(cp.count + cp.pinned.sum())
    dtype = np.result_type(q, q0)
    c = np.zeros((B, n_rows), dtype=dtype)
    J = np.zeros((B, n_rows, n_coord), dtype=dtype)
    F = np.zeros((B, n_rows, n_coord), dtype=dtype)
    r = 0
    for k in range(cp.count):
        if cp.pair is not None and cp.pair[k, 0] > -2:
            _pair_rows(cp.model, cp, k, q, q0, c, J, F, r)
            r += 2 if cp.pinned[k] else 1
            continue
        b = int(cp.body[k])
        cols = slice(3 * b, 3 * b + 2)
        arm_n = _turn(q, b, cp.local[k])
        point = q[:, b, :2] + arm_n
        g, nrm = ground_point(cp, point)
        c[:, r] = np.sum(nrm * (point - g), axis=-1) - cp.radius[k]
        J[:, r, cols] = nrm
        J[:, r, 3 * b + 2] = _cross(arm_n, nrm)
        # the material point held for the step, and the ground's frame, at q0
        arm0_n = _turn(q0, b, cp.local[k])
        g0, n0 = ground_point(cp, q0[:, b, :2] + arm0_n)
        t0 = _perp_tangent(n0)
        arm0 = arm0_n - cp.radius[k] * n0
        th0 = q0[:, b, 2]
        cs, sn = np.cos(th0), np.sin(th0)
        anchor = np.stack([cs * arm0[:, 0] + sn * arm0[:, 1], -sn * arm0[:, 0] + cs * arm0[:, 1]],
                          axis=-1)
        d = n0 - cp.mu_slip[k] * t0 if not cp.pinned[k] else n0
        F[:, r, cols] = d
        F[:, r, 3 * b + 2] = _cross(arm0, d)
        r += 1
        if cp.pinned[k]:
            if cp.radius[k] > 0.0:
                # a round sole rolls on the ground point without slipping: its centre's move
                # along t0 plus the arc r dtheta it rolls (ground_row)
                c[:, r] = (np.sum(t0 * (q[:, b, :2] + arm_n - g0), axis=-1)
                           + cp.radius[k] * (q[:, b, 2] - th0))
                J[:, r, cols] = t0
                J[:, r, 3 * b + 2] = _cross(arm_n, t0) + cp.radius[k]
            else:
                arm = _turn(q, b, anchor)
                c[:, r] = np.sum(t0 * (q[:, b, :2] + arm - g0), axis=-1)
                J[:, r, cols] = t0
                J[:, r, 3 * b + 2] = _cross(arm, t0)
            F[:, r, cols] = t0
            F[:, r, 3 * b + 2] = _cross(arm0, t0)
            r += 1
    return c, J, F




def ground_second_order(plan, q0, v0, held) -> np.ndarray:
    """(B, m) over mode_rows' rows: the second-order part [m] of each held ground contact's gap
    over the step at the start's velocity (kernels/geometry/contacts.py ground_second_order:
    the turn's n . ((cos t - 1) a + (sin t - t) a_perp), t = h w, and on hills the ground's
    curvature gap(p + e) - gap(p) - n . e); 0 on the other rows."""
    cp, h = plan.contacts, plan.h
    n = plan.model.n_body
    q, v = q0.reshape(-1, n, 3), v0.reshape(-1, n, 3)
    out = np.zeros((q.shape[0], held.shape[0]), dtype=np.result_type(q0, v0))
    r = plan.limits.shape[0]
    for k in range(cp.count):
        if held[r]:
            b = int(cp.body[k])
            arm = _turn(q, b, cp.local[k])
            t = h * v[:, b, 2]
            c1 = -2.0 * np.sin(0.5 * t) ** 2
            s1 = np.sin(t) - t
            perp = np.stack([-arm[:, 1], arm[:, 0]], axis=-1)
            d = c1[:, None] * arm + s1[:, None] * perp
            point = q[:, b, :2] + arm
            g, nrm = ground_point(cp, point)
            part = np.sum(nrm * d, axis=-1)
            if cp.terrain[2] != 0.0:
                e = h * (v[:, b, :2] + v[:, b, 2:3] * perp) + d
                g1, n1 = ground_point(cp, point + e)
                part = part + (np.sum(n1 * (point + e - g1), axis=-1)
                               - np.sum(nrm * (point - g), axis=-1) - np.sum(nrm * e, axis=-1))
            out[:, r] = part
        r += 2 if cp.pinned[k] else 1
    return out


def held_rows(plan, c0, approach) -> np.ndarray:
    """(m,) bool over mode_rows' rows: the normal row of a ground contact held from the step's
    start (touching then, or within HELD_GAP of its surface and not approaching it:
    constraints/rows.held_contact), whose velocity target takes its second-order part; a
    shape pair's never (its target is first order)."""
    cp = plan.contacts
    out = [False] * plan.limits.shape[0]
    r = plan.limits.shape[0]
    for k in range(cp.count):
        was = cp.was_touching is not None and bool(cp.was_touching[k])
        pair = cp.pair is not None and cp.pair[k, 0] > -2
        out.append(not pair and (was or (abs(float(c0[r])) <= HELD_GAP
                                         and float(approach[r]) <= HELD_GAP)))
        r += 1
        if cp.pinned[k]:
            out.append(False)
            r += 1
    return np.array(out, dtype=bool)


def contact_unilateral(cp) -> np.ndarray:
    """(m,) bool over contact_rows' rows: a normal row (moves positions only in the correction)."""
    out = []
    for k in range(cp.count):
        out.append(True)
        if cp.pinned[k]:
            out.append(False)
    return np.array(out, dtype=bool)


def limit_rows(model, limits, q):
    """(c (B, k), J (B, k, 3 n)) of the active joint limits' rows at q (B, n, 3): limits (k, 2)
    [joint, side]; a hinge's angle theta_b - theta_a - ref, or a world slide's coordinate
    along its axis, less the lower limit (side 0) or taken from the upper (side 1), as
    kernels/constraints/limit.py writes them (their rate rows g are constant: derivatives.check_covered)."""
    from .derivatives import rate_row
    a = model.arrays
    B, n = q.shape[0], q.shape[1]
    c = np.zeros((B, limits.shape[0]), dtype=q.dtype)
    J = np.zeros((B, limits.shape[0], 3 * n))
    flat = q.reshape(B, 3 * n)
    for r, (j, side) in enumerate(limits):
        g = rate_row(a, j, n)
        coordinate = flat @ g
        if a.pin_kind[j] & JOINT_SLIDE_BIT:
            coordinate = coordinate - a.pin_axis[j] @ a.pin_anchor[j, 0]
        else:
            coordinate = coordinate - a.pin_ref[j]
        sign = 1.0 if side == 0 else -1.0
        c[:, r] = sign * (coordinate - a.pin_limit[j, side])
        J[:, r] = sign * g
    return c, J


def mode_rows(plan, q, q0):
    """(c, J, F, unilateral) of the rows with a mode at q (B, 3 n), measured from q0 where
    they need it: the active limits' rows, then the touching contacts' (contact_rows); the
    mask marks the unilateral ones (limits, contacts' normals: their correction moves
    positions only and their velocity target is clipped at the surface)."""
    n = plan.model.n_body
    qq, qq0 = q.reshape(-1, n, 3), q0.reshape(-1, n, 3)
    cl, Jl = limit_rows(plan.model, plan.limits, qq)
    cc, Jc, Fc = contact_rows(plan.contacts, qq, qq0, 3 * n)
    Jl = np.broadcast_to(Jl, (qq.shape[0],) + Jl.shape[1:]).astype(Jc.dtype)
    unilateral = np.concatenate([np.ones(cl.shape[1], bool), contact_unilateral(plan.contacts)])
    return (np.concatenate([cl, cc], axis=1), np.concatenate([Jl, Jc], axis=1),
            np.concatenate([Jl, Fc], axis=1), unilateral)


def _rows(plan, q, q0):
    """Every row's (c, J) at q (B, 3 n): the held joints', then mode_rows'."""
    n = plan.model.n_body
    cj, Jj = joint_rows(plan.model, q.reshape(-1, n, 3), plan.held)
    cm, Jm, _, _ = mode_rows(plan, q, q0)
    return np.concatenate([cj, cm], axis=1), np.concatenate([Jj, Jm], axis=1)


def turning_forces(plan, q, u):
    """(B, 3 n) [N, N m] the forces of the actuators whose direction turns with the bodies
    (kernels/dynamics/forces.py apply_actuator): an axial force u along the line from its anchor on
    body a to its anchor on body b (on b, and its opposite on a, at the anchors), and a hip
    torque u as forces perpendicular to each leg from the hip body (-u on leg a, +u on leg
    b); commands past a bound held at it."""
    from .kernels.dynamics.forces import ACT_AXIAL
    model = plan.model
    a = model.arrays
    n = model.n_body
    qq = q.reshape(-1, n, 3)
    B = qq.shape[0]
    f = np.zeros((B, n, 3), dtype=np.result_type(q, u))
    lo, hi = a.act_range[:, 0], a.act_range[:, 1]
    for k in plan.turning:
        uk = np.clip(plan.u[k], lo[k], hi[k]) + 0.0 * u[:, k] if plan.u_held[k] else u[:, k]
        ba, bb = int(a.act_body[k, 0]), int(a.act_body[k, 1])
        if a.act_kind[k] == ACT_AXIAL:
            ends = []
            for body, anchor in ((ba, a.act_anchor[k, 0]), (bb, a.act_anchor[k, 1])):
                anchor = np.asarray(anchor, dtype=float)
                if body < 0:
                    ends.append((body, np.broadcast_to(anchor, (B, 2)), None))
                else:
                    arm = _turn(qq, body, anchor)
                    ends.append((body, qq[:, body, :2] + arm, arm))
            d = ends[1][1] - ends[0][1]
            length = np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1])
            push = (uk / length)[:, None] * d
            for (body, _, arm), sign in zip(ends, (-1.0, 1.0)):
                if body < 0:
                    continue
                f[:, body, :2] += sign * push
                f[:, body, 2] += sign * _cross(arm, push)
        else:                                       # ACT_HIP_TORQUE
            hip = int(a.act_body[k, 2])
            for leg, sign in ((ba, -1.0), (bb, 1.0)):
                d = qq[:, leg, :2] - qq[:, hip, :2]
                d2 = d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1]
                fx, fy = -sign * uk * d[:, 1] / d2, sign * uk * d[:, 0] / d2
                f[:, leg, 0] += fx
                f[:, leg, 1] += fy
                f[:, hip, 0] -= fx
                f[:, hip, 1] -= fy
    return f.reshape(B, 3 * n)


def _kept_rows(plan, c, unilateral, q, v, mj, v_start) -> np.ndarray:
    """The rows the Newton correction keeps (kernels/dynamics/integrate.py drop_leaving_rows): all but
    a unilateral row open at q (the start plus h v_new) by more than the step's turning
    explains (pull_allowance: the body leaves the surface, a disk rolling over a crest), and
    the tangent row of a contact whose normal row leaves. A row resting on its surface at the
    start (not lifted) is held: the engine may judge its opening of a few ulps either way,
    which moves the end by less than refine_tol, and the derivative across the surface is
    the one from inside. c: every row's error at q (real); v_start: the velocity at the step's start."""
    model = plan.model
    a = model.arrays
    n = model.n_body
    qq, vv = q.reshape(n, 3), v.reshape(n, 3)
    h = plan.h

    scale = 1.0 + np.abs(q).max()

    def allowance(bodies, lever):
        allow = 0.0
        for b in bodies:
            if b < 0:
                continue
            d = abs(h * vv[b, 2])
            # (integrate.pull_allowance: the step's turn too)
            d += abs(h * (vv[b, 2] - v_start.reshape(n, 3)[b, 2]))
            allow += (0.5 * d * d + d * d * d / 6.0) * lever
            allow += ROUNDING * (1.0 + abs(qq[b, 0]) + abs(qq[b, 1]) + lever)
        return allow

    leaving = np.zeros(c.shape[0], bool)
    near = []

    def judge(r, allow):
        if not plan.lifted[r - mj]:
            return          # resting on its surface: held (its derivative from inside)
        if abs(c[r] - allow) <= NEAR_ALLOWANCE * scale:
            near.append(r)
        leaving[r] = (c[r] > allow) != (r in plan.flip)

    r = mj
    for j, _ in plan.limits:
        judge(r, allowance(a.pin_body[j], 0.0))
        r += 1
    cp = plan.contacts
    for k in range(cp.count):
        b = int(cp.body[k])
        # (the normal row's point: a point contact's own, a round sole's centre; a shape
        # pair's face turns with its body: no bound, never leaving)
        if cp.pair is None or cp.pair[k, 0] == -2:
            judge(r, allowance([b], float(np.abs(cp.local[k]).sum())))
        if cp.pinned[k]:
            leaving[r + 1] = leaving[r]
            r += 2
        else:
            r += 1
    plan.near = np.array(near, dtype=np.int64)
    return np.flatnonzero(~leaving)


#: [m per m of the coordinates' size] a row opened within this of its pull allowance may have
#: been judged either way by the engine (its rounding differs from the replay's)
NEAR_ALLOWANCE = 1e-13




def _solve(N, b):
    """N x = b for a batch (B, m, m), (B, m)."""
    return np.linalg.solve(N, b[..., None])[..., 0]


# --- the step ---------------------------------------------------------------------------------
def replica(plan: StepPlan, q0, v0, u):
    """The step's end (q1, v1) (B, 3 n) from starts q0, v0 (B, 3 n) and commands u (B, n_act)
    under plan's decisions (module docstring). Where plan.passes is None the first row of the
    batch (real, or with imaginary parts of a complex step only) takes the decisions, which
    are stored in plan and hold for every row; it raises ReplicaRefused where a decision
    leaves what the replica reproduces."""
    model, h = plan.model, plan.h
    n = model.n_body
    deciding = plan.passes is None
    du = u - plan.u
    f = plan.f0 + du @ plan.F.T
    if plan.turning.size:
        f = f + turning_forces(plan, q0, u)
    dq0 = q0 - plan.q0
    f_spring = plan.fs0 + dq0 @ plan.K.T
    v_lin = v0 @ plan.R.T + h * ((f + f_spring) @ plan.W_D.T)
    q_pred = q0 + h * v_lin
    # the velocity solve
    cj_pred, _ = joint_rows(model, q_pred.reshape(-1, n, 3), plan.held)
    _, Pj = joint_rows(model, q0.reshape(-1, n, 3), plan.held)
    cp = plan.contacts
    cm0, Pm, Fm, unilateral_m = mode_rows(plan, q0, q0)
    mj = Pj.shape[1]
    if deciding:
        plan.held_m = held_rows(plan, cm0[0].real,
                                -h * np.einsum("rk,k->r", Pm[0].real, v0[0].real))
    held_m = plan.held_m
    unilateral = np.concatenate([np.zeros(mj, bool), unilateral_m])
    if deciding:
        # a row within refine_tol of its surface rests on it: its derivative across the
        # surface is taken from inside (pushed in, the correction moves it out), where the
        # engine's c / h target would add at most refine_tol / h
        plan.lifted = cm0[0].real > plan.tol
        plan.resting = bool((unilateral_m & ~plan.lifted).any())
        plan.v_lin = v_lin[0].real.copy()
    # a unilateral row that starts violated only stops approaching (solve.fill_row_b); one
    # resting open by at most refine_tol keeps the engine's target as a number (its
    # derivative is the one from inside)
    target = np.where(plan.lifted | ~unilateral_m, cm0,
                      np.where(cm0.real > 0.0, cm0.real, 0.0))
    P = np.concatenate([Pj, Pm], axis=1)
    Fd = np.concatenate([Pj, Fm], axis=1)
    m = P.shape[1]
    if m:
        rc = -target / h - np.einsum("brk,bk->br", Pm, v_lin)
        if held_m.any():
            # a held ground contact's normal: the second-order part of its gap
            # (solve.held_contact_curve)
            rc = rc - ground_second_order(plan, q0, v0, held_m) / h
        rhs = np.concatenate([-cj_pred / h, rc], axis=1)
        WdFt = np.einsum("ij,brj->bir", plan.W_D, Fd)          # (B, 3n, m)
        N = np.einsum("brk,bks->brs", P, WdFt)
        if deciding:
            if mj and independent_rows(N[0, :mj, :mj].real, np.arange(mj),
                                       plan.pivot_tol).size < mj:
                raise ReplicaRefused("dependent joints (an over-constrained loop): the step is "
                                     "not smooth there")
            plan.solved = independent_rows(N[0].real, plan.order, plan.pivot_tol)
        K = plan.solved
        lam = _solve(N[:, K][:, :, K], rhs[:, K])
        v_new = v_lin + np.einsum("bir,br->bi", WdFt[:, :, K], lam)
        if deciding:
            _check_held(P[0] @ (v_new[0] - v_lin[0]) - rhs[0],
                        np.abs(rhs[0]).max() + np.abs(P[0] @ v_lin[0]).max(), "velocity solve")
    else:
        v_new = v_lin
    # the Newton correction along W_A P^T (P at q0)
    q = q0 + h * v_new
    v = v_new.copy()
    if m:
        D = np.einsum("ij,brj->bir", plan.W_A, P)              # (B, 3n, m)
        # on hills a point mass's contact moves along the normal at the configuration being
        # corrected (integrate.normals_now), not at the start's
        now = np.zeros(m, bool)
        if cp.terrain[2] != 0.0:
            first = mj + plan.limits.shape[0]
            for k in range(cp.count):
                now[first] = cp.point_mass[k]
                first += 2 if cp.pinned[k] else 1
        c, G = _rows(plan, q, q0)
        if deciding:
            plan.kept = _kept_rows(plan, c[0].real, unilateral, q[0].real, v[0].real, mj,
                                   v0[0].real)
        keep = plan.kept
        D, now, unilateral_c = D[:, :, keep], now[keep], unilateral[keep]
        order = np.argsort(np.argsort(keep))     # (positions of the kept rows among themselves)
        kept_order = np.array([order[np.searchsorted(keep, r)] for r in plan.order
                               if r in set(keep.tolist())], dtype=np.int64)
        c, G = c[:, keep], G[:, keep]
        # the contacts' normal rows move positions only; a joint limit's row (one the step
        # started on) is corrected as a joint's: its move becomes velocity
        # (integrate.moves_without_velocity)
        still = np.concatenate([np.zeros(mj + plan.limits.shape[0], bool),
                                contact_unilateral(cp)])[keep]
        S = (~still).astype(float)
        any_unilateral = bool(still.any())
        worst = np.abs(c[0].real).max(initial=0.0) if deciding else None
        passes, stalled = 0, False
        Nn = None
        for _ in range(plan.iters if deciding else plan.passes):
            if deciding and worst <= plan.tol:
                break
            if now.any():
                D = D.copy()
                D[:, :, now] = np.einsum("ij,brj->bir", plan.W_A, G[:, now])
            Nn = np.einsum("brk,bks->brs", G, D)
            if plan.corrected is None:
                plan.corrected = independent_rows(Nn[0].real, kept_order, plan.refine_pivot_tol)
            K = plan.corrected
            Nn, DK = Nn[:, K][:, :, K], D[:, :, K]
            mu = _solve(Nn, -c[:, K])
            q = q + np.einsum("bir,br->bi", DK, mu)
            if any_unilateral:
                kappa = _solve(Nn, -(c * S)[:, K]) / h
                v = v + np.einsum("bir,br->bi", DK, kappa)
            else:
                v = v + np.einsum("bir,br->bi", DK, mu) / h
            c, G = _rows(plan, q, q0)
            c, G = c[:, keep], G[:, keep]
            passes += 1
            if deciding:
                after = np.abs(c[0].real).max(initial=0.0)
                if after > STALLED_RATIO * worst:
                    # (integrate.correct_positions: a pass that removed less than half the
                    # error ends the correction, kept; one that grew it tenfold is taken back
                    # and tried again on looser pivots, which the replay does not follow)
                    if after > DIVERGED_GROWTH * worst:
                        raise ReplicaRefused(f"a Newton correction that diverges (its rows' "
                                             f"errors {worst:.3g} -> {after:.3g})")
                    worst, stalled = after, True
                    break
                worst = after
        if deciding:
            plan.passes = passes
            plan.extra_pass = passes > 0 and not stalled and 0.0 < worst <= plan.tol
        if plan.extra_pass:
            # one more pass on the last factorisation (integrate.correct_positions)
            K = plan.corrected
            mu = _solve(Nn, -c[:, K])
            q = q + np.einsum("bir,br->bi", DK, mu)
            if any_unilateral:
                v = v + np.einsum("bir,br->bi", DK, _solve(Nn, -(c * S)[:, K]) / h)
            else:
                v = v + np.einsum("bir,br->bi", DK, mu) / h
        if plan.passes == 0 and plan.resting:
            # no pass (every row held at the step's end): a row resting on its surface, the
            # start pushed into it by dz (first order: its row at the start times the start's
            # move) keeps dz after the velocity solve, whose target is clipped there, and the
            # correction the engine then takes moves it out (positions only). That projection
            # alone, from inside: the start's other moves give nothing (real part 0)
            resting = unilateral_c.copy()           # (kept unilateral rows are mode rows)
            resting[unilateral_c] = ~plan.lifted[keep[unilateral_c] - mj]
            pushed = np.zeros_like(c)
            pushed[:, resting] = (q0 - plan.q0) @ P[0, keep[resting]].real.T
            if now.any():
                D = D.copy()
                D[:, :, now] = np.einsum("ij,brj->bir", plan.W_A, G[:, now])
            Nn = np.einsum("brk,bks->brs", G, D)
            K = independent_rows(Nn[0].real, kept_order, plan.refine_pivot_tol)
            q = q + np.einsum("bir,br->bi", D[:, :, K], _solve(Nn[:, K][:, :, K], -pushed[:, K]))
    elif deciding:
        plan.passes, plan.extra_pass = 0, False
    if plan.passes > 0:
        v = _energy_bound(plan, q0, v0, q, v, v_new, f + plan.f_alone0 + dq0 @ plan.K_force.T,
                          deciding)
    return q, v


#: the independent rows' matrix's condition number above which the step counts as not smooth
DEPENDENT_COND = 1e10
#: [m/s] the left-out rows' equations must hold to this (plus this share of the targets)
LEFT_OUT_TOL = 1e-9


def independent_rows(N, order, pivot_tol) -> np.ndarray:
    """The rows of N (m, m) kept by elimination in `order` (each row's pivot after the rows
    kept before it, kept if it keeps more than pivot_tol of its diagonal: the engine's
    StepOptions.pivot_tol for the velocity solve, refine_pivot_tol for the correction), as
    sorted indices; ReplicaRefused where the kept rows are still ill-conditioned."""
    kept = []
    for r in order:
        d = N[r, r]
        if kept:
            k = np.array(kept)
            pivot = d - N[r, k] @ np.linalg.solve(N[np.ix_(k, k)], N[k, r])
        else:
            pivot = d
        if abs(pivot) > pivot_tol * abs(d):
            kept.append(int(r))
    kept = np.array(sorted(kept), dtype=np.int64)
    if kept.size and np.linalg.cond(N[np.ix_(kept, kept)]) > DEPENDENT_COND:
        raise ReplicaRefused("nearly dependent rows (a loop or contacts near a dead point): "
                             "the step is not smooth there")
    return kept


def _check_held(residual, scale, stage):
    """ReplicaRefused where a left-out row's equation does not hold (targets that disagree):
    residual over every row, scale [m/s] the size of its terms."""
    off = np.abs(residual).max(initial=0.0)
    if off > LEFT_OUT_TOL * (1.0 + scale):
        raise ReplicaRefused(f"rows left out of the {stage} as dependent whose equations do "
                             f"not hold through the others (off by {off:.3g})")


def _sabs(x):
    """|x| for real x, continued analytically (its sign held) for a complex step."""
    return x * np.sign(x.real)


def _energy_bound(plan, q0, v0, q1, v, v_s, f, deciding):
    """kernels/dynamics/integrate.py bound_correction_work: v_s + k (v - v_s), k the largest share in
    [0, 1] of the correction's velocity change that adds no energy beyond its allowance (its
    branches the plan's); f (B, 3 n) [N, N m]: the step's applied forces (ws.force). Where
    the engine kept the correction whole as SHAKE's (plan.shake_whole: RATTLE, or joints
    alone, within SHAKE's regime), v."""
    if plan.shake_whole:
        plan.bound = {"branch": "whole"}
        return v
    model, h = plan.model, plan.h
    a_ = model.arrays
    n = model.n_body
    Mb = np.column_stack([a_.body_mass, a_.body_mass, a_.body_inertia]).ravel()
    E = np.diag(Mb) + plan.rotors
    dv = v - v_s
    move = q1 - (q0 + h * v_s)
    Ev, Edv = v_s @ E, dv @ E
    a = np.sum(v_s * Edv, axis=1)
    b = 0.5 * np.sum(dv * Edv, axis=1)
    kinetic = 0.5 * np.sum(v_s * Ev, axis=1)
    gravity = np.asarray(a_.gravity, dtype=float)
    g = float(np.hypot(*gravity))
    up = -gravity / g if g > 0.0 else np.zeros(2)
    f_g = np.zeros(3 * n)
    f_g[0::3] = a_.body_mass * gravity[0]
    f_g[1::3] = a_.body_mass * gravity[1]
    other = f - f_g
    start = 0.5 * np.sum(v0 * Mb * v0, axis=1)
    Up = np.zeros(3 * n)
    Up[0::3] = a_.body_mass * up[0]
    Up[1::3] = a_.body_mass * up[1]
    dp = (v_s - v0) @ Up
    total_mass = float(a_.body_mass.sum())
    lift = 0.5 * h * g * dp
    sink = -dp * dp / (2.0 * total_mass) if total_mass > 0.0 else 0.0 * dp
    gained0 = (0.5 * np.sum(v_s * Mb * v_s, axis=1) - start - h * np.sum(f * v_s, axis=1)
               + 0.5 * h * np.sum(other * (v_s - v0), axis=1))
    momentum = (_sabs(dv.reshape(-1, n, 3)[:, :, :2]).sum(axis=2)
                + _sabs(v_s.reshape(-1, n, 3)[:, :, :2]).sum(axis=2)) @ a_.body_mass
    forces = _sabs(f.reshape(-1, n, 3)[:, :, :2]).sum(axis=(1, 2))
    if deciding:
        owed_lift = total_mass > 0.0 and lift[0].real >= sink[0].real
        owed = lift if owed_lift else sink if total_mass > 0.0 else 0.0 * dp
        gained = gained0 - owed
        in_regime = bool(b[0].real <= SHAKE_REGIME * SHAKE_REGIME * kinetic[0].real)
        smaller_is_kinetic = bool(kinetic[0].real <= start[0].real)
        gained_on = bool(gained[0].real > 0.0)
        share_raw = CONSTRAINT_SHARE * (kinetic if smaller_is_kinetic else start) \
            - (gained if gained_on else 0.0)
        share_on = in_regime and bool(share_raw[0].real > 0.0)
        plan.bound = dict(owed_lift=owed_lift, share_on=share_on,
                          smaller_is_kinetic=smaller_is_kinetic, gained_on=gained_on,
                          sign_a=float(np.sign(a[0].real)))
    B_ = plan.bound
    if total_mass > 0.0:
        owed = lift if B_["owed_lift"] else sink
    else:
        owed = 0.0 * dp
    gained = gained0 - owed
    share = 0.0 * a
    if B_["share_on"]:
        share = CONSTRAINT_SHARE * (kinetic if B_["smaller_is_kinetic"] else start) \
            - (gained if B_["gained_on"] else 0.0)
    rounding = (VELOCITY_FLOOR * momentum + CORRECTION_MOVE_FLOOR * forces
                + RELATIVE_ROUNDING * (kinetic + B_["sign_a"] * a + b))
    room = share + np.sum(f * move, axis=1) + rounding
    if deciding:
        ar, br, rr = a[0].real, b[0].real, room[0].real
        if ar + br <= rr:
            branch = "whole"
        else:
            disc = ar * ar + 4.0 * br * rr
            k = (-ar + np.sqrt(disc)) / (2.0 * br) if disc >= 0.0 and br > 0.0 else -1.0
            short = k < 0.0 or (disc >= 0.0 and br > 0.0 and -ar - np.sqrt(disc) > 2.0 * br)
            if short:
                k = -ar / (2.0 * br) if br > 0.0 else 1.0
            branch = ("low" if k <= 0.0 else "whole" if k >= 1.0
                      else "least" if short else "root")
        B_["branch"] = branch
    branch = B_["branch"]
    if branch == "whole":
        return v
    if branch == "low":
        return v_s.copy()
    if branch == "least":
        k = -a / (2.0 * b)
    else:
        k = (-a + np.sqrt(a * a + 4.0 * b * room)) / (2.0 * b)
    return v_s + k[:, None] * dv


def project_velocities_batch(model, q, v, pinned=()):
    """planarsim.half_step.project_velocities for a batch, complex numbers passing through:
    velocities v (B, 3 n) made consistent with the rods, the hinge pins and the contacts in
    `pinned` (their points at rest) at q (B, 3 n) by the mass-weighted projection
    v - W J^T (J W J^T)^-1 J v (independent rows)."""
    a = model.arrays
    n = model.n_body
    qq = q.reshape(-1, n, 3)
    held = np.flatnonzero(np.repeat((a.pin_kind & JOINT_FREE_BIT) == 0, 2))
    _, J = joint_rows(model, qq, held)
    rows = [J]
    for c in pinned:
        b = int(a.contact_body[c])
        arm = _turn(qq, b, np.asarray(a.contact_local[c], dtype=float))
        P = np.zeros((qq.shape[0], 2, 3 * n), dtype=J.dtype)
        P[:, 0, 3 * b], P[:, 1, 3 * b + 1] = 1.0, 1.0
        P[:, 0, 3 * b + 2], P[:, 1, 3 * b + 2] = -arm[:, 1], arm[:, 0]
        rows.append(P)
    J = np.concatenate(rows, axis=1)
    if J.shape[1] == 0:
        return v.copy()
    w = np.c_[a.body_inv_mass, a.body_inv_mass, a.body_inv_inertia].ravel()
    WJt = w[None, :, None] * np.swapaxes(J, 1, 2)
    mu = _solve(J @ WJt, np.einsum("brk,bk->br", J, v))
    return v - np.einsum("bkr,br->bk", WJt, mu)
