"""planarsim: an exact, fast planar physics engine for walking machines."""
__version__ = "0.1.0"

from .builder import ModelBuilder
from .errors import ModelError, SimulationDiverged
from .model import Model
from .options import ContactMode, ModeStrategy, StepOptions, make_options
from .sim import Simulator
from .state import State, make_state
from . import batch, terrain
from .energy import kinetic_energy, potential_energy, total_energy
from .snapshot import load_snapshot, save_snapshot
from .trajectory import Trajectory

__all__ = ["ModelBuilder", "Model", "ModelError", "SimulationDiverged", "Simulator", "State",
           "StepOptions", "batch", "ContactMode", "ModeStrategy", "make_options", "make_state", "terrain",
           "kinetic_energy", "potential_energy", "total_energy", "save_snapshot", "load_snapshot",
           "Trajectory", "__version__"]


def _publish_cached_step():
    # a cached compiled function may call the step's C function through another cached one
    # (kernels/step.py, load_step): publish its address now if the cache holds it
    from .kernels.step import load_step
    try:
        load_step(compile=False)
    except Exception as exc:   # a damaged cache must not break the import; the step recompiles
        import warnings
        warnings.warn(f"planarsim: could not load the cached step ({exc}); it will be compiled "
                      "on first use", RuntimeWarning, stacklevel=2)


_publish_cached_step()
