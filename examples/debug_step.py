"""Step through one step of Ranger's contact solve in pdb, with the compiled run's numbers.

    NUMBA_DISABLE_JIT=1 python examples/debug_step.py

Under NUMBA_DISABLE_JIT=1 every kernel of the engine and of the walker runs as Python
(planarsim/compile/mode.py). Ranger walks 0.3 s (300 steps), then pdb stops where the next step
enters the contact solve (planarsim/kernels/solver/solve.py solve_impulses): `n` steps a line, `s`
steps into a call, `p ws.lam[:n]` prints the impulses, `c` finishes the step. Without the
variable the walk is compiled and no breakpoint can stop inside it: the script says so.
"""
import sys

import walkers
from planarsim.compile import MODE, PYTHON
from planarsim.link.debug import break_in


def main(seconds=0.3):
    if MODE != PYTHON:
        sys.exit("run me as: NUMBA_DISABLE_JIT=1 python examples/debug_step.py "
                 "(compiled code has no line for pdb to stop on)")
    run = walkers.load("ranger").Run(gait="walk")
    run.run(seconds)                                  # as Python: the same numbers as compiled
    debugger = break_in("solver.solve.solve_impulses")   # planarsim/kernels/solver/solve.py
    print(f"t = {run.trajectory().t[-1]:.3f} s; stepping once: 'c' runs on to the contact solve")
    debugger.runcall(run.run, run.model.dt)           # one step, stopping in solve_impulses
    return run


if __name__ == "__main__":
    main()
