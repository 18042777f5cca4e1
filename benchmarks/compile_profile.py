"""Where the cold start's time goes: the first-ever compile, function by function.

    python -m benchmarks.compile_profile            # one cold child (a fresh, empty NUMBA_CACHE_DIR)
    python -m benchmarks.compile_profile --top 30   # more rows of the per-function table

The child runs what benchmarks/startup.py times (``import planarsim``, one step of a 2-link
chain, one step of the Simple Biped) with a profiler installed, and prints:

- the phases: import, the engine's first step, the walker's first step [s];
- the CPU time by kind of work, exclusive (a compile nested in another is not counted twice):
  numba's typing (type inference, including the typing of functions numba inlines into it),
  numba's other passes (bytecode, IR rewrites, numba-level inlining, lowering to LLVM IR),
  LLVM's per-function passes, LLVM's module optimisation (O3) and LLVM's machine code
  emission, the numba cache's writes;
- per compiled function: its compiles (one per specialisation: argument types), its
  exclusive time in each kind of work, and for each module LLVM optimises, the size of its
  IR (instructions) before and after optimisation.

numba's own events drive it (``numba.core.event``: "numba:run_pass" around each compiler pass
of each function); the LLVM stages are timed by wrapping numba's code-library methods in the
child only. The profiler adds a little time of its own (counting IR instructions).
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
from collections import defaultdict

# the work a compiler pass does, by numba pass name (the rest: "numba other")
PASS_KIND = {
    "nopython_type_inference": "typing",
    "native_lowering": "lowering",
    "cfunc_native_lowering": "lowering",
}
# the profile's clock: this process's CPU time (the work, whatever else the machine runs)
CLOCK = time.process_time
KINDS = ("typing", "lowering", "numba other", "llvm function passes", "llvm module O3",
         "llvm machine code", "llvm link", "cache write")


class Profiler:
    """A stack of open timed regions; each region's time less its children's is its own
    (exclusive) time, added to (kind, function)."""

    def __init__(self):
        self.stack = []                       # [kind, function, start, children's time]
        self.own = defaultdict(float)         # (kind, function) -> s
        self.compiles = defaultdict(list)     # function -> [argument types] of each compile
        self.sizes = []                       # (function, IR instructions before, after O3)
        self.passes = defaultdict(float)      # numba pass name -> exclusive s

    def push(self, kind, function, name=None):
        self.stack.append([kind, function, CLOCK(), 0.0, name])

    def pop(self):
        kind, function, start, children, name = self.stack.pop()
        total = CLOCK() - start
        self.own[kind, function] += total - children
        if name is not None:
            self.passes[name] += total - children
        if self.stack:
            self.stack[-1][3] += total

    def timed(self, kind, name_of):
        """Decorator wrapping a method: its call is a region of `kind`, for name_of(self)."""
        def wrap(method):
            def wrapper(obj, *args, **kwargs):
                self.push(kind, name_of(obj))
                try:
                    return method(obj, *args, **kwargs)
                finally:
                    self.pop()
            return wrapper
        return wrap


def _instructions(module) -> int:
    return sum(1 for fn in module.functions for block in fn.blocks for _ in block.instructions)


def install(profiler: Profiler) -> None:
    """Listen to numba's pass events and wrap its code libraries' LLVM stages (this process)."""
    from numba.core import caching, codegen, event

    class Passes(event.Listener):
        def on_start(self, ev):
            name = ev.data["name"].split(" [")[0]
            qualname = ev.data["qualname"]
            if name == "nopython_type_inference":
                profiler.compiles[qualname].append(ev.data["args"])
            profiler.push(PASS_KIND.get(name, "numba other"), qualname, name)

        def on_end(self, ev):
            profiler.pop()

    event.register("numba:run_pass", Passes())
    lib_name = lambda lib: lib.name                      # noqa: E731
    cpu = codegen.CPUCodeLibrary
    cpu._optimize_functions = profiler.timed("llvm function passes", lib_name)(cpu._optimize_functions)
    plain_o3 = cpu._optimize_final_module

    def o3(lib):
        before = _instructions(lib._final_module)
        plain_o3(lib)
        profiler.sizes.append((lib.name, before, _instructions(lib._final_module)))
    cpu._optimize_final_module = profiler.timed("llvm module O3", lib_name)(o3)
    jit_lib = codegen.JITCodeLibrary
    jit_lib._finalize_specific = profiler.timed("llvm machine code", lib_name)(jit_lib._finalize_specific)
    cpu.finalize = profiler.timed("llvm link", lib_name)(cpu.finalize)
    try:
        from planarsim.compile.fast import KernelCodeLibrary
        KernelCodeLibrary.finalize = profiler.timed("llvm link", lib_name)(KernelCodeLibrary.finalize)
    except ImportError:
        pass
    caching.Cache.save_overload = profiler.timed(
        "cache write", lambda cache: cache._name)(caching.Cache.save_overload)


def child(top: int) -> dict:
    """Profile the cold start in this process (its NUMBA_CACHE_DIR must be empty)."""
    t0 = time.perf_counter()
    c0 = time.process_time()
    profiler = Profiler()
    import numba  # noqa: F401
    install(profiler)
    from benchmarks.startup import first_steps
    phases = first_steps(t0)
    cpu_walker = time.process_time() - c0
    by_kind = defaultdict(float)
    by_function = defaultdict(lambda: defaultdict(float))
    for (kind, function), seconds in profiler.own.items():
        by_kind[kind] += seconds
        by_function[function][kind] += seconds
    size = {}
    for name, before, after in profiler.sizes:
        b, a = size.get(name, (0, 0))
        size[name] = (b + before, a + after)
    rows = sorted(by_function.items(), key=lambda kv: -sum(kv[1].values()))
    return dict(
        phases=dict(**phases,
                    walker_step_cpu_s=cpu_walker),
        passes=dict(sorted(profiler.passes.items(), key=lambda kv: -kv[1])[:top]),
        by_kind=dict(by_kind),
        functions=[dict(name=name, compiles=len(profiler.compiles.get(name.split("$")[0], ())),
                        total_s=sum(kinds.values()), **{k: kinds.get(k, 0.0) for k in KINDS})
                   for name, kinds in rows[:top]],
        specialisations={name: args for name, args in profiler.compiles.items() if len(args) > 1},
        compiled_functions=len(profiler.compiles),
        compiles=sum(len(a) for a in profiler.compiles.values()),
        ir_sizes=sorted(([n, b, a] for n, (b, a) in size.items()), key=lambda r: -r[2])[:top],
    )


def measure(top=20, timeout=1800) -> dict:
    """Run the profiled cold start in a child with a fresh, empty numba cache directory."""
    tmp = tempfile.mkdtemp(prefix="planarsim-cold-profile-")
    env = {**os.environ, "NUMBA_CACHE_DIR": tmp}
    try:
        t0 = time.perf_counter()
        proc = subprocess.run([sys.executable, "-m", "benchmarks.compile_profile", "--child",
                               "--top", str(top)], capture_output=True, text=True, env=env,
                              timeout=timeout)
        wall = time.perf_counter() - t0
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("PROFILE ")]
    if proc.returncode or not lines:
        raise RuntimeError(f"profile child failed (exit {proc.returncode}):\n{proc.stderr[-3000:]}")
    out = json.loads(lines[-1][len("PROFILE "):])
    out["phases"]["process_s"] = wall
    return out


def report(out: dict) -> str:
    p = out["phases"]
    lines = [f"cold start: import {p['import_s']:.1f} s, engine's first step at "
             f"{p['engine_step_s']:.1f} s, walker's first step at {p['walker_step_s']:.1f} s "
             f"(process {p.get('process_s', float('nan')):.1f} s; load {os.getloadavg()[0]:.2f}); "
             f"CPU time to the walker's first step {p['walker_step_cpu_s']:.1f} s",
             f"{out['compiled_functions']} functions compiled, {out['compiles']} compiles",
             "", "CPU time by kind of work (exclusive) [s]:"]
    total = sum(out["by_kind"].values())
    for kind in KINDS:
        s = out["by_kind"].get(kind, 0.0)
        lines.append(f"  {kind:22s} {s:7.2f}  {100 * s / total:5.1f} %")
    lines.append(f"  {'all':22s} {total:7.2f}")
    short = ["typing", "lowering", "numba other", "llvm function passes", "llvm module O3",
             "llvm machine code"]
    lines += ["", "numba's passes, all functions (exclusive CPU) [s]:"]
    for name, s in out["passes"].items():
        lines.append(f"  {name:40s} {s:7.2f}")
    lines += ["", "per function (exclusive CPU) [s]:",
              f"  {'function':44s} {'n':>3s} {'total':>6s} " + " ".join(f"{k[:9]:>9s}" for k in short)]
    for row in out["functions"]:
        lines.append(f"  {row['name'][:44]:44s} {row['compiles']:3d} {row['total_s']:6.2f} "
                     + " ".join(f"{row[k]:9.2f}" for k in short))
    lines += ["", "LLVM IR instructions of the modules optimised (before -> after O3):"]
    for name, before, after in out["ir_sizes"]:
        lines.append(f"  {name[:60]:60s} {before:8d} -> {after:8d}")
    if out["specialisations"]:
        lines += ["", "functions typed more than once (argument types of each):"]
        for name, args in sorted(out["specialisations"].items()):
            lines.append(f"  {name}: {len(args)}")
            for a in args:
                lines.append(f"      {a[:150]}")
    return "\n".join(lines)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--top", type=int, default=20, help="rows of the per-function tables")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--json", action="store_true", help="print the raw numbers as JSON")
    a = ap.parse_args(argv)
    if a.child:
        print("PROFILE " + json.dumps(child(a.top)))
        return
    out = measure(a.top)
    print(json.dumps(out) if a.json else report(out))


if __name__ == "__main__":
    main()
