"""The energetic bound on restitution's rebound (step.bound_rebound takes the step's answer
again with the rebounds scaled down where it fails).

Newton's law of restitution asks each impacting contact to leave at e times its approach
speed. Without friction the rebound returns at most the energy the approach brought (e <= 1),
but with Coulomb friction it can return more: a sticking contact's friction impulse turns
the body, and the full normal rebound on top of that leaves it with more kinetic energy than
it came in with (Kane's paradox: a spinning triangle with e = 1, mu = 1 gained 25 % in one
impact). A passive impact cannot add energy, so where the contacts' impulses of an answer
with rebounds add any, every rebound of the step is scaled by one factor below 1, the
largest that adds none (Stronge's energetic restitution bounds the rebound by the same
energy argument).

What the contacts add is measured on symplectic Euler's modified energy E + (h/2) f . v
(f the applied forces; constant over a step, it is what the scheme conserves in free
flight, where E itself oscillates by h f . v / 2), so that an elastic ball without friction,
whose rebound is measured from its approach at the step's start, neither gains nor loses.
With v* = v + h M^-1 f and v_new = v* + W F^T lam, the step changes it by
KE(v_new) - KE(v*) - (h/2) f . (v_new - v*), and KE(v_new) - KE(v*) = sum_r lam_r F_r v_new
- |v_new - v*|^2 / 2 (mass-weighted): the contacts' share is that change less the other
rows' work (joints, limits, soft rows).

The energies are measured in the frame of the step's checks (checks/frame.py): the world's
for a model that touches it, else one drifting with the bodies' centre of mass, so that the
allowance for rounding (a share of the kinetic energy) and the result do not depend on how
fast a free pile drifts (measured in the world's frame, a pair
of squares drifting at 1000 m/s gained 3.5e-3 of its energy about its centre of mass in
Kane's impact, 3.8e-7 at rest).
"""
from ...compile import kernel
from ..codes import MODE_FREE
from ..constraints.rows import is_contact_row
from .solve import row_dot
from ..checks.frame import frame_velocity, kinetic_in_frame

# the share of the step's kinetic energy a rebound's rounding may add (lcp.ANSWER_TOL: the
# accuracy the complementarity solve accepts)
REBOUND_REL_TOL = 1e-7


@kernel
def rebounding(s, ws):
    """Some touching contact of the step's answer carries a rebound target (restitution)."""
    for k in range(ws.n_live[0]):
        i = ws.live[k]
        if ws.contact_bounce[i] > 0.0 and s.contact_mode[i] != MODE_FREE:
            return True
    return False


@kernel
def rebound_gain(m, ws, h):
    """The modified energy [J] the contacts' impulses of the answer (ws.lam, ws.v_new) add in
    the step of h [s] beyond its rounding (module docstring; > 0: they add energy)."""
    vx, vy = frame_velocity(m, ws, ws.v_pred)
    final = kinetic_in_frame(m, ws.v_new, vx, vy)
    start = kinetic_in_frame(m, ws.v_pred, vx, vy)
    other = 0.0
    for r in range(ws.n_row[0]):
        if not is_contact_row(ws.row_kind[r]):
            other += ws.lam[r] * row_dot(ws, r, ws.row_F, ws.v_new)
    kick = 0.0
    for i in range(ws.v_new.shape[0]):
        for k in range(3):
            kick += ws.force[i, k] * (ws.v_new[i, k] - ws.v_pred[i, k])
    return final - start - other - 0.5 * h * kick - REBOUND_REL_TOL * (final + start)
