"""The slider (prismatic) joint: free slide on an incline, its rows held, its limits, a
force motor, energy of a cart-pole, and the cart-pole against MuJoCo."""
import math

import numpy as np
import pytest

import planarsim as ps
from planarsim import measure
from planarsim.energy import total_energy
from planarsim.errors import ModelError

G = 9.81


def incline(dt, slope, limit=None, angle=0.3):
    """A 2 kg block on a frictionless slider to the world whose axis descends at `slope` [rad]
    below the horizontal; it starts at rest at its anchor (slide 0)."""
    b = ps.ModelBuilder(dt=dt)
    blk = b.add_body("block", mass=2.0, inertia=0.05, pos=(0.0, 1.0), angle=angle)
    b.add_slider("rail", None, blk, axis=(math.cos(slope), -math.sin(slope)), limit=limit)
    return b.compile()


def test_incline_slide_is_g_sin_a_t2_over_2():
    """Under gravity alone the slide accelerates at g sin(a): symplectic Euler gives exactly
    s_n = g sin(a) h^2 n (n + 1) / 2 (the rows remove the normal part of gravity exactly), which
    is g sin(a) t^2 / 2 to first order in h (error g sin(a) h t / 2)."""
    dt, slope, T = 1e-3, math.radians(30.0), 1.0
    model = incline(dt, slope)
    sim = ps.Simulator(model)
    traj = sim.run(T, record_every=1)
    acc = G * math.sin(slope)
    slide, rate = measure.joint_angles(traj, model)["rail"]
    n = np.round(np.asarray(traj.t) / dt)
    discrete = acc * dt * dt * n * (n + 1) / 2
    assert np.max(np.abs(slide - discrete)) < 1e-9
    t = np.asarray(traj.t)
    assert np.max(np.abs(slide - acc * t * t / 2) - acc * dt * t / 2) < 1e-9
    assert abs(rate[-1] - acc * T) < 1e-9
    # the perpendicular offset and the angle are held
    d = np.array([math.sin(slope), math.cos(slope)])      # the axis's normal
    perp = (traj.q[:, 0, :2] - [0.0, 1.0]) @ d
    assert np.max(np.abs(perp)) < 1e-9
    assert np.max(np.abs(traj.q[:, 0, 2] - 0.3)) < 1e-12
    assert sim.ws.audit.sum() == 0


def test_limit_stops_the_slide():
    """A limit at s = 0.5 m stops the block there and holds it (the limit's impulse pushes);
    without it the block would be 2.45 m down after 1 s."""
    model = incline(1e-3, math.radians(30.0), limit=(-1.0, 0.5))
    sim = ps.Simulator(model)
    traj = sim.run(2.0, record_every=1)
    slide, rate = measure.joint_angles(traj, model)["rail"]
    assert np.max(slide) < 0.5 + 1e-9
    assert abs(slide[-1] - 0.5) < 1e-9 and abs(rate[-1]) < 1e-9
    # the upper side's impulse carries the weight's component along the axis each step
    weight_along = 2.0 * G * math.sin(math.radians(30))
    assert sim.state.last_pin_impulse[0, 3] == pytest.approx(weight_along * 1e-3, rel=1e-9)
    assert sim.state.limit_active[0, 1] == 1
    assert sim.ws.audit.sum() == 0


def test_slider_between_two_bodies_turns_with_body_a():
    """A slider on a spinning free body a: b stays on a's axis line (which turns with a) and
    keeps its angle relative to a; momentum and angular momentum are kept (no gravity)."""
    b = ps.ModelBuilder(dt=1e-3, gravity=(0.0, 0.0))
    base = b.add_body("base", mass=3.0, inertia=0.2, pos=(0.0, 0.0), omega=2.0)
    blk = b.add_body("block", mass=1.0, inertia=0.01, pos=(0.3, 0.0), omega=2.0, vel=(0.5, 0.6))
    b.add_slider("rail", base, blk, axis=(1.0, 0.0), anchor_a=(0.0, 0.0), anchor_b=(0.0, 0.0))
    model = b.compile()
    sim = ps.Simulator(model)
    traj = sim.run(2.0, record_every=1)
    q, v = traj.q, traj.v
    th = q[:, 0, 2]
    e = q[:, 1, :2] - q[:, 0, :2]
    perp = -np.sin(th) * e[:, 0] + np.cos(th) * e[:, 1]
    assert np.max(np.abs(perp)) < 1e-9
    assert np.max(np.abs(q[:, 1, 2] - q[:, 0, 2])) < 1e-9
    mass = model.arrays.body_mass
    p = (mass[:, None] * v[:, :, :2]).sum(axis=1)
    assert np.max(np.abs(p - p[0])) < 1e-9
    # the block slid outward (the centrifugal effect of the spin)
    slide = measure.joint_angles(traj, model)["rail"][0]
    assert slide[-1] > 0.3


def test_slider_motor_pushes_along_the_axis():
    """A constant 3 N motor force on a 2 kg block on a horizontal slider: a = 1.5 m/s^2, and
    the motor's power is f ds/dt."""
    b = ps.ModelBuilder(dt=1e-3)
    blk = b.add_body("block", mass=2.0, inertia=0.05, pos=(0.0, 0.0))
    b.add_slider("rail", None, blk, axis=(0.0, -1.0))   # a vertical rail, +s downwards
    b.add_slider_motor("push", "rail", limit=(-100.0, 100.0))
    model = b.compile()
    sim = ps.Simulator(model)
    sim.run(1.0, controller=lambda s: np.array([3.0]))
    s, rate = measure.pin_angle_rate(model, sim.state.q, sim.state.v, "rail")
    assert rate == pytest.approx((3.0 / 2.0 + G) * 1.0, rel=1e-9)


def test_slider_errors():
    b = ps.ModelBuilder()
    blk = b.add_body("block", mass=1.0, inertia=0.1, pos=(0.0, 0.0))
    with pytest.raises(ModelError, match="axis"):
        b.add_slider("s0", None, blk, axis=(0.0, 0.0))
    with pytest.raises(ModelError, match="off the axis"):
        b.add_slider("s1", None, blk, axis=(1.0, 0.0), anchor_world=None, anchor_a=(0.0, 1.0),
                     anchor_b=(0.0, 0.0))
    b.add_slider("s2", None, blk, axis=(1.0, 0.0))
    with pytest.raises(ModelError, match="slider"):
        b.add_pin_motor("m", "s2")
    b.add_pin("p", None, blk, anchor_world=(0.0, 0.0))
    with pytest.raises(ModelError, match="not a slider"):
        b.add_slider_motor("m2", "p")


L_POLE, M_CART, M_POLE, TH0 = 0.6, 1.0, 0.5, 2.0
I_POLE = M_POLE * L_POLE ** 2 / 12


def cartpole(dt):
    """A cart on a horizontal slider to the world and a pole (a thin rod) pinned to it, the
    pole released at rest TH0 [rad] from hanging down."""
    b = ps.ModelBuilder(dt=dt)
    cart = b.add_body("cart", mass=M_CART, inertia=0.1, pos=(0.0, 0.0))
    d = L_POLE / 2
    pole = b.add_body("pole", mass=M_POLE, inertia=I_POLE,
                      pos=(d * math.sin(TH0), -d * math.cos(TH0)), angle=TH0)
    b.add_slider("rail", None, cart, axis=(1.0, 0.0))
    b.add_pin("hinge", cart, pole, anchor_world=(0.0, 0.0), ref_angle=0.0)
    return b.compile()


def test_cartpole_energy():
    """The cart-pole conserves energy: over 10 s at dt 1e-3 the total energy stays within 1 %
    of the pole's swing energy m g d (1 - cos TH0) (symplectic Euler: an O(h) oscillation,
    no drift); the band halves with dt (first order), and the momentum along the rail is
    kept (no force along it)."""
    swing = M_POLE * G * L_POLE / 2 * (1 - math.cos(TH0))
    bands = []
    for dt in (1e-3, 5e-4):
        model = cartpole(dt)
        sim = ps.Simulator(model)
        traj = sim.run(10.0, record_every=10)
        E = total_energy(model, traj.q, traj.v)
        bands.append(E.max() - E.min())
        px = (model.arrays.body_mass * traj.v[:, :, 0]).sum(axis=1)
        assert np.max(np.abs(px)) < 1e-9
        # the first and last thirds of the run: no drift beyond the oscillation
        k = len(E) // 3
        assert abs(E[-k:].mean() - E[:k].mean()) < 0.1 * bands[-1]
    assert bands[0] < 0.01 * swing
    assert 0.4 < bands[1] / bands[0] < 0.6


def cartpole_mujoco(dt):
    mujoco = pytest.importorskip("mujoco")
    xml = f"""<mujoco><option timestep="{dt}" integrator="Euler" gravity="0 0 -{G}">
      <flag contact="disable"/></option>
      <worldbody><body name="cart"><joint name="rail" type="slide" axis="1 0 0"/>
        <inertial pos="0 0 0" mass="{M_CART}" diaginertia="0.1 0.1 0.1"/>
        <body name="pole"><joint name="hinge" type="hinge" axis="0 -1 0"/>
          <inertial pos="0 0 {-L_POLE / 2}" mass="{M_POLE}"
                    diaginertia="{I_POLE} {I_POLE} {I_POLE}"/>
        </body></body></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    data.qpos[:] = [0.0, TH0]
    out = [data.qpos.copy()]
    for _ in range(round(1.0 / dt)):
        mujoco.mj_step(model, data)
        out.append(data.qpos.copy())
    return np.array(out)


def planarsim_cartpole(dt):
    model = cartpole(dt)
    traj = ps.Simulator(model).run(1.0, record_every=1)
    ang = measure.joint_angles(traj, model)
    return np.stack([ang["rail"][0], ang["hinge"][0]], axis=1)


def test_cartpole_matches_mujoco():
    """The cart-pole over 1 s against MuJoCo's (slide + hinge, Euler, no contacts) at the same
    dt. Both are first-order integrators, so they differ by O(h): the largest difference of
    slide [m] and angle [rad] at dt 1e-3 must be within twice MuJoCo's own first-order error
    there (estimated by its change from dt 2e-3 to 1e-3), and halve when dt halves (they
    converge to each other, the same equations)."""
    diffs = {}
    mj = {}
    for dt in (2e-3, 1e-3):
        ours = planarsim_cartpole(dt)
        mj[dt] = cartpole_mujoco(dt)
        k = min(len(ours), len(mj[dt]))
        diffs[dt] = np.max(np.abs(ours[:k] - mj[dt][:k]), axis=0)
    mujoco_error = np.abs(mj[1e-3][-1] - mj[2e-3][-1])
    assert np.all(diffs[1e-3] < 2.0 * np.maximum(mujoco_error, 1e-6)), (diffs, mujoco_error)
    ratio = diffs[1e-3] / diffs[2e-3]
    assert np.all((0.4 < ratio) & (ratio < 0.6)), ratio
    assert np.all(diffs[1e-3] < 1e-2)
