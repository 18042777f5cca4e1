"""Lemke's method and the polish of a regularised answer, on random complementarity problems
of contact shape: M = J J^T with more rows than degrees of freedom (redundant contacts
sharing a load, so M and the answer's basis are singular) and q built around a known
answer, so that every problem has one."""
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings, strategies as st
from hypothesis.extra.numpy import arrays

from numba import njit

from planarsim.compile import options as compile_options
from planarsim.kernels.solver.lcp import ANSWER_TOL, LCP_INACCURATE, LCP_SOLVED, lemke, polish
from strategies import full_rank, vectors

# not cached: numba checks a cached function against its own file only, and this wrapper
# must follow the kernels it calls
jit = njit(**dict(compile_options(), cache=False))


@jit
def _solve_in(M, q, eps, z_reg, z, T, basis):
    m = q.shape[0]
    for i in range(m):
        M[i, i] += eps
    status, pivots = lemke(M, q, m, T, basis, z, 40 * m + 10, 0, 0.0)
    for i in range(m):
        M[i, i] -= eps
    for i in range(m):
        z_reg[i] = z[i]
    if status != LCP_SOLVED:
        return status, -1
    return status, polish(M, q, m, T, basis, z, 0.0)


def _solve(M, q, eps, z_reg, z):
    """lemke on M + eps I into z_reg, then polish for M into z: (lemke's, polish's status)."""
    m = len(q)
    return _solve_in(M, q, eps, z_reg, z, np.zeros((m, 2 * m + 2)), np.zeros(m, np.int64))


def _miss(M, q, z):
    """Largest breach of z >= 0, w >= 0, z w = 0 (w = M z + q), relative to max |q|."""
    w = M @ z + q
    scale = np.abs(q).max()
    return max(-z.min(), -w.min(), np.abs(z * w).max() / scale) / scale


def _nearly_singular(M, z, eps):
    """The loaded rows of answer z have a non-zero eigenvalue of M below 100 eps: nearly
    dependent, not redundant (about 1 in 200 of redundant_contacts' problems)."""
    loaded = z > 0.0
    if not loaded.any():
        return False
    lam = np.linalg.eigvalsh(M[np.ix_(loaded, loaded)])
    lam = lam[lam > 1e-12 * lam.max()]
    return lam.min() < 100 * eps


def _problem(J, loaded, load, slack):
    """(M, q) of contact rows J (k x d) with a known answer: z = load on the `loaded` rows
    (w = 0 there), w = slack on the others (z = 0 there)."""
    M = J @ J.T
    z_star = np.where(loaded, load, 0.0)
    w_star = np.where(loaded, 0.0, slack)
    return M, w_star - M @ z_star


def _seeded_problem(d, k, seed):
    """(M, q) of k contact rows on d degrees of freedom from numpy seed `seed`, with a known
    answer: about half of the rows loaded in it."""
    rng = np.random.default_rng(seed)
    J = rng.normal(size=(k, d))
    loaded = rng.random(k) < 0.5
    return _problem(J, loaded, rng.uniform(0.1, 1.0, k), rng.uniform(0.0, 1.0, k))


@st.composite
def redundant_contacts(draw):
    """(M, q): k contact rows on d < k degrees of freedom (J of rank d, entries drawn in
    [-3, 3], no two rows within 1e-3 rad of parallel), each loaded in the answer with chance 1/2 (its load z in [0.1, 1]), else its
    slack w in [1e-3, 1]."""
    d = draw(st.integers(2, 6))
    k = draw(st.integers(d + 1, 2 * d + 2))
    loaded = draw(arrays(np.bool_, k, elements=st.booleans(), fill=st.nothing()))
    J = draw(full_rank(k, d))
    # no two rows within 1e-3 rad of (anti)parallel and slacks from 1e-3 up (as in all but
    # about 1 in 100 normal and uniform draws): closer, a contact may be a hair from touching
    # at another answer (test_polish_is_exact_where_a_contact_is_a_hair_short_of_touching).
    # A row nearly in the span of two or more others does the same (the triple there); that
    # is left in: 2 in some 30 000 of these draws, none of the derandomized search's
    unit = J / np.linalg.norm(J, axis=1, keepdims=True)
    assume(np.abs(np.triu(unit @ unit.T, 1)).max() < math.cos(1e-3))
    return _problem(J, loaded, draw(vectors(k, 0.1, 1.0)), draw(vectors(k, 1e-3, 1.0)))


def _check_polish(M, q):
    """lemke solves M + 1e-6 I; polish then solves M to 1e-9 of max |q| (ANSWER_TOL where the
    loaded rows are nearly singular) or says it could not and leaves the regularised answer."""
    if q.min() >= 0.0:          # nothing pushes: z = 0, no path, nothing to polish
        return
    z_reg = np.zeros(len(q))
    z = np.zeros(len(q))
    status, polished = _solve(M.copy(), q, 1e-6, z_reg, z)
    assert status == LCP_SOLVED
    if polished != LCP_SOLVED:
        # polish may fail (none of the next test's 17 731 problems does); it says so and
        # leaves the regularised answer, which the contact solve keeps only within ANSWER_TOL
        # and otherwise reports (mixed_lcp.py)
        assert polished == LCP_INACCURATE
        assert np.array_equal(z, z_reg)
        return
    if _nearly_singular(M, z, 1e-6):
        # refinement with the path's inverse of M + eps I gains eps / (lambda + eps) a pass
        # and stops at the damped answer (kept: see lcp._refine_basis), inside the tolerance
        assert _miss(M, q, z) < ANSWER_TOL
        return
    assert _miss(M, q, z) < 1e-9
    # the regularised answer itself misses by about eps z: polish did the work
    assert _miss(M, q, z_reg) > 10 * _miss(M, q, z) or _miss(M, q, z_reg) < 1e-9


# derandomized in every run, not only in CI: its random search meets the polish shortfall
# that test_polish_is_exact_where_a_contact_is_a_hair_short_of_touching pins down (a row
# nearly in the span of others, about 2 in 30 000 draws: 1 % of runs), and README's test
# command must not hinge on a draw; the shortfall stays visible in those strict xfails
@settings(max_examples=150, deadline=None, derandomize=True)
@given(redundant_contacts())
def test_polish_turns_a_regularised_answer_into_an_exact_one(problem):
    _check_polish(*problem)


def _identical_pair(slack):
    """Contacts 0 and 1 on the same direction (a redundant pair): contact 1 carries the load
    (z = 1), contact 0 is `slack` [m/s] short of touching; contact 2 on the other direction."""
    J = np.array([[1.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    return _problem(J, np.array([False, True, False]), np.ones(3), np.array([slack, 0.0, 0.0]))


# 8 contacts on 4 degrees of freedom (redundant_contacts' shrunk failure): contacts 5 and 6
# share the load, contact 7 is 1e-9 short of touching
_EIGHT = np.array([[3., -2., 1., -1., 0., -1., 0., -1.], [-2., 2., -1., 1., 0., 1., 0., 0.],
                   [1., -1., 1., 0., 1., 0., 0., 0.], [-1., 1., 0., 1., 1., 1., 0., 0.],
                   [0., 0., 1., 1., 2., 1., 0., 0.], [-1., 1., 0., 1., 1., 2., 1., 0.],
                   [0., 0., 0., 0., 0., 1., 1., 0.], [-1., 0., 0., 0., 0., 0., 0., 1.]])


def _nearly_opposed_pair(tilt):
    """Contact 0 nearly opposed to contact 1 (tilted `tilt` [m] out of line), both loaded
    (z = 1, 1); another answer, z = (0, 0.5, 0, 0), misses only by w_0 = -tilt^2."""
    J = np.array([[0.0, -0.5, tilt], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
    return _problem(J, np.array([True, True, False, False]), np.ones(4), np.ones(4))


def _nearly_balanced_triple():
    """Contacts 0, 1, 2 loaded (z = 1 each), contact 2 against the sum of 0 and half of 1
    tilted 1e-4 out of their plane; contacts 3, 4 apart (w = 1). Another answer,
    z = (0, 0.5, 0, 0, 0), misses only by w_2 = -1e-8."""
    J = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, -0.5, 1e-4], [0.0, 0.0, 1.0],
                  [-1.0, 0.0, 1.0]])
    return _problem(J, np.array([True, True, True, False, False]), np.ones(5),
                    np.ones(5))


@pytest.mark.xfail(strict=True, reason=(
    "engine: a contact a hair (below the regularisation 1e-6) from touching at the answer "
    "or at another: polish reports LCP_SOLVED with an answer off by about that hair "
    "(identical pair, gap 1e-7: z = (0.3, 0.7, 0) for (0, 1, 0), miss 5e-8 of max |q|; "
    "gap 1e-8: miss 5e-9; eight contacts, gap 1e-9: z_6 = 1 + 1e-9, miss 1e-9; nearly "
    "opposed pair, tilt 6.1e-5: z = (0, 0.5, 0, 0), w_0 = -3.7e-9; nearly balanced triple, "
    "tilt 1e-4: z = (0, 0.5, 0, 0, 0), w_2 = -1e-8; bound 1e-9)"))
@pytest.mark.parametrize("problem", [_identical_pair(1e-7), _identical_pair(1e-8),
                                     (_EIGHT, np.array([0, 0, 0, 0, 0, -1.0, -1.0, 1e-9])),
                                     _nearly_opposed_pair(2.0 ** -14), _nearly_balanced_triple()],
                         ids=["pair-1e-7", "pair-1e-8", "eight-1e-9", "opposed-6e-5", "triple-1e-4"])
def test_polish_is_exact_where_a_contact_is_a_hair_short_of_touching(problem):
    _check_polish(*problem)


def test_polish_solves_a_seeded_corpus_and_a_failure_would_say_so():
    """Over a seeded corpus of contact problems of redundant_contacts' family (_seeded_problem:
    normal J, uniform loads and slacks; every d, k it draws, 600 seeds each: 17 731 that
    push), polish solves every one exactly; a failure would return LCP_INACCURATE with the
    regularised answer left as it was. Before lcp._swap_to_answer two failed (d = 4, k = 9,
    seed 565; d = 6, k = 7, seed 90: the nearby problem's eps put a row with a nearly zero
    share on the wrong side, and its basis's answer for M missed by 3e-7 of max |q|)."""
    failed = solved = 0
    for d in range(2, 7):
        for k in range(d + 1, 2 * d + 3):
            for seed in range(600):
                M, q = _seeded_problem(d, k, seed)
                if q.min() >= 0.0:
                    continue
                z_reg, z = np.zeros(k), np.zeros(k)
                status, polished = _solve(M.copy(), q, 1e-6, z_reg, z)
                assert status == LCP_SOLVED
                if polished == LCP_SOLVED:
                    solved += 1
                    continue
                assert polished == LCP_INACCURATE and np.array_equal(z, z_reg), (d, k, seed)
                failed += 1
    assert solved > 10_000 and failed == 0, (solved, failed)


def test_polish_shares_a_redundant_load_without_drifting():
    """Two identical contacts under one load (a singular basis): the regularised answer
    splits it evenly; polish makes the total exact and keeps the split to rounding (the
    regularised tableau amplifies rounding by 1 / eps along the null space: 1e-10 here),
    rather than moving the load from one contact to the other."""
    M = np.array([[1.0, 1.0], [1.0, 1.0]])
    q = np.array([-1.0, -1.0])
    z_reg = np.zeros(2)
    z = np.zeros(2)
    status, polished = _solve(M.copy(), q, 1e-6, z_reg, z)
    assert (status, polished) == (LCP_SOLVED, LCP_SOLVED)
    assert abs(z_reg.sum() - 1.0) > 1e-7
    assert abs(z.sum() - 1.0) < 1e-14
    assert abs(z[0] - z[1]) < 1e-8


def test_polish_keeps_the_damped_answer_of_a_nearly_singular_basis():
    """Three loaded contacts on three degrees of freedom whose rows are nearly dependent
    (smallest singular value 2.3e-4: the loaded rows' M has an eigenvalue of 5e-8, far below
    the path's eps = 1e-6). The polish's refinement stalls short of the basis's exact answer
    and keeps its damped one, which meets the acceptance tolerance; it is still solved, and
    better than the regularised answer."""
    rng = np.random.default_rng(1_007_068)
    J = rng.normal(size=(4, 3))
    M = J @ J.T
    loaded = rng.random(4) < 0.5
    z_star = np.where(loaded, rng.uniform(0.1, 1.0, 4), 0.0)
    w_star = np.where(loaded, 0.0, rng.uniform(0.0, 1.0, 4))
    q = w_star - M @ z_star
    z_reg = np.zeros(4)
    z = np.zeros(4)
    assert _solve(M.copy(), q, 1e-6, z_reg, z) == (LCP_SOLVED, LCP_SOLVED)
    assert _nearly_singular(M, z, 1e-6)
    assert _miss(M, q, z) < ANSWER_TOL
    assert _miss(M, q, z) < _miss(M, q, z_reg)
