"""StepOptions: the integer and float switches that choose algorithms inside the step."""
from __future__ import annotations

import math
from enum import IntEnum
from typing import NamedTuple

import numpy as np

from .errors import plain
from .kernels.codes import (INTEGRATOR_EULER, INTEGRATOR_NAMES, MODE_FREE, MODE_PINNED,
                            MODE_SLIDING, MODES_ALL, MODES_ALTERNATING)


class ModeStrategy(IntEnum):
    ALTERNATING = MODES_ALTERNATING
    ALL = MODES_ALL


class ContactMode(IntEnum):
    FREE = MODE_FREE
    PINNED = MODE_PINNED
    SLIDING = MODE_SLIDING


class StepOptions(NamedTuple):
    """Algorithm switches passed to the compiled step.

    mode_strategy : MODES_ALTERNATING (default) or MODES_ALL: how the modes carried over
        from the last step are re-examined before the complementarity solve (both end at a
        consistent answer; see kernels/step.py solve_modes)
    refine_iters : Newton-SHAKE position corrections after integrating (0: off)
    refine_tol : stop refining when every constraint residual is below this [m or rad]
    max_ccd_splits : cap on time-of-impact splits of one step (a point mass reaching the
        ground, fast shapes touching or turning about a touching point: kernels/geometry/ccd.py,
        kernels/geometry/pair_toi.py); the rest of a step beyond it is taken whole, but where a fast
        shape pair would touch in it, or turn too far about a touching point, it ends there
        (the rest of the step's time dropped; step_info 'ccd_stops'; ccd.stop_at_impact)
    guard_limit : any |q| or |v| component above this stops the run
    pivot_tol : relative pivot below which the guess solve treats a row as redundant (its
        answer is checked against every rule; one that breaks a rule goes to the
        complementarity solve, which uses no such threshold)
    refine_pivot_tol : pivot_tol of the position correction. Rows dependent to within it are
        dropped there: at a fold (a closed loop stretched nearly straight, rows dependent to
        about 1e-7) the residual grows with the square of the motion and Newton only halves
        the motion per iteration (residual / 4), where dropping the row converges at once
    dt : [s] length of the steps taken with these options; 0 (default): the model's dt. A
        sub-step (a touchdown located inside a step, say) is options._replace(dt=tau): the
        model stays as it is
    audit_raise : 1 turns a violation of the step's audit (a pulling contact, friction outside
        its cone, positive contact work, a pin open by more than 1e-9 m, a contact deeper than
        1e-8 m, a solve that fell back; kernels/checks/audit.py) into an error naming the step, time,
        contact or pin and body; 0 (default) only counts them in Workspace.audit
    gross_limit : [m] a pin open or a contact below the ground (or inside another shape) by
        more than this at the end of a step stops the run at once (SimulationDiverged naming
        the step, time, pin or contact, body and how far; what to change): the step could
        not hold it (stiff actuators or a violent impact at this step size), and the run
        after it would not be physics. 0: never stop (the audit still counts it)
    speed_limit : [m/s] a body moving, or turning (|omega| times its radius of gyration),
        faster than this at the end of a step stops the run (SimulationDiverged naming the
        body, its speed and the bound): -1 (default) takes the bound from the model and the
        start state (planarsim.speed_bound.speed_bound: 100 times the fastest speed its
        gravity, size, start velocities and actuators can explain); 0: no bound (the
        guard_limit of 1e10 only)
    energy_limit : a step whose audited energy from nowhere (joint_work, correction_work:
        what its joints or position correction added beyond their allowance) exceeds this
        share of the energy it had to work with (its kinetic energy plus its own error under
        the forces) stops the run (SimulationDiverged naming step, time, cause and body);
        smaller gains are counted in the audit. 0 (default, for now): never stop, count only
        (0.25 stops 96 of 100 stiff bang-bang motor runs at once, but also a walker started
        below uneven ground, whose first steps lift it out against its controller)
    turn_limit : [rad] a torque actuator whose command (saturated) would by itself turn what
        it drives by more than this in one step from rest, dt^2 |u| / (I + dt c) (I the
        joint's effective inertia with its own pin holding its two bodies, armature included;
        c its damping, implicit in the step: the other joints and contacts only slow the
        turn, so an upper bound of it) stops
        the run before that step (SimulationDiverged naming the actuator, its torque, the
        turn, and the dt or torque limit that would do). 0.2 (default): a step resolves
        turns of about 2 * 0.1 rad (the position correction's regime, kernels/checks/work.py); a
        bang-bang 100-1000 N m motor on a light link at dt 1e-2 turns it 0.3 to 100 rad.
        0: no check
    jump_limit : [m] a body whose centre of mass moves in a step farther than its
        velocities explain, h max(|v_start|, |v_end|) (a step split at a time of impact or
        taken in sub-steps: per part, its length times the largest speed in it, summed), plus jump_limit, plus
        the depth it or a body joined to it started the step below the ground or inside
        another shape, stops the run (SimulationDiverged naming the body, a contact
        touching it, the step and the distance): a longer move is the position
        correction's, in a step beyond what a step resolves (a body turning by about a
        radian in it, a shape driven through a hill and pushed out). Such a step is first
        taken again in twice as many sub-steps, up to max_substeps; the error stands if
        the last still jumps. 0.01 (default); 0: no check
    integrator : 0 'euler' (default): symplectic Euler with SHAKE, energy error O(h);
        1 'rattle': RATTLE, the velocity of the instant kept on the joints' tangent space,
        energy error O(h^2) (bounded, no drift), pins closed as by the default step, 1.26
        to 1.35 times its cost; 2 'rattle4': RATTLE composed in five stages (Suzuki),
        energy and trajectory errors O(h^4) at about four times the cost of 'rattle'; 3
        'rattle6': seven stages (Yoshida), O(h^6) at 7/5 the cost of 'rattle4'. The accurate
        ones take mechanisms of pins, sliders and rods under gravity, pushes and actuators
        only: a model with a contact, a joint limit, a joint spring, damper or armature or a
        fluid drag is refused (ModelError naming it; kernels/dynamics/rattle.py)
    max_substeps : cap on the equal sub-steps a default (Euler) step is taken in where a
        pin's anchor or a touching ground contact's point would leave the motion its rows
        linearise by more than 1 mm as its body turns, L (h w)^2 / 2 (L its lever [m], w
        the body's turn rate [rad/s], at the step's start or at its answer, which then is
        taken again: kernels/step.py turn_substeps; step_info 'turn_substeps'), and where
        a body moves farther than its velocities explain (jump_limit). Each
        sub-step is a whole step (solve, positions, audit, guards) and the State counts
        one; its last impulses are the last sub-step's (as a step split at a time of
        impact keeps its last part's). 16 (default); 1: never
    keep_factors : 1: a pile at rest (1,024 rows or more, the sparse factorisation) keeps
        its velocity solve's factors from step to step while its rows stay the same, and
        each step's answer is refined against its own matrix to rounding (kernels/solver/solve.py
        refine_on_kept_factors; a 1,035-box pyramid at rest about 1.3x faster). The answer then
        depends, at rounding, on the step the factors were made at, which the State does not
        hold: a restored State continues to rounding, not bit for bit. 0 (default): every
        solve factors afresh
    """
    mode_strategy: int = MODES_ALTERNATING
    refine_iters: int = 4
    refine_tol: float = 1e-12
    max_ccd_splits: int = 16
    guard_limit: float = 1e10
    pivot_tol: float = 1e-11
    refine_pivot_tol: float = 1e-7
    audit_raise: int = 0
    gross_limit: float = 1e-6
    dt: float = 0.0
    speed_limit: float = -1.0
    energy_limit: float = 0.0
    turn_limit: float = 0.2
    integrator: int = INTEGRATOR_EULER
    jump_limit: float = 0.01
    max_substeps: int = 16
    keep_factors: int = 0


def make_options(strategy="alternating", refine=True, integrator="euler", **kw) -> StepOptions:
    """StepOptions from friendly names: strategy 'alternating' | 'all'; refine on/off;
    integrator 'euler' | 'rattle' | 'rattle4' | 'rattle6' (StepOptions.integrator)."""
    names = {"alternating": MODES_ALTERNATING, "all": MODES_ALL}
    if isinstance(strategy, str):
        if strategy not in names:
            raise ValueError(f"contact-mode strategy {strategy!r} unknown; use 'alternating' or 'all'")
        strategy = names[strategy]
    if not refine:
        kw["refine_iters"] = 0
    if isinstance(integrator, str):
        if integrator not in INTEGRATOR_NAMES:
            raise ValueError(f"integrator {integrator!r} unknown; use one of {list(INTEGRATOR_NAMES)}")
        integrator = INTEGRATOR_NAMES.index(integrator)
    kw["integrator"] = integrator
    return check_options(StepOptions(mode_strategy=strategy, **kw))


_OPTION_RULES = {
    # field: (type, test, rule)
    "mode_strategy": (int, lambda x: x in (MODES_ALTERNATING, MODES_ALL), "must be 0 (alternating) or 1 (all)"),
    "refine_iters": (int, lambda x: x >= 0, "must be an integer >= 0"),
    "refine_tol": (float, lambda x: math.isfinite(x) and x >= 0.0, "must be finite and >= 0"),
    "max_ccd_splits": (int, lambda x: x >= 0, "must be an integer >= 0"),
    "guard_limit": (float, lambda x: math.isfinite(x) and x > 0.0, "must be finite and > 0"),
    "pivot_tol": (float, lambda x: math.isfinite(x) and 0.0 < x < 1.0, "must be within (0, 1)"),
    "refine_pivot_tol": (float, lambda x: math.isfinite(x) and 0.0 < x < 1.0, "must be within (0, 1)"),
    "audit_raise": (int, lambda x: x in (0, 1), "must be 0 or 1"),
    "gross_limit": (float, lambda x: math.isfinite(x) and x >= 0.0, "must be finite and >= 0"),
    "dt": (float, lambda x: math.isfinite(x) and 0.0 <= x <= 1.0, "must be 0 (the model's dt) or a step in (0, 1] s"),
    "energy_limit": (float, lambda x: math.isfinite(x) and x >= 0.0, "must be finite and >= 0"),
    "turn_limit": (float, lambda x: math.isfinite(x) and x >= 0.0, "must be finite and >= 0 [rad]"),
    "integrator": (int, lambda x: 0 <= x < len(INTEGRATOR_NAMES),
                   f"must be one of 0..{len(INTEGRATOR_NAMES) - 1} ({', '.join(INTEGRATOR_NAMES)})"),
    "jump_limit": (float, lambda x: math.isfinite(x) and x >= 0.0, "must be finite and >= 0 [m]"),
    "max_substeps": (int, lambda x: x >= 1, "must be an integer >= 1"),
    "keep_factors": (int, lambda x: x in (0, 1), "must be 0 or 1"),
    "speed_limit": (float, lambda x: x == -1.0 or (math.isfinite(x) and x >= 0.0),
                    "must be -1 (from the model), 0 (none) or a speed > 0 [m/s]"),
}


def check_options(opt) -> StepOptions:
    """`opt` as a StepOptions of exactly the field types the compiled step expects (int64 /
    float64), or a ValueError naming the field, its value and the rule."""
    if not isinstance(opt, StepOptions):
        raise TypeError(f"options must be a StepOptions (see make_options), got {type(opt).__name__}")
    out = {}
    for name, (kind, test, rule) in _OPTION_RULES.items():
        value = getattr(opt, name)
        said = f"StepOptions.{name}={plain(value)!r} {rule}"
        if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
            raise ValueError(said)
        # an int field: a whole number (NaN and inf are not: int() of them raises)
        if kind is int and not (math.isfinite(value) and float(value) == int(value)):
            raise ValueError(said)
        value = kind(value)
        if not test(value):
            raise ValueError(said)
        out[name] = value
    return StepOptions(**out)
