"""Analytic terrain kernels: h(x) = h0 + s x + sum_k A_k sin(2 pi x / L_k + phi_k).

Coefficient layout (``terrain_coef``): ``[h0, s, K, A_1, L_1, phi_1, ..., A_K, L_K, phi_K]``
with h0 [m], s [-], A [m], L [m], phi [rad]. Flat ground is ``[0, 0, 0]``.
"""
import math

from ...compile import jit, kernel

TWO_PI = 2.0 * math.pi
# a Newton step of the closest-point search this small [m] (plus the rounding of x) is its last:
# the error left is of order K dx^2 (K = |f''/2f'|, bounded by the terrain's derivatives)
NEWTON_LAST_STEP = 1e-10
# closest-point samples on each side at most (tight hills far below or above the point)
MAX_HALF_SAMPLES = 512


@jit(inline="force")
def height(coef, x):
    """Ground height h(x) [m]."""
    h = coef[0] + coef[1] * x
    for k in range(int(coef[2])):
        a = coef[3 + 3 * k]
        w = TWO_PI / coef[4 + 3 * k]
        h += a * math.sin(w * x + coef[5 + 3 * k])
    return h


@jit(inline="force")
def height_derivs(coef, x):
    """(h, h', h'') at x: height [m], slope dh/dx [-], curvature term d2h/dx2 [1/m]."""
    h = coef[0] + coef[1] * x
    dh = coef[1]
    ddh = 0.0
    for k in range(int(coef[2])):
        a = coef[3 + 3 * k]
        w = TWO_PI / coef[4 + 3 * k]
        arg = w * x + coef[5 + 3 * k]
        sn = math.sin(arg)
        cs = math.cos(arg)
        h += a * sn
        dh += a * w * cs
        ddh -= a * w * w * sn
    return h, dh, ddh


@jit(inline="force")
def max_curvature(coef):
    """Upper bound on |h''| [1/m]: sum_k A_k (2 pi / L_k)^2."""
    acc = 0.0
    for k in range(int(coef[2])):
        w = TWO_PI / coef[4 + 3 * k]
        acc += abs(coef[3 + 3 * k]) * w * w
    return acc


@jit(inline="force")
def max_slope(coef):
    """Upper bound on |h'| [-]: |s| + sum_k A_k 2 pi / L_k."""
    acc = abs(coef[1])
    for k in range(int(coef[2])):
        acc += abs(coef[3 + 3 * k]) * TWO_PI / coef[4 + 3 * k]
    return acc


@jit(inline="force")
def min_wavelength(coef):
    """The shortest wavelength L_k [m] of the sines (inf without any)."""
    shortest = math.inf
    for k in range(int(coef[2])):
        shortest = min(shortest, abs(coef[4 + 3 * k]))
    return shortest


@kernel
def _closest_on_line(h0, slope, px, py):
    """closest_point for ground without sines (flat or a slope): the foot of the perpendicular
    from p to y = h0 + slope x, in closed form."""
    inv2 = 1.0 / (1.0 + slope * slope)
    x = (px + slope * (py - h0)) * inv2
    h = h0 + slope * x
    inv = math.sqrt(inv2)
    nx = -slope * inv
    ny = inv
    gap = nx * (px - x) + ny * (py - h)
    return x, h, nx, ny, gap


# [-] a few units of rounding: the relative error of a difference of two coordinates, each
# rounded (and a terrain's height, a sum of sines and its offset, rounded once more)
D2_ROUNDING = 8.0 * 2.220446049250313e-16


@kernel(inline="always")
def _d2_rounding(px, py, x, h):
    """The rounding [m^2] of the squared distance from (px, py) to the ground point (x, h):
    2 |x - px| and 2 |h - py| times their differences' rounding, which grows with the
    coordinates themselves (a scene 1e4 m up: about 2e-12 m). Far from the origin this is
    well above the distance's own change near its minimum, (x - x*)^2: a step of Newton's
    that the rounding alone makes look longer is taken, not halved (halving it stalled the
    search 4e-7 m from the closest point of hills 1e4 m up)."""
    return D2_ROUNDING * (abs(x - px) * (abs(x) + abs(px)) + abs(h - py) * (abs(h) + abs(py)))


@jit(inline="force")
def _descend(coef, px, py, x, bound):
    """Newton on f(x) = (x - px) + (h(x) - py) h'(x) = 0 from x, each step at most `bound`
    [m] and never taking the ground point farther from p (a step that would is halved: the
    search stays in the basin it starts in; a long step on tight hills could land on another
    valley's wall). Returns (x, h, h') at the minimum of the distance found."""
    h, dh, ddh = height_derivs(coef, x)
    d2 = (x - px) * (x - px) + (h - py) * (h - py)
    for _ in range(30):
        f = (x - px) + (h - py) * dh
        fp = 1.0 + dh * dh + (h - py) * ddh
        newton = fp >= 1e-3
        if not newton:
            fp = 1.0 + dh * dh
        dx = -f / fp
        if dx > bound:
            dx = bound
        elif dx < -bound:
            dx = -bound
        if newton and abs(dx) < NEWTON_LAST_STEP + 1e-14 * abs(x):
            # converging quadratically: the step after this one would be ~ dx^2 (rounding),
            # and h, h' at x + dx follow from their Taylor series to O(dx^2) (no new sines)
            x += dx
            h += dh * dx
            dh += ddh * dx
            break
        # an accepted step costs nothing more: its height and derivatives are the next
        # iteration's
        for _halving in range(40):
            hn, dhn, ddhn = height_derivs(coef, x + dx)
            d2n = (x + dx - px) * (x + dx - px) + (hn - py) * (hn - py)
            if d2n <= d2 * (1.0 + 1e-12) + _d2_rounding(px, py, x + dx, hn) + 1e-300:
                break
            dx *= 0.5
        x += dx
        h = hn
        dh = dhn
        ddh = ddhn
        d2 = d2n
    return x, h, dh


@jit(inline="force")
def _sample_distance(coef, px, py, x):
    hs = height(coef, x)
    return math.sqrt((x - px) * (x - px) + (hs - py) * (hs - py))


@jit(inline="force")
def closest_point(coef, px, py):
    """Closest ground point to (px, py) and the signed gap along its normal.

    The closest point lies within b = |py - h(px)| of px horizontally. Where b times the
    largest curvature is small the squared distance has one minimum there and Newton started
    at px finds it (_descend). Otherwise (far above or below tight hills) [px - b, px + b] is
    sampled, at most an eighth of the shortest wavelength apart, and Newton (steps of at most
    the spacing) starts from every sample that may lie next to the closest point: within the
    sampling's error (spacing times the largest slope, plus one) of the nearest sample.
    Exact (one iteration) for flat and sloped ground.

    Returns (gx, gy, nx, ny, gap): ground point [m], unit normal, gap = n.(p - g) [m]
    (negative below the ground).
    """
    if coef[2] == 0.0:
        return _closest_on_line(coef[0], coef[1], px, py)
    h = height(coef, px)
    bound = abs(py - h) + 1e-12
    if bound * max_curvature(coef) <= 0.5:
        x, h, dh = _descend(coef, px, py, px, bound)
    else:
        half = 16
        shortest = min_wavelength(coef)
        if bound * 8.0 / shortest > half:
            half = min(int(bound * 8.0 / shortest) + 1, MAX_HALF_SAMPLES)
        spacing = bound / half
        nearest = math.inf
        for k in range(-half, half + 1):
            nearest = min(nearest, _sample_distance(coef, px, py, px + spacing * k))
        reach = nearest + spacing * (1.0 + max_slope(coef))
        best = math.inf
        x = px
        dh = 0.0
        for k in range(-half, half + 1):
            if _sample_distance(coef, px, py, px + spacing * k) > reach:
                continue
            xk, hk, dhk = _descend(coef, px, py, px + spacing * k, spacing)
            dk = (xk - px) * (xk - px) + (hk - py) * (hk - py)
            if dk < best:
                best = dk
                x = xk
                h = hk
                dh = dhk
    inv = 1.0 / math.sqrt(1.0 + dh * dh)
    nx = -dh * inv
    ny = inv
    gap = nx * (px - x) + ny * (py - h)
    return x, h, nx, ny, gap


@kernel(inline="never")
def _closest_on_hills(coef, px, py):
    """closest_point as one call (see ground_point)."""
    return closest_point(coef, px, py)


@kernel
def ground_point(coef, px, py):
    """closest_point for the engine's stages: the flat and sloped case in closed form,
    inlined; the hills case (the Newton loop of sines) one call. Inlined, that loop was
    copied into each of the step's ground queries (over 90 copies, 60 % of the step's code
    and about a third of a first-ever compile), for a call that costs a few ns beside its
    sines."""
    if coef[2] == 0.0:
        return _closest_on_line(coef[0], coef[1], px, py)
    return _closest_on_hills(coef, px, py)


@jit
def gap_of_point(coef, px, py):
    """Signed distance [m] of (px, py) from the ground (negative below)."""
    return closest_point(coef, px, py)[4]
