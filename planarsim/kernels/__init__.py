"""Compiled kernels (numba). Private: use the public wrappers in planarsim."""
