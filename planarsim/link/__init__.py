"""The link layer: what links the step (planarsim/kernels/step.py) to its callers, above the
compiler layer (planarsim/compile, which knows no physics) and the engine's data (model,
state, options).

    engine.py     the step's argument types: ModelArrays, State, Workspace and StepOptions
                  registered as one pointer each (compile/refs.py), a sample model's types,
                  and the check that names a wrong argument
    step.py       ``step`` as compiled code calls it, and its entries from Python (run_steps,
                  step_entry, run_recorded, step_from_python, bind): the same in every mode
    fast_step.py  the fast mode's step: one C function, published once per process, that all
                  compiled code calls by address; its parts (compile/parts.py) bound and
                  compiled beside it
    caches.py     which sources the engine's compiled code is built from, and planarsim's
                  (and its callers') stale numba caches cleared
    debug.py      stepping through the engine in pdb (NUMBA_DISABLE_JIT=1)

planarsim.compiled is the public front of this layer for compiled callers.
"""
