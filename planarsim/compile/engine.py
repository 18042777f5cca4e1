"""The step's argument types: those of a sample model's arrays, State, Workspace and StepOptions,
and the check that names a wrong argument when compiled code that calls the step is typed."""
from numba import types
from numba.core.errors import TypingError

from ..options import StepOptions


def samples():
    """(model arrays, State, Workspace, StepOptions) of a small model with every kind of array."""
    from ..builder import ModelBuilder
    from ..state import make_state, make_workspace
    b = ModelBuilder()
    body = b.add_body("b", 1.0, 1.0)
    b.add_pin("p", None, body, anchor_world=(0.0, 0.0))
    b.add_point_contact("c", body, (0.0, 0.0))
    b.add_pin_motor("m", "p")
    model = b.compile()
    return model.arrays, make_state(model), make_workspace(model), StepOptions()


def check_step_types(got, expected):
    """Raise numba's TypingError naming the first of step's arguments (m, s, ws, opt, u) whose
    numba type `got` is not what the step is compiled for (`expected`: the first four)."""
    for name, have, want in zip(("model", "state", "workspace", "options"), got[:4], expected):
        if have != want:
            raise TypingError(f"step: {name} is {have}; the step is compiled for {want} "
                              "(pass model.arrays, a State, a Workspace and StepOptions)")
    u = got[4]
    if not (isinstance(u, types.Array) and u.dtype == types.float64 and u.ndim == 1 and u.layout == "C"):
        raise TypingError(f"step: commands u must be a C-contiguous 1-d float64 array, got {u}")
