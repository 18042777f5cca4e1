"""Ranger's stride-map multipliers for the default gait and the tuned one (--params efficient):
the eigenvalues of RangerGaitMap(params).jacobian(), a least-squares slope of the stride map,
and the largest modulus (docs/walkers.md's table; benchmarks/results/ranger-multipliers.txt).

    python benchmarks/ranger_multipliers.py
"""
import dataclasses, numpy as np
from pathlib import Path
import walkers.ranger as ranger
from walkers.common.params import load_values
from walkers.ranger.params import RangerParams
from walkers.ranger.gait_map import RangerGaitMap
values = load_values(Path(ranger.__file__).parent / "efficient.json", RangerParams)
for name, p in (("default", RangerParams()), ("efficient", dataclasses.replace(RangerParams(), **values))):
    lam = np.linalg.eigvals(RangerGaitMap(params=p).jacobian())
    print(name, "stride-map multipliers:", np.round(lam, 3), "largest |lambda|", round(float(np.max(np.abs(lam))), 4), flush=True)
