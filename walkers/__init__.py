"""Walker packages. ``WALKERS`` maps command-line names to module paths (used by the CLI).

Each walker module exposes ``NAME``, ``GAITS``, ``Params`` (its parameter dataclass, see
walkers.common.params), ``Run`` (its run class, a walkers.base.WalkerRun) and
``simulate(duration, gait=..., terrain=None, dt=1e-3, seed=0, params=None, ...) -> (Trajectory, summary, model)``
(walkers/base.py has the whole contract).
A walker is tunable (planarsim tune) when its package has an ``objective`` module.
"""
import importlib

WALKERS = {
    "quadruped": "walkers.quadruped",
    "ranger": "walkers.ranger",
    "simbicon": "walkers.simbicon",
    "simple-biped": "walkers.simple_biped",
    "simplest-walker": "walkers.passive.simplest",
    "compass-gait": "walkers.passive.compass_gait",
    "rimless-wheel": "walkers.passive.rimless_wheel",
}


def load(name: str):
    """Import the walker package registered under `name` (a KeyError names the known ones)."""
    if not isinstance(name, str) or name not in WALKERS:
        raise KeyError(f"unknown walker {name!r}; known walkers: {sorted(WALKERS)}")
    return importlib.import_module(WALKERS[name])


def objective(name: str):
    """The tuning objective module of walker `name` (``<package>.objective``), or None if the
    walker has none (the passive walkers: nothing to tune)."""
    mod = load(name)
    package = mod.__name__ if hasattr(mod, "__path__") else None
    if package is None:
        return None
    try:
        return importlib.import_module(package + ".objective")
    except ModuleNotFoundError as e:
        if e.name != package + ".objective":
            raise
        return None
