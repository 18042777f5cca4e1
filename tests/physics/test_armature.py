"""Joint armature (a reflected rotor inertia on a joint's coordinate, kernels/constraints/soft.py) against
MuJoCo's (M_joint += armature) and against its closed form."""
import math

import numpy as np
import pytest

import planarsim as ps
from planarsim import measure
from planarsim.energy import total_energy

G = 9.81
L, M, ARM = 0.5, 1.0, 0.1
I = M * L * L / 12
TH = (1.0, 0.5)          # shoulder, elbow [rad] at the start (from hanging down, at rest)


def double_pendulum(dt, armature):
    """Two thin rods, pinned to the world and to each other, each hinge with `armature`."""
    b = ps.ModelBuilder(dt=dt)
    a1, a2 = TH[0], TH[0] + TH[1]
    p1 = np.array([L / 2 * math.sin(a1), -L / 2 * math.cos(a1)])
    elbow = 2 * p1
    p2 = elbow + [L / 2 * math.sin(a2), -L / 2 * math.cos(a2)]
    l1 = b.add_body("l1", mass=M, inertia=I, pos=p1, angle=a1)
    l2 = b.add_body("l2", mass=M, inertia=I, pos=p2, angle=a2)
    b.add_pin("shoulder", None, l1, anchor_world=(0.0, 0.0), armature=armature, ref_angle=0.0)
    b.add_pin("elbow", l1, l2, anchor_world=elbow, armature=armature, ref_angle=0.0)
    return b.compile()


def ours(dt, armature, T=1.0):
    model = double_pendulum(dt, armature)
    sim = ps.Simulator(model)
    traj = sim.run(T, record_every=1)
    assert sim.ws.audit.sum() == 0
    ang = measure.joint_angles(traj, model)
    return np.stack([ang["shoulder"][0], ang["elbow"][0]], axis=1), traj, model


def mujoco_angles(dt, armature, T=1.0):
    mujoco = pytest.importorskip("mujoco")
    xml = f"""<mujoco><option timestep="{dt}" integrator="Euler" gravity="0 0 -{G}">
      <flag contact="disable"/></option>
      <worldbody><body name="l1">
        <joint name="shoulder" type="hinge" axis="0 -1 0" armature="{armature}"/>
        <inertial pos="0 0 {-L / 2}" mass="{M}" diaginertia="{I} {I} {I}"/>
        <body name="l2" pos="0 0 {-L}">
          <joint name="elbow" type="hinge" axis="0 -1 0" armature="{armature}"/>
          <inertial pos="0 0 {-L / 2}" mass="{M}" diaginertia="{I} {I} {I}"/></body></body>
      </worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    data.qpos[:] = TH
    out = [data.qpos.copy()]
    for _ in range(round(T / dt)):
        mujoco.mj_step(model, data)
        out.append(data.qpos.copy())
    return np.array(out)


def test_double_pendulum_with_armature_matches_mujoco():
    """Armature 0.1 kg m^2 on both hinges, 1 s, Euler in both, no contacts. The two
    first-order integrators differ by O(h): at dt 1e-4 the angles agree within 1e-3 rad, the
    difference halves from dt 2e-4 to 1e-4 (they converge to each other), and it is far below
    the armature's own effect (the same run without armature ends 0.18 rad away)."""
    diff = {}
    for dt in (2e-4, 1e-4):
        a, _, _ = ours(dt, ARM)
        b = mujoco_angles(dt, ARM)
        k = min(len(a), len(b))
        diff[dt] = np.max(np.abs(a[:k] - b[:k]))
    assert diff[1e-4] < 1e-3
    assert 0.4 < diff[1e-4] / diff[2e-4] < 0.6
    without = mujoco_angles(1e-4, 0.0)[-1]
    with_arm = mujoco_angles(1e-4, ARM)[-1]
    assert np.max(np.abs(without - with_arm)) > 100 * diff[1e-4]


def test_armature_on_a_hinge_to_the_world_closed_form():
    """A wheel pinned at its COM to the world, inertia I, armature a, driven by a constant
    torque tau: its rate is tau t / (I + a) exactly (no gravity torque about the COM)."""
    b = ps.ModelBuilder(dt=1e-3)
    wheel = b.add_body("wheel", mass=1.0, inertia=0.02)
    b.add_pin("axle", None, wheel, anchor_world=(0.0, 0.0), armature=0.03)
    b.add_pin_motor("motor", "axle")
    model = b.compile()
    sim = ps.Simulator(model)
    sim.run(1.0, controller=lambda s: np.array([0.5]))
    assert sim.state.v[0, 2] == pytest.approx(0.5 * 1.0 / 0.05, rel=1e-12)


def test_armature_on_a_slider_closed_form():
    """A 2 kg block on a vertical slider with armature 3 kg (a geared rotor): it falls at
    g m / (m + a)."""
    b = ps.ModelBuilder(dt=1e-3)
    blk = b.add_body("block", mass=2.0, inertia=0.1)
    b.add_slider("rail", None, blk, axis=(0.0, -1.0), armature=3.0)
    model = b.compile()
    sim = ps.Simulator(model)
    sim.run(1.0)
    assert -sim.state.v[0, 1] == pytest.approx(G * 2.0 / 5.0, rel=1e-12)


def test_armature_energy_is_kept():
    """The double pendulum with armature conserves the energy that counts the rotors'
    a rate^2 / 2 (planarsim.energy): over 5 s at dt 1e-3 within 1 % of its swing energy, the
    band shrinking with dt; without the rotors' share the 'energy' would swing by far more."""
    bands = []
    for dt in (1e-3, 5e-4):
        _, traj, model = ours(dt, ARM, T=5.0)
        E = total_energy(model, traj.q, traj.v)
        bands.append(E.max() - E.min())
    swing = E.max() - total_energy(model, np.array([[0, -L / 2, 0], [0, -1.5 * L, 0]]),
                                   np.zeros((2, 3)))
    assert bands[0] < 0.01 * swing
    assert 0.4 < bands[1] / bands[0] < 0.6
