"""Stage 8: the positions at the end of the step: integrate, correct, settle.

position_stage(m, s, ws, opt, h, answered):
  1. integrate q += h v with the solve's velocity (integrate.integrate_positions);
  2. keep the rows the correction holds (integrate.keep_correction_rows);
  3. the Newton-SHAKE correction (integrate.correct_positions), skipped where a bound from the
     rows already built proves every row within half of refine_tol (rows_hold_within);
  4. settle_positions: the end-of-step pin gaps and contact depths (audit.worst_violation),
     the complementarity projection where one is above a tenth of its audit tolerance
     (complementarity.project_positions), the audit of what is left;
  5. bound_correction_work: the velocity change of a correction or projection kept only as
     far as it adds no energy beyond its allowance (audited: correction_work); the share of
     the correction's impulses kept is added to the joints' recorded impulses
     (integrate.commit_moved_impulses).
"""
import math

from ...compile import kernel, part
from ..checks.audit import (AUDIT_CORRECTION_WORK, DEPTH_TOL, PIN_GAP_TOL, audit_positions,
                            mark_held_contacts, needs_ground_query, note, worst_limit_overshoot,
                            worst_violation)
from ..solver.complementarity import project_positions
from ..codes import INTEGRATOR_EULER
from ..info import INFO_PROJECTIONS
from .integrate import (bound_correction_work, clear_moved_impulses, commit_moved_impulses,
                        correct_positions, integrate_positions, keep_correction_rows,
                        rows_hold_within)
from ..math2d import update_trig
from ..checks.work import NEAR_DEPENDENT, gravity_lift, judge_energy, most_gaining_body
from ..constraints.joints import is_slider
from ..constraints.limit import limit_overshoot
from ..constraints.rows import is_joint_row, is_soft_row

# Newton iterations of the complementarity projection of the positions (quadratic)
PROJECTION_ITERS = 20
# rows held to refine_tol count as within the audit's tolerances when refine_tol is at most
# this share of them (a pin's gap is at most sqrt(2) times its rows' errors; the settling
# threshold is a tenth of the tolerance)
ROWS_HELD_SHARE = 0.05


@kernel
def limits_outside(m, s, ws, tol):
    """True if a joint lies outside its limit by more than tol [rad or m] at s.q (ws.body_cs
    brought to s.q first where a slider has a limit)."""
    fresh = False
    for j in range(m.pin_body.shape[0]):
        if m.pin_limit[j, 0] == -math.inf and m.pin_limit[j, 1] == math.inf:
            continue
        if is_slider(m, j) and not fresh:
            update_trig(s.q, ws.body_cs)
            fresh = True
        if limit_overshoot(m, s.q, ws.body_cs, s.v, j) > tol:
            return True
    return False


@kernel
def settle_positions(m, s, ws, h, opt, rows_held):
    """After the Newton correction: the end-of-step pin gaps and contact depths; where one is
    above a tenth of its audit tolerance, the complementarity projection (it also catches a
    free contact whose turning body dipped it below the ground). rows_held: the correction
    proved its rows within a tenth of the tolerances (audit.worst_violation then skips
    them). Returns the violations the audit counts at the configuration the step ends at.
    Where the rows are held and every other contact is surely clear (a body at rest on the
    ground) that is known without a ground query; the rest is one call (_settle_measured).
    A joint outside its limit with that side inactive (a start outside it: the velocity solve
    only stops a violated side approaching) is a violation too: the projection moves it
    onto its limit, as it lifts a contact out of the ground."""
    if rows_held and limits_outside(m, s, ws, 0.1 * PIN_GAP_TOL):
        rows_held = False
    if rows_held:
        if m.contact_body.shape[0] == 0:
            return 0        # joints held, nothing else to check
        mark_held_contacts(m, ws)
        if not needs_ground_query(m, s, ws):
            return 0        # joints and touching contacts held, the others surely clear
    return _settle_measured(m, s, ws, h, opt, rows_held)


@part("model", "state", "workspace", "float64", "options", "boolean", returns="int64")
def _settle_measured(m, s, ws, h, opt, rows_held):
    """settle_positions where the ground must be asked (rows_held: contact_held is marked)."""
    update_trig(s.q, ws.body_cs)
    gap, depth = worst_violation(m, s, ws, True, rows_held)
    over = worst_limit_overshoot(m, s, ws)
    if gap > 0.1 * PIN_GAP_TOL or depth > 0.1 * DEPTH_TOL or over > 0.1 * PIN_GAP_TOL:
        project_positions(m, s, ws, h, PROJECTION_ITERS, opt.refine_tol)
        update_trig(s.q, ws.body_cs)
        gap, depth = worst_violation(m, s, ws, False, False)
        over = worst_limit_overshoot(m, s, ws)
    if gap > PIN_GAP_TOL or depth > DEPTH_TOL or over > PIN_GAP_TOL:
        return audit_positions(m, s, ws, s.step[0])
    return 0


@kernel
def joints_alone(m, ws):
    """The correction's rows (keep_correction_rows) are hard joint rows alone (pins, sliders,
    rods) and hinges' rotor rows (armature: the correction moves the bodies and rotors with
    the constant inertia M + A, A the sum of a g^T g over hinges' fixed rate rows g): no contact or
    limit row, and no slider's rotor (its g turns with the slider, so its inertia is not
    constant). The joints close no loop of bodies (ws.joints_open) and their pivots are not
    nearly dependent (ws.joint_pivot). Its correction is then SHAKE's for the inertia
    M + A, which keeps the step symplectic and its momenta within SHAKE's regime
    (integrate.bound_correction_work keeps it whole there). A closed loop is left to the
    bound: folded near a dead point, its nearly dependent pins' correction carries huge
    impulses, and a loop of bodies whose inertias differ by 1e8 turns its heavy body."""
    if ws.joints_open[0] == 0 or ws.joint_pivot[0] < NEAR_DEPENDENT:
        return False
    for r in range(ws.n_row[0]):
        kind = ws.row_kind[r]
        if not is_joint_row(kind) or (is_soft_row(kind) and is_slider(m, ws.row_owner[r])):
            return False
    return True


@kernel(inline="always")
def position_stage(m, s, ws, opt, h, answered):
    """Stage 8 (the module's docstring) after a velocity solve over a step of h [s];
    answered: a linear solve's answer stood (its rows' envelope in ws is reused)."""
    integrate_positions(s, ws, ws.v_new, h)
    clear_moved_impulses(ws)
    kept_all = keep_correction_rows(s, ws) == 0
    # the solve's envelope stands where its rows all stay (no need to compute it again)
    envelope_ready = answered and kept_all
    # the correction only when the rows may be off by more than refine_tol: a bound of
    # half of it (far above rounding) proves the correction would find nothing to do
    # (bodies at rest, translating), at a few flops per row instead of re-evaluating them
    held = True
    corrected = False
    if opt.refine_iters > 0 and ws.n_row[0] > 0 and not (
            opt.refine_tol > 0.0 and rows_hold_within(m, s, ws, h, 0.5 * opt.refine_tol)):
        held = correct_positions(m, s, ws, h, opt.refine_iters, opt.refine_tol,
                                 opt.refine_pivot_tol, envelope_ready) <= opt.refine_tol
        corrected = True
    if opt.refine_iters > 0:
        # rows held to refine_tol are within the audit's tolerances where a point
        # contact's row is its exact gap (flat or sloped ground; pin rows are exact)
        held = (held and m.terrain_coef[2] == 0.0
                and opt.refine_tol <= ROWS_HELD_SHARE * min(PIN_GAP_TOL, DEPTH_TOL))
        settle_positions(m, s, ws, h, opt, held)
        if corrected or ws.info[INFO_PROJECTIONS] > 0:
            # only a correction or a projection changes the velocity the solve gave
            excess = bound_correction_work(m, s, ws, h, opt.integrator != INTEGRATOR_EULER
                                           or joints_alone(m, ws))
            if excess > 0.0:
                note(ws, s.step[0], AUDIT_CORRECTION_WORK, -1, most_gaining_body(m, s, ws), excess)
                # bodies lifted out of the ground (a terrain put in) are the depth's
                # business, counted here but not a reason to stop; so is a run's first step,
                # which moves a start below the ground to the surface (start_check names it)
                if s.step[0] > 0:
                    judge_energy(m, ws, opt, h, excess - gravity_lift(m, s, ws))
        if corrected:
            commit_moved_impulses(s, ws)
