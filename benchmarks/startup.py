"""Start-up times, each measured in a fresh Python subprocess.

The child starts a clock, runs ``import planarsim``, makes one engine step (a 2-link chain:
``Simulator.step``) and then the first step of a walker (``walkers.simple_biped.simulate`` of
one step: build, compiled rollout, Trajectory), and prints the times from its clock start
(cumulative, so "to walker step" includes the import and the engine's step). The wall time of
the whole child process (interpreter start included) is reported too.

- warm: the child uses the normal numba cache (``__pycache__`` next to the sources, or the
  user's own NUMBA_CACHE_DIR if set), which the parent has just filled by running the same
  script once (not timed).
- cold: the child gets ``NUMBA_CACHE_DIR`` pointing at a new, empty temporary directory.
  numba then looks up and writes every cached function there only (its user-provided cache
  locator comes first), so the engine's step and the walker's rollout are compiled from
  scratch, exactly as on a first-ever run; the directory is deleted afterwards. This takes
  about 36 s of one core (a quiet two-core AMD EPYC, numba 0.68).

Where the cold start's time goes (numba's typing and lowering, LLVM's optimisation and machine
code, per compiled function, the step's code size): ``python -m benchmarks.compile_profile``.
What an edit of one source file recompiles: ``python -m benchmarks.recompile``.
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

def first_steps(t0: float) -> dict:
    """Import planarsim, make one engine step (a 2-link chain) and a walker's first step (the
    Simple Biped's simulate of one step); the times [s] from t0 (perf_counter) at each."""
    import planarsim as ps
    t_import = time.perf_counter() - t0
    from benchmarks.scenes import chain
    sim = ps.Simulator(chain(2))
    sim.step()
    t_engine = time.perf_counter() - t0
    from walkers import simple_biped
    simple_biped.simulate(0.001)
    return {"import_s": t_import, "engine_step_s": t_engine, "walker_step_s": time.perf_counter() - t0}


CHILD = r"""
import json, time
t0 = time.perf_counter()
from benchmarks.startup import first_steps
print("STARTUP " + json.dumps(first_steps(t0)))
"""


def _child(env=None, timeout=900):
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True,
                          env=env, timeout=timeout)
    wall = time.perf_counter() - t0
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("STARTUP ")]
    if proc.returncode or not lines:
        raise RuntimeError(f"start-up child failed (exit {proc.returncode}):\n{proc.stderr[-2000:]}")
    out = json.loads(lines[-1][len("STARTUP "):])
    out["process_s"] = wall
    return out


def measure_startup(cold=True, timeout=900):
    """[{scene: 'startup', cache: 'warm'|'cold', import_s, engine_step_s, walker_step_s,
    process_s}] (see module doc)."""
    env = dict(os.environ)
    _child(env, timeout)  # fills the normal cache if anything was stale
    rows = [dict(scene="startup", engine="planarsim", cache="warm", **_child(env, timeout))]
    if cold:
        tmp = tempfile.mkdtemp(prefix="planarsim-cold-numba-")
        try:
            rows.append(dict(scene="startup", engine="planarsim", cache="cold",
                             **_child({**env, "NUMBA_CACHE_DIR": tmp}, timeout)))
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
    return rows
