"""Step events from a recorded run: the touchdown of a contact is a frame whose contact mode is
in contact (pinned or sliding) after a frame where it was not (free, or disabled: -1);
Poincare-section points at those frames.

Frame 0 of a recording is the state the run started from: its contact modes are the ones that
state was built with (a fresh state calls a foot standing on the ground free), not modes a step
found, so a change of mode from frame 0 to frame 1 is no event."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np

from ..checks import finite_number

IN_CONTACT = (1, 2)   # contact modes that touch the ground: pinned, sliding


# step events ---------------------------------------------------------------------------------
def touchdowns(contact_mode: np.ndarray) -> np.ndarray:
    """Frames at which a contact touches down.

    contact_mode : (K,) modes of one contact per recorded frame (0 free, 1 pinned, 2 sliding,
        -1 disabled).
    Returns the frame indices k >= 2 with mode[k] in contact and mode[k-1] not (frame 0 is
    the run's start: module doc).
    """
    mode = np.asarray(contact_mode)
    if mode.ndim != 1:
        raise ValueError(f"contact_mode must be 1-D (frames of one contact), got shape {mode.shape}")
    return _entries(np.isin(mode, IN_CONTACT))


def _entries(on: np.ndarray) -> np.ndarray:
    """Frames k >= 2 where `on` (K,) bool turns True."""
    return np.flatnonzero(on[2:] & ~on[1:-1]) + 2


@dataclass(frozen=True)
class StepEvents:
    """Touchdowns of several contacts, in time order.

    frame : (n,) int   recorded frame just after the touchdown
    time : (n,) [s]
    contact : (n,) int contact index that touched down
    """
    frame: np.ndarray
    time: np.ndarray
    contact: np.ndarray

    def __len__(self):
        return len(self.frame)

    @property
    def periods(self) -> np.ndarray:
        """(n - 1,) time between consecutive touchdowns [s]."""
        return np.diff(self.time)


def _contact_index(traj, contact) -> int:
    if isinstance(contact, str):
        names = list(traj.contact_names)
        if contact not in names:
            raise KeyError(f"no contact named {contact!r} in the trajectory; have {names}")
        return names.index(contact)
    c = int(contact)
    if not 0 <= c < traj.contact_mode.shape[1]:
        raise IndexError(f"contact index {c} out of range 0..{traj.contact_mode.shape[1] - 1}")
    return c


def foot_groups(contact_names) -> list:
    """Contacts grouped into feet by name: 'left_sole/0' .. 'left_sole/3' (the corners of one
    box foot, as add_box_contacts names them) are one foot; any other contact is a foot of
    its own. Returns a list of lists of contact indices."""
    groups = {}
    for i, name in enumerate(contact_names):
        groups.setdefault(str(name).split("/")[0], []).append(i)
    return list(groups.values())


def foot_x(traj, model, idx) -> np.ndarray:
    """(K,) horizontal position [m] of a foot (contact indices `idx`): the mean of its
    contacts' body-fixed points (an arc's centre, a pair slot's body) at every frame."""
    a = model.arrays
    q = np.asarray(traj.q)
    xs = []
    for c in idx:
        b = int(a.contact_body[c])
        lx, ly = a.contact_local[c]
        th = q[:, b, 2]
        xs.append(q[:, b, 0] + np.cos(th) * lx - np.sin(th) * ly)
    return np.mean(xs, axis=0)


def _lands_elsewhere(f, on, x, min_stride):
    """The landings `f` of one foot (on: (K,) in contact; x: (K,) its position) that follow a
    lift from the ground and land at least min_stride [m] from where the foot left it (a
    foot's first touch, with no lift before it, is a landing but not a step: a body dropped
    or falling onto the ground)."""
    left = np.flatnonzero(~on[1:] & on[:-1])       # last frames on the ground before a lift
    keep = []
    for k in f:
        before = left[left < k]
        keep.append(len(before) > 0 and abs(x[k] - x[before[-1]]) >= min_stride)
    return f[np.array(keep, dtype=bool)] if len(f) else f


def step_events(traj, contacts: Sequence | None = None, feet: Sequence | None = None,
                min_air: float = 0.0, together: float = 0.0, min_stride: float = 0.0,
                model=None) -> StepEvents:
    """Touchdown events of `contacts` (names or indices; default all) in a Trajectory.

    feet : groups of contacts (names or indices) that touch down as one: a foot touches down at
        the frame where one of its contacts is in contact and none was the frame before (a box
        foot landing heel then toe is one event); the event names the group's first contact.
        Overrides `contacts`. A name or index in place of a group is a foot of that one
        contact (feet=["left", "right"]).
    min_air : [s] with feet, a touchdown counts only after the foot was off the ground this
        long (a foot that bounces or chatters for a few frames at landing lands once).
    together : [s] with feet, touchdowns of several feet within this time of the first of
        them are one landing (a jump landing on both feet; the event names the first foot).
    min_stride : [m] with feet (and the model), a touchdown counts only where the foot lifted
        from the ground before it and lands at least this far (horizontally) from where it
        left: a step, not a foot rocking, chattering or hopping in place, nor a body's first
        touch (0: every landing counts).
    """
    for name, value in (("min_air", min_air), ("together", together), ("min_stride", min_stride)):
        # NaN compared False everywhere: a NaN min_stride counted every landing
        finite_number(name, value, least=0.0)
    for name, value in (("contacts", contacts), ("feet", feet)):
        if isinstance(value, (str, bytes)):
            raise ValueError(f"{name}={value!r} must be a list (of contact names or indices"
                             f"{', or of such lists' if name == 'feet' else ''}), not a string")
    if min_stride > 0.0 and (feet is None or model is None):
        raise ValueError(f"min_stride={min_stride} m needs feet and the model (the feet's positions)")
    if feet is not None:
        frames, which = [], []
        for group in feet:
            # (a name or an index alone is a foot of one contact: feet=["foot"] is one foot,
            # not one of four contacts named by its letters)
            if isinstance(group, str) or np.ndim(group) == 0:
                group = [group]
            idx = [_contact_index(traj, c) for c in group]
            if not idx:
                raise ValueError(f"feet={feet!r}: a foot needs at least one contact")
            on = np.isin(traj.contact_mode[:, idx], IN_CONTACT).any(axis=1)
            f = _entries(on)
            if min_air > 0.0 and len(f):
                t = np.asarray(traj.t)
                lift = np.flatnonzero(~on[1:] & on[:-1]) + 1      # frames the foot left
                keep = []
                for k in f:
                    left = lift[lift < k]
                    keep.append(len(left) == 0 or t[k] - t[left[-1]] >= min_air)
                f = f[np.array(keep, dtype=bool)]
            if min_stride > 0.0:
                f = _lands_elsewhere(f, on, foot_x(traj, model, idx), min_stride)
            frames.append(f)
            which.append(np.full(len(f), idx[0]))
        frame = np.concatenate(frames) if frames else np.zeros(0, int)
        contact = np.concatenate(which) if which else np.zeros(0, int)
        order = np.argsort(frame, kind="stable")
        frame, contact = frame[order], contact[order]
        time = np.asarray(traj.t)[frame]
        if together > 0.0 and len(frame):
            keep = np.ones(len(frame), dtype=bool)
            start = time[0]
            for k in range(1, len(frame)):
                if time[k] - start < together:
                    keep[k] = False
                else:
                    start = time[k]
            frame, contact, time = frame[keep], contact[keep], time[keep]
        return StepEvents(frame=frame, time=time, contact=contact)
    if contacts is None:
        contacts = range(traj.contact_mode.shape[1])
    frames, which = [], []
    for c in contacts:
        ci = _contact_index(traj, c)
        f = touchdowns(traj.contact_mode[:, ci])
        frames.append(f)
        which.append(np.full(len(f), ci))
    frame = np.concatenate(frames) if frames else np.zeros(0, int)
    contact = np.concatenate(which) if which else np.zeros(0, int)
    order = np.argsort(frame, kind="stable")
    frame, contact = frame[order], contact[order]
    return StepEvents(frame=frame, time=np.asarray(traj.t)[frame], contact=contact)


def poincare_section(traj, coords: Callable, contacts: Sequence | None = None):
    """Section points at touchdown: X[i] = coords(q, v, contact) at each event frame.

    coords(q (n_body, 3), v (n_body, 3), contact) -> (d,) section coordinates of the state
    whose new stance contact is `contact`. Returns (StepEvents, X (n, d)).
    """
    ev = step_events(traj, contacts)
    X = np.array([np.asarray(coords(traj.q[f], traj.v[f], c), dtype=np.float64)
                  for f, c in zip(ev.frame, ev.contact)])
    return ev, X.reshape(len(ev), -1)
