"""Where the cold start's time goes: the first-ever compile, function by function.

    python -m benchmarks.compile_profile            # one cold child (a fresh, empty NUMBA_CACHE_DIR)
    python -m benchmarks.compile_profile --top 30   # more rows of the per-function table

The child runs what benchmarks/startup.py times (``import planarsim``, one step of a 2-link
chain, one step of the Simple Biped) with a profiler installed, and prints:

- the phases: import, the engine's first step, the walker's first step [s];
- the CPU time by kind of work, exclusive (a compile nested in another is not counted twice):
  numba's typing (type inference, including the typing of functions numba inlines into it),
  numba's lowering to LLVM IR, numba's other passes (bytecode, IR rewrites, numba-level
  inlining) and LLVM (every call into LLVM: parsing, linking, optimisation, machine code);
- per compiled function: its compiles (one per specialisation: argument types) and its
  exclusive time in each kind of work;
- LLVM's own pass timers (numba's NUMBA_LLVM_PASS_TIMINGS, set in the child) per code library
  LLVM optimised in this process (the step's parts compile in a child process of their own):
  per-function passes, module optimisation (O3) and machine code, and the size of its
  optimised IR (instructions). Those timers run on the wall clock: on a busy machine they
  count the time LLVM waits for a core too.

numba's own events drive it (``numba.core.event``: "numba:run_pass" around each compiler pass
of each function, "numba:llvm_lock" around each call into LLVM, "numba:compile" naming each
dispatcher compiled); nothing of numba is replaced, in the child or anywhere.
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
KINDS = ("typing", "lowering", "numba other", "llvm")
# LLVM's pass timers' records (numba's code libraries name them) by stage
LLVM_STAGES = (("Function passes", "llvm function passes"), ("Module passes", "llvm module O3"),
               ("Finalize object", "llvm machine code"))


class Profiler:
    """A stack of open timed regions; each region's time less its children's is its own
    (exclusive) time, added to (kind, function)."""

    def __init__(self):
        self.stack = []                       # [kind, function, start, children's time]
        self.own = defaultdict(float)         # (kind, function) -> s
        self.compiles = defaultdict(list)     # function -> [argument types] of each compile
        self.passes = defaultdict(float)      # numba pass name -> exclusive s
        self.dispatchers = []                 # every dispatcher compiled (their libraries)

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

    def function(self):
        """The function whose compiler pass is running (the innermost open region's)."""
        return self.stack[-1][1] if self.stack else "(outside a compiler pass)"


def _instructions(module) -> int:
    return sum(1 for fn in module.functions for block in fn.blocks for _ in block.instructions)


def install(profiler: Profiler) -> None:
    """Listen to numba's events: its compiler passes, its calls into LLVM and its compiles."""
    from numba.core import event

    class Passes(event.Listener):
        def on_start(self, ev):
            name = ev.data["name"].split(" [")[0]
            qualname = ev.data["qualname"]
            if name == "nopython_type_inference":
                profiler.compiles[qualname].append(ev.data["args"])
            profiler.push(PASS_KIND.get(name, "numba other"), qualname, name)

        def on_end(self, ev):
            profiler.pop()

    class LLVM(event.Listener):
        def on_start(self, ev):
            profiler.push("llvm", profiler.function())

        def on_end(self, ev):
            profiler.pop()

    class Compiles(event.Listener):
        def on_start(self, ev):
            pass

        def on_end(self, ev):
            dispatcher = (ev.data or {}).get("dispatcher")
            if dispatcher is not None:
                profiler.dispatchers.append(dispatcher)

    event.register("numba:run_pass", Passes())
    event.register("numba:llvm_lock", LLVM())
    event.register("numba:compile", Compiles())


def _libraries(profiler: Profiler) -> list:
    """The code libraries LLVM optimised: every compiled dispatcher's, the step's and its
    parts' C functions'."""
    found = [cres.library for d in profiler.dispatchers
             for cres in getattr(d, "overloads", {}).values()]
    try:
        from planarsim.compile.parts import PARTS
        from planarsim.link.step import _ENGINE
        found += [c._library for c in (_ENGINE.get("cfunc"), PARTS.cfunc) if c is not None]
    except (ImportError, AttributeError):
        pass
    return [lib for lib in dict.fromkeys(found) if getattr(lib, "_finalized", False)]


def _llvm_timings(libraries) -> list:
    """[name, {stage: s}, IR instructions after O3] per library (LLVM's own pass timers)."""
    rows = []
    for lib in libraries:
        stages = dict.fromkeys((stage for _, stage in LLVM_STAGES), 0.0)
        for record in getattr(lib, "_recorded_timings", ()):
            for prefix, stage in LLVM_STAGES:
                if record.name.startswith(prefix):
                    stages[stage] += record.timings.get_total_time() or 0.0
        try:
            size = _instructions(lib._final_module)
        except Exception:   # a library whose module numba has since dropped
            size = 0
        if any(stages.values()):
            rows.append([lib.name, stages, size])
    return sorted(rows, key=lambda r: -sum(r[1].values()))


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
    llvm = _llvm_timings(_libraries(profiler))
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
        llvm_stages={stage: sum(r[1][stage] for r in llvm) for _, stage in LLVM_STAGES},
        llvm_libraries=llvm[:top],
    )


def measure(top=20, timeout=1800) -> dict:
    """Run the profiled cold start in a child with a fresh, empty numba cache directory."""
    tmp = tempfile.mkdtemp(prefix="planarsim-cold-profile-")
    env = {**os.environ, "NUMBA_CACHE_DIR": tmp, "NUMBA_LLVM_PASS_TIMINGS": "1"}
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
    short = list(KINDS)
    lines += ["", "numba's passes, all functions (exclusive CPU) [s]:"]
    for name, s in out["passes"].items():
        lines.append(f"  {name:40s} {s:7.2f}")
    lines += ["", "per function (exclusive CPU) [s]:",
              f"  {'function':44s} {'n':>3s} {'total':>6s} " + " ".join(f"{k[:9]:>9s}" for k in short)]
    for row in out["functions"]:
        lines.append(f"  {row['name'][:44]:44s} {row['compiles']:3d} {row['total_s']:6.2f} "
                     + " ".join(f"{row[k]:9.2f}" for k in short))
    stages = [stage for _, stage in LLVM_STAGES]
    lines += ["", "LLVM's own pass timers, all libraries [s]:"]
    for stage in stages:
        lines.append(f"  {stage:22s} {out['llvm_stages'][stage]:7.2f}")
    lines += ["", "per code library LLVM optimised (LLVM's pass timers [s], IR instructions after O3):",
              f"  {'library':44s} " + " ".join(f"{k[5:14]:>9s}" for k in stages) + f" {'IR':>8s}"]
    for name, times, size in out["llvm_libraries"]:
        lines.append(f"  {name[:44]:44s} " + " ".join(f"{times[k]:9.2f}" for k in stages)
                     + f" {size:8d}")
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
