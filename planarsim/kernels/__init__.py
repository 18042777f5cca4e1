"""The physics stages of the step (numba kernels). Private: use the public wrappers in planarsim.

Their decorators and the step's linkage are planarsim's compiler layer (planarsim/compile)."""
