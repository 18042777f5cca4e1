"""MJCF loader against MuJoCo itself: for gymnasium's planar models and the SIMBICON character,
masses, COMs, inertias about the plane's normal, joint anchors at the file's pose, limits,
passive terms, gears and the model's dt and gravity match mujoco.MjModel (1e-9 relative);
the fluid drag matches MuJoCo's passive forces; what the engine lacks and what leaves the
plane are ModelErrors naming the element and its line."""
import math
import os
from pathlib import Path

import numpy as np
import pytest

from planarsim import ModelError
from planarsim.compiled import jit
from planarsim.kernels.dynamics.fluid import apply_fluid
from planarsim.mjcf import load_mjcf

mujoco = pytest.importorskip("mujoco", reason="mujoco is not installed (pip install planarsim[test])")

ROOT = Path(__file__).resolve().parents[2]
LEGS = ROOT / "walkers" / "simbicon" / "legs.xml"
LEGS_LOCAL = ROOT / "walkers" / "simbicon" / "legs_local.xml"
REL = 1e-9
# gymnasium's planar files: all load, nothing dropped
LOADS = ["hopper", "walker2d", "walker2d_v5", "half_cheetah", "inverted_pendulum",
         "inverted_double_pendulum", "swimmer", "reacher"]


def gym_asset(name):
    gym = pytest.importorskip("gymnasium", reason="gymnasium is not installed (pip install planarsim[gym])")
    path = Path(os.path.dirname(gym.__file__)) / "envs" / "mujoco" / "assets" / f"{name}.xml"
    if not path.exists():
        pytest.skip(f"gymnasium {gym.__version__} does not ship {path.name}")
    return path


def plane_indices(loaded):
    return ((0, 2), 1) if loaded.plane == "x-z" else ((0, 1), 2)


def close(a, b, scale=1.0):
    """|a - b| <= 1e-9 relative to max(|b|, scale)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    return np.all(np.abs(a - b) <= REL * np.maximum(np.abs(b), scale))


def check_against_mujoco(path, loaded):
    """Every quantity the loader derives from the file against MuJoCo's compiled model."""
    mm = mujoco.MjModel.from_xml_path(str(path))
    md = mujoco.MjData(mm)
    mujoco.mj_forward(mm, md)
    model = loaded.compile()
    a = model.arrays
    (i1, i2), k = plane_indices(loaded)
    n = np.eye(3)[k]
    # dt and the in-plane gravity
    assert a.dt == mm.opt.timestep
    assert tuple(a.gravity) == (mm.opt.gravity[i1], mm.opt.gravity[i2])
    # mass, COM and inertia about the normal of each rigid body (welded MJCF bodies merged)
    for bid, rb in loaded.rigid.items():
        ids = [mujoco.mj_name2id(mm, mujoco.mjtObj.mjOBJ_BODY, nm) for nm in rb.mjcf_bodies]
        masses = mm.body_mass[ids]
        com3 = (masses[:, None] * md.xipos[ids]).sum(0) / masses.sum()
        inertia = 0.0
        for i, m_i in zip(ids, masses):
            R = md.ximat[i].reshape(3, 3)
            d = md.xipos[i] - com3
            inertia += n @ R @ np.diag(mm.body_inertia[i]) @ R.T @ n + m_i * (d[i1] ** 2 + d[i2] ** 2)
        assert close(a.body_mass[bid], masses.sum()), rb.name
        assert close(model.q0[bid, :2], (com3[i1], com3[i2])), rb.name
        if model.is_point(bid):             # translates only (two slides): no rotation
            assert a.body_inertia[bid] == 0.0, rb.name
        else:
            assert close(a.body_inertia[bid], inertia), rb.name
    # hinges: anchors in the world at the file's pose, limits, stiffness, damping
    for name, pid in loaded.pin.items():
        j = mujoco.mj_name2id(mm, mujoco.mjtObj.mjOBJ_JOINT, name)
        anchor = (md.xanchor[j][i1], md.xanchor[j][i2])
        for side in range(2):
            body = a.pin_body[pid, side]
            world = a.pin_anchor[pid, side] + (model.q0[body, :2] if body >= 0 else 0.0)
            assert close(world, anchor), name
        jm = loaded.joint[name]
        assert jm.sign == float(np.sign(md.xaxis[j] @ np.cross(np.eye(3)[i1], np.eye(3)[i2])))
        ref = mm.qpos0[mm.jnt_qposadr[j]]
        assert close(jm.ref, ref)
        if mm.jnt_limited[j]:
            expect = sorted(jm.sign * (mm.jnt_range[j] - ref))
            assert close(a.pin_limit[pid], expect), name
        else:
            assert tuple(a.pin_limit[pid]) == (-math.inf, math.inf), name
        assert close(a.pin_stiffness[pid], mm.jnt_stiffness[j]), name
        assert close(a.pin_damping[pid], mm.dof_damping[mm.jnt_dofadr[j]]), name
        assert close(a.pin_armature[pid], mm.dof_armature[mm.jnt_dofadr[j]]), name
    # a free root's joints: free coordinates with MuJoCo's armature, limits and passive terms
    for name in loaded.free_joints:
        j = mujoco.mj_name2id(mm, mujoco.mjtObj.mjOBJ_JOINT, name)
        jm = loaded.joint[name]
        pid = jm.pin
        assert a.pin_kind[pid] & 2, name                        # JOINT_FREE_BIT: no rows
        assert close(a.pin_armature[pid], mm.dof_armature[mm.jnt_dofadr[j]]), name
        assert close(a.pin_damping[pid], mm.dof_damping[mm.jnt_dofadr[j]]), name
        assert close(jm.ref, mm.qpos0[mm.jnt_qposadr[j]]), name
        if mm.jnt_limited[j]:
            assert close(a.pin_limit[pid], sorted(jm.sign * (mm.jnt_range[j] - jm.ref))), name
        else:
            assert tuple(a.pin_limit[pid]) == (-math.inf, math.inf), name
    # motors: gear (in the pin's sign) and torque range
    assert len(loaded.actuator) == mm.nu
    for u in range(mm.nu):
        jname = mujoco.mj_id2name(mm, mujoco.mjtObj.mjOBJ_JOINT, mm.actuator_trnid[u, 0])
        act = next(x for x in loaded.actuator.values() if x.joint == jname)
        sign = loaded.joint[jname].sign
        assert close(act.gear, sign * mm.actuator_gear[u, 0])
        if mm.actuator_ctrllimited[u]:
            expect = sorted(act.gear * mm.actuator_ctrlrange[u])
            assert close(a.act_range[act.id], expect)
    return mm, model


@pytest.mark.parametrize("name", LOADS)
def test_gymnasium_model_matches_mujoco(name):
    path = gym_asset(name)
    loaded = load_mjcf(path)
    mm, model = check_against_mujoco(path, loaded)
    assert model.total_mass == pytest.approx(mm.body_mass.sum(), rel=REL)
    assert model.n_pin == mm.njnt          # a free root's joints are free coordinates
    assert loaded.report.dropped == {}     # armature and fluid are modelled
    assert list(loaded.joint) == [mujoco.mj_id2name(mm, mujoco.mjtObj.mjOBJ_JOINT, j)
                                  for j in range(mm.njnt)]


def test_two_slides_below_the_root_name_the_body():
    xml = """<mujoco><worldbody><body name="a"><joint name="h" axis="0 0 1"/>
      <geom size=".1"/><body name="b" pos="1 0 0">
      <joint name="x" type="slide" axis="1 0 0"/><joint name="y" type="slide" axis="0 1 0"/>
      <geom size=".1"/></body></body></worldbody></mujoco>"""
    with pytest.raises(ModelError, match=r"<body name='b'> \(line 2\): joints \['slide', 'slide'\]"):
        load_mjcf(xml)


def test_reacher_target_is_a_point_mass_on_two_limited_slides():
    loaded = load_mjcf(gym_asset("reacher"))
    model = loaded.compile()
    target = loaded.body["target"]
    assert model.is_point(target)
    assert loaded.plane == "x-y" and tuple(model.arrays.gravity) == (0.0, 0.0)
    for name in ("target_x", "target_y"):
        assert tuple(model.arrays.pin_limit[loaded.joint[name].pin]) == pytest.approx((-0.37, 0.17)
                                                                                    if name == "target_x"
                                                                                    else (-0.17, 0.37))


@jit
def _fluid_forces(m, q, cs, v, f):
    apply_fluid(m, q, cs, v, f)


def test_swimmer_drag_is_mujocos_passive_force():
    """At a random state, the generalized force of planarsim's fluid boxes (their body
    forces mapped through the joints' Jacobian) equals MuJoCo's qfrc_passive (1e-9)."""
    from planarsim.envs.core import GeneralizedCoords
    path = gym_asset("swimmer")
    loaded = load_mjcf(path)
    model = loaded.compile()
    coords = GeneralizedCoords(loaded, model)
    mm = mujoco.MjModel.from_xml_path(str(path))
    md = mujoco.MjData(mm)
    rng = np.random.default_rng(3)
    for _ in range(3):
        qpos, qvel = rng.normal(size=mm.nq) * 0.5, rng.normal(size=mm.nv) * 2
        md.qpos[:], md.qvel[:] = qpos, qvel
        mujoco.mj_forward(mm, md)
        q, v = coords.to_maximal(qpos, qvel)
        f = np.zeros_like(q)
        cs = np.column_stack([np.cos(q[:, 2]), np.sin(q[:, 2]), q[:, 2]])
        _fluid_forces(model.arrays, q, cs, v, f)
        # generalized force: the power of f at v is qfrc . qvel for every qvel (unit vectors)
        gen = np.zeros(mm.nv)
        for i in range(mm.nv):
            e = np.zeros(mm.nv)
            e[i] = 1.0
            _, vi = coords.to_maximal(qpos, e)
            gen[i] = np.sum(f * vi)
        np.testing.assert_allclose(gen, md.qfrc_passive, rtol=1e-9, atol=1e-9 * np.abs(md.qfrc_passive).max())


def test_half_cheetah_total_mass_and_springs():
    loaded = load_mjcf(gym_asset("half_cheetah"), )
    model = loaded.compile()
    assert model.total_mass == pytest.approx(14.0, rel=REL)           # settotalmass
    assert model.arrays.pin_stiffness[loaded.pin["bthigh"]] == 240.0
    assert model.arrays.dt == 0.01


def test_swimmer_moves_in_the_x_y_plane_without_gravity():
    loaded = load_mjcf(gym_asset("swimmer"))
    assert loaded.plane == "x-y"
    assert tuple(loaded.compile().arrays.gravity) == (0.0, 0.0)
    assert loaded.free_joints == ("slider1", "slider2", "free_body_rot")


def test_hopper_stands_on_the_floor_and_reports_what_it_ignored():
    loaded = load_mjcf(gym_asset("hopper"), )
    model = loaded.compile()
    assert model.terrain.height(0.0) == 0.0
    assert any(n.endswith("/ground0") for n in model.contact_names)    # feet touch the floor
    text = str(loaded.report)
    for what in ("<light>", "<camera>", "<asset>", "geom rgba", "option integrator"):
        assert what in loaded.report.ignored and what in text
    assert loaded.report.dropped == {}                                   # armature is modelled


def test_walker_motor_torque_follows_the_pin_sign():
    """thigh_joint turns about -y: a positive MJCF torque is counter-clockwise in our plane,
    so the pin motor's gear is +100 and its range +-100 N m."""
    loaded = load_mjcf(gym_asset("walker2d"), )
    act = loaded.actuator["thigh_joint"]
    assert act.gear == 100.0 and act.ctrlrange == (-1.0, 1.0)
    assert tuple(loaded.compile().arrays.act_range[act.id]) == (-100.0, 100.0)


def test_legs_local_and_global_give_the_same_model():
    glob, loc = load_mjcf(LEGS).compile(), load_mjcf(LEGS_LOCAL).compile()
    assert glob.body_names == loc.body_names and glob.pin_names == loc.pin_names
    for f in glob.arrays._fields:
        x, y = np.asarray(getattr(glob.arrays, f), float), np.asarray(getattr(loc.arrays, f), float)
        assert x.shape == y.shape and np.allclose(x, y, rtol=1e-12, atol=1e-12), f
    assert np.allclose(glob.q0, loc.q0, atol=1e-12)


def test_legs_local_matches_mujoco():
    check_against_mujoco(LEGS_LOCAL, load_mjcf(LEGS_LOCAL))


def test_orientation_forms_match_mujoco():
    """Body euler (intrinsic and extrinsic), geom zaxis, xyaxes, axisangle and quat, a box and
    an ellipsoid turned about the normal, a cylinder across the plane, mass from density."""
    xml = """<mujoco><compiler angle="radian" eulerseq="zYx"/><worldbody>
      <body name="a" pos="0.1 0.2 0.3" euler="0 0.4 0">
        <joint name="r" type="hinge" axis="0 1 0"/>
        <geom type="box" size="0.1 0.2 0.3" xyaxes="0 0 1 0 1 0"/>
        <geom type="capsule" size="0.05 0.2" zaxis="1 0 1" pos="0.2 0 0"/>
        <body name="b" pos="0.3 -0.1 0" quat="0.9 0 0.3 0">
          <joint name="k" type="hinge" axis="0 -1 0" pos="0 0 0.1" range="-1 0.5"/>
          <geom type="ellipsoid" size="0.1 0.2 0.05" axisangle="0 1 0 0.7" density="300"
                contype="0" conaffinity="0"/>
          <geom type="cylinder" fromto="0 0 0 0.4 0 -0.1" size="0.03"/>
          <geom type="sphere" size="0.04" pos="0 0.5 0.2" mass="0.2"/>
        </body></body></worldbody></mujoco>"""
    path = Path(__file__).parent / "_orient.xml"
    try:
        path.write_text(xml)
        check_against_mujoco(path, load_mjcf(path))
    finally:
        path.unlink(missing_ok=True)


def test_default_classes_and_childclass_match_mujoco(tmp_path):
    xml = """<mujoco><default><geom density="500"/><joint damping="2"/>
        <default class="light"><geom density="100"/>
          <default class="stiff"><joint stiffness="30" damping="0"/></default></default></default>
      <worldbody><body name="a" childclass="light">
        <joint name="r" type="hinge" axis="0 1 0"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.05"/>
        <body name="b" pos="0 0 -0.5">
          <joint name="k" class="stiff" type="hinge" axis="0 1 0"/>
          <geom class="main" type="sphere" size="0.1"/>
        </body></body></worldbody></mujoco>"""
    path = tmp_path / "classes.xml"
    path.write_text(xml)
    loaded = load_mjcf(path)
    check_against_mujoco(path, loaded)
    assert loaded.compile().arrays.pin_stiffness[loaded.pin["k"]] == 30.0


@pytest.mark.parametrize("body, match", [
    ("<tendon>\n<spatial name='t'><site site='s'/></spatial></tendon>",
     r":3: <spatial name='t'> \(line 3\): spatial tendons .* are not supported"),
    ("<equality>\n<joint name='e' joint1='k' joint2='r'/></equality>",
     r":3: <joint name='e'> \(line 3\): <joint> inside <equality>: equality constraints"),
])
def test_spatial_tendon_and_equality_are_model_errors_naming_element_and_line(body, match):
    xml = ("<mujoco><worldbody><body name='a'><joint name='r' type='hinge' axis='0 1 0'/>"
           "<geom type='sphere' size='0.1'/><body name='b'><joint name='k' type='hinge' "
           "axis='0 1 0'/><geom type='sphere' size='0.1'/></body></body></worldbody>\n" + body +
           "</mujoco>")
    with pytest.raises(ModelError, match=match):
        load_mjcf(xml)


def test_hinge_about_x_is_a_model_error_naming_joint_and_line():
    xml = ("<mujoco><worldbody><body name='a'><joint name='r' type='hinge' axis='0 1 0'/>\n"
           "<geom type='sphere' size='0.1'/><body name='b'>\n<joint name='roll' type='hinge' "
           "axis='1 0 0'/><geom type='sphere' size='0.1'/></body></body></worldbody></mujoco>")
    with pytest.raises(ModelError, match=r":3: <joint name='roll'> \(line 3\): hinge axis=\(1.0, 0.0, 0.0\) "
                                         r"is not normal to the x-z plane.*leaving the plane"):
        load_mjcf(xml)


def test_empty_tendon_and_sites_are_ignored_and_reported():
    xml = ("<mujoco><default><tendon/></default><worldbody><body name='a'>"
           "<joint name='r' type='hinge' axis='0 1 0'/>\n<site name='s'/>"
           "<geom type='sphere' size='0.1' rgba='1 0 0 1'/></body></worldbody><tendon/></mujoco>")
    rep = load_mjcf(xml).report
    assert rep.ignored["<site>"] == [2] and "geom rgba" in rep.ignored
    # (a <default><tendon> is read: its attributes reach the fixed tendons of its class)
    assert "<tendon> (empty)" in rep.ignored


def test_loaded_hopper_lands_on_its_floor():
    """The loaded model runs: the hopper, dropped 4 cm onto the file's floor, comes to rest on
    its foot (nothing below the ground, the torso still up)."""
    import planarsim as ps
    loaded = load_mjcf(gym_asset("hopper"), )
    model = loaded.compile()
    sim = ps.Simulator(model)
    sim.steps(250)                                   # 0.5 s at the file's 0.002 s
    q = sim.state.q
    foot = loaded.body["foot"]
    assert q[foot, 1] > 0.06 - 1e-6                  # capsule radius 0.06 above y = 0
    assert q[loaded.root, 1] > 1.0
