"""The step's parts (planarsim/compile/parts.py): kernels compiled as C functions of their own,
called through a table of addresses, compiled in a child process on a first-ever start."""
import subprocess
import sys

import numpy as np
import pytest
from numba import njit
from numba.core.errors import TypingError

import planarsim as ps
from planarsim.compile import FAST, MODE, part

if MODE != FAST:
    pytest.skip("parts are plain kernels outside the fast mode", allow_module_level=True)

from planarsim.compile import options, parts  # noqa: E402


def _stepped():
    b = ps.ModelBuilder()
    body = b.add_body("b", 1.0, 0.1, pos=(0.5, 0.0))
    b.add_pin("p", None, body, anchor_world=(0.0, 0.0))
    sim = ps.Simulator(b.compile())
    sim.step()
    return sim


def test_every_part_is_loaded_into_its_slot_before_the_step_runs():
    _stepped()
    loaded = parts.all_parts()
    assert [p.name for p in loaded] == list(parts.PART_NAMES)
    for p in loaded:
        assert p.cfunc is not None and p.cfunc.address != 0
        assert parts._TABLE[p.index] == p.cfunc.address, p.name


def test_a_part_called_with_a_wrong_argument_is_named_when_its_caller_is_typed():
    from planarsim.kernels.complementarity import project_positions

    @njit(**dict(options(), cache=False))
    def wrong(x):
        return project_positions(x, x, x, 1.0, 2, 1e-9)

    with pytest.raises(TypingError, match="project_positions: argument 1 is"):
        wrong(np.zeros(3))


def test_a_part_needs_a_slot_and_engine_or_scalar_argument_types():
    def not_listed(m, s, ws):
        return 0
    with pytest.raises(ValueError, match="has no slot"):
        part("model", "state", "workspace")(not_listed)
    def solve_contacts(m, x):   # noqa: E306  (a listed name, a bad type)
        return 0
    solve_contacts.__module__ = "planarsim.kernels.complementarity"
    solve_contacts.__qualname__ = "solve_contacts"
    with pytest.raises(ValueError, match="'array'"):
        part("model", "array")(solve_contacts)


class _FakePart:
    """A part whose cache holds it after the child ran (cached=True) or never (False)."""

    def __init__(self, cached):
        self.cached, self.compiled = cached, False

    def load_cached(self):
        return self.cached

    def compile(self):
        self.compiled = True


def _child(code):
    return subprocess.Popen([sys.executable, "-c", code])


def test_a_failed_child_leaves_its_parts_to_this_process_and_a_finished_one_to_the_cache():
    failed = [_FakePart(False), _FakePart(False)]
    parts.finish(failed, _child("raise SystemExit(3)"))
    assert all(p.compiled for p in failed)
    done = [_FakePart(True)]
    parts.finish(done, _child("pass"))
    assert not done[0].compiled
    alone = [_FakePart(True)]
    parts.finish(alone, None)        # no child: nothing could have cached it since
    assert alone[0].compiled


def test_a_stuck_child_is_stopped_and_the_parts_it_left_are_compiled_here(monkeypatch):
    monkeypatch.setattr(parts, "CHILD_TIMEOUT", 0.5)
    stuck = [_FakePart(False)]
    child = _child("import time; time.sleep(60)")
    parts.finish(stuck, child)
    assert child.poll() is not None and stuck[0].compiled


def test_no_child_is_started_when_switched_off_or_frozen_or_with_nothing_to_do(monkeypatch):
    some = parts.all_parts()[:1]
    assert parts.start_child([]) is None
    monkeypatch.setenv(parts.CHILD_SWITCH, "0")
    assert parts.start_child(some) is None
    monkeypatch.delenv(parts.CHILD_SWITCH)
    monkeypatch.setattr(sys, "frozen", True, raising=False)
    assert parts.start_child(some) is None
