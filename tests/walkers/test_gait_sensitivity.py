"""The gait sensitivity norm (planarsim.analysis.sensitivity; walkers/passive/sensitivity.py):
the Lyapunov form against the impulse response's sum and a scalar closed form, and, on the
rimless wheel and the simplest walker, the linearised norm against the simulated response of
the nonlinear walker to a small tilt of one step's ground."""
import math

import numpy as np
import pytest

from planarsim.analysis import find_fixed_point
from planarsim.analysis.sensitivity import (gait_sensitivity, gait_sensitivity_norm,
                                            impulse_response)
from walkers.passive import PassiveWalker, RimlessParams, SimplestParams
from walkers.passive.rimless_wheel import closed_form
from walkers.passive.sensitivity import TiltStep, tilt_sensitivity


@pytest.mark.parametrize("seed", range(5))
def test_the_norm_is_the_whole_responses_size(seed):
    """Random stable systems (spectral radius 0.2-0.95, several disturbances and indicators):
    the Lyapunov form equals the root of the sum of the squared impulse response."""
    rng = np.random.default_rng(seed)
    d, m, p = rng.integers(1, 6), rng.integers(1, 3), rng.integers(1, 4)
    A = rng.normal(size=(d, d))
    A *= rng.uniform(0.2, 0.95) / np.max(np.abs(np.linalg.eigvals(A)))
    B, C, D = rng.normal(size=(d, m)), rng.normal(size=(p, d)), rng.normal(size=(p, m))
    R = impulse_response(A, B, C, D, 3000)
    assert gait_sensitivity_norm(A, B, C, D) == pytest.approx(math.sqrt(np.sum(R * R)), rel=1e-10)


def test_scalar_closed_form_and_an_unstable_gait():
    a, b, c, d = 0.5, 2.0, 3.0, 0.7
    assert gait_sensitivity_norm(a, b, c, d) == pytest.approx(
        math.sqrt(d * d + (c * b) ** 2 / (1 - a * a)), rel=1e-14)
    assert gait_sensitivity_norm(1.01, b, c, d) == math.inf
    with pytest.raises(ValueError, match="C must be"):
        gait_sensitivity_norm(np.eye(2), np.ones(2), np.ones((1, 3)))
    # a string disturbances failed in int(), 1.5 was 1; a NaN or 0 eps gave NaN matrices
    linear = lambda x, e: (0.5 * x, x + e[0])                 # noqa: E731
    for kw, said in ((dict(disturbances="1"), r"disturbances='1' must be a whole number"),
                     (dict(disturbances=1.5), r"disturbances=1.5 must be a whole number"),
                     (dict(eps=float("nan")), r"eps=nan must be a finite number > 0"),
                     (dict(eps_x=0.0), r"eps_x=0.0 must be a finite number > 0"),
                     (dict(steps=True), r"steps=True must be a whole number")):
        with pytest.raises(ValueError, match=said):
            gait_sensitivity(linear, np.zeros(1), **kw)
    # from a step function: a linear map gives its own matrices back
    A, B, C, D = np.array([[0.3, 0.1], [0.0, -0.4]]), np.array([1.0, 2.0]), np.array([[1.0, -1.0]]), 0.5
    s = gait_sensitivity(lambda x, e: (A @ x + B * e[0], C @ x + D * e[0]), np.zeros(2))
    assert np.allclose(s.A, A) and np.allclose(s.B[:, 0], B) and np.allclose(s.C, C)
    assert s.norm == pytest.approx(gait_sensitivity_norm(A, B, C, D), rel=1e-9)


def simulated_norm(params, x, tilt, steps=30):
    """The indicators' response to a tilt of +-tilt under the first step (central), walked by
    the nonlinear map for `steps` more steps: the root of its squared sum per unit tilt, and
    the response."""
    step = TiltStep(params)
    runs = []
    for sign in (1.0, -1.0):
        y, g = step(x, [sign * tilt])
        gs = [g]
        for _ in range(steps):
            y, g = step(y, [0.0])
            gs.append(g)
        runs.append(np.array(gs))
    r = (runs[0] - runs[1]) / (2 * tilt)
    return math.sqrt(np.sum(r * r)), r


@pytest.mark.parametrize("params, x0, rel", [
    (RimlessParams(), None, 1e-5),
    (SimplestParams(), np.array([0.2002, -0.1999, 0.4003, -0.0158]), 2e-3)])
def test_the_norm_predicts_the_walkers_response_to_a_tilted_step(params, x0, rel):
    """The linearised norm (exact A, differenced B, C, D) within `rel` of the nonlinear
    walker's response to a 1e-4 rad tilt (the rest its second-order terms: 1.9 % at 1e-3 on the
    simplest walker). The rimless wheel's spokes fix its step length: no response there."""
    if x0 is None:
        x0 = np.array([-closed_form(params)["omega_after"]])
    f = PassiveWalker(params, dt=1e-3).step_map()
    x = find_fixed_point(f, x0, tol=1e-12).x
    s = tilt_sensitivity(params, x)
    assert np.isfinite(s.norm) and s.norm > 0.1
    measured, response = simulated_norm(params, x, 1e-4)
    assert s.norm == pytest.approx(measured, rel=rel)
    assert np.allclose(s.response[:5, :, 0], response[:5], rtol=10 * rel, atol=1e-6 * s.norm)
    if isinstance(params, RimlessParams):
        assert np.max(np.abs(response[:, 1])) < 1e-8


@pytest.mark.parametrize("tilt", [0.01, -0.005])
def test_a_tilted_steps_start_is_the_same_world_state(tilt):
    """TiltStep's frame: the simplest walker at theta + e on a slope steeper by e stands and
    moves as the walker at theta on its own slope (the floor turned about the stance foot)."""
    params = SimplestParams()
    x = np.array([0.2002, -0.1999, 0.4003, -0.0158])
    a = PassiveWalker(params)
    b = PassiveWalker(params.replace(slope=params.slope + tilt))
    a.set_coords(x)
    b.set_coords(x + np.array([tilt, 0.0, 0.0, 0.0]))
    assert np.allclose(a.sim.state.q, b.sim.state.q, rtol=0.0, atol=1e-12)
    assert np.allclose(a.sim.state.v, b.sim.state.v, rtol=0.0, atol=1e-12)
