"""The physics stages of the step (numba kernels). Private: use the public wrappers in planarsim.

Their decorators and the step's linkage are planarsim's compiler layer (planarsim/compile).

The modules sit in one folder per group of stages (geometry/, constraints/, solver/,
dynamics/, checks/: stages.py names each stage's modules with their folder); what every
stage uses, and the step itself, stays here."""
