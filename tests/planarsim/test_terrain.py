"""Terrain: exact heights, slopes and normals; compiled and numpy versions agree."""
import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from planarsim import terrain
from planarsim.kernels.geometry.terrain import closest_point, height_derivs

amps = st.lists(st.floats(0.0, 0.3), min_size=0, max_size=3)


@st.composite
def terrains(draw, sines=(0, 3), amplitude=(0.0, 0.3), wavelength=(0.5, 10.0), grade=0.3,
             height=1.0):
    """Hills of `sines` sines (amplitudes, wavelengths in the given ranges [m]) on a grade
    within +-grade, at a height within +-height [m]."""
    n = draw(st.integers(*sines))
    a = [draw(st.floats(*amplitude)) for _ in range(n)]
    lam = [draw(st.floats(*wavelength)) for _ in range(n)]
    phi = [draw(st.floats(-math.pi, math.pi)) for _ in range(n)]
    return terrain.hills(a, lam, phi, grade=draw(st.floats(-grade, grade)),
                         height=draw(st.floats(-height, height)))


@settings(max_examples=200, deadline=None)
@given(terrains(), st.floats(-50, 50))
def test_normal_is_unit_and_orthogonal_to_tangent(ter, x):
    n = ter.normal(x)
    t = ter.tangent(x)
    assert abs(np.hypot(*n) - 1.0) < 1e-14
    assert abs(np.dot(n, t)) < 1e-14
    assert n[1] > 0


@settings(max_examples=200, deadline=None)
@given(terrains(), st.floats(-50, 50))
def test_slope_matches_central_difference(ter, x):
    h = 1e-5
    fd = (ter.height(x + h) - ter.height(x - h)) / (2 * h)
    assert abs(fd - ter.slope(x)) < 1e-7


@settings(max_examples=200, deadline=None)
@given(terrains(), st.floats(-50, 50))
def test_compiled_matches_numpy(ter, x):
    h, dh, ddh = height_derivs(ter.coef, x)
    assert abs(h - ter.height(x)) < 1e-12
    assert abs(dh - ter.slope(x)) < 1e-12


@settings(max_examples=200, deadline=None)
@given(terrains(), st.floats(-20, 20), st.floats(-0.2, 0.5))
def test_closest_point_is_the_nearest_ground_point(ter, px, dy):
    py = float(ter.height(px)) + dy
    gx, gy, nx, ny, gap = closest_point(ter.coef, px, py)
    assert abs(gy - ter.height(gx)) < 1e-12
    # no sampled ground point is closer than the one found
    xs = np.linspace(px - 1.0, px + 1.0, 4001)
    d = np.hypot(xs - px, ter.height(xs) - py)
    assert abs(gap) <= d.min() + 1e-9
    # the gap is signed: positive above the ground
    if abs(dy) > 1e-9:
        assert np.sign(gap) == np.sign(dy)


def test_flat_and_slope_are_exact():
    t = terrain.slope(10.0)
    assert abs(t.slope(3.0) - math.tan(math.radians(10))) < 1e-15
    gx, gy, nx, ny, gap = closest_point(t.coef, 1.0, 2.0)
    expected = (2.0 - math.tan(math.radians(10))) * math.cos(math.radians(10))
    assert abs(gap - expected) < 1e-14


def test_default_hills_meet_the_seed_claim():
    t = terrain.default_hills()
    assert 11.0 < terrain.max_slope_deg(t) <= 12.0
    x = np.linspace(0, 200, 200001)
    assert np.ptp(t.height(x)) > 0.3


def tight_hills():
    """Steep, tight hills: wavelengths 0.1-2 m, amplitudes 0.05-0.4 m (slopes to ~25, 87 deg)."""
    return terrains(sines=(1, 3), amplitude=(0.05, 0.4), wavelength=(0.1, 2.0), grade=0.0,
                    height=0.0)


@settings(max_examples=300, deadline=None)
@given(tight_hills(), st.floats(-2, 2), st.floats(-0.8, 0.8))
def test_closest_point_on_tight_hills_is_the_nearest(ter, px, dy):
    """Far below or above tight hills the nearest ground point may lie a valley away: the
    search finds it (a Newton step that would take it to another valley's wall is not taken)
    and its gap has the height field's sign."""
    py = float(ter.height(px)) + dy
    gx, gy, nx, ny, gap = closest_point(ter.coef, px, py)
    assert abs(gy - ter.height(gx)) < 1e-12
    xs = np.linspace(px - 1.5, px + 1.5, 60001)
    d = np.hypot(xs - px, ter.height(xs) - py)
    assert abs(gap) <= d.min() + 1e-9       # no sampled ground point is closer
    if abs(dy) > 1e-9:
        assert np.sign(gap) == np.sign(dy)


@settings(max_examples=200, deadline=None)
@given(terrains(height=0.0), st.floats(-20, 20), st.floats(-0.2, 0.5),
       st.sampled_from([1e3, 1e4, 1e5, 1e6]))
def test_closest_point_far_up_is_the_one_near_the_origin_to_rounding(ter, px, dy, up):
    """The same hills and point raised by `up` [m]: the same closest point, to the rounding of
    coordinates that large (a few eps * up), not to the square root of it (a search that
    compared squared distances without their rounding stalled 4e-7 m short of the closest
    point of hills 1e4 m up)."""
    coef = np.array(ter.coef, dtype=float)
    coef[0] += up                       # (its height h0)
    raised = terrain.Terrain(coef, name=ter.name)
    assert raised.height(px) == pytest.approx(ter.height(px) + up, abs=1e-9)
    py = float(ter.height(px)) + dy
    near = closest_point(ter.coef, px, py)
    far = closest_point(raised.coef, px, py + up)
    tol = 64 * np.finfo(float).eps * up
    assert abs(far[0] - near[0]) <= tol
    assert abs(far[4] - near[4]) <= tol
    assert abs(far[2] - near[2]) <= tol
