"""The energy-accurate integrators (StepOptions.integrator): RATTLE and its fourth-order
composition, built around the default step (kernels/step.py).

The default step is symplectic Euler with SHAKE: v+ = v + h M^-1 (f(q) + J(q)^T lam),
q+ = q + h v+, c(q+) = 0, with the correction along J(q) (integrate.py). Read with v the
velocity at the START of the step, its energy error is first order in h. RATTLE (Andersen
1983; Hairer, Lubich & Wanner, Geometric Numerical Integration, VII.1.4) keeps the velocity
of the instant, on the joints' tangent space:

    v_half = v + h/2 M^-1 (f(q) + J(q)^T lam),  q+ = q + h v_half,  c(q+) = 0     (SHAKE)
    v+ = v_half + h/2 M^-1 (f(q+) + J(q+)^T mu),  J(q+) v+ = 0                    (RATTLE)

so one RATTLE step is: a half kick back, v - h/2 M^-1 f(q) (rattle_begin; the default step's
full kick then leaves the half kick forward), the default step (its SHAKE solve finds lam: an
input velocity's part along M^-1 J(q)^T only changes lam), a half kick at q+ and the
mass-weighted projection onto J(q+) v = 0 (rattle_end). RATTLE is symmetric and symplectic:
its energy error is O(h^2) and stays bounded (no drift), the pins are closed to the position
correction's tolerance (StepOptions.refine_tol). Its symmetric composition with Suzuki's
(1990) weights is fourth order: five RATTLE stages of p h, p h, (1 - 4 p) h, p h, p h with
p = 1 / (4 - 4^(1/3)) (the middle one, -0.66 h, backwards in time). Measured on a 4-link chain
at h = 1 ms, its energy error is 23 times below that of Yoshida's three stages of
1 / (2 - 2^(1/3)) h, 1 - 2 / (2 - 2^(1/3)) h, ..., at 5/3 their cost (two more stages).
Yoshida's (1990) seven stages (solution A, w0 = 1.315, w1 = -1.178, w2 = 0.236, w3 = 0.785)
make it sixth order, for errors near rounding (a double pendulum: 4.6e-11 J at h = 2 ms,
64 to 84 times less per halving of h).

Only mechanisms of pins, sliders and rods under position-dependent forces (gravity, pushes,
actuator commands held over the step) are supported: a contact, a joint limit, a joint's
spring, damper or armature (solved implicitly inside the velocity solve) or a fluid drag
(velocity-dependent) would make the half kicks wrong. A model with any of them is refused
(unsupported: GUARD_UNSUPPORTED, errors.accurate_unsupported names the culprit) before
anything is stepped.
"""
import math

from ...compile import kernel
from ..codes import INTEGRATOR_RATTLE4, INTEGRATOR_RATTLE6
from .forces import kick
from ..checks.guards import GUARD_OK, GUARD_UNSUPPORTED
from ..info import INFO_GUARD_BODY, INFO_GUARD_FIELD
from ..math2d import update_trig
from ..constraints.rows import eval_rows
from ..solver.matrix import assemble, factor_ws, substitute_ws
from ..solver.solve import apply_impulses, row_dot

# Suzuki's fourth-order fractal: stages of p h, p h, (1 - 4 p) h, p h, p h
SUZUKI_P = 1.0 / (4.0 - 4.0 ** (1.0 / 3.0))
SUZUKI_MIDDLE = 1.0 - 4.0 * SUZUKI_P
# Yoshida's sixth-order composition (solution A): stages of w3, w2, w1, w0, w1, w2, w3 times h
YOSHIDA6_W1 = -1.17767998417887
YOSHIDA6_W2 = 0.235573213359357
YOSHIDA6_W3 = 0.784513610477560
YOSHIDA6_W0 = 1.0 - 2.0 * (YOSHIDA6_W1 + YOSHIDA6_W2 + YOSHIDA6_W3)

# what a model has that the accurate integrators cannot take (ws.info[INFO_GUARD_FIELD] of
# GUARD_UNSUPPORTED; ws.info[INFO_GUARD_BODY] holds the element's index; the same test from
# Python: planarsim/integrator.py)
UNSUPPORTED_CONTACT = 0   # a contact (index: the contact)
UNSUPPORTED_LIMIT = 1     # a joint limit (index: the joint)
UNSUPPORTED_SOFT = 2      # a joint's spring, damper or armature (index: the joint)
UNSUPPORTED_FRICTION = 4  # a joint's dry friction, frictionloss (index: the joint)
UNSUPPORTED_FLUID = 3     # a body under fluid drag (index: the fluid entry)


@kernel
def stage_count(integrator):
    """Stages (default steps) of one step of `integrator`."""
    if integrator == INTEGRATOR_RATTLE4:
        return 5
    if integrator == INTEGRATOR_RATTLE6:
        return 7
    return 1


@kernel
def longest_stage(integrator):
    """The largest |share| of the step any stage of `integrator` takes."""
    top = 0.0
    for k in range(stage_count(integrator)):
        top = max(top, abs(stage_weight(integrator, k)))
    return top


@kernel
def stage_weight(integrator, k):
    """Stage k's share of the step (the shares sum to 1)."""
    if integrator == INTEGRATOR_RATTLE4:
        return SUZUKI_MIDDLE if k == 2 else SUZUKI_P
    if integrator == INTEGRATOR_RATTLE6:
        j = abs(3 - k)          # the middle stage is w0, then w1, w2, w3 outwards
        if j == 0:
            return YOSHIDA6_W0
        if j == 1:
            return YOSHIDA6_W1
        return YOSHIDA6_W2 if j == 2 else YOSHIDA6_W3
    return 1.0


@kernel
def _refuse(ws, what, index):
    ws.info[INFO_GUARD_FIELD] = what
    ws.info[INFO_GUARD_BODY] = index
    return GUARD_UNSUPPORTED


@kernel
def unsupported(m, ws):
    """GUARD_UNSUPPORTED (the culprit recorded in ws.info) if the model has a contact, a
    joint limit, a joint's spring, damper or armature, or a fluid drag; else GUARD_OK."""
    if m.contact_body.shape[0] > 0:
        return _refuse(ws, UNSUPPORTED_CONTACT, 0)
    for j in range(m.pin_body.shape[0]):
        if math.isfinite(m.pin_limit[j, 0]) or math.isfinite(m.pin_limit[j, 1]):
            return _refuse(ws, UNSUPPORTED_LIMIT, j)
        if m.pin_armature[j] > 0.0 or m.pin_stiffness[j] > 0.0 or m.pin_damping[j] > 0.0:
            return _refuse(ws, UNSUPPORTED_SOFT, j)
        if m.pin_frictionloss[j] > 0.0:
            return _refuse(ws, UNSUPPORTED_FRICTION, j)
    if m.fluid_body.shape[0] > 0:
        return _refuse(ws, UNSUPPORTED_FLUID, 0)
    return GUARD_OK


@kernel
def project_velocities(m, s, ws, pivot_tol):
    """s.v <- s.v - W J^T (J W J^T)^-1 J s.v with the joints' rows J at s.q: the velocity of
    least kinetic-energy change that keeps every pin, slider and rod (RATTLE's velocity
    equation). Rows dependent to within pivot_tol (a closed loop) are dropped: the others
    hold them. After a default step of a supported model (unsupported) ws holds the rows it
    built, the joints' and no others, and their envelope: only J is evaluated again."""
    n = ws.n_row[0]
    if n == 0:
        return
    update_trig(s.q, ws.body_cs)
    eval_rows(m, s.q, ws.body_cs, ws, ws.row_J, ws.row_c, n, False)
    assemble(m, ws, ws.row_J, ws.row_J, n, True)
    factor_ws(ws, n, pivot_tol, True)
    for r in range(n):
        ws.rhs[r] = -row_dot(ws, r, ws.row_J, s.v)
    substitute_ws(ws, ws.rhs, ws.lam, n, True)
    apply_impulses(m, ws, ws.row_J, ws.lam, n, s.v, 1.0)


@kernel
def rattle_begin(m, s, ws, u, h):
    """Before a default step of h [s]: the half kick back (the step's full kick then gives
    RATTLE's first half kick)."""
    kick(m, s, ws, u, -0.5 * h, h)


@kernel
def rattle_end(m, s, ws, u, h, pivot_tol, project):
    """After a default step of h [s]: RATTLE's second half kick at the new configuration and,
    if `project`, the projection onto the joints' tangent space there (between stages of a
    composition it is left out: the next stage's SHAKE solve absorbs that component)."""
    kick(m, s, ws, u, 0.5 * h, h)
    if project:
        project_velocities(m, s, ws, pivot_tol)
