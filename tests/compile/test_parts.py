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
from planarsim.link.fast_step import PART_NAMES  # noqa: E402


def _stepped():
    b = ps.ModelBuilder()
    body = b.add_body("b", 1.0, 0.1, pos=(0.5, 0.0))
    b.add_pin("p", None, body, anchor_world=(0.0, 0.0))
    sim = ps.Simulator(b.compile())
    sim.step()
    return sim


def test_the_parts_are_loaded_into_the_table_before_the_step_runs():
    _stepped()
    assert [p.name for p in parts.all_parts()] == list(PART_NAMES)
    assert parts.PARTS.cfunc is not None and parts.PARTS.cfunc.address != 0
    assert parts._TABLE[0] == parts.PARTS.cfunc.address


def test_each_part_takes_its_arguments_in_slots_of_their_kind():
    width = parts.slot_counts()
    first = {"float64": 4, "int64": 4 + width["float64"],
             "boolean": 4 + width["float64"] + width["int64"]}
    for p in parts.all_parts():
        slots = p.slots()
        assert len(set(slots)) == len(slots), p.name
        for a, k in zip(p.args, slots):
            if a in ("model", "state", "workspace", "options"):
                assert k == ("model", "state", "workspace", "options").index(a)
            else:
                assert first[a] <= k < first[a] + width[a], (p.name, a, k)


def test_a_part_called_with_a_wrong_argument_is_named_when_its_caller_is_typed():
    from planarsim.kernels.solver.complementarity import project_positions

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
    solve_contacts.__module__ = "planarsim.kernels.solver.complementarity"
    solve_contacts.__qualname__ = "solve_contacts"
    with pytest.raises(ValueError, match="'array'"):
        part("model", "array")(solve_contacts)
    with pytest.raises(ValueError, match="returns 'boolean'"):
        part("model", "float64", returns="boolean")(solve_contacts)


class _FakeParts:
    """Parts whose cache holds them after the child ran (cached=True) or never (False)."""

    def __init__(self, cached):
        self.cached, self.compiled = cached, False

    def load_cached(self):
        return self.cached

    def compile(self):
        self.compiled = True


def _child(code):
    return subprocess.Popen([sys.executable, "-c", code])


def test_a_failed_child_leaves_the_parts_to_this_process_and_a_finished_one_to_the_cache():
    failed = _FakeParts(False)
    parts.finish(failed, _child("raise SystemExit(3)"))
    assert failed.compiled
    done = _FakeParts(True)
    parts.finish(done, _child("pass"))
    assert not done.compiled
    alone = _FakeParts(True)
    parts.finish(alone, None)        # no child: nothing could have cached them since
    assert alone.compiled
    parts.finish(None, None)         # nothing to do


def test_a_stuck_child_is_stopped_and_the_parts_it_left_are_compiled_here(monkeypatch):
    monkeypatch.setattr(parts, "CHILD_WAIT_MIN", 0.5)
    stuck = _FakeParts(False)
    child = _child("import time; time.sleep(60)")
    parts.finish(stuck, child, 0.1)
    assert child.poll() is not None and stuck.compiled


def test_no_child_is_started_when_switched_off_or_frozen_or_on_one_cpu_or_with_nothing_to_do(
        monkeypatch):
    some = parts.PARTS
    assert parts.start_child(None) is None
    monkeypatch.setenv(parts.CHILD_SWITCH, "0")
    assert parts.start_child(some) is None
    monkeypatch.delenv(parts.CHILD_SWITCH)
    with monkeypatch.context() as m:
        m.setattr(sys, "frozen", True, raising=False)
        assert parts.start_child(some) is None
    with monkeypatch.context() as m:
        m.setattr(parts, "_cores", lambda: 1)
        assert parts.start_child(some) is None


def test_the_child_imports_from_this_process_path_and_leaves_edited_sources_to_it(
        monkeypatch, tmp_path):
    """The child reads sys.path as this process has it (strings only: a Path in sys.path is
    skipped, not a crash) and compiles nothing when its engine sources hash otherwise than
    this process's (an edit meanwhile): it exits 3 and leaves the caches alone."""
    monkeypatch.setattr(sys, "path", [*sys.path, tmp_path])          # a Path entry
    monkeypatch.setattr(parts, "_cores", lambda: 2)
    import planarsim.link.caches as caches
    monkeypatch.setattr(caches, "ENGINE_HASH", "edited-since")        # what the child is told
    monkeypatch.delenv(parts.CHILD_SWITCH, raising=False)
    child = parts.start_child(parts.PARTS)
    assert child is not None
    assert child.wait(timeout=120) == 3
