"""planarsim.analysis on maps with known answers: step events from contact modes, Newton fixed
points, Floquet multipliers, the symmetric reduction, failure handling, plots."""
import math
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from planarsim.analysis import (StepMap, StepMapError, find_fixed_point, floquet_multipliers,
                                jacobian, plot_limit_cycle, plot_multipliers, poincare_section,
                                sort_multipliers, step_events, touchdowns)


# step events ---------------------------------------------------------------------------------
def test_touchdowns_are_entries_into_contact():
    mode = np.array([0, 0, 1, 1, 0, -1, -1, 2, 2, 1, 0, 1])
    assert touchdowns(mode).tolist() == [2, 7, 11]
    assert touchdowns(np.array([1, 1, 1])).tolist() == []   # in contact from the start: no event
    with pytest.raises(ValueError, match="1-D"):
        touchdowns(np.zeros((3, 2)))


def test_step_events_merge_contacts_in_time_order_and_section():
    modes = np.array([[1, 0], [1, 0], [0, 1], [0, 1], [1, 0], [1, 1], [0, 1]])
    traj = SimpleNamespace(contact_mode=modes, contact_names=("left", "right"),
                           t=np.arange(7) * 0.5, q=np.arange(7.0)[:, None, None] * np.ones((7, 1, 3)),
                           v=np.zeros((7, 1, 3)))
    ev = step_events(traj)
    assert ev.frame.tolist() == [2, 4, 5] and ev.contact.tolist() == [1, 0, 1]
    assert np.allclose(ev.time, [1.0, 2.0, 2.5]) and np.allclose(ev.periods, [1.0, 0.5])
    ev = step_events(traj, ["left"])
    assert ev.frame.tolist() == [4] and ev.contact.tolist() == [0]
    ev2, X = poincare_section(traj, lambda q, v, c: [q[0, 0], c])
    assert X.tolist() == [[2.0, 1.0], [4.0, 0.0], [5.0, 1.0]]
    with pytest.raises(KeyError, match="middle"):
        step_events(traj, ["middle"])


def test_feet_landing_together_land_once():
    # both feet leave at frame 2 and land at frames 5 and 6 (0.01 s apart), then walk: the
    # right foot lifts at 8 and lands alone at 10
    modes = np.array([[1, 1], [1, 1], [0, 0], [0, 0], [0, 0], [1, 0], [1, 1], [1, 1], [1, 0],
                      [1, 0], [1, 1]])
    traj = SimpleNamespace(contact_mode=modes, contact_names=("left", "right"), t=np.arange(11) * 0.01)
    feet = [["left"], ["right"]]
    assert step_events(traj, feet=feet).frame.tolist() == [5, 6, 10]
    assert step_events(traj, feet=feet, together=0.02).frame.tolist() == [5, 10]
    assert step_events(traj, feet=feet, together=0.06).frame.tolist() == [5]
    # a name or an index in place of a group is a foot of that one contact (["left"] was
    # read as contacts 'l', 'e', 'f', 't'; [0] failed as "'int' object is not iterable")
    for single in (["left", "right"], [0, 1], [np.int64(0), "right"]):
        assert step_events(traj, feet=single).frame.tolist() == [5, 6, 10]


# fixed points and multipliers ----------------------------------------------------------------
def henon(a=1.4, b=0.3):
    return lambda x: np.array([1.0 - a * x[0] ** 2 + x[1], b * x[0]])


@pytest.mark.parametrize("kw, said", [
    (dict(min_air=math.nan), r"min_air=nan must be a finite number >= 0"),
    (dict(together=-1.0), r"together=-1.0 must be a finite number >= 0"),
    (dict(min_air="long"), r"min_air='long' must be a finite number >= 0"),   # was a '>' TypeError
    (dict(feet="left"), r"feet='left' must be a list .* not a string"),        # was "no contact 'l'"
])
def test_step_events_settings_are_checked(kw, said):
    """A NaN or negative min_air or together compared False and counted every landing (a NaN
    min_stride gave measure.summary a whole step where 0 gave none), silently."""
    modes = np.zeros((11, 2), int)
    modes[3:, 0] = 1
    traj = SimpleNamespace(contact_mode=modes, contact_names=("left", "right"), t=np.arange(11) * 0.01)
    with pytest.raises(ValueError, match=said):
        step_events(traj, **({"feet": [["left"]]} | kw))


def test_henon_fixed_point_and_multipliers_match_closed_form():
    a, b = 1.4, 0.3
    xs = (-(1 - b) + math.sqrt((1 - b) ** 2 + 4 * a)) / (2 * a)
    exact = np.array([xs, b * xs])
    lam = sort_multipliers([-a * xs + math.sqrt(a * a * xs * xs + b), -a * xs - math.sqrt(a * a * xs * xs + b)])
    fp = find_fixed_point(henon(a, b), [0.5, 0.1], tol=1e-13)
    assert fp.converged and fp.iterations <= 10
    assert np.allclose(fp.x, exact, atol=1e-12)
    assert np.allclose(fp.multipliers, lam, atol=1e-7)
    assert not fp.stable   # the Henon saddle: one multiplier outside the unit circle
    assert np.allclose(floquet_multipliers(henon(a, b), exact), lam, atol=1e-7)


# a multiplier's modulus kept 0.01 away from 1 (J - I safely invertible; stability not a
# matter of rounding)
MODULI = st.one_of(st.floats(0.0, 0.99), st.floats(1.01, 1.35))


@st.composite
def affine_maps(draw):
    """(A, fixed point, start, multipliers) of a d-dimensional affine step map x -> xs + A (x - xs)
    (d = 1..5), drawn by its multipliers (real ones, and complex pairs of drawn modulus and
    angle) in an orthonormal basis of drawn rotation angles: A = Q B Q^T, B block diagonal, so
    its multipliers are known without an eigenvalue solver and are well conditioned."""
    d = draw(st.integers(1, 5))
    pairs = draw(st.integers(0, d // 2))
    B = np.zeros((d, d))
    lam = []
    for k in range(pairs):
        r, th = draw(MODULI), draw(st.floats(0.05, math.pi - 0.05))
        B[2 * k:2 * k + 2, 2 * k:2 * k + 2] = r * np.array([[math.cos(th), -math.sin(th)],
                                                            [math.sin(th), math.cos(th)]])
        lam += [r * complex(math.cos(th), math.sin(th)), r * complex(math.cos(th), -math.sin(th))]
    for i in range(2 * pairs, d):
        B[i, i] = draw(MODULI) * draw(st.sampled_from([1.0, -1.0]))
        lam.append(complex(B[i, i]))
    Q = np.eye(d)
    for i in range(d):
        for j in range(i + 1, d):
            a = draw(st.floats(-math.pi, math.pi))
            G = np.eye(d)
            G[[i, i, j, j], [i, j, i, j]] = math.cos(a), -math.sin(a), math.sin(a), math.cos(a)
            Q = Q @ G
    vec = st.lists(st.floats(-3.0, 3.0), min_size=d, max_size=d).map(np.array)
    return Q @ B @ Q.T, draw(vec), draw(vec), np.array(lam)


@settings(max_examples=30, deadline=None)
@given(affine_maps())
def test_affine_map_newton_is_exact_and_multipliers_are_eigenvalues(case):
    A, xs, offset, lam = case
    d = len(xs)
    f = StepMap(lambda x: xs + A @ (x - xs), dim=d)
    fp = find_fixed_point(f, xs + offset, tol=1e-11, eps=1e-4)
    assert fp.converged and fp.iterations <= 2
    assert np.allclose(fp.x, xs, atol=1e-9)
    assert np.allclose(fp.jacobian, A, atol=1e-8)
    # each computed multiplier paired with a drawn one (the pairing that minimises the total
    # distance: sorting would pair wrongly where two share a real part up to rounding)
    from scipy.optimize import linear_sum_assignment
    gap = np.abs(np.asarray(fp.multipliers)[:, None] - lam[None, :])
    rows, cols = linear_sum_assignment(gap)
    assert len(fp.multipliers) == d and gap[rows, cols].max() <= 1e-7, (fp.multipliers, lam)
    assert fp.stable == bool(np.max(np.abs(lam)) < 1.0)


def test_forward_and_central_differences_agree_on_a_smooth_map():
    f = henon()
    x = np.array([0.3, -0.2])
    exact = np.array([[-2 * 1.4 * 0.3, 1.0], [0.3, 0.0]])
    assert np.allclose(jacobian(f, x, 1e-6), exact, atol=1e-8)
    assert np.allclose(jacobian(f, x, 1e-7, central=False), exact, atol=1e-6)
    with pytest.raises(ValueError, match="eps"):
        jacobian(f, x, 0.0)


def test_symmetric_reduction_finds_the_one_step_gait():
    # a "walker" in side coordinates (x_left, x_right): P = S Q with Q symmetric (Q S = S Q)
    S = np.array([[0.0, 1.0], [1.0, 0.0]])
    A = np.array([[0.3, -0.5], [-0.5, 0.3]])   # commutes with the swap

    def Q(x):
        return A @ x + 0.1 * np.sin(x) + 0.7

    def P(x):
        return S @ Q(x)

    reduced = StepMap(P, dim=2, symmetry=S)
    fp = find_fixed_point(reduced, [0.0, 0.0], tol=1e-13)
    assert fp.converged
    assert np.allclose(Q(fp.x), fp.x, atol=1e-12)           # a fixed point of Q = S P
    assert np.allclose(P(P(fp.x)), fp.x, atol=1e-12)         # hence a period-two orbit of P
    two_step = floquet_multipliers(lambda x: P(P(x)), fp.x, eps=1e-6)
    assert np.allclose(np.sort(np.abs(two_step)), np.sort(np.abs(fp.multipliers) ** 2), atol=1e-6)
    with pytest.raises(ValueError, match="symmetry"):
        StepMap(P, dim=2, symmetry=np.eye(3))


def test_newton_halves_steps_across_a_failure_region_and_reports_failure():
    def f(x):
        if x[0] > 1.5:
            raise StepMapError("fell")
        return np.array([0.5 * x[0] + 0.5 + 0.3 * math.sin(3 * x[0])])

    fp = find_fixed_point(StepMap(f, dim=1), [0.0], tol=1e-12)
    assert fp.converged and abs(f(fp.x)[0] - fp.x[0]) < 1e-12
    with pytest.raises(StepMapError, match="initial guess"):
        find_fixed_point(StepMap(f, dim=1), [2.0])
    # a map without a fixed point: Newton stops and says it did not converge
    fp = find_fixed_point(StepMap(lambda x: x + 1.0 + 0.1 * np.cos(x), dim=1), [0.0], max_iter=5)
    assert not fp.converged and fp.residual >= 0.9


def test_step_map_checks_shapes_and_counts_evaluations():
    m = StepMap(lambda x: 2 * x, dim=2)
    m([1.0, 2.0])
    assert m.evaluations == 1
    with pytest.raises(ValueError, match="shape"):
        m([1.0])
    bad = StepMap(lambda x: np.array([np.nan, 0.0]), dim=2)
    with pytest.raises(StepMapError, match="non-finite"):
        bad([0.0, 0.0])
    orbit = StepMap(lambda x: 0.5 * x, dim=1).iterate([8.0], 3)
    assert orbit[:, 0].tolist() == [8.0, 4.0, 2.0, 1.0]


def test_plots_write_png_files(tmp_path):
    lam = np.array([-0.19 + 0.56j, -0.19 - 0.56j, 0.0])
    p1 = tmp_path / "mult.png"
    plot_multipliers(lam, p1)
    th = np.linspace(0, 2 * np.pi, 200)
    p2 = tmp_path / "cycle.png"
    plot_limit_cycle(np.cos(th), np.sin(th), p2, section=np.array([[1.0, 0.0]]))
    import matplotlib.image as mpimg
    for p in (p1, p2):
        img = mpimg.imread(p)
        assert img.shape[0] > 200 and img.shape[1] > 200
        assert img[..., :3].std() > 0.05   # something was drawn
