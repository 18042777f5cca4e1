"""Where a scene's or walker's step time goes, per compiled function (Linux `perf`, sampling).

    python benchmarks/profile_kernels.py chain4                # a bench scene (Simulator.steps)
    python benchmarks/profile_kernels.py walker:simbicon       # a walker's simulate()
    python benchmarks/profile_kernels.py biped_collapse --seconds 20
    python benchmarks/profile_kernels.py world:pyramid45 --seconds 0.2   # benchmarks/worlds.py
    python benchmarks/profile_kernels.py mjcf:inverted_double_pendulum.xml   # a gymnasium file
    python benchmarks/profile_kernels.py dmc:cheetah-run --seconds 10   # a dmc task, random actions

numba's machine code has no symbols that perf can see, so this script writes perf's map file
(/tmp/perf-<pid>.map: address, size, name of every compiled function the run links), samples
its own process with `perf record -e cpu-clock` while the kernels run, and prints each
function's share of the samples. The kernels that are normally inlined into the step are
compiled as calls here (PLANARSIM_KERNEL_CALLS=1), so each stage shows as its own; the
figures are therefore of a slightly slower build.
The kernels are compiled afresh into a temporary numba cache (about a minute): code loaded from
the cache carries no list of its functions. Needs perf (Debian: apt-get install linux-perf);
it is not part of the test suite.
"""
from __future__ import annotations

import argparse
import collections
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

if __name__ == "__main__":
    if "NUMBA_CACHE_DIR" not in os.environ:
        # before numba is imported: a fresh cache, so every function is compiled here (above)
        os.environ["NUMBA_CACHE_DIR"] = tempfile.mkdtemp(prefix="planarsim-profile-")
        os.environ["PLANARSIM_KERNEL_CALLS"] = "1"   # stages as calls (see compile/fast.py)
    # the step's parts compiled here, not loaded from a child's cache (no list of functions)
    os.environ["PLANARSIM_COMPILE_CHILD"] = "0"

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


def _compiled_functions(dispatchers):
    """{address: symbol} of every function in the libraries of the dispatchers' overloads."""
    from planarsim.link.step import _ENGINE, load_step
    from planarsim.compile.parts import PARTS
    load_step()
    libraries = [cres.library for disp in dispatchers for cres in disp.overloads.values()]
    libraries.append(_ENGINE["cfunc"]._library)   # the step: called by address, not linked
    libraries.append(PARTS.cfunc._library)   # its parts (compile/parts.py), too
    out = {}
    for library in libraries:
        engine = library._codegen._engine
        seen, todo = set(), [library]
        while todo:
            lib = todo.pop()
            if id(lib) in seen:
                continue
            seen.add(id(lib))
            for fn in lib.get_defined_functions():
                addr = engine.get_function_address(fn.name)
                if addr:
                    out[addr] = fn.name
            todo.extend(getattr(lib, "_linking_libraries", []))
    return out


def _short(symbol):
    """planarsim.kernels.solver.solve.factor from numba's mangled _ZN9planarsim7kernels6solver5solve6factor..."""
    if not symbol.startswith("_ZN"):
        return symbol
    rest, names = symbol[3:], []
    while rest[:1].isdigit():
        m = re.match(r"\d+", rest)
        n, k = int(m.group()), m.end()
        names.append(rest[k:k + n])
        rest = rest[k + n:]
    return ".".join(names) or symbol


def _workload(target, seconds, skip=0):
    """(callable running the workload once, [dispatchers whose code it runs])."""
    from numba.core.registry import CPUDispatcher
    if target.startswith("walker:"):
        import importlib
        import walkers
        name = target.split(":", 1)[1]
        mod = walkers.load(name)
        mod.simulate(0.05)   # compile or load
        package = mod.__name__.rsplit(".", 1)[0] if name in ("simplest-walker", "compass-gait",
                                                              "rimless-wheel") else mod.__name__
        importlib.import_module(package + ".rollout")
        # the rollout's and every compiled function of the walker's modules it calls (its
        # controller's, compiled apart where not inlined), and the shared walker code's
        modules = [m for key, m in list(sys.modules.items())
                   if m is not None and (key == package or key.startswith(package + ".")
                                         or key.startswith("walkers.common"))]
        disps = {id(v): v for m in modules for v in vars(m).values()
                 if isinstance(v, CPUDispatcher) and v.overloads}
        return (lambda: mod.simulate(seconds)), list(disps.values())
    import planarsim as ps
    from benchmarks.scenes import SCENES
    from benchmarks.worlds import WORLDS
    from planarsim.link.step import run_steps
    if target.startswith("dmc:"):
        # a DeepMind Control Suite task under uniformly random actions (seed 0), env.step by
        # env.step: the observation's and reward's Python shows as the interpreter's symbols
        import gymnasium
        import numpy as np
        import planarsim.envs  # noqa: F401  (registers the environments)
        from planarsim.envs.dmc import env_id
        env = gymnasium.make(env_id(target[4:]))
        env.reset(seed=0)
        calls = max(1, int(round(seconds / env.unwrapped.dt)))
        actions = np.random.default_rng(0).uniform(env.action_space.low, env.action_space.high,
                                                   size=(calls, *env.action_space.shape))
        for a in actions[:skip]:
            env.step(a)

        def run_env():
            env.reset(seed=0)
            for a in actions:
                if any(env.step(a)[2:4]):
                    env.reset()
        return run_env, [run_steps]
    from benchmarks.stress_scenes import ALL_SCENES, build_model
    if target.startswith("world:"):
        model = WORLDS[target[6:]]()
    elif target.startswith("stress:"):
        model = build_model(ALL_SCENES[target[7:]])
    elif target.startswith("mjcf:"):
        from planarsim.envs.core import gym_asset
        from planarsim.mjcf import load_mjcf
        model = load_mjcf(gym_asset(target[5:])).compile()
    else:
        model = SCENES[target][0]()
    sim = ps.Simulator(model)
    sim.steps(max(skip, 10))
    start = sim.state.copy()
    n = int(round(seconds / model.dt))

    def run():
        sim.state = start
        sim.steps(n)
    return run, [run_steps]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("target", help="a bench scene (chain4, biped_collapse, ...), walker:<name> or "
                    "world:<name> (benchmarks/worlds.py), stress:<name> "
                    "(benchmarks/stress_scenes.py), mjcf:<gymnasium's file> (its model at rest, "
                    "no command) or dmc:<task> (planarsim/dmc-<task>-v0 under random actions)")
    ap.add_argument("--skip", type=int, default=0,
                    help="steps taken before the timed runs start (the scene's later part)")
    ap.add_argument("--seconds", type=float, default=10.0, help="simulated seconds per run")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--top", type=int, default=20)
    args = ap.parse_args(argv)
    if shutil.which("perf") is None:
        sys.exit("perf is not installed (Debian: apt-get install linux-perf)")
    run, disps = _workload(args.target, args.seconds, args.skip)
    funcs = _compiled_functions(disps)
    addrs = sorted(funcs)
    map_path = Path(f"/tmp/perf-{os.getpid()}.map")
    with map_path.open("w") as fh:
        for i, a in enumerate(addrs):
            size = (addrs[i + 1] - a) if i + 1 < len(addrs) else 1 << 16
            fh.write(f"{a:x} {min(size, 1 << 20):x} {_short(funcs[a])}\n")
    data = Path(f"/tmp/perf-{os.getpid()}.data")
    rec = subprocess.Popen(["perf", "record", "-q", "-F", "5000", "-e", "cpu-clock", "-p",
                            str(os.getpid()), "-o", str(data)],
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(1.0)
    t0 = time.perf_counter()
    for _ in range(args.runs):
        run()
    wall = time.perf_counter() - t0
    rec.send_signal(2)
    rec.wait()
    out = subprocess.run(["perf", "script", "-i", str(data), "-F", "ip,sym"], capture_output=True,
                         text=True).stdout
    counts = collections.Counter((line.split(None, 1) + ["[unknown]"])[1].strip()
                                 for line in out.splitlines() if line.strip())
    total = sum(counts.values()) or 1
    print(f"{args.target}: {args.runs} x {args.seconds:g} s simulated in {wall:.2f} s wall; "
          f"{total} samples")
    for sym, c in counts.most_common(args.top):
        print(f"{100.0 * c / total:6.1f}%  {sym}")
    data.unlink(missing_ok=True)
    map_path.unlink(missing_ok=True)


if __name__ == "__main__":
    main()
