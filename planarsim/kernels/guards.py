"""Stage 9: guards. Every q and v component must be finite and below the magnitude bound."""
import math

from ..compile import kernel
from .info import INFO_COMMAND, INFO_GUARD_BODY, INFO_GUARD_FIELD

GUARD_OK = 0
GUARD_NONFINITE = 1
GUARD_TOO_LARGE = 2
GUARD_AUDIT = 3           # the step broke a rule of its own audit (StepOptions.audit_raise = 1)
GUARD_GROSS = 4           # a pin open or a contact deep beyond StepOptions.gross_limit at the end
                          # of the step (ws.audit_worst: which, ws.audit_worst_value: how far)
GUARD_ENERGY = 6          # the step gained energy from nowhere beyond StepOptions.energy_limit
                          # (work.judge_energy; ws.audit_last: cause, element, body; audit_value)
GUARD_SPEED = 5           # a body faster than StepOptions.speed_limit (check_speeds)
FIELD_SPEED = 6           # ws.info[INFO_GUARD_FIELD] of a body's speed |v| [m/s]
FIELD_TURNING = 7         # ... of its turning speed |omega| r_g [m/s] (r_g its radius of gyration)
GUARD_BAD_COMMANDS = -1   # the commands array does not have one entry per actuator (ws.info[INFO_COMMAND]:
                          # its length); negative, so that no walker's own return code clashes
GUARD_NONFINITE_COMMAND = -2   # a command is NaN or infinite (ws.info[INFO_COMMAND]: its index,
                               # ws.guard_value: the value); nothing is stepped


@kernel
def check_guards(s, ws, limit):
    """Return GUARD_*; on failure ws.info[INFO_GUARD_BODY] = body,
    ws.info[INFO_GUARD_FIELD] = field 0..5 (x y th vx vy w)."""
    for i in range(s.q.shape[0]):
        for f in range(6):
            x = s.q[i, f] if f < 3 else s.v[i, f - 3]
            bad = GUARD_OK
            if not math.isfinite(x):
                bad = GUARD_NONFINITE
            elif abs(x) > limit:
                bad = GUARD_TOO_LARGE
            if bad != GUARD_OK:
                ws.info[INFO_GUARD_BODY] = i
                ws.info[INFO_GUARD_FIELD] = f
                ws.guard_value[0] = x
                return bad
    return GUARD_OK


@kernel
def check_commands(u, ws):
    """GUARD_NONFINITE_COMMAND if some command u[k] is NaN or infinite (recorded in
    ws.info[INFO_COMMAND] and ws.guard_value), else GUARD_OK."""
    for k in range(u.shape[0]):
        if not math.isfinite(u[k]):
            ws.info[INFO_COMMAND] = k
            ws.guard_value[0] = u[k]
            return GUARD_NONFINITE_COMMAND
    return GUARD_OK


@kernel
def check_speeds(m, s, ws, bound):
    """GUARD_SPEED if some body's speed |v| or turning speed |omega| r_g (r_g = sqrt(I / m),
    its radius of gyration: the speed whose kinetic energy equals the body's turning energy)
    exceeds bound [m/s] (recorded: body, FIELD_SPEED or FIELD_TURNING, the speed and the
    bound in ws.guard_value), else GUARD_OK. One bound for both: a body's kinetic energy is at
    most m bound^2."""
    for i in range(s.v.shape[0]):
        speed = math.sqrt(s.v[i, 0] * s.v[i, 0] + s.v[i, 1] * s.v[i, 1])
        turning = abs(s.v[i, 2]) * math.sqrt(m.body_inertia[i] * m.body_inv_mass[i])
        if speed > bound or turning > bound:
            ws.info[INFO_GUARD_BODY] = i
            ws.info[INFO_GUARD_FIELD] = FIELD_SPEED if speed > bound else FIELD_TURNING
            ws.guard_value[0] = speed if speed > bound else turning
            ws.guard_value[1] = bound
            return GUARD_SPEED
    return GUARD_OK
