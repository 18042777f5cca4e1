"""Trajectory: recorded arrays of a run, with save/load (.npz, atomic) and CSV export.

Frame 0 holds the state a run starts from (its impulses, commands and powers are those of the
step before it, zero for a fresh state); every later frame the state after a recorded step
(steps whose count is a multiple of record_every). contact_mode is 0 free, 1 pinned, 2 sliding,
-1 disabled. contact_impulse is (normal, tangential) impulse of the step [N s]; divide by dt
for a mean force [N]. act_power is the mechanical power of each actuator [W]: its command times
its coordinate's move (joint angle, anchors' distance, slide, ...) over the steps since the frame
before, divided by their time, so that the time between two frames times it is the work the
command did in between (every step recorded: the step's own).
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import NamedTuple

import numpy as np

from . import memory
from .energy import kinetic_energy, potential_energy
from .errors import RecordingTooLarge
from .files import discard, publish, staging_file
from .state import check_shapes
from .terrain import from_coef

FORMAT_VERSION = 1

# Every recorded per-frame array, declared once: its name, its dimensions over K frames, its
# dtype and where a frame's value comes from (a State or Workspace field). Recorder,
# FRAME_DIMS, make_recorder, record_state and Trajectory's arrays follow this table; a new
# quantity also needs its Trajectory field and its line in kernels/record.py (compiled code).
RECORDED = (
    ("t", ("K",), np.float64, "state.time"),                       # [s]
    ("q", ("K", "n_body", 3), np.float64, "state.q"),              # x [m], y [m], theta [rad]
    ("v", ("K", "n_body", 3), np.float64, "state.v"),              # [m/s], [m/s], [rad/s]
    ("contact_mode", ("K", "n_contact"), np.int64, "state.contact_mode"),   # -1 disabled
    ("contact_impulse", ("K", "n_contact", 2), np.float64, "ws.contact_impulse"),   # [N s]
    ("contact_point", ("K", "n_contact", 2), np.float64, "ws.contact_point"),       # [m]
    ("act_u", ("K", "n_act"), np.float64, "ws.act_u"),             # [N or N m]
    ("act_power", ("K", "n_act"), np.float64, "ws.act_power"),     # [W]
    # unit normal of each contact (the ground's, or a shape pair's, from the reference shape
    # to the other)
    ("contact_normal", ("K", "n_contact", 2), np.float64, "ws.contact_normal"),
)
FRAME_DIMS = {name: dims for name, dims, _, _ in RECORDED}   # shape of each per-frame array


def terrain_info(model) -> dict:
    """{terrain: name, terrain_coef: coefficients as a tuple} of the model's terrain: what a
    Trajectory records so that it reproduces its ground."""
    coef = np.asarray(model.arrays.terrain_coef, dtype=np.float64)
    ter = getattr(model, "terrain", None)
    if ter is None:
        return {"terrain": "none"}      # no ground (ModelBuilder(ground=None))
    return {"terrain": str(getattr(ter, "name", "terrain")), "terrain_coef": tuple(coef.tolist())}


Recorder = NamedTuple("Recorder", [(name, np.ndarray) for name, *_ in RECORDED])
Recorder.__doc__ = "Preallocated frame arrays (RECORDED) filled by kernels.record.record_frame."


def frame_bytes(model, extra_columns: int = 0) -> int:
    """Memory [bytes] of one recorded frame of `model` (a Recorder's arrays, plus
    `extra_columns` float64 labels per frame)."""
    sizes = dict(n_body=model.n_body, n_contact=model.n_contact, n_act=model.n_act)
    items = sum(int(np.prod([sizes.get(d, d) for d in dims[1:]])) for dims in FRAME_DIMS.values())
    return 8 * (items + int(extra_columns))   # every recorded dtype is 8 bytes


def check_recording(model, n_frames, what: str = "", extra_columns: int = 0) -> None:
    """Raise RecordingTooLarge, before anything is allocated, when `n_frames` frames of
    `model` (frame_bytes) need more memory than the machine has (machine_memory). `what`
    says what asked for them (a run's duration, say)."""
    need = int(n_frames) * frame_bytes(model, extra_columns)
    have = memory.machine_memory()
    if have and need > have:
        raise RecordingTooLarge(
            f"{what + ': ' if what else ''}recording {int(n_frames):,} frames needs "
            f"{memory.gib(need)} of memory, more than this machine's {memory.gib(have)}; record fewer frames "
            f"(a shorter run, or a frame every more steps)", n_frames, need, have)


def make_recorder(model, n_frames: int) -> Recorder:
    """Zeroed frame arrays for `n_frames` frames (RecordingTooLarge, before allocating, if
    they cannot fit in the machine's memory)."""
    sizes = dict(K=int(n_frames), n_body=model.n_body, n_contact=model.n_contact, n_act=model.n_act)
    check_recording(model, sizes["K"])
    return Recorder(*(np.zeros(tuple(sizes.get(d, d) for d in dims), dtype)
                      for _, dims, dtype, _ in RECORDED))


def record_state(rec: Recorder, k: int, state, ws) -> None:
    """Write State `state` and Workspace `ws` into frame k of rec, as the compiled
    kernels.record.record_frame does after a step (here from Python, for a run's first frame)."""
    sources = {"state": state, "ws": ws}
    ws.act_work[:] = 0.0        # (a run's first frame: the work of later frames from here)
    ws.act_work_time[:] = 0.0
    for name, _, _, source in RECORDED:
        owner, attr = source.split(".")
        value = np.asarray(getattr(sources[owner], attr))
        if name == "contact_mode":   # a disabled contact is -1
            value = np.where(np.asarray(state.contact_enabled) != 0, value, -1)
        getattr(rec, name)[k] = value[0] if name == "t" else value


@dataclass
class Trajectory:
    """Recorded run. Arrays as in Recorder; `labels` holds extra per-frame series (e.g. the
    controller's gait/state as ints under 'phase'); `info` holds scalars (walker, dt, ...) and
    the terrain the run was on: ``terrain`` (its name, a spec planarsim.terrain.parse reads
    for the command line's terrains) and ``terrain_coef`` (its coefficients, exact; see
    terrain())."""
    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    contact_mode: np.ndarray
    contact_impulse: np.ndarray
    contact_point: np.ndarray
    act_u: np.ndarray
    act_power: np.ndarray
    contact_normal: np.ndarray = None   # (K, n_contact, 2); NaN where a file had none
    body_names: tuple = ()
    contact_names: tuple = ()
    act_names: tuple = ()
    labels: dict = field(default_factory=dict)
    info: dict = field(default_factory=dict)

    _ARRAYS = tuple(FRAME_DIMS)

    @classmethod
    def from_recorder(cls, model, rec: Recorder, n: int | None = None, **kw) -> "Trajectory":
        n = len(rec.t) if n is None else int(n)
        arrs = {k: np.array(getattr(rec, k)[:n]) for k in cls._ARRAYS}
        kw["info"] = {**terrain_info(model), **kw.get("info", {})}
        return cls(**arrs, body_names=model.body_names, contact_names=model.contact_names,
                   act_names=model.act_names, **kw)

    def terrain(self):
        """The planarsim.terrain.Terrain the run was on (from info's terrain_coef and
        terrain), or None for a world without ground or a recording that did not keep it."""
        coef = self.info.get("terrain_coef")
        if coef is None:
            return None
        name = self.info.get("terrain")
        return from_coef(np.asarray(coef, dtype=np.float64), None if name is None else str(name))

    @classmethod
    def concatenate(cls, chunks) -> "Trajectory":
        """Join trajectories recorded one after another (chunks of one run) into one; labels
        are those the chunks share, names and info come from the first chunk."""
        chunks = list(chunks)
        if not chunks:
            raise ValueError("concatenate needs at least one trajectory")
        first = chunks[0]
        for k, c in enumerate(chunks):
            if not isinstance(c, Trajectory):
                raise TypeError(f"Trajectory.concatenate: chunk {k} is {type(c).__name__}, not a "
                                "Trajectory")
            for names in ("body_names", "contact_names", "act_names"):
                if tuple(getattr(c, names)) != tuple(getattr(first, names)):
                    raise ValueError(f"Trajectory.concatenate: chunk {k} has {names} "
                                     f"{list(getattr(c, names))} but chunk 0 has "
                                     f"{list(getattr(first, names))}: chunks of one run only")
        if len(chunks) == 1:
            return chunks[0]
        arrays = {k: np.concatenate([getattr(c, k) for c in chunks]) for k in cls._ARRAYS}
        shared = [k for k in first.labels if all(k in c.labels for c in chunks)]
        labels = {k: np.concatenate([np.asarray(c.labels[k]) for c in chunks]) for k in shared}
        return cls(**arrays, body_names=first.body_names, contact_names=first.contact_names,
                   act_names=first.act_names, labels=labels, info=dict(first.info))

    def __len__(self):
        return len(self.t)

    def com(self, model) -> np.ndarray:
        """(K, 2) centre of mass [m]."""
        check_recorded_by(self, model, "Trajectory.com")
        m = model.arrays.body_mass
        return np.einsum("b,kbc->kc", m, self.q[:, :, :2]) / m.sum()

    def com_velocity(self, model) -> np.ndarray:
        check_recorded_by(self, model, "Trajectory.com_velocity")
        m = model.arrays.body_mass
        return np.einsum("b,kbc->kc", m, self.v[:, :, :2]) / m.sum()

    def energy(self, model) -> dict:
        """Kinetic, potential and total energy per frame [J]."""
        check_recorded_by(self, model, "Trajectory.energy")
        ke = kinetic_energy(model, self.q, self.v)
        pe = potential_energy(model, self.q)
        return {"kinetic": ke, "potential": pe, "total": ke + pe}

    # files ------------------------------------------------------------------------------------
    def save(self, path) -> Path:
        """Write a .npz atomically (temporary file, then rename) with a format version."""
        path = file_with_suffix(path, ".npz", "trajectory")
        payload = {k: getattr(self, k) for k in self._ARRAYS}
        payload["format_version"] = np.array(FORMAT_VERSION)
        payload["body_names"] = np.array(self.body_names, dtype=str)
        payload["contact_names"] = np.array(self.contact_names, dtype=str)
        payload["act_names"] = np.array(self.act_names, dtype=str)
        for k, v in self.labels.items():
            payload[f"label__{k}"] = np.asarray(v)
        for k, v in self.info.items():
            payload[f"info__{k}"] = np.asarray(v)
        atomic_write(path, lambda f: np.savez_compressed(f, **payload))
        return path

    @classmethod
    def load(cls, path) -> "Trajectory":
        """Read a .npz written by save. ValueError naming the file for a damaged file, another
        format version, missing arrays, or arrays whose shapes disagree (FRAME_DIMS)."""
        path = Path(path)
        data = read_npz(path, "trajectory")
        version = int(data.get("format_version", -1))
        if version != FORMAT_VERSION:
            raise ValueError(f"{path}: trajectory format version {version}; this planarsim reads "
                             f"version {FORMAT_VERSION}")
        if "contact_normal" not in data and "contact_point" in data:
            # written before normals were recorded: unknown (drawn along the ground's normal)
            data["contact_normal"] = np.full(np.shape(data["contact_point"]), np.nan)
        missing = [k for k in cls._ARRAYS if k not in data]
        if missing:
            raise ValueError(f"{path}: trajectory is missing arrays {missing}")
        check_shapes(data, FRAME_DIMS, f"{path}: trajectory")
        return cls(**{k: data[k] for k in cls._ARRAYS},
                   body_names=tuple(data["body_names"].tolist()),
                   contact_names=tuple(data["contact_names"].tolist()),
                   act_names=tuple(data["act_names"].tolist()),
                   labels={k[7:]: data[k] for k in data if k.startswith("label__")},
                   info={k[6:]: data[k].item() if data[k].ndim == 0 else data[k]
                         for k in data if k.startswith("info__")})

    def to_csv(self, path, model=None) -> Path:
        """One row per frame, SI units in every column name (csv_columns); with the model, each
        actuator's applied effort is named torque_Nm or force_N by its kind. `path` must end
        in .csv (as save's in .npz)."""
        path = file_with_suffix(path, ".csv", "CSV")
        if model is not None:       # another model's names and kinds would head the columns
            check_recorded_by(self, model, "Trajectory.to_csv")
        cols, blocks = csv_columns(self, model)
        table = np.hstack([np.asarray(b, dtype=np.float64).reshape(len(self.t), -1) for b in blocks])
        atomic_write(path, lambda f: np.savetxt(f, table, delimiter=",", header=",".join(cols),
                                                comments="", fmt="%.10g"), binary=False)
        return path


# per-column unit suffixes of the CSV
_BODY_COLS = ("x_m", "y_m", "theta_rad", "vx_m_per_s", "vy_m_per_s", "omega_rad_per_s")
# actuator kinds (model.ACT_*): what their command is, once saturated
_EFFORT = {0: "torque_Nm", 1: "force_N", 2: "torque_Nm", 3: "force_N", 4: "torque_Nm"}


# Trajectory's array fields are RECORDED's, in its order (a field added to one and not the other
# fails here, on import)
assert tuple(f for f in Trajectory.__dataclass_fields__ if f in FRAME_DIMS) == Trajectory._ARRAYS, \
    "Trajectory's array fields must be trajectory.RECORDED's"


def csv_columns(traj, model=None) -> tuple:
    """(column names, per-frame blocks) of Trajectory.to_csv:

    t_s; per body NAME.x_m, .y_m, .theta_rad, .vx_m_per_s, .vy_m_per_s, .omega_rad_per_s;
    per contact NAME.mode (0 free, 1 pinned, 2 sliding, -1 disabled), .impulse_n_Ns and
    .impulse_t_Ns (normal and tangential impulse of the step; / dt for a mean force),
    .point_x_m, .point_y_m; per actuator its applied (saturated) command NAME.torque_Nm or
    NAME.force_N (NAME.u, in N or N m, without the model) and NAME.power_W; then the labels
    (controller gait/state codes, ...).
    """
    K = len(traj.t)
    cols, blocks = ["t_s"], [traj.t]
    bodies = traj.body_names or [f"body{i}" for i in range(traj.q.shape[1])]
    for i, name in enumerate(bodies):
        cols += [f"{name}.{c}" for c in _BODY_COLS]
        blocks += [traj.q[:, i, :], traj.v[:, i, :]]
    contacts = traj.contact_names or [f"contact{i}" for i in range(traj.contact_mode.shape[1])]
    for i, name in enumerate(contacts):
        cols += [f"{name}.mode", f"{name}.impulse_n_Ns", f"{name}.impulse_t_Ns",
                 f"{name}.point_x_m", f"{name}.point_y_m"]
        blocks += [traj.contact_mode[:, i], traj.contact_impulse[:, i, :], traj.contact_point[:, i, :]]
    acts = traj.act_names or [f"act{i}" for i in range(traj.act_u.shape[1])]
    kinds = list(model.arrays.act_kind) if model is not None else [None] * len(acts)
    if model is not None and tuple(model.act_names) != tuple(acts):
        raise ValueError(f"the model's actuators {list(model.act_names)} are not the trajectory's "
                         f"{list(acts)}: wrong model for this trajectory?")
    for i, (name, kind) in enumerate(zip(acts, kinds)):
        cols += [f"{name}.{_EFFORT.get(int(kind), 'u') if kind is not None else 'u'}", f"{name}.power_W"]
        blocks += [traj.act_u[:, i], traj.act_power[:, i]]
    for k, v in traj.labels.items():
        v = np.asarray(v)
        if v.ndim == 1 and len(v) == K:
            cols.append(k)
            blocks.append(v)
    return cols, blocks


def file_with_suffix(path, suffix: str, what: str) -> Path:
    """`path` as a Path; a ValueError naming it, `what` file it is and `suffix` unless its
    name ends in `suffix` (".npz", ".csv")."""
    path = Path(path)
    if path.suffix != suffix:
        raise ValueError(f"{what} file {str(path)!r} must end in {suffix}")
    return path


def read_npz(path, what: str) -> dict:
    """All arrays of a .npz file; a damaged file raises ValueError naming `what` it should be."""
    try:
        with np.load(path, allow_pickle=False) as z:
            return {k: z[k] for k in z.files}
    except FileNotFoundError:
        raise
    except Exception as e:  # zipfile.BadZipFile, ValueError, EOFError, OSError ...
        raise ValueError(f"{path}: not a readable planarsim {what} (truncated or corrupted?): {e}") from None


def atomic_write(path, write, binary=True) -> None:
    """Call write(fileobj) on a temporary file, then move it onto `path` in one step
    (planarsim.files): an interrupted write (error, Ctrl-C, SIGKILL) leaves no file under
    the final name and none beside it.
    """
    path = Path(path)
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.is_dir():
        raise OSError(f"cannot write {str(path)!r}: folder {str(parent)!r} does not exist")
    if not os.access(parent, os.W_OK):
        raise OSError(f"cannot write {str(path)!r}: folder {str(parent)!r} is not writable")
    tmp = staging_file(path)
    try:
        with open(tmp, "wb" if binary else "w") as f:
            write(f)
        publish(tmp, path)
    except BaseException:
        discard(tmp)
        raise


def check_recorded_by(traj, model, who):
    """ValueError naming `who` where traj's frames do not hold model's bodies (n_body, 3);
    TypeError naming it where model is not a Model or traj not a Trajectory."""
    from .model import Model
    if not isinstance(model, Model):
        raise TypeError(f"{who}: model={model!r} must be the planarsim Model the trajectory was "
                        "recorded with")
    if not isinstance(traj, Trajectory):
        raise TypeError(f"{who}: traj={type(traj).__name__} must be a planarsim Trajectory "
                        "(Simulator.run, a walker's simulate, Trajectory.load)")
    q = np.asarray(traj.q)
    if q.ndim != 3 or q.shape[1:] != (model.n_body, 3):
        raise ValueError(f"{who}: the trajectory has {q.shape[1] if q.ndim == 3 else '?'} "
                         f"bodies per frame but the model has {model.n_body} "
                         f"({list(model.body_names)}): wrong model for this trajectory?")
