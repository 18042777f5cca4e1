"""The step's argument types: the model's arrays, State, Workspace and StepOptions registered
with the compiler layer (one pointer each in compiled code: compile/refs.py), those of a
sample model, and the check that names a wrong argument when compiled code that calls the
step is typed."""
import numba
from numba import types
from numba.core.errors import TypingError

from ..builder import ModelBuilder
from ..compile import TABLES, register
from ..model import ModelArrays
from ..options import StepOptions
from ..state import State, Workspace, make_state, make_workspace

if TABLES:     # (compile/refs.py uses numba's extension API, which TABLES says is there)
    from ..compile.refs import TableRef, layout_of

register(ModelArrays, readonly=True)
for _cls in (State, Workspace, StepOptions):
    register(_cls)


def samples():
    """(model arrays, State, Workspace, StepOptions) of a small model with every kind of array."""
    b = ModelBuilder()
    body = b.add_body("b", 1.0, 1.0)
    b.add_pin("p", None, body, anchor_world=(0.0, 0.0))
    b.add_point_contact("c", body, (0.0, 0.0))
    b.add_pin_motor("m", "p")
    model = b.compile()
    return model.arrays, make_state(model), make_workspace(model), StepOptions()


_TYPES = []


def engine_types():
    """(model, state, workspace, options) numba types the step is compiled for: those of
    samples() (a TableRef each where TABLES, else numba's types of the NamedTuples)."""
    if not _TYPES:
        if TABLES:
            found = tuple(TableRef(layout_of(x)) for x in samples())
        else:
            found = tuple(numba.typeof(x) for x in samples())
        _TYPES.append(found)
    return _TYPES[0]


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
