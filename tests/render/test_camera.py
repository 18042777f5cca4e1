"""The follow camera (planarsim/render/camera.py): a damped oscillator that tracks the COM."""

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from planarsim.render import Camera, step_overshoot
from strategies import vectors


def analytic_step(t, wn, z, amplitude):
    wd = wn * math.sqrt(1 - z * z)
    return amplitude * (1 - np.exp(-z * wn * t) * (np.cos(wd * t) + z / math.sqrt(1 - z * z) * np.sin(wd * t)))


@settings(max_examples=25, deadline=None)
@given(z=st.floats(0.1, 0.95), wn=st.floats(0.5, 20.0), amplitude=st.floats(-5.0, 5.0).filter(lambda a: abs(a) > 1e-3),
       shares=vectors(400, 0.2, 1.0))
def test_camera_step_response_is_the_damped_oscillator(z, wn, amplitude, shares):
    """Uneven frame intervals (400 frames, each 0.2 to 1 of min(0.05 s, 0.5 / wn), drawn):
    the camera samples the continuous step response exactly, so its overshoot never exceeds
    exp(-zeta pi / sqrt(1 - zeta^2)) of the step."""
    dts = shares * min(0.05, 0.5 / wn)
    times = np.r_[0.0, np.cumsum(dts)]
    cam = Camera(natural_frequency=wn, damping_ratio=z, position=(0.0, 0.0))
    path = cam.track(times, np.tile([amplitude, -amplitude], (len(times), 1)))
    np.testing.assert_allclose(path[:, 0], analytic_step(times, wn, z, amplitude), atol=1e-9 * abs(amplitude))
    np.testing.assert_allclose(path[:, 1], -path[:, 0], atol=1e-12)
    overshoot = path[:, 0].max() / amplitude - 1 if amplitude > 0 else path[:, 0].min() / amplitude - 1
    assert overshoot <= step_overshoot(z) + 1e-9


@pytest.mark.parametrize("z", [0.3, 0.7])
def test_camera_overshoot_matches_its_damping_ratio_at_fine_frames(z):
    """At 1000 fps the sampled peak reaches the theory (so the camera really rings as zeta says)."""
    wn = 4.0
    times = np.arange(0, 5.0, 1e-3)
    cam = Camera(wn, z, position=(0.0, 0.0))
    x = cam.track(times, np.tile([1.0, 0.0], (len(times), 1)))[:, 0]
    assert x.max() - 1 == pytest.approx(step_overshoot(z), rel=1e-4)
    t_peak = times[np.argmax(x)]
    assert t_peak == pytest.approx(math.pi / (wn * math.sqrt(1 - z * z)), abs=1.5e-3)


@settings(max_examples=25, deadline=None)
@given(z=st.floats(1.0, 3.0), wn=st.floats(0.5, 20.0), fps=st.floats(5, 240))
def test_camera_without_overshoot_when_critically_or_over_damped(z, wn, fps):
    times = np.arange(0, 20.0 / wn + 1.0, 1.0 / fps)
    cam = Camera(wn, z, position=(0.0, 0.0))
    x = cam.track(times, np.tile([2.0, 0.0], (len(times), 1)))[:, 0]
    assert x.max() <= 2.0 + 1e-12
    assert np.all(np.diff(x) >= -1e-12)           # monotone approach
    assert x[-1] > 1.9                             # it does get there


def test_camera_is_smoother_than_the_com_it_tracks():
    """A walking COM whose speed jumps at every heel strike (1 +- 0.3 m/s, twice a second): a
    camera locked on it would change speed by 0.6 m/s in one frame; the tracking camera's
    velocity stays continuous, and with the COM velocity fed in it does not lag behind."""
    fps = 60
    t = np.arange(0, 6, 1 / fps)
    v = 1.0 + 0.3 * np.sign(np.sin(2 * np.pi * 2 * t + 0.1))
    x = np.r_[0.0, np.cumsum(v[:-1]) / fps]
    com, com_v = np.column_stack([x, np.zeros_like(t)]), np.column_stack([v, np.zeros_like(t)])
    for cam, max_error in ((Camera(3.0, 0.9), 0.2), (Camera(3.0, 0.9), None)):
        cx = cam.track(t, com, com_v if max_error else None)[:, 0]
        cam_dv = np.abs(np.diff(np.gradient(cx, t)[1:-1])).max()
        assert cam_dv < 0.15 * np.abs(np.diff(v)).max()
        if max_error:
            assert np.abs(cx - x).max() < max_error
        else:   # form (1) lags a ramp by 2 zeta v / wn
            assert (x - cx)[-fps:].mean() == pytest.approx(2 * 0.9 * 1.0 / 3.0, rel=0.05)


def test_camera_rejects_bad_parameters():
    with pytest.raises(ValueError, match="natural_frequency"):
        Camera(natural_frequency=0.0)
    with pytest.raises(ValueError, match="damping_ratio"):
        Camera(damping_ratio=float("nan"))
