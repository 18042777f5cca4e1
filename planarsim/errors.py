"""Errors raised by planarsim.

``ModelError`` is raised while building a model; its message names the element kind, name,
index, field, value and the rule broken. ``SimulationDiverged`` is raised when a guard in the
compiled step fires (non-finite or huge state); it carries the last finite state.
"""


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
