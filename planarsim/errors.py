"""Errors raised by planarsim.

``ModelError`` is raised while building a model; its message names the element kind, name,
index, field, value and the rule broken. ``SimulationDiverged`` is raised when a guard in the
compiled step fires (non-finite or huge state); it carries the last finite state.
``AuditViolation`` is raised, with StepOptions.audit_raise = 1, when a step breaks a rule of
its own audit (kernels/checks/audit.py); it names the step, time, rule, contact or pin and body.
``RecordingTooLarge`` is raised before a recording is allocated that would not fit in the
machine's memory (a duration far too long for its frame interval); it names the frames and
the memory they would need. ``WorkspaceTooLarge`` is raised before a model's step workspace is
allocated that would not fit (its solve matrices are sized by every pair of shapes that may
touch); it names the sizes and what to change.
"""
import math

import numpy as np

from .capacity import workspace_capacity
from .kernels.checks.audit import (AUDIT_CORRECTION_WORK, AUDIT_FALLBACK, AUDIT_JOINT_FRICTION,
                                   AUDIT_JOINT_WORK, AUDIT_LIMIT_GAP, AUDIT_LIMIT_WORK,
                                   AUDIT_NAMES, AUDIT_PIN_GAP, AUDIT_UNSOLVED)
from .kernels.info import INFO_COMMAND, INFO_GUARD_BODY, INFO_GUARD_FIELD
from .kernels.codes import INTEGRATOR_NAMES
from .kernels.dynamics.forces import ACT_PIN_TORQUE
from .kernels.dynamics.rattle import (UNSUPPORTED_CONTACT, UNSUPPORTED_FLUID, UNSUPPORTED_LIMIT,
                                      UNSUPPORTED_FRICTION, UNSUPPORTED_SOFT)
from .kernels.checks.guards import (FIELD_SPEED, GUARD_AUDIT, GUARD_BAD_COMMANDS, GUARD_BAD_MODE,
                                    GUARD_ENERGY, GUARD_GROSS, GUARD_JUMP, GUARD_NONFINITE_COMMAND,
                                    GUARD_ROOM, GUARD_SPEED, GUARD_STIFF_ACTUATOR,
                                    GUARD_UNSUPPORTED)


def plain(value):
    """`value` as messages print it: numpy numbers and arrays as plain floats and lists
    (0.0, not np.float64(0.0)); tuples and lists element by element."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, (tuple, list)):
        return type(value)(plain(v) for v in value)
    return value


class ModelError(ValueError):
    """A malformed model: the message names the culprit and the rule."""


class RecordingTooLarge(ValueError):
    """A recording that cannot fit in this machine's memory, refused before it is allocated.

    Attributes
    ----------
    frames : int      frames the recording would hold
    nbytes : int      memory they would need [bytes]
    available : int   the machine's physical memory [bytes]
    """

    def __init__(self, message, frames=0, nbytes=0, available=0):
        super().__init__(message)
        self.frames = int(frames)
        self.nbytes = int(nbytes)
        self.available = int(available)

    def __reduce__(self):
        # picklable, so that a tuning worker's refusal reaches the command line intact
        return (type(self), (str(self), self.frames, self.nbytes, self.available))


class WorkspaceTooLarge(MemoryError):
    """A model whose step's workspace cannot fit in this machine's memory, refused before it
    is allocated (state.check_workspace); it names what sizes it.

    Attributes
    ----------
    nbytes : int      memory the workspace's dense solve matrices would need [bytes]
    available : int   the machine's physical memory [bytes]
    """

    def __init__(self, message, nbytes=0, available=0):
        super().__init__(message)
        self.nbytes = int(nbytes)
        self.available = int(available)

    def __reduce__(self):
        return (type(self), (str(self), self.nbytes, self.available))


class SimulationDiverged(RuntimeError):
    """The simulation state became non-finite or exceeded the magnitude bound.

    Attributes
    ----------
    step : int       step index at which the guard fired
    time : float     simulated time at the start of that step [s]
    body : str       name of the offending body
    field : str      'q' or 'v' component name
    value : float    the offending value
    last_state       the State at the start of the failed step (bit for bit)
    """

    def __init__(self, message, step, time, body, field, value, last_state):
        super().__init__(message)
        self.step = step
        self.time = time
        self.body = body
        self.field = field
        self.value = value
        self.last_state = last_state

    def __reduce__(self):
        # picklable, so that an error raised in a worker process reaches the caller intact
        return (type(self), (str(self), self.step, self.time, self.body, self.field, self.value,
                             self.last_state))


FIELD_NAMES = ("x", "y", "theta", "vx", "vy", "omega")


class AuditViolation(SimulationDiverged):
    """A step broke a rule of its own audit (StepOptions.audit_raise = 1).

    Attributes as SimulationDiverged, plus rule : str (pull, cone, work, pin_gap, depth,
    fallback, unsolved) and element : str (the contact or pin named)."""

    def __init__(self, message, step, time, body, field, value, last_state, rule="", element=""):
        super().__init__(message, step, time, body, field, value, last_state)
        self.rule = rule
        self.element = element

    def __reduce__(self):
        return (type(self), (str(self), self.step, self.time, self.body, self.field, self.value,
                             self.last_state, self.rule, self.element))


_AUDIT_TEXT = {
    "pull": "a contact impulse pulls (lambda_n = {v:.3g} N s)",
    "cone": "friction outside its cone by {v:.3g} N s",
    "work": "a contact impulse does positive work ({v:.3g} J)",
    "pin_gap": "a pin is open by {v:.3g} m",
    "depth": "a contact is {v:.3g} m below the ground",
    "fallback": "the contact solve with friction found no answer: solved without friction",
    "unsolved": "the contact solve found no consistent answer",
    "joint_work": "joint impulses added {v:.3g} J beyond their second-order share, even as "
                  "a projection (J v = 0)",
    "limit_work": "a joint limit's impulse does positive work ({v:.3g} J)",
    "correction_work": "the position correction added {v:.3g} J beyond its allowance",
    "joint_friction": "a joint's dry friction outside its bound or pushing the motion "
                      "({v:.3g} N s beyond its bound, or J of positive work)",
    "limit_gap": "a joint is {v:.3g} rad (or m, a slider) outside its limit",
}


def audit_violation(model, ws, who="simulation"):
    """The AuditViolation of the step that just broke a rule of its audit (ws.audit_last)."""
    step, kind, element, body = (int(x) for x in ws.audit_last)
    rule = AUDIT_NAMES[kind]
    value = float(ws.audit_value[0])
    element_name = _element_name(model, kind, element)
    body_name = _body_name(model, body)
    t = float(ws.prev.time[0])
    last = _start_of_step(ws)
    return AuditViolation(f"{who}: audit at step {step} (t={t:.6g} s): "
                          f"{_AUDIT_TEXT[rule].format(v=value)}; {element_name} on body "
                          f"{body_name!r} ({body}); all counts {dict(zip(AUDIT_NAMES, ws.audit.tolist()))}",
                          step, t, body_name, rule, value, last, rule, element_name)


def _start_of_step(ws):
    """A copy of the state at the start of the step that failed (ws.prev)."""
    return type(ws.prev)(*(a.copy() for a in ws.prev))


def _body_name(model, body) -> str:
    """A body's name, or '-' for the world (-1)."""
    return model.body_names[body] if 0 <= body < len(model.body_names) else "-"


def _element_name(model, kind, element):
    """'pin NAME (j)', 'rod NAME (j)', 'contact NAME (i)' or what else an audit record of rule
    `kind` names."""
    if kind in (AUDIT_PIN_GAP, AUDIT_JOINT_WORK, AUDIT_LIMIT_WORK,
                AUDIT_JOINT_FRICTION, AUDIT_LIMIT_GAP) and element < len(model.pin_names):
        return f"pin {model.pin_names[element]!r} ({element})"
    if kind in (AUDIT_PIN_GAP, AUDIT_JOINT_WORK):
        rod = element - len(model.pin_names)
        return f"rod {model.rod_names[rod]!r} ({rod})"
    if kind == AUDIT_CORRECTION_WORK:
        return "the position correction"
    if kind in (AUDIT_FALLBACK, AUDIT_UNSOLVED) or element < 0:
        return "contacts"
    return f"contact {model.contact_names[element]!r} ({element})"


def gross_violation(model, ws, who="simulation"):
    """The SimulationDiverged of a step that ended with a pin open, a joint outside its limit,
    or a contact below the ground or inside another shape, by more than
    StepOptions.gross_limit (ws.audit_worst)."""
    step, kind, element, body = (int(x) for x in ws.audit_worst)
    value = float(ws.audit_worst_value[0])
    t = float(ws.prev.time[0])
    body_name = _body_name(model, body)
    what = ("is open by" if kind == AUDIT_PIN_GAP
            else "is outside its limit by" if kind == AUDIT_LIMIT_GAP
            else "is below the ground (or inside another shape) by")
    unit = "rad (m for a slider)" if kind == AUDIT_LIMIT_GAP else "m"
    last = _start_of_step(ws)
    if model.n_act:
        why = "actuators too stiff, or an impact too violent, for this step size"
        fix = "Take a smaller dt, lower the actuators' limits, or raise"
    else:
        why = "a motion too fast for this step size: a body turning far in one step, or an " \
              "impact too violent"
        fix = "Take a smaller dt, or raise"
    return SimulationDiverged(
        f"{who} stopped at step {step} (t={t:.6g} s): {_element_name(model, kind, element)} on "
        f"body {body_name!r} ({body}) {what} {value:.3g} {unit} at the end of the step; the step "
        f"could not hold it ({why}). {fix} "
        f"StepOptions.gross_limit (0: count it in the audit and go on)",
        step, t, body_name, AUDIT_NAMES[kind], value, last)


def energy_from_nowhere(model, ws, who="simulation"):
    """The SimulationDiverged of a step that gained energy from nowhere beyond
    StepOptions.energy_limit (kernels/checks/work.judge_energy; the cause in ws.audit_last)."""
    step, kind, element, body = (int(x) for x in ws.audit_last)
    rule = AUDIT_NAMES[kind]
    value = float(ws.audit_value[0])
    t = float(ws.prev.time[0])
    name = _body_name(model, body)
    last = _start_of_step(ws)
    return SimulationDiverged(
        f"{who} stopped at step {step} (t={t:.6g} s): {_AUDIT_TEXT[rule].format(v=value)} "
        f"({rule}; {_element_name(model, kind, element)}; body {name!r} ({body})), more than "
        f"StepOptions.energy_limit of the energy the step had: the step is too large for "
        f"these actuators, impacts or inertias. Take a smaller dt (or raise energy_limit; "
        f"0 counts it in the audit and goes on)", step, t, name, rule, value, last)


def too_fast(model, ws, who="simulation"):
    """The SimulationDiverged of a step that ended with a body faster than
    StepOptions.speed_limit (guards.check_speeds)."""
    body = int(ws.info[INFO_GUARD_BODY])
    speed, bound = float(ws.guard_value[0]), float(ws.guard_value[1])
    turning = int(ws.info[INFO_GUARD_FIELD]) != FIELD_SPEED
    field = "turning speed" if turning else "speed"
    step = int(ws.prev.step[0])
    t = float(ws.prev.time[0])
    name = _body_name(model, body)
    last = _start_of_step(ws)
    how = (" (|omega| times its radius of gyration)" if turning else "")
    return SimulationDiverged(
        f"{who} stopped at step {step} (t={t:.6g} s): body {name!r} ({body}) reached a {field} "
        f"of {speed:.4g} m/s{how}, beyond the bound of {bound:.4g} m/s set from the model (100 "
        f"times the fastest speed its gravity, size, start, actuators and springs explain): the run "
        f"has left physics (a step too large for its actuators or impacts). Take a smaller dt, "
        f"or if such speeds are real, set StepOptions.speed_limit higher (0: no bound)",
        step, t, name, field, speed, last)


def jumped(model, ws, who="simulation"):
    """The SimulationDiverged of a step that moved a body farther than its velocities explain
    (guards.check_displacements, StepOptions.jump_limit)."""
    body = int(ws.info[INFO_GUARD_BODY])
    contact = int(ws.info[INFO_GUARD_FIELD])
    moved, explained, allowed = (float(x) for x in ws.guard_value[:3])
    step = int(ws.prev.step[0])
    t = float(ws.prev.time[0])
    name = _body_name(model, body)
    touching = (f"contact {model.contact_names[contact]!r} ({contact}) touching it"
                if contact >= 0 else "no contact touching it (its joints' correction moved it)")
    return SimulationDiverged(
        f"{who} stopped at step {step} (t={t:.6g} s): body {name!r} ({body}) moved {moved:.4g} m "
        f"in one step, farther than its velocities explain (h max(|v_start|, |v_end|), per "
        f"part of a step split at an impact: {explained:.4g} m; {allowed:.3g} m allowed beyond "
        f"it: StepOptions.jump_limit and the depth it or a body joined to it started the step "
        f"below the ground or inside a shape), with {touching}: the step's position "
        f"correction moved it (a body turning by about a radian in one step, a contact normal "
        f"or a rod turned within it, or a body driven into the ground within the step and "
        f"pushed out). Take a smaller dt (or raise StepOptions.jump_limit; 0: no check)",
        step, t, name, "displacement", moved, _start_of_step(ws))


def stiff_actuator(model, ws, who="simulation"):
    """The SimulationDiverged of a step not taken because a torque actuator's command would
    turn what it drives further in one step than the step resolves (guards.check_actuator_turns,
    StepOptions.turn_limit)."""
    k = int(ws.info[INFO_COMMAND])
    turn, kappa, limit = (float(x) for x in ws.guard_value[:3])
    torque = float(ws.act_u[k])
    step = int(ws.prev.step[0])
    t = float(ws.prev.time[0])
    u = abs(torque)
    h = math.sqrt(turn / (u * kappa))          # turn = h^2 |u| kappa (kappa of this step)
    # kappa = 1 / (1 / kappa_a + h c): the joint's damper c, implicit, holds the turn back
    c = 0.0
    if int(model.arrays.act_kind[k]) == ACT_PIN_TORQUE:
        c = float(model.arrays.pin_damping[int(model.arrays.act_ref[k])])
    inertia = 1.0 / kappa - h * c              # [kg m^2] what it drives, its rotor included
    held = f", {c:.3g} N m s/rad of damping" if c > 0.0 else ""
    # the largest step that resolves it: h^2 u / (inertia + h c) = limit
    most = (limit * c + math.sqrt((limit * c) ** 2 + 4.0 * u * limit * inertia)) / (2.0 * u)
    name = model.act_names[k]
    return SimulationDiverged(
        f"{who} stopped before step {step} (t={t:.6g} s): actuator {name!r} commands "
        f"{torque:.4g} N m, which alone would turn what it drives (inertia {inertia:.3g} "
        f"kg m^2{held}) by {turn:.3g} rad in one step of {h:.3g} s, more than the {limit:g} rad "
        f"a step resolves (StepOptions.turn_limit): the motor acts faster than the step. Take "
        f"dt <= {most:.3g} s, or limit its torque to {limit / (h * h * kappa):.3g} N m (or give "
        f"the joint an armature or damping; turn_limit 0: no check)", step, t, name, "torque",
        torque, _start_of_step(ws))


# what the accurate integrators cannot step, by kernels/dynamics/rattle.py's UNSUPPORTED_* code
_UNSUPPORTED = {UNSUPPORTED_CONTACT: "contact", UNSUPPORTED_LIMIT: "joint limit",
                UNSUPPORTED_SOFT: "joint spring, damper or armature",
                UNSUPPORTED_FRICTION: "joint friction (frictionloss)",
                UNSUPPORTED_FLUID: "fluid drag"}


def accurate_unsupported(model, what, index, integrator=None, who="simulation"):
    """The ModelError of a model that an accurate StepOptions.integrator (kernels/dynamics/rattle.py;
    `integrator` its code, None: not known here) cannot step: `what` an UNSUPPORTED_* code,
    `index` the element."""
    if what == UNSUPPORTED_CONTACT:
        element = f"contact {model.contact_names[index]!r} ({index})"
    elif what == UNSUPPORTED_FLUID:
        element = f"the fluid drag on body {_body_name(model, int(model.arrays.fluid_body[index]))!r}"
    else:
        element = f"joint {model.pin_names[index]!r} ({index})"
    which = ("an accurate StepOptions.integrator" if integrator is None else
             f"StepOptions.integrator={integrator} ({INTEGRATOR_NAMES[integrator]!r})")
    return ModelError(
        f"{who}: {which} steps mechanisms of pins, "
        f"sliders and rods under gravity, pushes and actuators only; the model has a "
        f"{_UNSUPPORTED[what]}: {element}. Use the default integrator (0, 'euler') for it; "
        f"nothing was stepped")


def out_of_room(model, ws, who):
    """Step stopped by GUARD_ROOM where nothing grows the workspace: its rows, their matrix's
    envelope or an island's complementarity problem did not fit."""
    step = int(ws.prev.step[0])
    t = float(ws.prev.time[0])
    held, profile, lcp_rows = workspace_capacity(model, ws)
    if ws.room[2] > profile:
        what = (f"needs {int(ws.room[2]):,} entries of its rows' matrix, more than its "
                f"workspace's solve holds ({profile:,})")
        keyword = "profile"
    elif ws.room[3] > lcp_rows:
        what = (f"needs a complementarity problem of {int(ws.room[3]):,} rows, more than its "
                f"workspace's solve holds ({lcp_rows:,})")
        keyword = "lcp_rows"
    else:
        what = (f"touches with more contacts than its workspace's solve holds ({held:,} of the "
                f"model's {model.n_contact:,} contact slots)")
        keyword = "contacts"
    return SimulationDiverged(
        f"{who}: step {step} (t={t:.6g} s) {what}; the state is left at that step's start. "
        f"Simulator.step / steps / run grow the workspace and go on; a workspace of your own: "
        f"make_workspace(model, {keyword}=...) with more",
        step, t, "", "", float(held), _start_of_step(ws))


def diverged(model, ws, code, guard_limit, who="simulation"):
    """The SimulationDiverged for guard `code` (1 non-finite, 2 too large) of the step that
    just failed on workspace ws: step, time, body, field and value from the guard's record,
    and a copy of the state at the start of that step. Code GUARD_BAD_COMMANDS (-1: commands
    of the wrong length) and GUARD_NONFINITE_COMMAND (-2: a NaN or infinite command), where
    nothing was stepped, give a ValueError instead."""
    if code == GUARD_AUDIT:
        return audit_violation(model, ws, who)
    if code == GUARD_GROSS:
        return gross_violation(model, ws, who)
    if code == GUARD_BAD_COMMANDS:
        return ValueError(f"{who}: the commands u have {int(ws.info[INFO_COMMAND])} entries; the model has "
                          f"{len(model.act_names)} actuators {list(model.act_names)}")
    if code == GUARD_NONFINITE_COMMAND:
        k = int(ws.info[INFO_COMMAND])
        return ValueError(f"{who}: command u[{k}] for actuator {model.act_names[k]!r} is "
                          f"{float(ws.guard_value[0])}; commands must be finite (N or N m); "
                          f"nothing was stepped")
    if code == GUARD_BAD_MODE:
        i = int(ws.info[INFO_GUARD_BODY])
        name = (f" (contact {model.contact_names[i]!r})" if i < len(model.contact_names)
                else "")
        return ValueError(f"{who}: state.contact_mode[{i}] = {int(ws.guard_value[0])}{name} "
                          "must be 0 (free), 1 (pinned) or 2 (sliding): the State was changed "
                          "in place; nothing was stepped")
    if code == GUARD_SPEED:
        return too_fast(model, ws, who)
    if code == GUARD_ENERGY:
        return energy_from_nowhere(model, ws, who)
    if code == GUARD_JUMP:
        return jumped(model, ws, who)
    if code == GUARD_STIFF_ACTUATOR:
        return stiff_actuator(model, ws, who)
    if code == GUARD_ROOM:
        return out_of_room(model, ws, who)
    if code == GUARD_UNSUPPORTED:
        return accurate_unsupported(model, int(ws.info[INFO_GUARD_FIELD]),
                                    int(ws.info[INFO_GUARD_BODY]), None, who)
    body = int(ws.info[INFO_GUARD_BODY])
    field = FIELD_NAMES[int(ws.info[INFO_GUARD_FIELD])]
    value = float(ws.guard_value[0])
    step = int(ws.prev.step[0])
    t = float(ws.prev.time[0])
    name = model.body_names[body]
    what = "is not finite" if code == 1 else f"exceeds {guard_limit:g} in magnitude"
    last = _start_of_step(ws)
    return SimulationDiverged(f"{who} diverged at step {step} (t={t:.6g} s): body {name!r} ({body}) "
                              f"{field}={value} {what}", step, t, name, field, value, last)
