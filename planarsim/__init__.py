"""planarsim: an exact, fast planar physics engine for walking machines."""
__version__ = "0.1.0"

from .link import caches as _caches   # noqa: F401  (planarsim's stale numba caches cleared first)
from .builder import ModelBuilder
from .errors import AuditViolation, ModelError, SimulationDiverged, WorkspaceTooLarge
from .model import Model
from .options import ContactMode, ModeStrategy, StepOptions, make_options
from .sim import Simulator
from .state import State, make_state, make_workspace
from . import batch, measure, terrain
from .energy import kinetic_energy, potential_energy, total_energy
from .snapshot import load_snapshot, save_snapshot
from .trajectory import Trajectory

__all__ = ["ModelBuilder", "Model", "ModelError", "SimulationDiverged", "AuditViolation", "WorkspaceTooLarge",
           "Simulator", "State", "StepOptions", "batch", "measure", "ContactMode", "ModeStrategy", "make_options",
           "make_state", "make_workspace", "terrain",
           "kinetic_energy", "potential_energy", "total_energy", "save_snapshot", "load_snapshot",
           "Trajectory", "__version__"]
