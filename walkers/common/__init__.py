"""Helpers shared by walker controllers (compiled): Bezier curves, PD laws."""
from planarsim.kernels._jit import drop_stale_caches

drop_stale_caches(__path__[0])
