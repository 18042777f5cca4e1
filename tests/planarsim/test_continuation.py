"""Continuation, bifurcation detection, brute-force diagrams, basins and multiplier error
estimates on maps with known answers (logistic map: period doubling at r = 3 and
1 + sqrt(6), chaos, escape past r = 4; a fold x -> x + p - x^2 at p = 0; a rotation-dilation
with a Neimark-Sacker point at modulus 1)."""
import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from planarsim.analysis import (MapPool, MultiplierWarning, StepMapError, basin_of_attraction,
                                bifurcation_diagram, continue_branch, multipliers_with_error,
                                period_doubling_branch, plot_basin, plot_bifurcation_diagram,
                                plot_branch_multipliers, bifurcation_tests)
from planarsim.analysis import StepMap, find_fixed_point
from planarsim.analysis.stepmap import jacobian, map_noise, multipliers_by_fit, serial_evaluator
from strategies import matrices


def logistic(r):
    def f(x):
        y = r * x * (1.0 - x)
        if not 0.0 <= y[0] <= 1.0:
            raise StepMapError("left [0, 1]")
        return y
    return f


def fold_family(p):
    return lambda x: x + p - x * x


def ns_family(p, theta=0.7):
    c, s = math.cos(theta), math.sin(theta)

    def f(x):
        r2 = x @ x
        return p * np.array([c * x[0] - s * x[1], s * x[0] + c * x[1]]) * (1.0 - r2)
    return f


def test_logistic_period_doublings_located_and_followed():
    with MapPool(logistic, backend="serial") as pool:
        br = continue_branch(pool, [0.6], 2.65, 3.35, points=8, param="r", tol=1e-12)
        assert br.end.startswith("reached") and len(br.points) == 8
        for b in br.points:   # x* = 1 - 1/r, multiplier 2 - r
            assert abs(b.x[0] - (1 - 1 / b.p)) < 1e-10 and abs(b.multipliers[0] - (2 - b.p)) < 1e-6
            assert b.stable == (b.p < 3.0)
        pd = br.first("period-doubling")
        assert pd is not None and pd.located and abs(pd.p - 3.0) < 1e-6
        assert br.first("fold") is None and br.first("neimark-sacker") is None
        br2 = period_doubling_branch(pool, pd, 3.5, points=8, param="r", tol=1e-12)
        assert br2.period == 2 and br2.points[0].stable
        pd2 = br2.first("period-doubling")
        assert pd2 is not None and abs(pd2.p - (1 + math.sqrt(6))) < 1e-5
        rows = br2.rows(["x"])
        assert rows[0]["period"] == 2 and "mult0_re" in rows[0]


def exact_logistic(r):
    """The logistic map as a StepMap with its exact Jacobian."""
    from planarsim.analysis import StepMap
    f = logistic(r)
    return StepMap(f, dim=1, derivative=lambda x: (f(x), np.array([[r * (1.0 - 2.0 * x[0])]])))


def test_the_continuation_takes_the_maps_exact_jacobian():
    """With a map that has its exact Jacobian (the default: where it has one) the multipliers
    are exact (error 0) and the doublings at r = 3 and 1 + sqrt(6) are located as with the
    fits, tighter; exact=True on a map without one is an error, exact=False takes the fits."""
    with MapPool(exact_logistic, backend="serial") as pool:
        assert pool.exact(3.0)
        br = continue_branch(pool, [0.6], 2.65, 3.35, points=8, param="r", tol=1e-12,
                             p_tol=1e-10)
        for b in br.points:
            assert b.error == 0.0 and abs(b.multipliers[0] - (2 - b.p)) < 1e-10
        pd = br.first("period-doubling")
        assert pd is not None and abs(pd.p - 3.0) < 1e-8
        br2 = period_doubling_branch(pool, pd, 3.5, points=8, param="r", tol=1e-12,
                                     p_tol=1e-10)
        pd2 = br2.first("period-doubling")
        assert pd2 is not None and abs(pd2.p - (1 + math.sqrt(6))) < 1e-8
    with MapPool(exact_logistic, backend="serial", exact=False) as pool:
        assert not pool.exact(3.0)
        b = continue_branch(pool, [0.6], 2.65, 2.9, points=3, param="r", tol=1e-12).points[0]
        assert b.error > 0.0
    with MapPool(logistic, backend="serial", exact=True) as pool, \
            pytest.raises(ValueError, match="no exact Jacobian"):
        pool.exact(3.0)


def test_fold_found_by_arclength_which_turns_back():
    # fixed points x = +-sqrt(p) for p > 0; multiplier 1 - 2x: the stable upper branch meets
    # the unstable lower one at the fold p = 0
    with MapPool(fold_family, backend="serial") as pool:
        nat = continue_branch(pool, [1.0], 1.0, -0.5, points=7, tol=1e-12)
        assert not nat.end.startswith("reached")     # no fixed point past the fold
        arc = continue_branch(pool, [1.0], 1.0, -0.5, points=7, method="arclength", tol=1e-12,
                              max_points=40)
        folds = [b for b in arc.bifurcations if b.kind == "fold"]
        assert len(folds) == 1 and abs(folds[0].p) < 0.05
        assert arc.points[-1].x[0] < 0                # came back along the lower branch
        assert min(arc.p) > -0.05


def test_neimark_sacker_detected():
    with MapPool(ns_family, backend="serial") as pool:
        br = continue_branch(pool, [0.0, 0.0], 0.8, 1.2, points=5, tol=1e-12)
        ns = br.first("neimark-sacker")
        assert ns is not None and abs(ns.p - 1.0) < 0.02
        assert br.first("period-doubling") is None and br.first("fold") is None


def test_bifurcation_test_function_signs():
    t = bifurcation_tests([-1.2, 0.3])
    assert t["period-doubling"] < 0 and t["fold"] > 0 and t["neimark-sacker"] == 0
    assert bifurcation_tests([1.1 + 0.2j, 1.1 - 0.2j])["neimark-sacker"] == 2


def test_brute_force_diagram_periods_chaos_and_escape():
    rs = np.array([2.8, 3.2, 3.5, 3.9, 4.05])
    with MapPool(logistic, backend="serial") as pool:
        d = bifurcation_diagram(pool, rs, [0.3], transient=400, keep=32, param="r")
    assert d.periods(1e-6).tolist()[:3] == [1, 2, 4]
    assert d.periods(1e-6)[3] == 0                 # chaos: no period up to 16
    assert d.fell.tolist() == [False] * 4 + [True] and d.fall_onset() == 4.05
    assert len(d.orbits[0]) == 32 and len(d.orbits[4]) == 0
    assert len(d.rows()) == 4 * 32 + 1


@pytest.mark.parametrize("call, said", [
    # keep=1 or 0: every orbit read as a fall (period -1), transient=-5 ran silently
    (lambda pool: bifurcation_diagram(pool, [2.8], [0.3], transient=10, keep=1),
     r"keep=1 must be a whole number >= 2"),
    (lambda pool: bifurcation_diagram(pool, [2.8], [0.3], transient=-5, keep=8),
     r"transient=-5 must be a whole number >= 0"),
    (lambda pool: bifurcation_diagram(pool, [2.8], [0.3], transient=10, keep=2.5),
     r"keep=2.5 must be a whole number"),
    # period 0: the identity, whose every point "converged" as a fixed point
    (lambda pool: continue_branch(pool, [0.6], 2.8, 2.9, 3, period=0),
     r"period=0 must be a whole number >= 1"),
    # numbers of the wrong kind: a string p0 failed in math.isfinite() (TypeError), points="3"
    # in int() raw, 2.7 points were 2, True was taken for 1; a NaN or inf mult_tol or p_tol
    # passed into the detection
    (lambda pool: continue_branch(pool, [0.6], "2.8", 2.9, 3), r"p0='2.8' must be a finite number"),
    (lambda pool: continue_branch(pool, [0.6], 2.8, float("nan"), 3), r"p1=nan must be a finite number"),
    (lambda pool: continue_branch(pool, [0.6], 2.8, 2.9, "3"), r"points='3' must be a whole number"),
    (lambda pool: continue_branch(pool, [0.6], 2.8, 2.9, 2.7), r"points=2.7 must be a whole number"),
    (lambda pool: continue_branch(pool, [0.6], 2.8, 2.9, True), r"points=True must be a whole number"),
    (lambda pool: continue_branch(pool, [0.6], 2.8, 2.9, 1), r"points=1 must be a whole number >= 2"),
    (lambda pool: continue_branch(pool, [0.6], 2.8, 2.9, 3, mult_tol=float("nan")),
     r"mult_tol=nan must be a finite number > 0"),
    (lambda pool: continue_branch(pool, [0.6], 2.8, 2.9, 3, p_tol=-1e-6),
     r"p_tol=-1e-06 must be a finite number > 0"),
    (lambda pool: continue_branch(pool, [0.6], 2.8, 2.9, 3, tol=math.inf),
     r"tol=inf must be a finite number > 0"),
    (lambda pool: continue_branch(pool, [0.6], 2.8, 2.9, 3, max_points="many", method="arclength"),
     r"max_points='many' must be a whole number"),
    (lambda pool: basin_of_attraction(pool, 2.8, [0.3], [0.0], lambda a, b: [a], [0.64],
                                      n_steps="50"), r"n_steps='50' must be a whole number"),
    (lambda pool: basin_of_attraction(pool, 2.8, [0.3], [0.0], lambda a, b: [a], [0.64],
                                      tol=float("nan")), r"tol=nan must be a finite number >= 0"),
])
def test_counts_that_would_give_wrong_answers_are_refused(call, said):
    with MapPool(logistic, backend="serial") as pool:
        with pytest.raises(ValueError, match=said):
            call(pool)


@pytest.mark.parametrize("call, said", [
    # find_fixed_point: a NaN eps passed "eps <= 0" and gave a NaN Jacobian, a string failed
    # in numpy's conversion; max_iter="30" failed in range()
    (lambda f: find_fixed_point(f, [0.6], eps=float("nan")),
     r"finite-difference step eps=nan must be a finite number > 0"),
    (lambda f: find_fixed_point(f, [0.6], eps="small"),
     r"finite-difference step eps='small' must be a finite number > 0"),
    (lambda f: find_fixed_point(f, [0.6], max_iter="30"), r"max_iter='30' must be a whole number"),
    (lambda f: find_fixed_point(f, [0.6], max_halvings=-1), r"max_halvings=-1 must be a whole number >= 0"),
    (lambda f: find_fixed_point(f, [0.6], tol=True), r"tol=True must be a finite number > 0"),
    (lambda f: jacobian(f, [0.6], eps=[1e-6, float("nan")]), r"eps=\[1e-06, nan\] must be a finite"),
    (lambda f: StepMap(f, dim=1).iterate([0.6], "5"), r"n='5' must be a whole number"),
    (lambda f: map_noise(serial_evaluator(f), [0.6], probes=0), r"probes=0 must be a whole number >= 1"),
    # multipliers_with_error took eps=True for a step of 1 and any tol; multipliers_by_fit's
    # points="21" failed in int(), 21.5 points were 21
    (lambda f: multipliers_with_error(f, [0.6], eps=True),
     r"finite-difference step eps=True must be a finite number > 0 \(or 'auto'\)"),
    (lambda f: multipliers_with_error(f, [0.6], tol=float("nan")), r"tol=nan must be a finite number > 0"),
    (lambda f: multipliers_by_fit(f, [0.6], points="21"), r"points='21' must be a whole number"),
    (lambda f: multipliers_by_fit(f, [0.6], points=21.5), r"points=21.5 must be a whole number"),
    (lambda f: multipliers_by_fit(f, [0.6], window="wide"), r"window='wide' must be a finite number > 0"),
])
def test_step_map_tools_name_bad_numbers(call, said):
    with pytest.raises(ValueError, match=said):
        call(logistic(2.8))


def test_map_pool_names_a_bad_cache():
    for cache, said in (("8", r"cache='8' must be a whole number"), (0, r"cache=0 must be a whole number >= 1")):
        with pytest.raises(ValueError, match=said):
            MapPool(logistic, backend="serial", cache=cache)


def test_newton_and_the_doubling_branch_name_bad_numbers():
    from planarsim.analysis.continuation import newton_fixed_point
    with MapPool(logistic, backend="serial") as pool:
        with pytest.raises(ValueError, match=r"max_iter=2.5 must be a whole number"):
            newton_fixed_point(pool, 2.8, [0.6], max_iter=2.5)
        with pytest.raises(ValueError, match=r"eps=0.0 must be a finite number > 0"):
            newton_fixed_point(pool, 2.8, [0.6], eps=0.0)
        br = continue_branch(pool, [0.6], 2.65, 3.35, points=8, param="r", tol=1e-12)
        pd = br.first("period-doubling")
        with pytest.raises(ValueError, match=r"points='8' must be a whole number"):
            period_doubling_branch(pool, pd, 3.5, points="8")
        with pytest.raises(ValueError, match=r"p1=nan must be a finite number"):
            period_doubling_branch(pool, pd, float("nan"))
        assert pool.evaluations == br.evaluations


def pair(p):
    g = logistic(p)
    return lambda x: np.array([g(x[:1])[0], 0.5 * x[1]])


def test_basin_of_a_decoupled_map():
    a = np.linspace(-0.15, 1.15, 8)
    b = np.linspace(-1.0, 1.0, 3)
    xs = 1 - 1 / 2.8
    with MapPool(pair, backend="serial") as pool:
        bs = basin_of_attraction(pool, 2.8, a, b, lambda u, v: [u, v], [xs, 0.0], n_steps=200,
                                 tol=1e-8, names=("x", "y"))
    inside = (a > 0) & (a < 1)
    assert np.array_equal(bs.reached, np.repeat(inside[:, None], 3, axis=1))
    assert np.array_equal(bs.fell, ~bs.reached)
    assert abs(bs.fraction - inside.mean()) < 1e-12 and len(bs.rows()) == 24


@pytest.mark.parametrize("backend", ["thread", "process"])
def test_pool_backends_agree_with_serial(backend):
    X = np.linspace(0.05, 0.95, 23)[:, None]
    done = []
    with MapPool(logistic, backend="serial") as s, MapPool(logistic, workers=2, backend=backend) as pool:
        Y0, ok0 = s.evaluate(X, 3.7, period=3)
        Y1, ok1 = pool.evaluate(X, 3.7, period=3)
        d = pool.run(__import__("planarsim.analysis.parallel", fromlist=["x"]).evaluate_task,
                     [(4.2, [0.5], 1)], progress=lambda k, n: done.append((k, n)))
    assert np.array_equal(Y0, Y1) and np.array_equal(ok0, ok1) and ok0.all()
    assert d == [None] and done == [(1, 1)]        # 4.2 * 0.25 > 1: escaped


def smooth(x):
    return np.array([math.sin(x[0]) + 0.5 * x[1], 0.3 * math.tanh(x[0]) + 0.1 * math.exp(x[1])])


def test_multipliers_with_error_on_a_smooth_map():
    x = np.array([0.4, -0.2])
    J = np.array([[math.cos(0.4), 0.5], [0.3 / math.cosh(0.4) ** 2, 0.1 * math.exp(-0.2)]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        m = multipliers_with_error(smooth, x)
    assert m.converged and m.error < 1e-6
    assert np.allclose(np.sort(m.values.real), np.sort(np.linalg.eigvals(J).real), atol=1e-8)
    assert m.eps < 1e-4            # a smooth map goes down the ladder
    two = multipliers_with_error(smooth, x, eps=1e-3)
    assert two.eps == 1e-3 and len(two.ladder) == 2 and 1e-9 < two.error < 1e-5


@settings(max_examples=15, deadline=None)
@given(st.floats(1e-9, 1e-6), matrices(3, 3, -1.2, 1.2))
def test_multiplier_error_covers_noise(noise, A):
    """A linear map x -> A x (entries of A drawn in [-1.2, 1.2], 3 sigma of the normal 0.4 it
    stands for) with a rough (piecewise-constant) perturbation of amplitude `noise`."""

    def f(x):
        return A @ x + noise * np.sin(np.floor(x * 1e6))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MultiplierWarning)
        m = multipliers_with_error(f, np.zeros(3))
    from planarsim.analysis import match_distance
    err = match_distance(m.values, np.linalg.eigvals(A))
    assert err <= 2 * m.error + 1e-9     # the estimate bounds the true error (up to 2x)


def test_unconverged_multipliers_warn():
    def f(x):
        return np.array([0.5 * x[0] + 1e-3 * np.sign(np.sin(1e7 * x[0]))])
    with pytest.warns(MultiplierWarning, match="not converged"):
        m = multipliers_with_error(f, [0.1234567], tol=1e-6)
    assert not m.converged
    with pytest.raises(ValueError, match="eps"):
        multipliers_with_error(f, [0.0], eps="fine")


def test_plots_of_branch_diagram_and_basin(tmp_path):
    import matplotlib.image as mpimg
    with MapPool(logistic, backend="serial") as pool:
        br = continue_branch(pool, [0.6], 2.6, 3.3, points=5, tol=1e-12)
        d = bifurcation_diagram(pool, np.linspace(2.8, 4.0, 6), [0.3], transient=50, keep=8)
    with MapPool(pair, backend="serial") as pool:
        bs = basin_of_attraction(pool, 2.8, np.linspace(-0.1, 1.1, 5), [0.0, 1.0],
                                 lambda u, v: [u, v], [1 - 1 / 2.8, 0.0], n_steps=100, tol=1e-6)
    paths = [tmp_path / n for n in ("d.png", "m.png", "b.png")]
    plot_bifurcation_diagram(d, 0, paths[0], branches=[br], bifurcations=br.bifurcations)
    plot_branch_multipliers(br, paths[1])
    plot_basin(bs, paths[2], attractor=[1 - 1 / 2.8, 0.0])
    for p in paths:
        img = mpimg.imread(p)
        assert img.shape[0] > 200 and img[..., :3].std() > 0.05
    br.to_csv(tmp_path / "b.csv")
    d.to_csv(tmp_path / "d.csv")
    bs.to_csv(tmp_path / "s.csv")
    assert (tmp_path / "b.csv").read_text().splitlines()[0].startswith("p,period,x0")
    assert len((tmp_path / "d.csv").read_text().splitlines()) > 6


def test_the_birth_of_a_period_two_orbit_is_not_a_fold():
    """Half a step past a doubling the period-2 orbit's multiplier is near +1 (the pitchfork of
    P^2); the simplest walker's map, noisy at 1e-5, estimated it at 1.13 +- 0.04 there and 0.72
    at the next point, and a fold was reported where the orbit is born. Between a branch's
    first point and the next (born=True) that crossing is not a fold; anywhere else it is."""
    from planarsim.analysis.continuation import BranchPoint, _detect
    a = BranchPoint(0.015144, np.zeros(2), np.array([1.1322, 0.0102]), 0.041, 1e-7, 2)
    b = BranchPoint(0.015540, np.zeros(2), np.array([0.7212, 0.0386]), 0.037, 1e-7, 2)
    assert [f.kind for f in _detect(None, [a], b, False, 1e-6, 1e-6, 3e-3)] == ["fold"]
    assert _detect(None, [a], b, False, 1e-6, 1e-6, 3e-3, born=True) == []


def noisy_logistic(amplitude):
    """The logistic map with a rough perturbation (piecewise constant on a 1e-6 grid) of
    `amplitude`: a simulated map's noise, which the multipliers' error estimate must see."""
    def family(r):
        g = logistic(r)
        return lambda x: g(x) + amplitude * np.sin(np.floor(x * 1e6))
    return family


def test_a_crossing_within_the_noise_is_refined_and_located_not_discarded():
    """At r = 3 the multiplier 2 - r is exactly -1, inside any error estimate: the doubling is
    taken between the resolved points around it (r = 2.9 and 3.1), located by regula falsi,
    and its note says how."""
    with MapPool(noisy_logistic(1e-7), backend="serial") as pool:
        br = continue_branch(pool, [0.6], 2.8, 3.2, points=5, param="r")
    middle = br.points[2]
    assert middle.p == pytest.approx(3.0) and abs(middle.multipliers[0] + 1.0) <= middle.error
    pd = br.first("period-doubling")
    assert pd is not None and pd.located and abs(pd.p - 3.0) < max(1e-4, 2 * pd.p_error)
    assert "within its error of -1 at p=3 (refined" in pd.note and "between p=2.9 and 3.1" in pd.note
    assert [b.kind for b in br.bifurcations] == ["period-doubling"]


def test_a_crossing_left_open_at_the_branch_end_is_reported():
    """The branch ends at r = 3.0001, its multiplier -1.0001 within its error of -1: the
    crossing is reported, not located, with a note to extend the range."""
    with MapPool(noisy_logistic(1e-7), backend="serial") as pool:
        br = continue_branch(pool, [0.6], 2.8, 3.0001, points=3, param="r")
    last = br.points[-1]
    assert abs(last.multipliers[0] + 1.0) <= last.error
    assert bifurcation_tests(last.multipliers)["period-doubling"] < 0
    pd = br.first("period-doubling")
    assert pd is not None and not pd.located and "extend the range" in pd.note


def test_fixed_point_tolerance_follows_the_map_noise():
    """A map with noise 1e-9 cannot be solved to 1e-12: find_fixed_point raises its tolerance
    to a few times the measured noise and says so (FixedPoint.noise, .tol), and converges."""
    from planarsim.analysis import find_fixed_point, map_noise, serial_evaluator
    f = noisy_logistic(1e-9)(2.8)
    noise = map_noise(serial_evaluator(f), np.array([0.6]))
    assert 1e-10 < noise < 3e-9
    fp = find_fixed_point(f, [0.6], tol=1e-12, eps=1e-4)
    assert fp.converged and fp.tol > 1e-12 and fp.tol == pytest.approx(4 * fp.noise)
    assert abs(fp.x[0] - (1 - 1 / 2.8)) < 1e-7
    smooth_fp = find_fixed_point(logistic(2.8), [0.6], tol=1e-12)
    assert smooth_fp.tol == 1e-12 and smooth_fp.residual <= 1e-12
    assert find_fixed_point(f, [0.6], eps=1e-4).tol == max(1e-9, 4 * fp.noise)   # "auto"


def test_a_dask_cluster_gives_the_pools_answers_bit_for_bit():
    """MapPool(scheduler=...) on a local dask cluster of two worker processes: a basin of the
    simplest walker and the maps' evaluations equal the serial pool's bit for bit (each worker
    builds its own walkers from the pickled family)."""
    distributed = pytest.importorskip("distributed")
    from walkers.passive.family import WalkerFamily
    family = WalkerFamily("simplest-walker", "slope", dt=2e-3)
    x = np.array([0.2002, -0.1999, 0.4003, -0.0158])
    a, b = np.linspace(0.17, 0.23, 3), np.linspace(-0.23, -0.17, 3)

    def state(u, v):
        return [u, v, 2 * u, -0.0158]

    with MapPool(family, backend="serial") as serial:
        want = basin_of_attraction(serial, 0.009, a, b, state, x, n_steps=12, tol=1e-3)
        Y0, ok0 = serial.evaluate(np.array([x, x + 0.001, x - 0.001]), 0.009)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=2, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        client.wait_for_workers(2)
        with pytest.raises(ValueError, match="scheduler"):
            MapPool(family, backend="process", scheduler=client)
        with MapPool(family, scheduler=client) as pool:
            assert pool.backend == "dask" and pool.workers == 4     # (threads: each its maps)
            got = basin_of_attraction(pool, 0.009, a, b, state, x, n_steps=12, tol=1e-3)
            Y, ok = pool.evaluate(np.array([x, x + 0.001, x - 0.001]), 0.009)
        # a second pool of another family on the same workers uses its own maps
        with MapPool(WalkerFamily("simplest-walker", "slope", dt=1e-3), scheduler=client) as other:
            Y1, _ = other.evaluate(np.array([x]), 0.009)
        with MapPool(WalkerFamily("simplest-walker", "slope", dt=1e-3), backend="serial") as ref:
            assert np.array_equal(Y1, ref.evaluate(np.array([x]), 0.009)[0])
    assert np.array_equal(got.steps, want.steps) and np.array_equal(got.fell, want.fell)
    assert np.array_equal(got.reached, want.reached)
    assert np.array_equal(ok, ok0) and np.array_equal(Y[ok], Y0[ok0])
