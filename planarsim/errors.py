"""Errors raised by planarsim.

``ModelError`` is raised while building a model; its message names the element kind, name,
index, field, value and the rule broken. ``SimulationDiverged`` is raised when a guard in the
compiled step fires (non-finite or huge state); it carries the last finite state.
"""
from .kernels.guards import GUARD_BAD_COMMANDS


class ModelError(ValueError):
    """A malformed model: the message names the culprit and the rule."""


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


def diverged(model, ws, code, guard_limit, who="simulation"):
    """The SimulationDiverged for guard `code` (1 non-finite, 2 too large) of the step that
    just failed on workspace ws: step, time, body, field and value from the guard's record,
    and a copy of the state at the start of that step. Code GUARD_BAD_COMMANDS (-1: commands
    of the wrong length, nothing stepped) gives a ValueError instead."""
    if code == GUARD_BAD_COMMANDS:
        return ValueError(f"{who}: the commands u have {int(ws.info[2])} entries; the model has "
                          f"{len(model.act_names)} actuators {list(model.act_names)}")
    body = int(ws.info[2])
    field = FIELD_NAMES[int(ws.info[3])]
    value = float(ws.guard_value[0])
    step = int(ws.prev.step[0])
    t = float(ws.prev.time[0])
    name = model.body_names[body]
    what = "is not finite" if code == 1 else f"exceeds {guard_limit:g} in magnitude"
    last = type(ws.prev)(*(a.copy() for a in ws.prev))
    return SimulationDiverged(f"{who} diverged at step {step} (t={t:.6g} s): body {name!r} ({body}) "
                              f"{field}={value} {what}", step, t, name, field, value, last)
