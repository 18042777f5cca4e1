"""Helpers shared by walker controllers (compiled): Bezier curves, PD laws."""
from planarsim.compiled import drop_stale_caches

drop_stale_caches(__path__[0])
