"""NamedTuples as one pointer in compiled code (planarsim/compile/refs.py)."""
from typing import NamedTuple

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from numba import njit
from numba.core.errors import TypingError

import planarsim as ps
from planarsim.compile import TABLES
from strategies import reals, vectors

if not TABLES:
    pytest.skip("NamedTuples reach compiled code as they are in this mode", allow_module_level=True)

from planarsim.compile import refs  # noqa: E402
from planarsim.link.step import step_entry  # noqa: E402


@refs.register
class Inner(NamedTuple):
    a: np.ndarray
    k: np.ndarray


@refs.register
class Outer(NamedTuple):
    scale: float
    count: int
    grid: np.ndarray
    inner: Inner


@refs.register(readonly=True)
class Frozen(NamedTuple):
    x: np.ndarray


@njit(_nrt=False)
def _total(o):
    """scale * (sum of grid + sum of inner.a) + count + sum of inner.k; bumps inner.k[0]."""
    t = 0.0
    for i in range(o.grid.shape[0]):
        for j in range(o.grid.shape[1]):
            for k in range(o.grid.shape[2]):
                t += o.grid[i, j, k]
    for i in range(o.inner.a.shape[0]):
        t += o.inner.a[i]
    t = o.scale * t + o.count
    for i in range(o.inner.k.shape[0]):
        t += o.inner.k[i]
    if o.inner.k.shape[0] > 0:
        o.inner.k[0] += 1
    return t


@njit(_nrt=False)
def _first(f):
    return f.x[0]


def _outer(grid_shape, n_a, n_k, seed=0):
    rng = np.random.default_rng(seed)
    return Outer(scale=rng.uniform(-2, 2), count=int(rng.integers(-5, 5)),
                 grid=rng.normal(size=grid_shape), inner=Inner(rng.normal(size=n_a),
                                                               rng.integers(-9, 9, size=n_k)))


def _expected(o):
    return o.scale * (o.grid.sum() + o.inner.a.sum()) + o.count + o.inner.k.sum()


@st.composite
def outers(draw):
    """An Outer of drawn fields: a scale in [-2, 2], a count in [-5, 4], a grid of 0 to 4 x 0 to
    4 x 0 to 4 floats, inner.a of 0 to 6 floats (in [-3, 3]), inner.k of 0 to 3 ints in [-9, 8]."""
    grid_shape = draw(st.tuples(st.integers(0, 4), st.integers(0, 4), st.integers(0, 4)))
    a = draw(vectors(draw(st.integers(0, 6)), -3.0, 3.0))
    k = draw(arrays(np.int64, draw(st.integers(0, 3)), elements=st.integers(-9, 8), fill=st.nothing()))
    return Outer(scale=draw(reals(-2.0, 2.0)), count=draw(st.integers(-5, 4)),
                 grid=draw(arrays(np.float64, grid_shape, elements=reals(-3.0, 3.0), fill=st.nothing())),
                 inner=Inner(a, k))


@settings(max_examples=40, deadline=None)
@given(outers())
def test_fields_read_and_write_the_numpy_arrays(o):
    n_k = len(o.inner.k)
    want = _expected(o)
    k0 = o.inner.k.copy()
    assert _total(o) == pytest.approx(want, rel=1e-12, abs=1e-12)
    if n_k:
        assert o.inner.k[0] == k0[0] + 1     # written through to the numpy array
    # a handle (packed once) reads the same memory
    h = refs.TableHandle(o)
    want = _expected(o)
    assert _total(h) == pytest.approx(want, rel=1e-12, abs=1e-12)


def test_a_new_namedtuple_gets_its_own_table():
    o = _outer((2, 2, 2), 3, 1)
    first = _total(o)
    other = o._replace(grid=o.grid * 0.0, inner=Inner(o.inner.a * 0.0, np.zeros(1, np.int64)))
    assert _total(other) == pytest.approx(other.count)
    assert _total(o) == pytest.approx(first + 1)    # k[0] was bumped by the first call


def test_float_fields_take_ints_and_int_fields_refuse_floats():
    o = _outer((1, 1, 1), 1, 1)._replace(scale=2)       # an int where a float is declared
    want = _expected(o)
    assert _total(o) == pytest.approx(want)
    with pytest.raises(TypeError, match="Outer.count must be an int"):
        _total(o._replace(count=1.5))


@pytest.mark.parametrize("bad, message", [
    (lambda o: o._replace(grid=np.zeros((2, 3, 4))[:, ::2]), "Outer.grid must be a C-contiguous"),
    (lambda o: o._replace(inner=Inner(np.zeros(3, np.float32), o.inner.k)), "Inner.a is a 1-d float32"),
    (lambda o: o._replace(inner=Inner(np.zeros((1, 1, 1, 1)), o.inner.k)), "Inner.a is a 4-d float64"),
    (lambda o: o._replace(scale="fast"), "Outer.scale"),
])
def test_malformed_fields_are_named(bad, message):
    o = _outer((2, 3, 2), 3, 2)
    _total(o)
    with pytest.raises(TypeError, match=message):
        _total(bad(o))


def test_read_only_arrays_are_refused_where_compiled_code_writes():
    o = _outer((1, 1, 1), 2, 1)
    o.inner.k.setflags(write=False)
    with pytest.raises(TypeError, match="Inner.k is read-only"):
        _total(o)
    x = np.arange(3.0)
    x.setflags(write=False)
    assert _first(Frozen(x)) == 0.0      # a read-only class takes them


def test_the_step_names_what_it_was_given():
    from tests.planarsim.test_reliability import two_link_on_hills
    sim = ps.Simulator(two_link_on_hills())
    m, s, ws = sim.model.arrays, sim.state, sim.ws
    with pytest.raises(TypingError, match="step: commands u must be a C-contiguous 1-d float64"):
        step_entry(m, s, ws, sim.options, np.zeros((2, 2)))
    with pytest.raises(TypingError, match="step: workspace is"):
        step_entry(m, s, s, sim.options, np.zeros(0))
    assert step_entry(m, s, ws, sim.options, np.zeros(sim.model.n_act)) == 0


def test_commands_of_the_wrong_length_step_nothing_and_are_explained():
    from planarsim.errors import diverged
    from tests.planarsim.test_reliability import two_link_on_hills
    sim = ps.Simulator(two_link_on_hills())
    m, s, ws = sim.model.arrays, sim.state, sim.ws
    before = s.copy()
    for n in (0, sim.model.n_act + 1):
        code = step_entry(m, s, ws, sim.options, np.zeros(n))
        assert code == -1
        assert all(np.array_equal(a, b) for a, b in zip(s, before))
        err = diverged(sim.model, ws, code, sim.options.guard_limit)
        assert isinstance(err, ValueError) and f"have {n} entries" in str(err)


def test_step_from_python_steps_as_the_simulator_does():
    """planarsim.compiled.step_from_python on a model's own State and Workspace gives the
    Simulator's step bit for bit, and refuses commands of the wrong length with its code."""
    from planarsim.compiled import RUN_BAD_COMMANDS, step_from_python
    from planarsim.state import make_workspace
    from tests.conftest import make_chain
    model = make_chain(3)
    sim = ps.Simulator(model)
    s, ws, opt = ps.make_state(model), make_workspace(model), ps.StepOptions()
    u = np.zeros(model.n_act)
    for _ in range(200):
        sim.step()
        assert step_from_python(model.arrays, s, ws, opt, u) == 0
    assert np.array_equal(s.q, sim.state.q) and np.array_equal(s.v, sim.state.v)
    assert step_from_python(model.arrays, s, ws, opt, np.zeros(model.n_act + 1)) == RUN_BAD_COMMANDS


def test_step_from_python_follows_new_options_on_the_same_state():
    """A new StepOptions each call (a sub-step of another length) takes effect at once."""
    from planarsim.compiled import step_from_python
    from planarsim.state import make_workspace
    from tests.conftest import make_chain
    model = make_chain(2)
    sim = ps.Simulator(model, ps.StepOptions(dt=2.5e-4))
    s, ws = ps.make_state(model), make_workspace(model)
    u = np.zeros(model.n_act)
    for k in range(100):
        assert step_from_python(model.arrays, s, ws, ps.StepOptions(dt=1e-3), u) == 0
        s.time[0] -= 1e-3
        s.q[:], s.v[:] = ws.prev.q, ws.prev.v       # undo it: the next call's options count
        assert step_from_python(model.arrays, s, ws, ps.StepOptions(dt=2.5e-4), u) == 0
        sim.step()
    assert np.array_equal(s.q, sim.state.q) and np.array_equal(s.v, sim.state.v)


def test_step_from_python_names_bad_options_and_commands():
    from planarsim.compiled import step_from_python
    from planarsim.state import make_workspace
    from tests.conftest import make_chain
    model = make_chain(2)
    s, ws = ps.make_state(model), make_workspace(model)
    u = np.zeros(model.n_act)
    with pytest.raises(ValueError, match="dt"):
        step_from_python(model.arrays, s, ws, ps.StepOptions(dt=float("nan")), u)
    assert step_from_python(model.arrays, s, ws, ps.StepOptions(), u) == 0
    with pytest.raises(ValueError, match="dt"):
        step_from_python(model.arrays, s, ws, ps.StepOptions(dt=-1e-3), u)
    with pytest.raises(ValueError, match="1-d"):
        step_from_python(model.arrays, s, ws, ps.StepOptions(), np.zeros((1, model.n_act)))
