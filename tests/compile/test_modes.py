"""The compiler layer's modes (planarsim/compile/mode.py): which one a process gets, three
decorators, and NUMBA_DISABLE_JIT=1 running every kernel as Python with the compiled numbers."""
import json
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import planarsim.compiled
from planarsim.compile import mode

# a pendulum chain and Ranger (curved feet, motors, its controller), 50 steps each: final and
# recorded positions [m, rad] as JSON (float repr round-trips exactly)
_RUN = textwrap.dedent("""
    import json, sys
    import numpy as np
    import planarsim as ps
    import walkers
    from planarsim.compile import MODE
    from tests.conftest import make_chain
    sim = ps.Simulator(make_chain(4))
    sim.state.v[:, 2] += 1.0          # set it turning
    for _ in range(50):
        sim.step()                    # the Python step path (run_steps)
    traj = sim.run(n_steps=50)        # the recorded path (run_recorded)
    ranger = walkers.load("ranger")
    dt = float(ranger.build().dt)
    rtraj, summary, _ = ranger.simulate(50 * dt)
    json.dump({"mode": MODE, "chain": sim.state.q.tolist(), "chain_traj": traj.q.tolist(),
               "ranger": rtraj.q.tolist(), "ranger_t": rtraj.t.tolist(),
               "dt": dt}, sys.stdout)
""")


def _run(env_extra):
    env = dict(os.environ, PYTHONPATH=os.getcwd(), **env_extra)
    out = subprocess.run([sys.executable, "-c", _RUN], capture_output=True, text=True, env=env,
                         timeout=900)
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout)


def test_numba_disable_jit_runs_every_kernel_as_python_with_the_compiled_numbers():
    python = _run({"NUMBA_DISABLE_JIT": "1"})
    compiled = _run({})
    assert python["mode"] == "python" and compiled["mode"] != "python"
    assert compiled["ranger_t"][-1] == pytest.approx(50 * compiled["dt"])   # 50 steps ran
    for key in ("chain", "chain_traj", "ranger"):
        a, b = np.array(python[key]), np.array(compiled[key])
        assert a.shape == b.shape and a.size > 0
        assert np.abs(a - b).max() <= 1e-12, key
    # the runs moved: the comparison is not of two resting states
    assert np.abs(np.diff(np.array(compiled["ranger"]), axis=0)).max() > 1e-5
    assert np.abs(np.array(compiled["chain"]) - np.array(compiled["chain_traj"])[0]).max() > 1e-3


def test_under_numba_disable_jit_the_step_is_python_that_pdb_can_enter():
    code = textwrap.dedent("""
        import inspect
        from planarsim.compile import MODE
        from planarsim.link import step as link
        from planarsim.kernels.solver import solve
        from planarsim.kernels import step
        print(MODE, inspect.isfunction(step._step), inspect.isfunction(solve.solve_impulses),
              inspect.isfunction(link.step))
    """)
    env = dict(os.environ, PYTHONPATH=os.getcwd(), NUMBA_DISABLE_JIT="1")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.split() == ["python", "True", "True", "True"]


@pytest.mark.parametrize("environ, disabled, missing, expected", [
    ({}, False, [], mode.FAST),
    ({"PLANARSIM_PLAIN_NUMBA": "1"}, False, [], mode.PLAIN),
    ({"PLANARSIM_PLAIN_NUMBA": "0"}, False, [], mode.FAST),
    ({"PLANARSIM_PLAIN_NUMBA": "1"}, True, [], mode.PYTHON),
    ({}, True, ["numba.core.codegen.JITCodeLibrary"], mode.PYTHON),
])
def test_the_mode_follows_the_switches(environ, disabled, missing, expected):
    assert mode.choose_mode(environ, disabled, lambda: missing) == expected


def test_a_numba_without_the_fast_internals_gets_plain_numba_and_a_warning():
    with pytest.warns(RuntimeWarning, match="numba.core.codegen.JITCodeLibrary.*plain numba"):
        assert mode.choose_mode({}, False, lambda: ["numba.core.codegen.JITCodeLibrary"]) == mode.PLAIN


def test_three_decorators_and_their_options():
    from planarsim import compile as layer
    assert {"jit", "jit_inline", "kernel"} <= set(planarsim.compiled.__all__)
    for gone in ("jit_force", "kernel_call", "kernel_inline"):
        assert not hasattr(layer, gone) and not hasattr(planarsim.compiled, gone)
    with pytest.raises(ValueError, match=r"kernel\(inline='sometimes'\)"):
        layer.kernel(inline="sometimes")
    with pytest.raises(ValueError, match=r"jit\(inline='never'\)"):
        layer.jit(inline="never")


def test_break_in_needs_python_mode_and_names_an_unknown_stage():
    from planarsim.link import debug
    if mode.PYTHON != planarsim.compile.MODE:
        with pytest.raises(RuntimeError, match="NUMBA_DISABLE_JIT=1"):
            debug.break_in("solver.solve.solve_impulses")
    code = ("from planarsim.link.debug import break_in\n"
            "d = break_in('solver.solve.solve_impulses'); print(len(d.get_all_breaks()))\n"
            "try:\n    break_in('solver.solve.no_such_stage')\nexcept ValueError as e:\n    print(e)\n")
    env = dict(os.environ, PYTHONPATH=os.getcwd(), NUMBA_DISABLE_JIT="1")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert out.returncode == 0, out.stderr[-2000:]
    lines = out.stdout.splitlines()
    assert lines[0] == "1" and "no function 'no_such_stage' in planarsim/kernels/solver/solve.py" in lines[1]


def test_ci_runs_in_the_mode_its_switches_ask_for():
    """In CI (.ci/run sets CI) the process runs in the mode its switches ask for: fast unless
    PLANARSIM_PLAIN_NUMBA=1 or NUMBA_DISABLE_JIT=1 say otherwise. Elsewhere a numba release
    without the fast mode's internals falls back to plain numba with a warning (a slower
    first compile, the same numbers); in CI that fallback would skip the fast mode's own test
    modules and still pass, so there it fails here instead."""
    from numba import config
    if os.environ.get("CI", "") in ("", "0"):
        pytest.skip("not in CI: a fallback to plain numba is a warning there, not a failure")
    asked = mode.choose_mode(os.environ, bool(config.DISABLE_JIT), lambda: ())
    assert planarsim.compile.MODE == asked, (
        f"CI runs in the {planarsim.compile.MODE!r} mode where its switches ask for {asked!r}: "
        f"numba lacks {mode_missing()} that the fast mode builds on")


def mode_missing():
    """The numba internals the fast mode lacks in this process (numba_check.py)."""
    from planarsim.compile.numba_check import changed_internals
    return ", ".join(changed_internals()) or "nothing"
