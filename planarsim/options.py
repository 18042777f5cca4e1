"""StepOptions: the integer and float switches that choose algorithms inside the step."""
from __future__ import annotations

from enum import IntEnum
from typing import NamedTuple

MODES_ALTERNATING = 0   # the seed's scheme: check one contact per step, in turn
MODES_ALL = 1           # check every contact each step, iterate to a consistent set
MODES_COUNT = 2


class ModeStrategy(IntEnum):
    ALTERNATING = MODES_ALTERNATING
    ALL = MODES_ALL


class ContactMode(IntEnum):
    FREE = 0
    PINNED = 1
    SLIDING = 2


class StepOptions(NamedTuple):
    """Algorithm switches passed to the compiled step.

    mode_strategy : MODES_ALTERNATING (default) or MODES_ALL
    max_mode_iters : cap on solve / mode-check rounds within one step
    refine_iters : Newton-SHAKE position corrections after integrating (0: off)
    refine_tol : stop refining when every constraint residual is below this [m or rad]
    max_ccd_splits : cap on time-of-impact splits of one step
    guard_limit : any |q| or |v| component above this stops the run
    pivot_tol : relative pivot below which a constraint row is treated as redundant (closed loops)
    cap_policy : when the mode rounds hit max_mode_iters: 1 (default) contacts engaged in this
        step stick (never left free below the ground); 0 the modes of the last round stand
        (the seed's tolerance: a cycling contact may be left free and sink for a step)
    """
    mode_strategy: int = MODES_ALTERNATING
    max_mode_iters: int = 8
    refine_iters: int = 4
    refine_tol: float = 1e-12
    max_ccd_splits: int = 4
    guard_limit: float = 1e10
    pivot_tol: float = 1e-11
    cap_policy: int = 1


def make_options(strategy="alternating", refine=True, **kw) -> StepOptions:
    """StepOptions from friendly names: strategy 'alternating' | 'all'; refine on/off."""
    names = {"alternating": MODES_ALTERNATING, "all": MODES_ALL}
    if isinstance(strategy, str):
        if strategy not in names:
            raise ValueError(f"contact-mode strategy {strategy!r} unknown; use 'alternating' or 'all'")
        strategy = names[strategy]
    if not refine:
        kw["refine_iters"] = 0
    return StepOptions(mode_strategy=int(strategy), **kw)
