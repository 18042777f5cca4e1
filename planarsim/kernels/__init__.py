"""Compiled kernels (numba). Private: use the public wrappers in planarsim.

Importing them first checks the numba internals they build on (numba_check.py)."""
from .numba_check import check_numba

check_numba()
