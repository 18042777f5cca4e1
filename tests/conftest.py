"""Shared fixtures: tiny canonical models."""
import math
from pathlib import Path

import numpy as np
import pytest

import planarsim as ps
from planarsim.compiled import drop_stale_caches

# the tests' own compiled helpers inline engine kernels: their numba caches follow those
# sources as a walker's do (numba checks a cached function against its own file only)
for _folder in ("physics", "planarsim"):
    drop_stale_caches(Path(__file__).resolve().parent / _folder)


def make_chain(n_links=4, length=0.5, mass=1.0, dt=1e-3, gravity=(0.0, -9.81), limit=None):
    """Pendulum chain of thin rods pinned end to end, link 0 pinned to the world at the origin,
    all links horizontal (along +x) at rest."""
    b = ps.ModelBuilder(dt=dt, gravity=gravity)
    prev = None
    for i in range(n_links):
        body = b.add_body(f"link{i}", mass=mass, inertia=mass * length ** 2 / 12,
                          pos=((i + 0.5) * length, 0.0),
                          shapes=[("capsule", (-length / 2, 0.0), (length / 2, 0.0), 0.02, {"collide": False})])
        b.add_pin(f"pin{i}", prev, body, anchor_world=(i * length, 0.0),
                  limit=limit if i > 0 else None)
        prev = body
    return b.compile()


@pytest.fixture
def chain4():
    return make_chain(4)


# The property tests run derandomized (the same search every run, CI's and a newcomer's README
# command alike, so that passing cannot hinge on a draw: a few bounds hold the states drawn, not
# every state, e.g. test_envs_under_torque's RATIO); PLANARSIM_SEARCH=1 searches new examples.
import os as _os

from hypothesis import settings as _settings

_settings.register_profile("ci", derandomize=True, print_blob=True)
if _os.environ.get("CI") or not _os.environ.get("PLANARSIM_SEARCH"):
    _settings.load_profile("ci")
