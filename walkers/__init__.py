"""Walker packages. ``WALKERS`` maps command-line names to module paths (used by the CLI).

Each walker module exposes ``NAME``, ``GAITS`` and
``simulate(duration, gait=..., terrain=None, dt=1e-3, seed=0, ...) -> (Trajectory, summary, model)``.
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
    if name not in WALKERS:
        raise KeyError(f"unknown walker {name!r}; known walkers: {sorted(WALKERS)}")
    return importlib.import_module(WALKERS[name])
