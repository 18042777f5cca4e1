"""The walker contract: what a walker module registered in walkers.WALKERS offers, so that the
command line, tuning, batches, the viewer and the summary treat every walker alike
(tests/walkers/test_contract.py checks every shipped walker against it).

A walker module has
  NAME            its command-line name
  GAITS           its gait names; simulate's `gait` default is one of them
  Params          its parameter dataclass (walkers.common.params.WalkerParams: every field with
                  unit, bounds and doc; TUNABLE names the fields tuning may vary)
  SUMMARY_EXTRAS  {raw summary key: (name with unit, meaning) or None}: its own numbers beyond
                  the common summary (walkers.common.summary)
  FEET            optional: groups of contact names that are one foot each (default: by name)
  simulate(duration, gait=..., terrain=None, dt=1e-3, seed=0, params=None, record_every=10, ...)
                  -> (Trajectory, summary dict, Model); the summary has at least `fell`,
                  `audit` and `time` (or `duration`) and otherwise only keys its
                  SUMMARY_EXTRAS or walkers.common.summary.REPLACED declare
  live(gait=..., terrain=None, ...)
                  optional: the interactive viewer's hook (planarsim.render.viewer.view_walker)
and, to be tunable, a sibling module `objective` (Params, DEFAULT_SETTINGS,
evaluate(params, settings) -> {"score": ...}).
Its compiled rollout stops with planarsim.compiled's run codes: RUN_OK, an engine failure
(raised with check_run), or its own reasons from RUN_WALKER up (RUN_FELL).
"""
from __future__ import annotations

import inspect

SIMULATE_KEYWORDS = ("gait", "terrain", "dt", "seed", "params", "record_every")
REQUIRED = ("NAME", "GAITS", "Params", "SUMMARY_EXTRAS", "simulate")


def contract_problems(name: str, module) -> list:
    """What walker module `module` (registered as `name`) lacks of the contract; [] if nothing."""
    problems = [f"no {attr}" for attr in REQUIRED if not hasattr(module, attr)]
    if problems:
        return problems
    if module.NAME != name:
        problems.append(f"NAME is {module.NAME!r}, registered as {name!r}")
    sig = inspect.signature(module.simulate)
    missing = [k for k in SIMULATE_KEYWORDS if k not in sig.parameters]
    if missing:
        problems.append(f"simulate() lacks the keywords {missing}")
    elif sig.parameters["gait"].default not in module.GAITS:
        problems.append(f"simulate()'s default gait {sig.parameters['gait'].default!r} is not in GAITS")
    from walkers.common.params import WalkerParams
    if not (isinstance(module.Params, type) and issubclass(module.Params, WalkerParams)):
        problems.append("Params is not a WalkerParams dataclass")
    for key, spec in module.SUMMARY_EXTRAS.items():
        if spec is not None and not (isinstance(spec, tuple) and len(spec) == 2 and all(spec)):
            problems.append(f"SUMMARY_EXTRAS[{key!r}] is not (name with unit, meaning)")
    return problems
