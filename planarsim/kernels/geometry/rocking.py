"""A body on a straight edge over a convex hill rocks about its contact like a spring; the step
takes that spring explicitly, so its length is bounded by the rocking's rate (step.turn_substeps)."""
import math

from ...compile import kernel
from ..codes import CONTACT_EDGE, MODE_FREE
from ..math2d import update_trig
from .contacts import edge_deepest
from .terrain import ground_point, height_derivs


# [-] a free body's straight edge held on a convex hill rocks about its contact like a spring:
# turned by phi, its deepest point moves (R + r) phi along the edge (R the hill's radius of
# curvature there, r a capsule side's radius), so its weight m g acts at that lever: a
# stiffness m g (R + r) [N m / rad] against its inertia about the contact point. The step
# holds the edge at the deepest point of its start, that is it takes this spring explicitly;
# beyond h w of about 1 the step's turn overshoots the rocking's rest and the next swings it
# back, a two-step cycle whose every step the projection lifts and the energy bound audits
# (a 0.28 m board on a crest of radius 175 m: w 508 rad/s, audited every step at dt 3 ms and
# not at 2 ms; benchmarks/crest_rest.py). So the step is cut to sub-steps of h w <= this.
ROCK_TARGET = 1.0


@kernel
def body_has_joint(m, b):
    """Body b is an end of some pin (hinge, slider, weld) or rod."""
    for j in range(m.pin_body.shape[0]):
        if m.pin_body[j, 0] == b or m.pin_body[j, 1] == b:
            return True
    for j in range(m.rod_body.shape[0]):
        if m.rod_body[j, 0] == b or m.rod_body[j, 1] == b:
            return True
    return False


@kernel
def edge_rocking(m, s, ws):
    """The largest squared rocking rate w^2 [1/s^2] (ROCK_TARGET) of a body free of joints on
    a straight edge touching (not free) a convex hill at the state s; 0 where there is none
    (flat ground or a slope: no curvature). A body held by joints is not counted: its rocking
    moves the bodies it is joined to as well, whose inertia its own would understate."""
    coef = m.terrain_coef
    if int(coef[2]) == 0:
        return 0.0
    weight = math.hypot(m.gravity[0], m.gravity[1])
    worst = 0.0
    for k in range(ws.ground_contacts.shape[0]):
        i = ws.ground_contacts[k]
        if m.contact_kind[i] != CONTACT_EDGE or s.contact_mode[i] == MODE_FREE:
            continue
        b = m.contact_body[i]
        if not m.body_inertia[b] > 0.0 or body_has_joint(m, b):
            continue
        update_trig(s.q, ws.body_cs)
        inside, px, py = edge_deepest(m, s.q, ws.body_cs, i)
        if not inside:
            continue
        gx = ground_point(coef, px, py)[0]
        _, slope, curve = height_derivs(coef, gx)
        if not curve < 0.0:
            continue                    # (a valley: the edge rests on its ends)
        radius = (1.0 + slope * slope) ** 1.5 / -curve + m.contact_radius[i]
        dx = px - s.q[b, 0]
        dy = py - s.q[b, 1]
        inertia = m.body_inertia[b] + m.body_mass[b] * (dx * dx + dy * dy)
        worst = max(worst, m.body_mass[b] * weight * radius / inertia)
    return worst
