"""Which models the step takes by its pin-chain path (kernels/solver/pin_chain.py), and in what order.

A model qualifies when its only constraint rows are the x and y rows of plain hinge pins
(no rods, sliders, joint limits, springs, dampers, armature or joint friction, no contacts)
and its pins form open chains: every body carries at most two pins, two pins share at most
one body, and no ring of bodies closes on itself; a chain's pins are listed in the model in
their order along it (either way), and there are fewer than SPARSE_MIN_ROWS / 2 pins, so that
the path eliminates the rows in the general solve's order (the same pivots, and the same
decisions taken on them). A pin to the world ends a chain (a chain may hang from the world
at one end, or at both: a bridge). Along such a chain the pins'
effective-mass matrix J W J^T is block tridiagonal in 2 x 2 blocks (a pin couples only to its
neighbours, through the body they share), so the solve is a block elimination linear in the
number of links with no fill.
"""
from __future__ import annotations

import numpy as np

from .disjoint_sets import DisjointSets
from .kernels.codes import JOINT_HINGE
from .kernels.solver.sparse_factor import SPARSE_MIN_ROWS


def _plain_hinges(a) -> bool:
    """Every pin a plain hinge: no limit, spring, damper, armature or friction."""
    return bool(np.all(np.asarray(a.pin_kind) == JOINT_HINGE)
                and np.all(np.isinf(np.asarray(a.pin_limit)))
                and not np.any(np.asarray(a.pin_stiffness))
                and not np.any(np.asarray(a.pin_damping))
                and not np.any(np.asarray(a.pin_armature))
                and not np.any(np.asarray(a.pin_frictionloss)))


def joints_form_no_loop(model) -> bool:
    """The model's joints (pins of every kind, rods) close no loop of bodies, the world
    counted as one body: a forest hanging from the world. Such joints' rows are independent
    at any configuration, so a step of these rows alone has SHAKE's correction
    (position.joints_alone)."""
    a = model.arrays
    joints = np.concatenate([np.asarray(a.pin_body).reshape(-1, 2),
                             np.asarray(a.rod_body).reshape(-1, 2)])
    world = model.n_body
    sets = DisjointSets(world + 1)
    return all(sets.join(int(ba) if ba >= 0 else world, int(bb) if bb >= 0 else world)
               for ba, bb in joints)


def pin_chain_order(model) -> tuple[np.ndarray, np.ndarray] | None:
    """(order, ends) if the model qualifies (module docstring), else None.

    order: (n_pin,) int the pins chain by chain, each pin next to the one it shares a body
    with; ends: (n_pin, 2) int for place k, the end (0: body a, 1: body b) of pin order[k]
    and of pin order[k - 1] at the body they share, (-1, -1) where a chain starts."""
    a = model.arrays
    n_pin = int(np.asarray(a.pin_body).shape[0])
    if (n_pin == 0 or 2 * n_pin >= SPARSE_MIN_ROWS or np.asarray(a.rod_body).shape[0]
            or np.asarray(a.contact_body).shape[0] or not _plain_hinges(a)):
        return None
    pin_body = np.asarray(a.pin_body).reshape(-1, 2)
    pins_of: dict[int, list[int]] = {}
    for j, (ba, bb) in enumerate(pin_body):
        if ba == bb:
            return None
        for b in (ba, bb):
            if b >= 0:
                pins_of.setdefault(int(b), []).append(j)
    if any(len(p) > 2 for p in pins_of.values()):
        return None

    def neighbours(j):
        """[(other pin, shared body)] of pin j."""
        out = []
        for b in pin_body[j]:
            if b >= 0:
                out.extend((i, int(b)) for i in pins_of[int(b)] if i != j)
        return out

    for j in range(n_pin):
        others = [i for i, _ in neighbours(j)]
        if len(others) != len(set(others)):
            return None                 # two pins sharing both their bodies
    seen = np.zeros(n_pin, bool)
    order, ends = [], []
    for start in range(n_pin):
        if seen[start] or len(neighbours(start)) > 1:
            continue                    # chains start at a pin with one neighbour or none
        prev, j = -1, start
        while j >= 0:
            seen[j] = True
            link = [(i, b) for i, b in neighbours(j) if i == prev]
            if link:
                b = link[0][1]
                ends.append((int(np.flatnonzero(pin_body[j] == b)[0]),
                             int(np.flatnonzero(pin_body[prev] == b)[0])))
            else:
                ends.append((-1, -1))
            order.append(j)
            nxt = [i for i, _ in neighbours(j) if i != prev and not seen[i]]
            prev, j = j, (nxt[0] if nxt else -1)
    if not seen.all():
        return None                     # a ring of bodies: every pin has two neighbours
    # each chain walked from its lowest pin: the path repeats the general solve's
    # elimination (rows in pin order) where its pins' indices increase along it
    if any(ends[k][0] >= 0 and order[k] < order[k - 1] for k in range(n_pin)):
        return None
    return np.asarray(order, np.int64), np.asarray(ends, np.int64).reshape(n_pin, 2)

