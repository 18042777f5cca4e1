"""Passive walkers against physics: the simplest walking model against an independent scipy
integration of Garcia et al.'s reduced equations (and their published fixed point), the
rimless wheel against its closed-form gait, the compass gait against an independent scipy
integration of Goswami et al.'s model (its limit cycle and Floquet multipliers).

Tolerances are convergence statements: errors must shrink as dt and the foot mass ratio
shrink, not merely sit under one bound."""
import math

import numpy as np
import pytest

from planarsim.analysis import find_fixed_point
from walkers.passive import CompassParams, PassiveWalker, RimlessParams, SimplestParams
from walkers.passive.gait import project_velocities
from walkers.passive.reference import (GARCIA_THETA, GARCIA_THETA_DOT, compass_fixed_point,
                                       compass_heel_strike, compass_momenta, compass_step,
                                       simplest_fixed_point, simplest_step)


@pytest.fixture(scope="module")
def garcia():
    return simplest_fixed_point(0.009)


def test_reference_reproduces_garcia_fixed_point(garcia):
    # the independent reference (scipy, rtol 1e-12) lands on the published stable gait
    x = garcia["x"]
    assert abs(x[0] - GARCIA_THETA) < 1e-8 and abs(x[1] - GARCIA_THETA_DOT) < 1e-8
    assert abs(x[2] - 2 * x[0]) < 1e-12                      # on the heel-strike surface
    lam = garcia["multipliers"]
    # stable: a complex pair inside the unit circle, the other two ~0 (phi, phi' are slaved)
    assert abs(lam[0].real + 0.19) < 0.01 and abs(abs(lam[0].imag) - 0.56) < 0.02
    assert np.all(np.abs(lam[2:]) < 1e-6) and np.all(np.abs(lam) < 1)
    # one step maps the fixed point onto itself at the reported period
    xn, period, _ = simplest_step(x, 0.009)
    assert np.allclose(xn, x, atol=1e-10) and 3.8 < period < 3.95


def engine_gait(beta, dt):
    w = PassiveWalker(SimplestParams(foot_mass_ratio=beta), dt=dt)
    fp = find_fixed_point(w.step_map(), simplest_fixed_point()["x"], tol=1e-9, eps=1e-4,
                          exact=False)
    w.advance(fp.x)
    return fp, w.last_period * math.sqrt(9.81 / 1.0), w


def gait_errors(garcia, beta, dt):
    """|theta* error|, |theta_dot* error|, |period error| (dimensionless) and the largest
    distance of the complex multiplier pair from the reference's."""
    fp, period, w = engine_gait(beta, dt)
    assert fp.converged, (beta, dt, fp.residual)
    assert fp.stable
    assert w.last_release_ok           # the trailing foot left the ground at heel strike
    dlam = np.max(np.abs(fp.multipliers[:2] - garcia["multipliers"][:2]))
    return np.array([abs(fp.x[0] - garcia["x"][0]), abs(fp.x[1] - garcia["x"][1]),
                     abs(period - garcia["period"]), dlam])


def test_simplest_walker_fixed_point_matches_the_reduced_model(garcia):
    """At foot mass ratio 1e-5 the gait is the reduced model's (beta -> 0) at every dt: the
    step map is second order in dt (next test), so what is left is the model difference of
    beta 1e-5 (measured: theta* 1.5e-6, theta_dot* 1e-6, period 5.7e-6, multipliers 9e-5,
    the same at the three dt; with the step's velocities taken as instantaneous they were
    2.4e-3, 2.2e-3, 1.8e-3, 1.3e-2 at dt 1e-3, first order)."""
    errs = np.array([gait_errors(garcia, 1e-5, dt) for dt in (1e-3, 5e-4, 2.5e-4)])
    print("beta 1e-5, dt 1e-3 / 5e-4 / 2.5e-4: errors theta*, theta_dot*, period, multipliers\n", errs)
    assert np.all(errs[:, 0] < 5e-6) and np.all(errs[:, 1] < 5e-6)
    assert np.all(errs[:, 2] < 2e-5) and np.all(errs[:, 3] < 5e-4)


def test_simplest_walker_step_map_is_second_order_in_dt():
    """The step map of the walker with feet of mass 1e-3 against the scipy reference of the
    same model (walkers.passive.reference.simplest_feet_step) at the reference's fixed point
    near the first period doubling: the error falls fourfold per halving of dt (measured
    4.3e-6, 1.1e-6, 2.7e-7; the touchdown located within the step, the velocities converted
    between instants and steps by half kicks, planarsim.half_step)."""
    from walkers.passive.reference import simplest_feet_map, simplest_feet_step
    from walkers.passive.simplest import garcia_start
    x = garcia_start()
    for slope in np.linspace(0.009, 0.0149, 4):
        p = SimplestParams(slope=slope)
        x = find_fixed_point(simplest_feet_map(p), x, tol=1e-12, eps=1e-7).x
    period = simplest_feet_step(x, p)[1]
    errs, periods = [], []
    for dt in (1e-3, 5e-4, 2.5e-4):
        w = PassiveWalker(p, dt=dt)
        errs.append(np.max(np.abs(w.advance(x) - x)))
        periods.append(abs(w.last_period - period))
    print("step map error, step period error [s] at dt 1e-3, 5e-4, 2.5e-4:", errs, periods)
    assert errs[0] < 1e-5 and periods[0] < 1e-5
    assert f"{errs[0]:.1e}" == "4.3e-06", errs[0]        # docs/gait-analysis.md: "error 4.3e-6 at dt 1e-3 s"
    for big, small in ((errs[0], errs[1]), (errs[1], errs[2]), (periods[0], periods[1]),
                       (periods[1], periods[2])):
        assert 3.0 < big / small < 5.5


def test_simplest_walker_fixed_point_converges_with_foot_mass_ratio(garcia):
    errs = np.array([gait_errors(garcia, beta, 2.5e-4) for beta in (1e-2, 1e-3)])
    print("dt 2.5e-4, beta 1e-2 / 1e-3: errors theta*, theta_dot*, period, multipliers\n", errs)
    # theta*, period and multipliers move toward the beta -> 0 reference as beta shrinks
    assert errs[1, 0] < errs[0, 0] / 2 and errs[1, 2] < errs[0, 2] / 2 and errs[1, 3] < errs[0, 3] / 4


def test_simplest_walker_walks_with_refined_impacts(garcia):
    # every heel strike located and resolved as in the step map, 30 s from the published gait
    from walkers.passive.simplest import simulate
    traj, summary, model = simulate(30.0, dt=2.5e-4, params=SimplestParams(foot_mass_ratio=1e-4))
    assert not summary["fell"] and summary["code"] == 0
    period = garcia["period"] / math.sqrt(9.81)
    assert abs(summary["steps"] - 30.0 / period) <= 1
    assert abs(summary["step_period"] / period - 1) < 2e-3
    assert abs(traj.t[-1] - 30.0) < 1e-3
    # hip height never below the leg length times cos(max stance angle) minus a margin
    assert np.min(traj.q[:, 0, 1] - model.terrain.height(traj.q[:, 0, 0])) > 0.95


def test_simplest_walker_walks_on_the_engines_own_contacts(garcia):
    # no step map here: the engine finds every heel strike (continuous collision) and the
    # "all" strategy releases the trailing foot; 30 s of walking from the published gait
    from walkers.passive.simplest import simulate
    traj, summary, model = simulate(30.0, dt=2.5e-4, params=SimplestParams(foot_mass_ratio=1e-4),
                                    impacts="engine")
    assert not summary["fell"]
    period = garcia["period"] / math.sqrt(9.81)
    assert abs(summary["steps"] - 30.0 / period) <= 2
    assert abs(summary["step_period"] / period - 1) < 0.01
    assert summary["distance"] > 0


def test_velocity_projection_is_minimal_and_consistent():
    w = PassiveWalker(SimplestParams(foot_mass_ratio=1e-3))
    q = w.sim.state.q.copy()
    rng = np.random.default_rng(1)
    v = rng.normal(size=q.shape)
    v[:, 2] = 0.0
    vp = project_velocities(w.model, q, v, [w.feet[0]])
    assert np.allclose(vp[1, :2], 0.0, atol=1e-12)           # pinned foot at rest
    for j, (a, b) in enumerate(w.model.arrays.rod_body):      # rods keep their length
        e = q[b, :2] - q[a, :2]
        assert abs(e @ (vp[b, :2] - vp[a, :2])) < 1e-12
    assert np.allclose(project_velocities(w.model, q, vp, [w.feet[0]]), vp, atol=1e-12)


# rimless wheel -------------------------------------------------------------------------------
RIMLESS = [RimlessParams(), RimlessParams(n_spokes=12, slope=0.06, hub_gyration=0.3, spoke_length=0.8)]


@pytest.mark.parametrize("p", RIMLESS, ids=["N8-k0.1", "N12-k0.3"])
def test_rimless_wheel_matches_closed_form(p):
    from walkers.passive.rimless_wheel import closed_form, simulate
    cf = closed_form(p)
    # step map: fixed point, its multiplier eta^2, the steady speed; first order in dt
    errs = []
    for dt in (5e-4, 2.5e-4):
        w = PassiveWalker(p, dt=dt)
        fp = find_fixed_point(w.step_map(), [-1.2 * cf["omega_after"]], tol=1e-10, eps=1e-4,
                              exact=False)
        w.advance(fp.x)
        assert fp.converged
        errs.append([abs(fp.x[0] / -cf["omega_after"] - 1), abs(fp.multipliers[0] - cf["eta"] ** 2),
                     abs(w.last_length / w.last_period / cf["speed"] - 1)])
    errs = np.array(errs)
    print("rimless map errors (omega*, multiplier, speed) at dt 5e-4, 2.5e-4:\n", errs)
    # omega* and speed still first order (the wheel's pivot is a contact; not investigated)
    assert np.all(errs[1, [0, 2]] < errs[0, [0, 2]] / 1.6) and errs[1, 1] < errs[0, 1]
    assert errs[1, 0] < 3e-3 and errs[1, 1] < 5e-3 and errs[1, 2] < 5e-3
    # the engine on its own (every spoke enabled, impacts found by the contact solver):
    # steady speed within 1%, and closer at smaller dt
    errs = []
    for dt in (1e-3, 2.5e-4):
        traj, summary, model = simulate(20.0, params=p, dt=dt, impacts="engine")
        assert not summary["fell"]
        x = traj.q[:, 0, 0]
        half = len(x) // 2
        speed = (x[-1] - x[half]) / (traj.t[-1] - traj.t[half]) / math.cos(p.slope)
        errs.append(abs(speed / cf["speed"] - 1))
    print("rimless speed error (dt 1e-3, 2.5e-4):", errs)
    assert errs[1] < 0.01 and errs[1] < errs[0]


# compass gait --------------------------------------------------------------------------------
def test_compass_gait_has_a_stable_period_one_gait():
    from walkers.passive.compass_gait import default_start, simulate
    p = CompassParams()
    w = PassiveWalker(p, dt=5e-4)
    fp = find_fixed_point(w.step_map(), default_start(p), tol=1e-9, eps=1e-3, exact=False)
    assert fp.converged and fp.stable
    w.advance(fp.x)
    assert w.last_release_ok and w.last_length > 0
    # on the engine's own contacts the walker keeps walking from the fixed point
    traj, summary, model = simulate(20.0, params=p, dt=5e-4, x0=fp.x, impacts="engine")
    assert not summary["fell"] and abs(summary["step_period"] / w.last_period - 1) < 0.02


@pytest.fixture(scope="module")
def compass_ref():
    return compass_fixed_point(CompassParams())


def test_compass_reference_conserves_what_it_should(compass_ref):
    from walkers.passive.reference import _compass_consts, compass_energy
    p = CompassParams()
    c = _compass_consts(p)
    x = compass_ref["x"]
    xn, period, step, y = compass_step(x, p)
    assert np.allclose(xn, x, atol=1e-10)                   # a fixed point
    # swing phase: the ODE (M, C, G) conserves the energy computed from the kinematics alone
    E = [compass_energy(y(t), c) for t in np.linspace(0.0, period, 101)]
    assert np.ptp(E) < 1e-9 * abs(E[0])
    # heel strike: the foot is on the slope, ahead; both angular momenta are conserved
    ye = y(period)
    foot = p.leg_length * np.array([math.sin(ye[1]) - math.sin(ye[0]), math.cos(ye[0]) - math.cos(ye[1])])
    assert abs(foot[1]) < 1e-12 and abs(foot[0] - step) < 1e-12 and step > 0
    yp = compass_heel_strike(ye, c)
    H_minus = compass_momenta(ye, c, foot)
    H_total_plus = compass_momenta(yp, c, np.zeros(2))[0]
    assert abs(H_total_plus - H_minus[0]) < 1e-12 * abs(H_minus[0])
    # old stance leg about the hip, by hand (I = m r^2): before (I - m a b) th1', after (the
    # new swing leg) (m b^2 + I) th2' - m l b cos(th1 - th2) th1'
    mH, m, l, a, b, I = c[:6]
    H_leg_minus = (I - m * a * b) * ye[2]
    H_leg_plus = (m * b * b + I) * yp[3] - m * l * b * math.cos(yp[0] - yp[1]) * yp[2]
    assert abs(H_minus[1] - H_leg_minus) < 1e-12 * abs(H_leg_minus)
    assert abs(H_leg_plus - H_leg_minus) < 1e-12 * abs(H_leg_minus)
    # the impact agrees with Goswami et al.'s closed form (point-mass legs: no leg inertia)
    c0 = c[:5] + (0.0,) + c[6:]
    c2 = math.cos(ye[1] - ye[0])                             # cos(2 alpha)
    Qm = np.array([[-m * a * b, -m * a * b + (mH * l * l + 2 * m * a * l) * c2], [0.0, -m * a * b]])
    Qp = np.array([[m * b * (b - l * c2), m * l * (l - b * c2) + m * a * a + mH * l * l],
                   [m * b * b, -m * b * l * c2]])
    w_ns, w_s = np.linalg.solve(Qp, Qm @ [ye[3], ye[2]])    # (non-stance, stance) after
    yp0 = compass_heel_strike(ye, c0)
    assert abs(yp0[2] - w_s) < 1e-12 and abs(yp0[3] - w_ns) < 1e-12
    # a stable period-one gait: a complex pair, one real multiplier, one zero (phi+ = 2 theta+)
    lam = compass_ref["multipliers"]
    assert np.all(np.abs(lam) < 1) and abs(lam[0].imag) > 0.1 and abs(lam[3]) < 1e-6


def test_compass_reference_gait_matches_the_engines_walk(compass_ref):
    from walkers.passive.compass_gait import simulate
    traj, summary, model = simulate(10.0)
    assert not summary["fell"]
    for key in ("step_period", "step_length", "speed"):
        assert abs(summary[key] / compass_ref[key.replace("step_period", "period")] - 1) < 0.01, key


def test_compass_gait_multipliers_converge_to_the_reference(compass_ref):
    """Engine multipliers (eps 'auto') against the scipy reference's. The error is first order
    in dt, about 3 dt (benchmarks/gait_analysis.py --only multipliers: 3.0e-3, 1.0e-3,
    7.5e-4, 3.3e-4 at dt 1e-3 ... 1.25e-4, 9x over three halvings; the engine's own
    finite-difference error estimate is 2e-4), so at dt 5e-4 it must be under 4 dt = 2e-3
    and at least 1.6x smaller than at 1e-3."""
    from planarsim.analysis import match_distance, multipliers_with_error
    from walkers.passive.compass_gait import default_start
    errs = []
    for dt in (1e-3, 5e-4):
        w = PassiveWalker(CompassParams(), dt=dt)
        fp = find_fixed_point(w.step_map(), default_start(), tol=1e-10, eps=1e-4, exact=False)
        assert fp.converged
        m = multipliers_with_error(w.step_map(), fp.x)
        errs.append(match_distance(m.values, compass_ref["multipliers"]))
    print("compass multiplier errors at dt 1e-3, 5e-4:", errs)
    assert errs[1] < 2e-3 and errs[1] < errs[0] / 1.6


@pytest.mark.parametrize("name", ["simplest-walker", "compass-gait", "rimless-wheel"])
def test_runs_shorter_than_one_recording_interval(name):
    """simulate(0.001) with record_every=10 records nothing but must not fail."""
    import walkers
    traj, summary, model = walkers.load(name).simulate(0.001)
    assert len(traj) <= 1 and summary["steps"] == 0 and not summary["fell"]


@pytest.mark.parametrize("name", ["simplest-walker", "compass-gait", "rimless-wheel"])
def test_cost_of_transport_is_sin_slope_whatever_the_duration(name):
    """Energy lost per weight and distance along the slope, over whole steps (touchdown to
    touchdown), is sin(slope) on a steady gait: within 0.6% for runs that end anywhere in a
    step (the end-of-run version gave 0.0074-0.0083 for the simplest walker's 0.009)."""
    import walkers
    mod = walkers.load(name)
    cots = []
    for duration in (3.0, 4.1, 7.3):
        traj, summary, model = mod.simulate(duration)
        assert summary["whole_steps"] == summary["steps"] - 1 >= 1
        cots.append(summary["cost_of_transport"])
        assert abs(summary["step_length"] / summary["step_period"] - summary["speed"]) < 1e-12
    slope = {"simplest-walker": SimplestParams().slope, "compass-gait": CompassParams().slope,
             "rimless-wheel": RimlessParams().slope}[name]
    print(name, cots, math.sin(slope))
    assert np.all(np.abs(np.array(cots) / math.sin(slope) - 1) < 0.006)   # docs/gait-analysis.md: 0.6%


def test_compass_fixed_point_converges_to_the_map_noise():
    """Asked for 1e-16, below the compass gait map's noise (~3e-14), the solve raises its
    tolerance to 4x the measured noise, says so, and converges (it used to report failure)."""
    from walkers.passive.compass_gait import default_start
    w = PassiveWalker(CompassParams(), dt=5e-4)
    fp = find_fixed_point(w.step_map(), default_start(), tol=1e-16, eps=1e-4, exact=False)
    assert 1e-16 < fp.noise < 1e-8 and fp.tol == pytest.approx(4 * fp.noise)
    assert fp.converged and fp.residual <= fp.tol


@pytest.mark.parametrize("dt, said", [
    ("1e-3", r"dt='1e-3' s must be a finite step size > 0 \[s\]"),
    (True, r"dt=True s must be a finite step size > 0"),
    (float("nan"), r"dt=nan s must be a finite step size > 0"),
    (0.0, r"dt=0.0 s must be a finite step size > 0"),
    (-1e-3, r"dt=-0.001 s must be a finite step size > 0"),
    # each evaluation runs up to MAP_HORIZON = 20 s of steps: at 1e-9 s, 2e10 of them
    (1e-9, r"dt=1e-09 s is too small for the step map: .* 20,000,000,000 steps, more than "
           r"MAX_RUN_STEPS=100,000,000; use dt >= 2e-07 s"),
])
def test_step_map_family_refuses_a_bad_dt_before_building(dt, said):
    """WalkerFamily (what planarsim analyze builds) and tilt_sensitivity's TiltStep name a bad
    dt at once; at dt 1e-9 every step-map evaluation ran on practically forever, a string
    failed in float(), True was taken for a 1 s step."""
    from walkers.passive.family import WalkerFamily
    from walkers.passive.sensitivity import TiltStep
    with pytest.raises(ValueError, match=said):
        WalkerFamily("simplest-walker", "slope", dt=dt)
    with pytest.raises(ValueError, match=said):
        TiltStep(SimplestParams(), dt=dt)


def test_a_walker_at_a_tiny_dt_refuses_its_step_map_before_running():
    """PassiveWalker itself may run at 1e-9 s (a short walk), but its step map, and the map's
    exact Jacobian, would need 2e10 steps an evaluation: refused before any step is taken."""
    from walkers.passive.gait import check_map_dt
    from walkers.passive.simplest import garcia_start
    assert check_map_dt(2e-7) == 2e-7          # (the bound itself is allowed)
    with pytest.raises(ValueError, match=r"dt=1e-08 s is too small for the step map"):
        check_map_dt(1e-8)
    w = PassiveWalker(SimplestParams(), dt=1e-9)
    said = r"dt=1e-09 s is too small for the step map"
    for call in (w.step_map, lambda: w.advance(garcia_start()),
                 lambda: w.advance_with_jacobian(garcia_start())):
        with pytest.raises(ValueError, match=said):
            call()
    assert w.sim.state.time[0] == 0.0


def test_step_map_keywords_are_named_before_running():
    """advance's record_every ("10" failed in n_steps // "10", True recorded every step) and
    tilt_sensitivity's eps and steps (checked only after the map's Jacobian had run)."""
    from walkers.passive.sensitivity import tilt_sensitivity
    from walkers.passive.simplest import garcia_start
    w = PassiveWalker(SimplestParams(), dt=2e-3)
    for bad in ("10", True, -1, 2.5):
        with pytest.raises(ValueError, match=r"record_every=.* must be a whole number"):
            w.advance(garcia_start(), record_every=bad)
    assert w.sim.state.time[0] == 0.0
    with pytest.raises(ValueError, match=r"eps=nan must be a finite number > 0"):
        tilt_sensitivity(SimplestParams(), garcia_start(), eps=float("nan"))
    with pytest.raises(ValueError, match=r"steps='20' must be a whole number"):
        tilt_sensitivity(SimplestParams(), garcia_start(), steps="20")
