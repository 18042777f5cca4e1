"""This machine's memory, for the checks that refuse a recording or a workspace before
allocating what cannot fit (planarsim/trajectory.py, planarsim/state.py)."""
from __future__ import annotations

import os


def machine_memory() -> int:
    """This machine's physical memory [bytes]; 0 where the system does not say."""
    try:
        return int(os.sysconf("SC_PHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE"))
    except (AttributeError, OSError, ValueError):
        return 0


def gib(nbytes) -> str:
    return f"{nbytes / 2 ** 30:.3g} GiB"
