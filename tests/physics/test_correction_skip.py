"""The step skips the position correction when integrate.rows_hold_within proves that every
row already holds within refine_tol / 2. That proof must be a true bound: whenever it claims
the rows hold within a limit, evaluating them again must find no error above that limit."""
import math

import numpy as np
from hypothesis import HealthCheck, given, settings, strategies as st
from numba import float64, njit

import planarsim as ps
from planarsim import terrain
from planarsim.kernels.dynamics.integrate import max_residual, rows_hold_within
from planarsim.options import StepOptions


@njit(cache=False)   # a test helper: compiled per run, never a stale cache entry
def _bound_and_error(args, limit):
    """(rows_hold_within(limit), largest row error) right after a step without correction."""
    ok = rows_hold_within(args.m, args.s, args.ws, args.m.dt, limit)
    return ok, max_residual(args.m, args.s, args.ws)


def _scene(kind, slope_deg, y_offset):
    """A box resting on two corners, a rolling disk, or a 3-link chain pinned to the world
    and released horizontal, on flat or sloped ground."""
    b = ps.ModelBuilder(dt=1e-3, terrain=terrain.slope(slope_deg))
    a = math.radians(slope_deg)
    if kind == "box":
        # bottom corners at y_offset along the ground normal, the box turned with the slope
        box = b.add_body("box", 2.0, 2.0 * (0.4 ** 2 + 0.1 ** 2) / 12,
                         pos=(-(0.05 + y_offset) * math.sin(a), (0.05 + y_offset) * math.cos(a)),
                         angle=a)
        b.add_box_contacts("box", box, (0.0, 0.0), 0.4, 0.1, mu=0.3)
    elif kind == "disk":
        disk = b.add_body("disk", 2.0, 0.04, pos=(0.0, (0.2 + y_offset) / math.cos(a)))
        b.add_arc_contact("rim", disk, (0.0, 0.0), 0.2, mu=1.0)
    else:
        prev = None
        for i in range(3):
            body = b.add_body(f"l{i}", 1.0, 1.0 / 12, pos=((i + 0.5) * 0.5, 2.0))
            b.add_pin(f"p{i}", prev, body, anchor_world=(i * 0.5, 2.0))
            prev = body
    return b.compile()


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(kind=st.sampled_from(["box", "disk", "chain"]),
       slope_deg=st.sampled_from([0.0, 12.0, -25.0]),
       y_offset=st.sampled_from([0.0, 1e-6]),
       omega=st.floats(-0.2, 0.2),
       vx=st.floats(-0.5, 0.5),
       warmup=st.integers(0, 30),
       limit_exp=st.integers(-13, -8))
def test_skip_bound_never_understates_a_rows_error(kind, slope_deg, y_offset, omega, vx, warmup,
                                                   limit_exp):
    model = _scene(kind, slope_deg, y_offset)
    sim = ps.Simulator(model)
    state = sim.state
    state.v[:, 0] += vx
    state.v[:, 2] += omega
    sim.state = state
    sim.steps(warmup)                                   # contacts engaged, modes settled
    sim.options = StepOptions(refine_iters=0)           # the rows as the bound sees them
    sim.step()
    entry = _bound_and_error.compile((sim._args.numba_type, float64))
    limit = 10.0 ** limit_exp
    ok, error = entry(sim._args, limit)
    if ok:
        assert error <= limit


def test_skip_happens_at_rest_and_not_in_motion():
    """The bound is not vacuous: a box at rest passes it at the default tolerance, a swinging
    chain does not."""
    results = {}
    for kind in ("box", "chain"):
        model = _scene(kind, 0.0, 0.0)
        sim = ps.Simulator(model)
        sim.steps(200)
        sim.options = StepOptions(refine_iters=0)
        sim.step()
        entry = _bound_and_error.compile((sim._args.numba_type, float64))
        results[kind] = entry(sim._args, 0.5e-12)
    assert results["box"][0] and results["box"][1] <= 0.5e-12
    assert not results["chain"][0]
    assert np.isfinite(results["chain"][1])
