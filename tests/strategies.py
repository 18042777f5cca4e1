"""Hypothesis strategies shared by the property tests: every case is built from drawn numbers
(sizes, masses, angles, matrix entries), never from a drawn seed, so that a failure shrinks to
a small, readable case. Units SI (m, kg, kg m^2, rad, s)."""
import math

import numpy as np
from hypothesis import assume, strategies as st
from hypothesis.extra.numpy import arrays


def reals(lo, hi):
    """A finite float in [lo, hi]."""
    return st.floats(lo, hi, allow_nan=False, allow_infinity=False)


def decades(lo, hi):
    """10^u, u drawn in [lo, hi]: a scale spread evenly over decades (mass or size ratios)."""
    return reals(lo, hi).map(lambda u: 10.0 ** u)


def angles(lo=-math.pi, hi=math.pi):
    """An angle [rad]."""
    return reals(lo, hi)


def chance(p):
    """True with probability about p (shrinks to False)."""
    return reals(0.0, 1.0).map(lambda u: u > 1.0 - p)


def vectors(n, lo, hi):
    """n floats in [lo, hi], each drawn on its own (no fill value shared by many entries)."""
    return arrays(np.float64, n, elements=reals(lo, hi), fill=st.nothing())


def matrices(rows, cols, lo, hi):
    """A rows x cols matrix of entries in [lo, hi], each drawn on its own."""
    return arrays(np.float64, (rows, cols), elements=reals(lo, hi), fill=st.nothing())


@st.composite
def full_rank(draw, rows, cols, lo=-3.0, hi=3.0, max_condition=1e3, min_row_norm=0.1):
    """A rows x cols matrix of entries in [lo, hi] (a clipped normal draw's range), of full rank
    min(rows, cols) with condition number at most max_condition and no row shorter than
    min_row_norm: a normal draw's structure (its condition number is nearly always far below,
    its rows nearly always longer), without the exact degeneracies a shrink heads for (a zero
    row or column, a repeated column)."""
    m = draw(matrices(rows, cols, lo, hi))
    assume(np.linalg.norm(m, axis=1).min() >= min_row_norm)
    assume(np.linalg.cond(m) <= max_condition)
    return m


# bodies and the constraint rows between them -------------------------------------------------

MASS = (0.2, 5.0)          # [kg]
INERTIA = (0.01, 2.0)      # [kg m^2]
LEVER = 3.0                # Jacobian entries in [-3, 3]: unit directions and lever arms [m]


@st.composite
def body_rows(draw, n_body, n_row, dependent, chain):
    """n_row constraint rows (a, b, ja, jb) on body a and body b (b = -1: the world), ja and jb
    their Jacobian blocks (x, y, angle) with entries in [-LEVER, LEVER]. With chance
    `dependent` a row is an exact multiple (0.5 to 2) of an earlier row (a closed loop, a
    redundant contact). With chance 0.7 a row joins a second body: the next one if `chain`
    (the world past the last body), else any other (the world if it draws a itself)."""
    block = st.tuples(*[reals(-LEVER, LEVER)] * 3)
    rows = []
    for r in range(n_row):
        if r > 0 and draw(chance(dependent)):
            a, b, ja, jb = rows[draw(st.integers(0, r - 1))]
            factor = draw(reals(0.5, 2.0))
            rows.append((a, b, factor * ja, factor * jb))
            continue
        a = draw(st.integers(0, n_body - 1))
        b = -1
        if draw(chance(0.7)):
            b = a + 1 if chain else draw(st.integers(0, n_body - 1))
            if b == a or b >= n_body:
                b = -1
        ja = np.array(draw(block))
        jb = np.array(draw(block)) if b >= 0 else np.zeros(3)
        rows.append((a, b, ja, jb))
    return rows


def dense_jacobian(rows, n_body):
    """J (n_row, 3 n_body) of body_rows' rows."""
    J = np.zeros((len(rows), 3 * n_body))
    for r, (a, b, ja, jb) in enumerate(rows):
        J[r, 3 * a:3 * a + 3] += ja
        if b >= 0:
            J[r, 3 * b:3 * b + 3] += jb
    return J
