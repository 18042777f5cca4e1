"""The same numbers on every machine: bit-level fingerprints of the shipped walkers
(walker_digests.py), of a fixed set of stress-corpus runs (contact_stress.py) and of two pin
chains (the step's pin-chain path), computed in
fresh processes with numba's code generated for this CPU, for a generic x86-64 target
(NUMBA_CPU_NAME=generic: no AVX, no FMA; numba then sets NUMBA_CPU_FEATURES to none), and
with 1 and 2 threads (NUMBA_NUM_THREADS, OPENBLAS_NUM_THREADS), and with numpy's BLAS on its
SSE3 kernels (OPENBLAS_CORETYPE); every fingerprint must be identical across all five.

    python benchmarks/target_digests.py                  # 3 s per walker, the corpus set
    python benchmarks/target_digests.py --seconds 1      # quicker
    python benchmarks/target_digests.py --print          # this process's fingerprints only
    python benchmarks/target_digests.py --write-baseline # commit what the numbers are now

Prints each setting's difference from the host's (none: "identical") and exits 1 if any.
The committed baseline (benchmarks/results/digests-<machine>-<system>.txt, this platform's,
at BASELINE_SECONDS per walker; tests/planarsim/test_digests_baseline.py compares a fresh
run with it) is what the numbers were when it was last written: a change of physics that
moves them writes it again, and its commit says which lines moved and why. Across x86-64
CPUs the numbers are the same (the settings above); another architecture or C library may
differ in the last bits of sin / cos, hence a file per platform.
A first run of the generic target compiles every kernel for it (numba caches it beside the
host's code, one cache entry per target).
"""
from __future__ import annotations

import argparse
import contextlib
import io
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

#: (label, environment settings) of each run; the first is the reference
SETTINGS = (("host", {}),
            ("generic", {"NUMBA_CPU_NAME": "generic"}),
            ("threads=1", {"NUMBA_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}),
            ("threads=2", {"NUMBA_NUM_THREADS": "2", "OPENBLAS_NUM_THREADS": "2"}),
            # OpenBLAS's SSE3 kernels in place of the host's (numpy's BLAS picks its kernels per
            # CPU; a set-up that ran through it gave other bits on an AVX-512 machine than on an
            # AVX2 one: planarsim.dense)
            ("blas=sse3", {"OPENBLAS_CORETYPE": "Prescott"}))

#: stress-corpus runs fingerprinted: (family, seed), each for its family's whole run
CORPUS = (("biped_stance", 0), ("biped_collapse", 1), ("chain_hills", 2), ("mass_ratio", 3),
          ("shape_pile", 4), ("shape_hills", 5), ("loop_inertia", 36), ("loop_inertia", 162),
          ("hills_fast", 7), ("ranger_loop", 2))

#: pin chains fingerprinted (benchmarks.scenes.chain: links, steps), whose steps the pin-chain
#: path takes (kernels/solver/pin_chain.py; the walkers and the corpus runs all have contacts)
CHAINS = ((4, 2000), (16, 2000))


#: simulated time per walker [s] of the committed baseline
BASELINE_SECONDS = 1.0


def baseline_path() -> Path:
    """This platform's committed fingerprints."""
    import platform
    return ROOT / "benchmarks" / "results" / f"digests-{platform.machine()}-{sys.platform}.txt"


def corpus_lines():
    """One line per CORPUS run: a digest of every step's q and v [m, rad, m/s, rad/s] and how
    the run ended (the error's text, or ok)."""
    import numpy as np

    import planarsim as ps
    from benchmarks.contact_stress import MAX_STEPS, SECONDS, build, commands
    from benchmarks.walker_digests import digest
    for family, seed in CORPUS:
        model, _, q0, v0 = build(family, seed)
        n = min(int(round(SECONDS[family] / model.dt)), MAX_STEPS)
        u = commands(family, seed, model, n)
        sim = ps.Simulator(model, ps.make_options(), ps.make_state(model, q0, v0))
        frames, end = [np.concatenate([q0, v0])], "ok"
        try:
            for k in range(n):
                sim.step(None if u is None else u[k])
                frames.append(np.concatenate([sim.state.q, sim.state.v]))
        except ps.SimulationDiverged as exc:
            end = str(exc).splitlines()[0]
        yield f"{family:14s} {seed:4d} {digest(np.array(frames))} steps {len(frames) - 1} {end}"


def chain_lines():
    """One line per CHAINS run: a digest of every step's q and v and how many steps the
    pin-chain path took."""
    import numpy as np

    import planarsim as ps
    from benchmarks.scenes import chain
    from benchmarks.walker_digests import digest
    from planarsim.compiled import step_info
    for links, steps in CHAINS:
        sim = ps.Simulator(chain(links))
        frames, taken = [np.concatenate([sim.state.q, sim.state.v])], 0
        for _ in range(steps):
            sim.step()
            taken += step_info(sim.ws)["chain_path"]
            frames.append(np.concatenate([sim.state.q, sim.state.v]))
        yield f"chain{links:<13d} {digest(np.array(frames))} steps {steps} chain path {taken}"


def fingerprints(seconds):
    """This process's fingerprints: walker_digests' lines, then corpus_lines', then
    chain_lines'."""
    from benchmarks import walker_digests
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        walker_digests.main(["--seconds", str(seconds)])
    return out.getvalue().splitlines() + list(corpus_lines()) + list(chain_lines())


def run(settings, seconds):
    """The fingerprints of a fresh process with `settings` in its environment."""
    env = dict(os.environ, **settings)
    for name in ("NUMBA_CPU_NAME", "NUMBA_CPU_FEATURES"):
        if name not in settings:
            env.pop(name, None)
    done = subprocess.run([sys.executable, __file__, "--print", "--seconds", str(seconds)],
                          env=env, cwd=ROOT, capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(f'{k}={v}' for k, v in settings.items()) or 'host'}: "
                         f"the fingerprints' run failed:\n{done.stderr}")
    return done.stdout.splitlines()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=3.0, help="simulated time per walker [s]")
    ap.add_argument("--print", action="store_true", help="print this process's fingerprints")
    ap.add_argument("--write-baseline", action="store_true",
                    help=f"write this platform's baseline ({BASELINE_SECONDS} s per walker)")
    a = ap.parse_args(argv)
    if a.print:
        print("\n".join(fingerprints(a.seconds)))
        return 0
    if a.write_baseline:
        path = baseline_path()
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text("\n".join(run({}, BASELINE_SECONDS)) + "\n")
        print(f"wrote {path.relative_to(ROOT)}")
        return 0
    reference = None
    differing = 0
    for label, settings in SETTINGS:
        lines = run(settings, a.seconds)
        if reference is None:
            reference = lines
            print(f"{label}: {len(lines)} fingerprints")
            continue
        diff = [(x, y) for x, y in zip(reference, lines) if x != y]
        if len(lines) != len(reference):
            diff.append((f"{len(reference)} lines", f"{len(lines)} lines"))
        differing += bool(diff)
        print(f"{label}: " + ("identical" if not diff else f"{len(diff)} lines differ"))
        for x, y in diff:
            print(f"  host:   {x}\n  {label}: {y}")
    return 1 if differing else 0


if __name__ == "__main__":
    sys.exit(main())
