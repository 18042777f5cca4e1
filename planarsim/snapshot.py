"""Snapshots on disk: the complete State (and any controller memory) saved atomically with a
format version, so that a restored run continues bit for bit.

>>> save_snapshot("s.npz", sim.state, memory={"fsm": ctrl_memory})   # doctest: +SKIP
>>> state, memory = load_snapshot("s.npz")
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .model import Model
from .state import State, check_state, with_defaults
from .trajectory import atomic_write, file_with_suffix, read_npz

SNAPSHOT_VERSION = 2   # 2: the State holds the last step's impulses


def save_snapshot(path, state: State, memory: dict | None = None) -> Path:
    """Write state (a State: sim.state) and memory (name -> array) to a .npz atomically."""
    path = file_with_suffix(path, ".npz", "snapshot")
    if not isinstance(state, State):
        hint = " (a Simulator's is sim.state)" if hasattr(state, "state") else ""
        raise TypeError(f"save_snapshot: state must be a planarsim State{hint}, got "
                        f"{type(state).__name__}")
    if memory is not None and not isinstance(memory, dict):
        raise TypeError(f"save_snapshot: memory must be a dict (name -> array) or None, got "
                        f"{type(memory).__name__}")
    payload = {f"state__{k}": v for k, v in state.as_dict().items()}
    for k, v in (memory or {}).items():
        arr = np.asarray(v)
        if not isinstance(k, str) or arr.dtype.kind not in "biufcUS":
            # an object array is pickled, which load_snapshot (allow_pickle=False) then
            # refuses as a damaged file: refused here, before anything is written
            raise TypeError(f"save_snapshot: memory[{k!r}] = {type(v).__name__} must be numbers "
                            "(an array or a number) under a string name, which load_snapshot "
                            "reads back")
        payload[f"memory__{k}"] = arr
    payload["snapshot_version"] = np.array(SNAPSHOT_VERSION)
    atomic_write(path, lambda f: np.savez(f, **payload))
    return path


def load_snapshot(path, model=None):
    """Read a snapshot: returns (State, memory dict). Clear errors for damaged files; a state
    whose arrays disagree in shape (or, given `model`, do not fit it), hold NaN or infinite
    numbers or codes out of range raises ValueError naming the file and the field
    (state.check_state); a `model` that is no Model a TypeError, before the file is read."""
    if model is not None and not isinstance(model, Model):
        raise TypeError(f"load_snapshot: model={model!r} must be a planarsim Model (from "
                        "ModelBuilder.compile()) to check the state against, or None")
    path = Path(path)
    data = read_npz(path, "snapshot")
    version = int(data.get("snapshot_version", -1))
    if version != SNAPSHOT_VERSION:
        raise ValueError(f"{path}: snapshot format version {version}; this planarsim reads version "
                         f"{SNAPSHOT_VERSION}")
    arrays = with_defaults({k[7:]: v for k, v in data.items() if k.startswith("state__")})
    missing = [k for k in State._fields if k not in arrays]
    if missing:
        raise ValueError(f"{path}: snapshot is missing state arrays {missing}")
    state = State(*(np.array(arrays[k]) for k in State._fields))
    check_state(state, model, what=f"{path}: snapshot state")
    memory = {k[8:]: v for k, v in data.items() if k.startswith("memory__")}
    return state, memory
