"""On the actuated walkers: step-to-step maps of the Simple Biped and Ranger at a
section where the controller resets its memory, their fixed points (the settled gait) and
Floquet multipliers (central finite differences).

Bounds, stated:
- Simple Biped (dt = 0.1 ms, section: controller touchdown, stride map, 6 coordinates): the
  settled section state is returned by the map within 1e-3 (m, m/s; measured ~1e-4, the size
  of the map's jumps from the controller switching at step boundaries); multipliers bit for bit
  reproducible, inside the unit circle at eps = 3e-3 and 1e-2, and a 1e-2 perturbation decays.
- Ranger (dt = 1 ms, section: controller mid-stance, stride map, 11 coordinates), with the
  engine's default StepOptions that Ranger runs with: the acceptance asks for a
  period-one gait with all multipliers inside the unit circle. The controller acts at 1 ms
  steps, so the map jumps by up to ~1.6e-2 (rad/s) between nearby points (see
  walkers/ranger/gait_map.py) and a settled gait either repeats exactly (every event on the
  same step each stride) or wanders within that jitter. Period-one is therefore asserted as:
  12 strides from the settled section state all return within PERIOD_TOL = 5e-2 of it
  (measured: 0 on the engine at c758571, exactly repeating, |P(x0) - x0| = 3e-7; 1.9e-2 with the
  engine's frictionless rule for a heel landing in Painleve's configuration; up to 4.2e-2 over
  ten 1 % parameter changes; an earlier parameter set wandered 0.16 off, irregular).
  The Jacobian is a least-squares slope over perturbations of 0.5..2 x 1e-2 (measured
  spectral radius 0.66 / 0.48 on those two engines; 0.2..0.8 over eps 2e-3..2e-2 and 1 %
  parameter changes); a two-point central difference at eps = 1e-3 measured the jumps (radius
  1.3 here, 0.3..12 over parameter digits). A 0.1 perturbation shrinks to the jitter within a
  few strides.
"""
import math

import numpy as np
import pytest

from walkers.ranger import gait_map as rgm
from walkers.simple_biped import gait_map as sgm


@pytest.fixture(scope="module")
def biped():
    return sgm.SimpleBipedGaitMap()


@pytest.fixture(scope="module")
def ranger():
    return rgm.RangerGaitMap()


# Simple Biped ----------------------------------------------------------------------------------
def test_simple_biped_map_returns_settled_gait(biped):
    P = biped.step_map()
    assert biped.residual() <= 1e-3
    # and keeps returning it over further strides (not a transient that happens to pass by)
    orbit = P.iterate(biped.x0, 4)
    assert len(orbit) == 5 and np.max(np.abs(orbit - biped.x0)) <= 1e-3
    # a walking gait: hip behind-to-ahead of the front foot is negative at touchdown, moving on
    assert biped.x0[0] < 0 and biped.x0[2] > 0.5 and biped.x0[4] < -0.2


def test_simple_biped_multipliers_finite_reproducible_stable(biped):
    lam = biped.multipliers(sgm.EPS)
    assert lam.shape == (6,) and np.all(np.isfinite(lam))
    assert np.array_equal(lam, biped.multipliers(sgm.EPS))           # bit for bit
    assert np.max(np.abs(lam)) < 1.0
    assert np.max(np.abs(biped.multipliers(1e-2))) < 1.0             # not an artefact of one eps


def test_simple_biped_perturbation_decays(biped):
    # the nonlinear statement behind |lambda| < 1: a perturbation of 1e-2 (m, m/s) shrinks
    d = np.array([0.0, 0.0, 1e-2, -1e-2, 1e-2, 1e-2])
    orbit = biped.step_map().iterate(biped.x0 + d, 6)
    assert len(orbit) == 7
    err = np.max(np.abs(orbit - biped.x0), axis=1)
    assert err[-1] < 0.2 * err[0]


# Ranger -------------------------------------------------------------------------------------------
def _pin_gaps(model, q):
    a = model.arrays
    out = []
    for j in range(model.n_pin):
        pts = []
        for side in range(2):
            b = int(a.pin_body[j, side])
            c, s = math.cos(q[b, 2]), math.sin(q[b, 2])
            lx, ly = a.pin_anchor[j, side]
            pts.append(q[b, :2] + np.array([c * lx - s * ly, s * lx + c * ly]))
        out.append(np.hypot(*(pts[0] - pts[1])))
    return np.array(out)


def test_ranger_perturbed_section_is_consistent(ranger):
    x = ranger.x0 + np.array([1e-2, -2e-2, 1e-2, 5e-2, -5e-2, 5e-2, -5e-2, 1e-3, 1e-3, 1e-3, 1e-3])
    ranger.set_section(x)
    # the perturbation lands where asked, the pins stay closed as in the reference state
    assert np.allclose(ranger.coords(ranger.s, ranger.mem), x, rtol=0, atol=1e-12)
    assert np.max(_pin_gaps(ranger.model, ranger.s.q)) <= np.max(_pin_gaps(ranger.model, ranger.state0.q)) + 1e-12
    # the stance foot rolled on its sole: its lowest sole point still touches flat ground
    st = ranger.stance
    q = ranger.s.q[2 + st]
    c, s = math.cos(q[2]), math.sin(q[2])
    lc = ranger.sole_center
    center_y = q[1] + s * lc[0] + c * lc[1]
    q0 = ranger.state0.q[2 + st]
    c0, s0 = math.cos(q0[2]), math.sin(q0[2])
    assert abs(center_y - (q0[1] + s0 * lc[0] + c0 * lc[1])) < 1e-12


def test_ranger_map_deterministic_and_multipliers_finite(ranger):
    P = ranger.step_map()
    y1, y2 = P(ranger.x0), P(ranger.x0)
    assert np.array_equal(y1, y2) and np.all(np.isfinite(y1))
    lam = ranger.multipliers(rgm.EPS)
    assert lam.shape == (11,) and np.all(np.isfinite(lam))
    assert np.array_equal(lam, ranger.multipliers(rgm.EPS))


PERIOD_TOL = 5e-2   # [rad, rad/s, -] the 1 ms control jitter of the section state (module doc)


def test_ranger_gait_is_period_one(ranger):
    orbit = ranger.step_map().iterate(ranger.x0, 12)
    assert len(orbit) == 13
    assert np.max(np.abs(orbit - ranger.x0)) <= PERIOD_TOL


def test_ranger_multipliers_inside_unit_circle(ranger):
    assert np.max(np.abs(ranger.multipliers(rgm.EPS))) < 1.0


def test_ranger_perturbation_decays(ranger):
    # the nonlinear statement behind |lambda| < 1, down to the map's jump scale (~2e-2, module
    # doc): a perturbation of 0.1 (rad, rad/s) is below half of it after 4 strides and stays so
    d = 2.0 * np.array([1e-2, -2e-2, 1e-2, 5e-2, -5e-2, 5e-2, -5e-2, 0.0, 0.0, 0.0, 0.0])
    orbit = ranger.step_map().iterate(ranger.x0 + d, 8)
    assert len(orbit) == 9
    err = np.max(np.abs(orbit - ranger.x0), axis=1)
    assert np.all(err[4:] < 0.5 * err[0]), err
