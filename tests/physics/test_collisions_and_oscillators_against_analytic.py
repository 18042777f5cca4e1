"""Closed forms and conservation laws at the extremes, in families that
test_extremes_against_analytic.py leaves out: two free bodies colliding in zero gravity
(mass ratio 1e-3..1e3, 0.1..100 m/s, dt 1e-4..1e-2), a small-amplitude pendulum's period
and energy, a body sliding down a prismatic joint, a joint's spring and damper against
the discrete recurrence the step takes, a spinning pair on a slider, and the invariance of a
scene under a shift of 1e3 m, a mirror in x and a drift. One silent defect found here is
xfail(strict=True) with its measurements in DEFECTS: a plastic grazing impact's angular
momentum. Three more found here are mended: a free pinned pair with armature's angular
momentum, and two frame dependences (the rebound bound's allowance, the time-of-impact
split)."""
import math

import numpy as np
import pytest

import planarsim as ps
from planarsim.compiled import audit_counts

G = 9.81
R = 0.1


def assert_clean(sim):
    assert sum(audit_counts(sim.ws).values()) == 0, audit_counts(sim.ws)


def _shape(kind, e, mu):
    if kind == "circle":
        return [("circle", (0.0, 0.0), R, {"restitution": e, "mu": mu})]
    return [("box", (0.0, 0.0), 2 * R, 2 * R, {"restitution": e, "mu": mu})]


def _momenta(sim, model):
    """Linear momentum, angular momentum about the origin, kinetic energy."""
    q, v = sim.state.q, sim.state.v
    m, inertia = model.arrays.body_mass, model.arrays.body_inertia
    L = sum(m[i] * (q[i, 0] * v[i, 1] - q[i, 1] * v[i, 0]) + inertia[i] * v[i, 2]
            for i in range(len(m)))
    p = np.array([np.sum(m * v[:, 0]), np.sum(m * v[:, 1])])
    ke = 0.5 * np.sum(m * (v[:, 0] ** 2 + v[:, 1] ** 2) + inertia * v[:, 2] ** 2)
    return p, L, ke


def _pair(kind, m1, m2, u, dt, e, mu=0.0, off=0.0, w0=0.0, angle=0.0):
    """Two bodies (circles of radius R, or 2R squares) in zero gravity without ground: the
    first at u m/s along +x toward the second at rest, its centre `off` above the line;
    returns (simulator, model, steps to run past the impact)."""
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    gap = 0.3 + 3.7 * u * dt                   # a few steps of travel apart at any speed
    b.add_body("a", m1, 0.5 * m1 * R * R, pos=(-R - gap / 2, 0.0), vel=(u, 0.0), omega=w0,
               shapes=_shape(kind, e, mu))
    b.add_body("b", m2, 0.5 * m2 * R * R, pos=(R + gap / 2, off), angle=angle,
               shapes=_shape(kind, e, mu))
    model = b.compile()
    return ps.Simulator(model), model, int(gap / (u * dt)) + 20


@pytest.mark.parametrize("kind", ["circle", "box"])
@pytest.mark.parametrize("e", [0.0, 0.5, 1.0])
@pytest.mark.parametrize("m1, m2", [(1e-3, 1.0), (1.0, 1e3), (1e3, 1.0)])
@pytest.mark.parametrize("u, dt", [(0.1, 1e-4), (10.0, 1e-3), (100.0, 1e-2)])
def test_a_head_on_central_impact_gives_newtons_closed_form(kind, e, m1, m2, u, dt):
    """A central head-on impact of two free bodies with restitution e: v1 = (m1 - e m2) u / M,
    v2 = (1 + e) m1 u / M, no spin, no sideways motion; momentum (linear and angular) kept
    and energy never gained, all to rounding (the impulses act along the line of centres
    through both centres, so the scheme keeps them exactly); e = 1 keeps the energy.
    Measured: every velocity within 3e-16 u of the closed form, momenta to rounding."""
    sim, model, n = _pair(kind, m1, m2, u, dt, e)
    p0, L0, ke0 = _momenta(sim, model)
    sim.steps(n)
    p, L, ke = _momenta(sim, model)
    M = m1 + m2
    v1, v2 = (m1 - e * m2) * u / M, (1 + e) * m1 * u / M
    v = sim.state.v
    print(f"{kind} e={e} m={m1:g},{m2:g} u={u} dt={dt}: v1 {v[0, 0]!r} ({v1!r}), "
          f"v2 {v[1, 0]!r} ({v2!r}), KE {ke / ke0 - 1:+.2e}")
    assert abs(v[0, 0] - v1) <= 1e-12 * u and abs(v[1, 0] - v2) <= 1e-12 * u
    assert np.abs(v[:, 1]).max() <= 1e-12 * u and np.abs(v[:, 2]).max() <= 1e-12 * u / R
    assert np.abs(p - p0).max() <= 1e-12 * max(m1, m2) * u
    assert abs(L - L0) <= 1e-12 * max(m1, m2) * u * R
    assert ke <= ke0 * (1 + 1e-12)
    if e == 1.0:
        assert abs(ke / ke0 - 1) <= 1e-12
    else:                                          # the closed form's loss
        assert abs(ke - 0.5 * (m1 * v1 * v1 + m2 * v2 * v2)) <= 1e-12 * ke0
    assert_clean(sim)


@pytest.mark.parametrize("kind", ["circle", "box"])
@pytest.mark.parametrize("m1, m2", [(1.0, 1.0), (1e-3, 1.0), (1e3, 1.0)])
@pytest.mark.parametrize("u, dt", [(10.0, 1e-4), (10.0, 1e-2), (100.0, 1e-3)])
def test_an_oblique_frictional_impact_keeps_both_momenta_and_gains_no_energy(kind, m1, m2, u, dt):
    """An off-centre impact (the second body 0.08 m above the line of motion, a square
    turned 0.3 rad), restitution 0.5, friction 0.5: each contact's normal and friction
    impulses act on both bodies at one point, equal and opposite, so linear and angular
    momentum are kept to rounding, and energy can only be lost. Measured: both momenta to
    3e-16, the energy down by 0.1..60 %. (A plastic impact, e = 0, after which the bodies
    stay in touch while sliding past each other, is not kept: DEFECTS["plastic_graze"].)"""
    sim, model, n = _pair(kind, m1, m2, u, dt, 0.5, mu=0.5, off=0.08, angle=0.3)
    p0, L0, ke0 = _momenta(sim, model)
    sim.steps(n + 20)
    p, L, ke = _momenta(sim, model)
    print(f"{kind} m={m1:g},{m2:g} u={u} dt={dt}: dp {np.abs(p - p0).max() / (m1 * u):.1e}, "
          f"dL {abs(L - L0) / (m1 * u * R):.1e}, KE {ke / ke0 - 1:+.3f}")
    assert m2 * np.hypot(*sim.state.v[1, :2]) > 0.1 * min(m1, m2) * u   # they did collide
    assert ke <= ke0 * (1 + 1e-12)
    assert np.abs(p - p0).max() <= 1e-12 * max(m1, m2) * u
    assert abs(L - L0) <= 1e-12 * max(m1, m2) * u * R
    assert_clean(sim)


@pytest.mark.parametrize("m1, m2, e", [(1.0, 1.0, 1.0), (1e-3, 1.0, 0.5), (1e-3, 1.0, 1.0),
                                       (1.0, 1e3, 0.5), (1.0, 1e3, 1.0)])
@pytest.mark.parametrize("off", [0.05, 0.09])
@pytest.mark.parametrize("u, dt", [(0.1, 1e-4), (10.0, 1e-3), (1.0, 1e-2), (100.0, 1e-2)])
def test_a_disk_striking_a_square_off_centre_gives_the_eccentric_impact_closed_form(m1, m2, e, off, u, dt):
    """A frictionless disk hits the face of a resting square `off` above its centre: the
    normal impulse is (1 + e) u / (1/m1 + 1/m2 + off^2 / I2), the square spins at -off Pn / I2
    (the impulse's line does not move with the contact's depth along it, so even a
    speculative contact or a split step keeps it exact): to rounding. Cases where the disk
    would strike the square again after the first impact (the disk then faster than the
    square: e = 0.5 with equal masses, a heavy disk) are left out: a step split at the time of
    impact (100 m/s at dt 0.01) takes them within the step, which the closed form of one
    impact does not describe. Measured: 3e-16 u."""
    r = R
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    gap = 0.3 + 3.7 * u * dt
    I1, I2 = 0.5 * m1 * r * r, m2 * (0.2 ** 2 + 0.2 ** 2) / 12
    b.add_body("disk", m1, I1, pos=(-r - gap / 2, off), vel=(u, 0.0),
               shapes=[("circle", (0.0, 0.0), r, {"restitution": e, "mu": 0.0})])
    b.add_body("square", m2, I2, pos=(0.1 + gap / 2, 0.0),
               shapes=[("box", (0.0, 0.0), 0.2, 0.2, {"restitution": e, "mu": 0.0})])
    model = b.compile()
    sim = ps.Simulator(model)
    p0, L0, ke0 = _momenta(sim, model)
    sim.steps(int(gap / (u * dt)) + 5)
    p, L, ke = _momenta(sim, model)
    Pn = (1 + e) * u / (1 / m1 + 1 / m2 + off * off / I2)
    expected = np.array([[u - Pn / m1, 0.0, 0.0], [Pn / m2, 0.0, -off * Pn / I2]])
    err = np.abs(sim.state.v - expected)
    print(f"m={m1:g},{m2:g} e={e} off={off} u={u} dt={dt}: velocities off by "
          f"{err[:, :2].max() / u:.1e} u, spin by {err[1, 2] * r / u:.1e} u / r")
    assert err[:, :2].max() <= 1e-12 * u and err[:, 2].max() <= 1e-12 * u / r
    assert np.abs(p - p0).max() <= 1e-12 * max(m1, m2) * u
    assert ke <= ke0 * (1 + 1e-12)
    assert abs(L - L0) <= 1e-12 * max(m1, m2) * u * r
    assert_clean(sim)


@pytest.mark.parametrize("e, mu, wa, wb", [(0.5, 0.3, 50.0, 0.0), (1.0, 0.1, 100.0, 100.0),
                                            (0.8, 0.2, -20.0, 60.0)])
@pytest.mark.parametrize("m1, m2", [(1.0, 1.0), (1e-3, 1.0), (1e3, 1.0), (1.0, 1e3)])
@pytest.mark.parametrize("u, dt", [(0.1, 1e-4), (10.0, 1e-3), (1.0, 1e-2), (100.0, 1e-2)])
def test_spinning_disks_in_a_head_on_impact_slide_as_the_closed_form_says(e, mu, wa, wb, m1, m2, u, dt):
    """Two disks (I = m r^2 / 2) spinning at wa u, wb u [rad/s] meet head on, centre to centre,
    at u: the normal and the tangent decouple (the contact lies on the line of centres), the
    normal impulse is Newton's (1 + e) m* u and, the slip at the contact (wa + wb) u r being
    too fast for friction to stop, the friction impulse is mu times it, all closed forms: the
    velocities v1 = (u - Pn / m1, -Pt / m1), v2 = (Pn / m2, Pt / m2) to rounding, and the spins
    w - r Pt / I. A speculative contact (found apart, up to a step's travel u h before the
    touch) applies both bodies' friction impulses at one point, a gap g <= u h off one
    body's surface, so that body's spin changes by (r + g) Pt / I instead: a first-order
    error within u h Pt / I. Measured: 0.2 and 0.7 of that bound on the first body (the
    start gaps leave 0.2 u h and 0.7 u h at the step before the touch), the second's to
    rounding; a pair that closes more than a quarter of its width a step (100 m/s at dt
    0.01) is split at its time of impact and is exact to rounding. Both momenta are kept to
    rounding, and energy is lost."""
    r = R
    wa, wb = wa * u, wb * u
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    gap = 0.3 + 3.7 * u * dt
    I1, I2 = 0.5 * m1 * r * r, 0.5 * m2 * r * r
    disk = [("circle", (0.0, 0.0), r, {"restitution": e, "mu": mu})]
    b.add_body("a", m1, I1, pos=(-r - gap / 2, 0.0), vel=(u, 0.0), omega=wa, shapes=disk)
    b.add_body("b", m2, I2, pos=(r + gap / 2, 0.0), omega=wb, shapes=disk)
    model = b.compile()
    sim = ps.Simulator(model)
    p0, L0, ke0 = _momenta(sim, model)
    sim.steps(int(gap / (u * dt)) + 20)
    p, L, ke = _momenta(sim, model)
    Pn = (1 + e) * m1 * m2 / (m1 + m2) * u
    slip = (wa + wb) * r
    assert abs(slip) / (1 / m1 + 1 / m2 + r * r / I1 + r * r / I2) > mu * Pn   # it slides
    Pt = mu * Pn * math.copysign(1.0, slip)
    v = sim.state.v
    lin = max(abs(v[0, 0] - (u - Pn / m1)), abs(v[0, 1] + Pt / m1), abs(v[1, 0] - Pn / m2),
              abs(v[1, 1] - Pt / m2)) / u
    spin = (abs(v[0, 2] - (wa - r * Pt / I1)) / (u * dt * abs(Pt) / I1),
            abs(v[1, 2] - (wb - r * Pt / I2)) / (u * dt * abs(Pt) / I2))
    print(f"e={e} mu={mu} w={wa:g},{wb:g} m={m1:g},{m2:g} u={u} dt={dt}: velocities off by "
          f"{lin:.1e} u; spins off by {spin[0]:.2e}, {spin[1]:.2e} of u h Pt / I")
    assert lin <= 1e-12
    assert max(spin) <= 1.0 + 1e-9
    assert np.abs(p - p0).max() <= 1e-12 * max(m1, m2) * u
    assert abs(L - L0) <= 1e-12 * (abs(L0) + max(m1, m2) * u * r)
    assert ke <= ke0 * (1 + 1e-12)
    assert_clean(sim)


@pytest.mark.parametrize("m1, w0, angle, off", [(1.0, 30.0, 0.3, 0.05), (1.0, 30.0, 0.3, 0.0),
                                                (1e3, 20.0, 0.3, 0.05), (1e-3, 10.0, 0.5, 0.03)])
def test_an_elastic_frictional_impact_of_a_spinning_square_gains_at_most_the_rebound_allowance(
        m1, w0, angle, off):
    """Kane's paradox: a square spinning at w0 hits a second square (turned `angle`, its
    centre `off` above the line) at 10 m/s with e = 1, mu = 1; Newton's full rebound on top
    of a sticking friction impulse would add energy, so the step scales the rebounds down to
    the largest factor adding none (kernels/solver/rebound.py) less its allowance,
    REBOUND_REL_TOL (1e-7) of the start and end kinetic energies. Measured: the energy rises
    by 1.78e-7..2.0e-7 of itself, i.e. at that allowance (the search stops at the first
    factor within it; these answers are direct solves, exact to rounding, so the allowance,
    not rounding, is what is added, uncounted), and both momenta are kept to 1e-15."""
    from planarsim.kernels.solver.rebound import REBOUND_REL_TOL
    u, dt = 10.0, 1e-3
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    shape = _shape("box", 1.0, 1.0)
    gap = 0.4 + 3.7 * u * dt
    b.add_body("a", m1, 0.5 * m1 * R * R, pos=(-R - gap / 2, 0.0), vel=(u, 0.0), omega=w0, shapes=shape)
    b.add_body("b", 1.0, 0.5 * R * R, pos=(R + gap / 2, off), angle=angle, shapes=shape)
    model = b.compile()
    sim = ps.Simulator(model)
    p0, L0, ke0 = _momenta(sim, model)
    sim.steps(int(gap / (u * dt)) + 60)
    p, L, ke = _momenta(sim, model)
    print(f"m1={m1} w0={w0} angle={angle} off={off}: KE {ke / ke0 - 1:+.3e}, "
          f"dL {abs(L - L0) / (max(m1, 1.0) * u * R):.1e}")
    assert np.hypot(*sim.state.v[1, :2]) * 1.0 > 0.1 * min(m1, 1.0) * u   # they did collide
    assert ke - ke0 <= REBOUND_REL_TOL * (ke + ke0) + 1e-12 * ke0
    assert np.abs(p - p0).max() <= 1e-12 * max(m1, 1.0) * u
    assert abs(L - L0) <= 1e-12 * max(m1, 1.0) * u * R
    assert_clean(sim)


@pytest.mark.parametrize("ratio", [1.0, 1e-3, 1e3])
@pytest.mark.parametrize("w, dt", [(1.0, 1e-3), (10.0, 1e-3), (1.0, 1e-2), (30.0, 1e-2)])
def test_a_spinning_pair_on_a_slider_keeps_its_momenta_and_energy(ratio, w, dt):
    """Two free bodies (1 kg and `ratio` kg, 0.5 m apart) joined by a slider along the line
    between them, spinning at w about their centre of mass while they slide apart at 0.3 m/s
    (zero gravity): the rail turns, so the slide feels Coriolis and centrifugal forces, but
    the slider's impulses are internal (equal and opposite, along a line through the anchor)
    and so keep both momenta to rounding; the energy is kinetic alone and symplectic Euler
    with SHAKE keeps it to second order: after the first step, within (h (w + 0.3 / 0.5))^2
    over 2 s. Measured: L to 4.2e-14, p to 2.3e-13 kg m/s, energy -4.8e-8 (w 1, dt 1e-3)
    .. -3.5e-4 (w 30, dt 0.01, h w = 0.3)."""
    m1, m2 = 1.0, ratio
    c = m2 * 0.5 / (m1 + m2)
    xa, xb, slide = -c, 0.5 - c, 0.3
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    a = b.add_body("a", m1, 0.1 * m1, pos=(xa, 0.0), vel=(-slide * m2 / (m1 + m2), w * xa), omega=w)
    d = b.add_body("b", m2, 0.1 * m2, pos=(xb, 0.0), vel=(slide * m1 / (m1 + m2), w * xb), omega=w)
    b.add_slider("rail", a, d, axis=(1.0, 0.0))
    model = b.compile()
    sim = ps.Simulator(model)
    p0, L0, _ = _momenta(sim, model)
    sim.step()
    _, _, ke1 = _momenta(sim, model)
    sim.steps(round(2.0 / dt))
    p, L, ke = _momenta(sim, model)
    print(f"ratio {ratio:g} w {w} dt {dt}: L {L / L0 - 1:+.1e}, p {np.abs(p - p0).max():.1e}, "
          f"KE {ke / ke1 - 1:+.2e}")
    assert abs(L / L0 - 1) <= 1e-12
    assert np.abs(p - p0).max() <= 1e-12 * max(m1, m2)
    assert abs(ke / ke1 - 1) <= (dt * (w + slide / 0.5)) ** 2
    assert_clean(sim)


@pytest.mark.parametrize("kind, angle", [("circle", 0.0), ("box", 0.3)])
@pytest.mark.parametrize("dt", [1e-3, 1e-2])
@pytest.mark.parametrize("drift", [(3.0, -2.0), (100.0, 0.0)])
def test_an_oblique_impact_seen_from_a_moving_frame_is_the_same(kind, angle, dt, drift):
    """Galilean invariance: the oblique impact of test_an_oblique_frictional_impact_keeps_
    both_momenta_and_gains_no_energy (e = 0.5, mu = 0.5, 10 m/s), made by a pair drifting at
    `drift`, is the same impact moving along: positions less the drift and velocities less it
    agree with the pair at rest to 1e-9 (measured: 6.6e-13 m, 1.5e-12 m/s). (A plastic impact
    and Kane's do not: DEFECTS["drifting_kane"], and the report of this search.)"""
    u = 10.0
    runs = []
    for d in ((0.0, 0.0), drift):
        b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
        gap = 0.4 + 3.7 * u * dt
        b.add_body("a", 1.0, 0.5 * R * R, pos=(-R - gap / 2, 0.0), vel=(u + d[0], d[1]),
                   shapes=_shape(kind, 0.5, 0.5))
        b.add_body("b", 1.0, 0.5 * R * R, pos=(R + gap / 2, 0.08), vel=d, angle=angle,
                   shapes=_shape(kind, 0.5, 0.5))
        sim = ps.Simulator(b.compile())
        n = int(gap / (u * dt)) + 60
        sim.steps(n)
        q, v = sim.state.q.copy(), sim.state.v.copy()
        q[:, :2] -= np.array(d) * n * dt
        v[:, :2] -= np.array(d)
        runs.append((q, v))
        assert_clean(sim)
    dq, dv = np.abs(runs[1][0] - runs[0][0]).max(), np.abs(runs[1][1] - runs[0][1]).max()
    print(f"{kind} dt={dt} drift={drift}: dq {dq:.1e}, dv {dv:.1e}")
    assert dq <= 1e-9 and dv <= 1e-9


DEFECTS = {
    "plastic_graze": (
        "two free bodies (1 kg, radius 0.1 m circles or 0.2 m squares, zero gravity, no "
        "ground) in an off-centre plastic impact (e = 0, impact parameter b = 0.12 m) lose or "
        "gain angular momentum, uncounted, while linear momentum is kept to rounding: after "
        "the impact the bodies stay in touch sliding past each other, the drift q += h v "
        "sinks the curved contact by a second-order amount, and the position correction "
        "(stage 8: contacts move positions only) moves the two bodies apart along the normal "
        "by mass-weighted amounts without a velocity change, which changes L by "
        "lambda n x (v_a - v_b) (measured at dt 1e-3: each step's change of L equals sum m dx x v of the "
        "correction's move dx exactly). Frictionless circles: dL / (m u b) = -4.5e-6, "
        "-4.3e-4, -1.9e-2 at a travel u h of 1 mm, 1 cm, 10 cm a step (second order in u h; "
        "u 1..100 m/s, dt 1e-4..1e-2); frictionless squares: +1.4e-4, +1.5e-3, +6.2e-3; a "
        "circle spinning at -50 rad/s with mu = 2: -2.6e-7, -2.6e-5, -1.1e-3. With e = 0.5 "
        "(the bodies part) both momenta are kept to 5e-15."),
}


@pytest.mark.parametrize("drift", [(30.0, 0.0), (100.0, 0.0), (0.0, 300.0), (-1000.0, 500.0)])
def test_a_plastic_spinning_impact_drifting_fast_is_the_same_impact(drift):
    """Galilean invariance of a plastic frictional impact of a spinning disk on another, off
    centre: drifting at `drift` (m/s, m/s), the velocities less the drift are those of the
    pair at rest (to 1e-9). Whether the step is split at the pair's time of impact is decided
    on their speeds relative to each other (a bound on each one's own speed split it drifting
    at 30 m/s and not at rest: the second disk then spun at 36.301 rad/s, 35.666 at rest)."""
    u, dt = 10.0, 1e-3
    out = []
    for d in ((0.0, 0.0), drift):
        b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
        disk = _shape("circle", 0.0, 2.0)
        gap = 0.4 + 3.7 * u * dt
        b.add_body("a", 1.0, 0.5 * R * R, pos=(-R - gap / 2, 0.0), vel=(u + d[0], d[1]),
                   omega=-50.0, shapes=disk)
        b.add_body("b", 1.0, 0.5 * R * R, pos=(R + gap / 2, 0.12), vel=d, shapes=disk)
        sim = ps.Simulator(b.compile())
        sim.steps(int(gap / (u * dt)) + 60)
        v = sim.state.v.copy()
        v[:, :2] -= d
        out.append(v)
        assert_clean(sim)
    print(f"drift {drift}: velocities differ by {np.abs(out[1] - out[0]).max():.2e}")
    assert np.abs(out[1] - out[0]).max() <= 1e-9


@pytest.mark.parametrize("drift", [(100.0, 0.0), (1000.0, 0.0), (0.0, 300.0), (-3000.0, 1000.0)])
def test_kanes_impact_drifting_fast_gains_no_energy_in_its_own_frame(drift):
    """Kane's impact (an elastic frictional impact of a spinning square on another) made by
    a pair drifting at `drift` (m/s, m/s): physics does not depend on the frame, so the
    energy about the centre of mass may rise by no more than it does for the pair at rest
    (3.8e-7 of it); bound 1e-6. (The rebound bound's rounding allowance, a share of the
    kinetic energy, was measured in the world's frame: +7.6e-5 drifting at 100 m/s,
    +3.5e-3 at 1000 m/s.)"""
    u, dt = 10.0, 1e-3
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    shape = _shape("box", 1.0, 1.0)
    gap = 0.4 + 3.7 * u * dt
    b.add_body("a", 1.0, 0.5 * R * R, pos=(-R - gap / 2, 0.0), vel=(u + drift[0], drift[1]),
               omega=30.0, shapes=shape)
    b.add_body("b", 1.0, 0.5 * R * R, pos=(R + gap / 2, 0.05), vel=drift, angle=0.3,
               shapes=shape)
    sim = ps.Simulator(b.compile())

    def internal():
        v = sim.state.v.copy()
        v[:, :2] -= v[:, :2].mean(axis=0)
        return 0.5 * np.sum(v[:, 0] ** 2 + v[:, 1] ** 2) + 0.5 * 0.5 * R * R * np.sum(v[:, 2] ** 2)
    start = internal()
    sim.steps(int(gap / (u * dt)) + 60)
    gain = internal() / start - 1
    print(f"drift {drift} m/s: energy about the centre of mass {gain:+.2e}")
    assert_clean(sim)
    assert gain <= 1e-6


@pytest.mark.parametrize("k, armature, dt, rel", [
    (0.0, 0.01, 1e-2, 20.0), (0.0, 0.05, 1e-2, 20.0), (0.0, 1.0, 1e-2, 20.0), (0.0, 1e-3, 1e-4, 60.0),
    (1e4, 0.01, 1e-3, 2.0), (1e2, 0.05, 1e-2, 20.0), (1e4, 1.0, 1e-3, 60.0), (1e2, 1e-3, 2e-2, 2.0)])
@pytest.mark.parametrize("drift", [0.0, 100.0])
def test_a_free_pinned_pair_with_armature_keeps_its_angular_momentum(k, armature, dt, rel, drift):
    """Two free bodies pinned together with an armature (and a spring k) on the pin, the
    pair spinning at 3 rad/s, the bodies' spins `rel` apart (each turning up to 0.23 rad a
    step), seen at rest and drifting at `drift` m/s: every impulse of the pin, its armature
    and spring is internal, and the armature's energy is invariant under a rotation of the
    pair, so the bodies' angular momentum about their centre of mass is kept (to 1e-9; it
    fell by up to 28 % in 2 s at rest, and was kept drifting, when the correction's energy
    bound cut the correction of such a step)."""
    w, c = 3.0, 0.25
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    a = b.add_body("a", 1.0, 0.02, pos=(-c, 0.0), vel=(drift, -w * c), omega=w + rel)
    d = b.add_body("b", 1.0, 0.02, pos=(0.5 - c, 0.0), vel=(drift, w * (0.5 - c)), omega=w - rel,
                   angle=0.3)
    b.add_pin("pin", a, d, anchor_world=(0.0, 0.0), stiffness=k, armature=armature, ref_angle=0.0)
    model = b.compile()
    sim = ps.Simulator(model)
    n = round(min(2.0, 2e4 * dt) / dt)
    p0, L0, _ = _momenta(sim, model)        # the centre of mass starts at the origin
    sim.steps(n)
    q = sim.state.q
    p, L, _ = _momenta(sim, model)
    # about the centre of mass, which moved by drift n dt along x (linear momentum 2 drift)
    L -= (q[:, 0].mean() * p[1] - q[:, 1].mean() * p[0])
    print(f"k={k} armature={armature} dt={dt} rel={rel} drift={drift}: L / L0 - 1 = {L / L0 - 1:+.2e}")
    assert np.abs(p - p0).max() <= 1e-12 * max(1.0, drift)
    assert_clean(sim)
    assert abs(L / L0 - 1) <= 1e-9


@pytest.mark.xfail(strict=True, raises=AssertionError, reason=DEFECTS["plastic_graze"])
@pytest.mark.parametrize("kind, u, dt, mu, w0", [
    ("circle", 10.0, 1e-4, 0.0, 0.0), ("circle", 100.0, 1e-4, 0.0, 0.0), ("box", 10.0, 1e-4, 0.0, 0.0),
    ("box", 100.0, 1e-3, 0.0, 0.0), ("circle", 10.0, 1e-3, 2.0, -50.0)])
def test_a_plastic_grazing_impact_keeps_angular_momentum(kind, u, dt, mu, w0):
    """Two free bodies in an off-centre plastic impact (restitution 0, the second body's
    centre b = 0.12 m off the line of motion): contact impulses are internal, equal and
    opposite at one point, so the pair keeps its angular momentum (about any point, its
    linear momentum being kept) to rounding through the impact and the sliding after it."""
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    shape = _shape(kind, 0.0, mu)
    gap = 0.1 + 3.7 * u * dt
    b.add_body("a", 1.0, 0.5 * R * R, pos=(-R - gap / 2, 0.0), vel=(u, 0.0), omega=w0, shapes=shape)
    b.add_body("b", 1.0, 0.5 * R * R, pos=(R + gap / 2, 0.12), shapes=shape)
    model = b.compile()
    sim = ps.Simulator(model)
    p0, L0, _ = _momenta(sim, model)
    sim.steps(int(gap / (u * dt)) + int(0.5 / (u * dt)) + 20)
    p, L, _ = _momenta(sim, model)
    print(f"{kind} u={u} dt={dt} mu={mu} w0={w0}: dL / (m u b) {(L - L0) / (u * 0.12):+.2e}, "
          f"dp / (m u) {np.abs(p - p0).max() / u:.1e}")
    assert np.abs(p - p0).max() <= 1e-12 * u
    assert_clean(sim)
    assert abs(L - L0) <= 1e-12 * u * 0.12


def _pendulum(m, Ic, d, dt, a0):
    b = ps.ModelBuilder(dt=dt)
    p = b.add_body("p", m, Ic, pos=(d * math.sin(a0), -d * math.cos(a0)), angle=a0)
    b.add_pin("pin", None, p, anchor_world=(0.0, 0.0))
    return ps.Simulator(b.compile())


@pytest.mark.parametrize("m, Ic, d, dt", [(1.0, 0.01, 0.5, 1e-2), (1.0, 0.01, 0.5, 1e-3),
                                          (1e-3, 1e-5, 0.2, 1e-2), (1e4, 1e3, 1.0, 1e-3)])
def test_a_small_pendulum_swings_at_symplectic_eulers_discrete_period(m, Ic, d, dt):
    """A rigid body on a pin released at 1e-3 rad: symplectic Euler's linear oscillator turns
    by arccos(1 - (w h)^2 / 2) a step, w = sqrt(m g d / I_pivot), a period shorter than
    2 pi / w by (w h)^2 / 24 (second order: -7.9e-5 at w h = 0.043), and the amplitude adds
    a0^2 / 16 = 6.3e-8. Measured over 10 periods (zero crossings interpolated): within
    3e-12..1.2e-7 of that discrete period (within 1e-8 + 1e-4 (w h)^2). Its energy
    oscillates by w h of the swing's energy (symplectic Euler's modified energy) and does
    not drift: measured up to 1.2e-3 w h between the first and last tenth."""
    a0 = 1e-3
    Ip = Ic + m * d * d
    w = math.sqrt(m * G * d / Ip)
    T = 2 * math.pi / w
    T_discrete = 2 * math.pi * dt / math.acos(1 - (w * dt) ** 2 / 2) * (1 + a0 * a0 / 16)
    sim = _pendulum(m, Ic, d, dt, a0)
    n = int(10 * T / dt) + 2
    ang, E = np.empty(n), np.empty(n)
    for k in range(n):
        sim.step()
        q, v = sim.state.q[0], sim.state.v[0]
        ang[k] = math.atan2(q[0], -q[1])
        E[k] = m * G * q[1] + 0.5 * m * (v[0] ** 2 + v[1] ** 2) + 0.5 * Ic * v[2] ** 2
    t = (np.arange(n) + 1) * dt
    s = np.where((ang[:-1] < 0) & (ang[1:] >= 0))[0]
    tc = t[s] + dt * (-ang[s]) / (ang[s + 1] - ang[s])
    period = (tc[-1] - tc[0]) / (len(tc) - 1)
    scale = m * G * d * (1 - math.cos(a0))
    osc = (E.max() - E.min()) / scale
    drift = (E[-n // 10:].mean() - E[:n // 10].mean()) / scale
    print(f"m={m} d={d} dt={dt} (w h {w * dt:.2e}): period {period:.10f}, discrete "
          f"{T_discrete:.10f} ({period / T_discrete - 1:+.1e}), continuous {T:.10f} "
          f"({period / T - 1:+.1e}); energy oscillation {osc:.3e}, drift {drift:+.1e}")
    assert abs(period / T_discrete - 1) <= 1e-8 + 1e-4 * (w * dt) ** 2
    assert abs(period / T - 1) <= (w * dt) ** 2 / 20
    assert abs(osc - w * dt) <= 0.05 * w * dt
    assert abs(drift) <= 2e-3 * w * dt
    assert_clean(sim)


@pytest.mark.parametrize("m, deg, dt", [(1e-4, 30.0, 1e-2), (1.0, 30.0, 1e-3), (1e4, 60.0, 1e-2),
                                        (1e6, 10.0, 1e-4)])
def test_a_body_on_an_inclined_slider_falls_as_symplectic_euler_does_exactly(m, deg, dt):
    """A body on a prismatic joint to the world whose axis descends at `deg`, released at
    rest: a constant force g sin(a) along it, so symplectic Euler gives s_n = g sin(a) h^2
    n (n + 1) / 2 exactly (its position error against g sin(a) t^2 / 2 is the first-order
    1 / n), the body stays on its axis and does not turn. Measured: within 2e-14 of the
    discrete form, 0 m off the axis, at 1e-4..1e6 kg."""
    a = math.radians(deg)
    b = ps.ModelBuilder(dt=dt)
    body = b.add_body("s", m, 0.01 * m, pos=(0.0, 0.0))
    b.add_slider("rail", None, body, axis=(math.cos(a), -math.sin(a)))
    sim = ps.Simulator(b.compile())
    n = round(1.0 / dt)
    sim.steps(n)
    x, y, th = sim.state.q[0]
    s = x * math.cos(a) - y * math.sin(a)
    discrete = G * math.sin(a) * dt * dt * n * (n + 1) / 2
    print(f"m={m} {deg} deg dt={dt}: s {s!r}, discrete {discrete!r} ({s / discrete - 1:+.1e}), "
          f"continuous {s / (G * math.sin(a) / 2) - 1:+.1e}")
    assert abs(s / discrete - 1) <= 1e-12
    assert abs(-x * math.sin(a) - y * math.cos(a)) <= 1e-12 and abs(th) <= 1e-12
    assert abs(float(sim.state.v[0, :2] @ (math.cos(a), -math.sin(a))) - G * math.sin(a) * n * dt) \
        <= 1e-12 * G * n * dt
    assert_clean(sim)


@pytest.mark.parametrize("inertia, k, c, dt", [(0.02, 2.0, 0.01, 1e-3), (0.02, 2.0, 0.1, 1e-2),
                                               (1e3, 1e5, 1e2, 1e-3), (1e-4, 1e-2, 1e-3, 1e-2)])
def test_a_hinge_spring_damper_takes_the_semi_implicit_recurrence_exactly(inertia, k, c, dt):
    """A wheel pinned to the world at its centre of mass with a spring k and damper c (the
    step resolves the spring: h sqrt(k / I) <= 0.1), released at rest at 0.1 rad: the step
    takes the spring at the step's start and the damper implicitly, w' = (I w - h k x) /
    (I + h c), x' = x + h w' (the damper's first-order loss; the continuous closed form is
    checked in test_joint_springs.py), at 1e-4..1e3 kg m^2. Measured: the angle follows that
    recurrence to 2.5e-14 of the amplitude over 3 s."""
    theta0 = 0.1
    b = ps.ModelBuilder(dt=dt)
    w = b.add_body("w", 1.0, inertia, angle=theta0)
    b.add_pin("axle", None, w, anchor_world=(0.0, 0.0), stiffness=k, damping=c, ref_angle=0.0)
    sim = ps.Simulator(b.compile())
    n = round(3.0 / dt)
    x, om, err = theta0, 0.0, 0.0
    for _ in range(n):
        sim.step()
        om = (inertia * om - dt * k * x) / (inertia + dt * c)
        x += dt * om
        err = max(err, abs(sim.state.q[0, 2] - x))
    print(f"I={inertia} k={k} c={c} dt={dt}: largest difference from the recurrence "
          f"{err / theta0:.1e}")
    assert err <= 1e-12 * theta0
    assert_clean(sim)


def _scene(kind, shift, mirror, dt):
    """A double pendulum released at 2 rad, or a spinning box thrown at a rolling disk on the
    ground (friction 0.6, restitution 0.3): moved by `shift` along x and mirrored in x
    (mirror = -1) about x = shift. (The box hits the disk at 0.24 s, at dt 1e-3.)"""
    b = ps.ModelBuilder(dt=dt)

    def X(x):
        return shift + mirror * x
    if kind == "double pendulum":
        a0 = 2.0
        elbow = (0.5 * math.sin(a0), 0.5 - 0.5 * math.cos(a0))
        p = b.add_body("p", 1.0, 0.02, pos=(X(elbow[0]), elbow[1]), angle=mirror * a0)
        b.add_pin("pin", None, p, anchor_world=(X(0.0), 0.5))
        q = b.add_body("q", 0.5, 0.01, pos=(X(elbow[0] + 0.3), elbow[1]), angle=mirror * a0)
        b.add_pin("elbow", p, q, anchor_world=(X(elbow[0]), elbow[1]))
    else:
        b.add_body("box", 1.0, 0.01, pos=(X(-0.5), 0.15), angle=mirror * 0.3,
                   vel=(mirror * 3.0, 0.5), omega=mirror * -4.0,
                   shapes=[("box", (0, 0), 0.2, 0.2, {"mu": 0.6, "restitution": 0.3})])
        b.add_body("disk", 2.0, 0.02, pos=(X(0.5), 0.1), angle=mirror * 0.1, vel=(mirror * -1.0, 0.0),
                   shapes=[("circle", (0, 0), 0.1, {"mu": 0.6})])
    return ps.Simulator(b.compile())


def _mirrored_contacts(model, mirror):
    """index[c]: the reference scene's contact that the moved scene's contact c is the image
    of (the same body and kind, its body-frame point (mirror x, y))."""
    a = model.arrays
    index = np.arange(a.contact_body.shape[0])
    for c in range(index.size):
        for d in [c] + list(range(index.size)):     # (itself if it is its own image)
            if (a.contact_body[d] == a.contact_body[c] and a.contact_kind[d] == a.contact_kind[c]
                    and np.allclose(a.contact_local[d], a.contact_local[c] * [mirror, 1.0])):
                index[c] = d
                break
    assert np.array_equal(np.sort(index), np.arange(index.size)), index
    return index


def _slip(sim, c):
    """Ground contact c's body point's speed along the (flat) ground [m/s]."""
    a, q, v = sim.model.arrays, sim.state.q, sim.state.v
    b = a.contact_body[c]
    th = q[b, 2]
    lx, ly = a.contact_local[c]
    arm_y = math.sin(th) * lx + math.cos(th) * ly
    return v[b, 0] - v[b, 2] * arm_y


#: [m/s] a contact slipping slower than this is at the edge between sticking and sliding:
#: either mode answers its step (the mode solver's own tolerance), and rounding picks one
SLIP_EDGE = 1e-6


@pytest.mark.parametrize("kind", ["double pendulum", "box and disk"])
@pytest.mark.parametrize("dt", [1e-3, 1e-2])
@pytest.mark.parametrize("shift, mirror", [(1e3, 1), (0.0, -1), (-1e3, -1)])
def test_a_scene_moved_by_a_kilometre_or_mirrored_moves_the_same(kind, dt, shift, mirror):
    """The same scene 1e3 m away along x, or mirrored in x, over 1 s (the spinning box hits the
    disk): the motion is the same, mirrored. A mirror is exact but for rounding (measured: bit
    for bit but the box and disk at dt 0.01, 2e-17 m, 3e-16 m/s); a shift of 1e3 m costs its
    positions' rounding, 1e3 eps = 2.2e-13 m, which a joint's or contact's correction turns
    into velocities of that / h, and the box's corner impact amplifies: measured 2.8e-12 m,
    1.8e-10 m/s (double pendulum, dt 1e-3), 7.9e-10 m, 1.7e-9 m/s (box and disk, dt 1e-3:
    the closest to the bounds, 1e-9 m and 10 x 1e3 eps / h = 2.2e-9 m/s). The two runs take
    the same contact modes step by step, but where a contact slips slower than SLIP_EDGE (at
    the edge between sticking and sliding, where rounding picks the mode): the motions are
    compared up to the step before such a pick (the box settling at dt 0.01 shifted by -1e3 m
    and mirrored, in its last step: one corner sliding at 8e-8 m/s in one run, stuck in the
    other)."""
    n = round(1.0 / dt)
    ref = _scene(kind, 0.0, 1, dt)
    sim = _scene(kind, shift, mirror, dt)
    index = _mirrored_contacts(sim.model, mirror)
    q, v, ref_q, ref_v = sim.state.q.copy(), sim.state.v.copy(), ref.state.q, ref.state.v
    for _ in range(n):
        ref.step()
        sim.step()
        modes = np.empty_like(ref.state.contact_mode)
        modes[index] = sim.state.contact_mode
        differ = np.flatnonzero(modes != ref.state.contact_mode)
        if differ.size:
            mirrored = {int(index[c]): c for c in range(index.size)}
            for c in differ:
                assert abs(_slip(ref, c)) <= SLIP_EDGE or abs(_slip(sim, mirrored[c])) <= SLIP_EDGE, (
                    c, modes, ref.state.contact_mode, _slip(ref, c))
            break
        q, v = sim.state.q.copy(), sim.state.v.copy()
        ref_q, ref_v = ref.state.q.copy(), ref.state.v.copy()
    q[:, 0] = (q[:, 0] - shift) * mirror
    q[:, 2] *= mirror
    v[:, 0] *= mirror
    v[:, 2] *= mirror
    dq, dv = np.abs(q - ref_q).max(), np.abs(v - ref_v).max()
    print(f"{kind} dt={dt} shift={shift} mirror={mirror}: dq {dq:.1e}, dv {dv:.1e}")
    assert dq <= 1e-9
    assert dv <= 10 * (abs(shift) + 1.0) * np.finfo(float).eps / dt
    if shift == 0.0:
        assert dq <= 1e-15 and dv <= 1e-14
    assert_clean(sim)
    assert_clean(ref)
