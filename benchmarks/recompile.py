"""What an edit recompiles: a copy of planarsim and walkers with a warm numba cache, one source
file edited (a comment line appended), then the same first steps timed again.

    python -m benchmarks.recompile                                   # the default edits below
    python -m benchmarks.recompile planarsim/kernels/solver/lcp.py          # your own choice of files

For each edit it prints the time to the first steps (a 2-link chain, then each walker named in
WALKERS) and the cached compiled functions that compiled again (the engine's step, its parts'
C function, compiled in a child process, and the `jit` functions: rollouts, run_steps, ...),
next to the kernels compiled for them (in this process). It works on a
temporary copy (the sources here and their caches are left alone); each edit starts from the
warm copy.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
EDITS = ("planarsim/kernels/solver/lcp.py", "planarsim/kernels/geometry/terrain.py",
         "walkers/simple_biped/controller.py")
WALKERS = ("simple_biped", "ranger")

CHILD = r"""
import json, sys, time
from numba.core import event
compiled = []

class Compiles(event.Listener):
    def on_start(self, ev):
        d = ev.data
        if "dispatcher" in d:
            f = d["dispatcher"].py_func
            compiled.append([f.__module__ + "." + f.__qualname__, type(d["dispatcher"]).__name__])
        elif ev.data["name"].startswith("nopython_type_inference") and d["qualname"] == "_step_c":
            compiled.append(["planarsim.link.fast_step._step_c", "cfunc"])
    def on_end(self, ev):
        pass

listener = Compiles()
event.register("numba:compile", listener)
event.register("numba:run_pass", listener)
t0 = time.perf_counter()
import planarsim as ps
from benchmarks.scenes import chain
ps.Simulator(chain(2)).step()
times = {"engine": time.perf_counter() - t0}
from planarsim.compile.parts import PARTS
if PARTS.missed:     # compiled in a child process (or here, where none could help)
    compiled.append(["planarsim.compile.parts.parts_c", "cfunc"])
import importlib
for name in sys.argv[1:]:
    importlib.import_module("walkers." + name).simulate(0.001)
    times[name] = time.perf_counter() - t0
print("RECOMPILE " + json.dumps({"times": times, "compiled": compiled}))
"""


def _run(folder: Path, walkers) -> dict:
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["PYTHONPATH"] = str(folder)
    proc = subprocess.run([sys.executable, "-c", CHILD, *walkers], capture_output=True, text=True,
                          cwd=folder, env=env, timeout=1800)
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("RECOMPILE ")]
    if proc.returncode or not lines:
        raise RuntimeError(f"child failed (exit {proc.returncode}):\n{proc.stderr[-3000:]}")
    return json.loads(lines[-1][len("RECOMPILE "):])


def _copy(dst: Path) -> None:
    ignore = shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc", "out", ".git")
    for part in ("planarsim", "walkers", "benchmarks"):
        shutil.copytree(ROOT / part, dst / part, ignore=ignore)


def _summary(label: str, out: dict) -> str:
    cached = [name for name, kind in out["compiled"] if kind != "KernelDispatcher"]
    kernels = sum(1 for _, kind in out["compiled"] if kind == "KernelDispatcher")
    times = ", ".join(f"{k} at {v:.1f} s" for k, v in out["times"].items())
    lines = [f"{label}: first steps: {times}",
             f"  {len(cached)} cached functions compiled ({kernels} kernels compiled for them):"]
    lines += [f"    {name}" for name in cached]
    return "\n".join(lines)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("files", nargs="*", default=list(EDITS), help="source files to edit, one at a time")
    ap.add_argument("--walkers", default=",".join(WALKERS), help="walkers to step after the engine")
    a = ap.parse_args(argv)
    walkers = [w for w in a.walkers.split(",") if w]
    with tempfile.TemporaryDirectory(prefix="planarsim-recompile-") as tmp:
        warm = Path(tmp) / "warm"
        _copy(warm)
        t0 = time.perf_counter()
        _run(warm, walkers)                      # cold: fills the copy's caches
        print(f"cold copy compiled in {time.perf_counter() - t0:.0f} s (load {os.getloadavg()[0]:.1f})")
        print(_summary("no edit", _run(warm, walkers)))
        for rel in a.files:
            edited = Path(tmp) / "edited"
            shutil.rmtree(edited, ignore_errors=True)
            shutil.copytree(warm, edited, symlinks=True)   # the caches come along
            with open(edited / rel, "a") as f:
                f.write("# an edit\n")
            print(_summary(f"edit {rel}", _run(edited, walkers)))


if __name__ == "__main__":
    main()
