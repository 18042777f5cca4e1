"""The DeepMind Control Suite's planar models (dm_control.suite) through the MJCF loader,
against MuJoCo.

The ten planar domains load as shipped, from the file's path (their <include>s of
./common/*.xml next to them), swimmer from its generated XML with its assets dict; finger
with its spinner's joint frictionloss (planarsim's exact friction row; its motion against
MuJoCo's: tests/physics/test_joint_friction.py). point_mass's motors pull on fixed tendons
(test_mjcf_tendons.py compares its motion under them with MuJoCo's).

For each model that loads: every rigid body's mass and inertia about the plane's normal
equal MuJoCo's compiled model (1e-9 relative; point_mass's body only translates: the
inertia its geoms assemble, which no motion uses); and a passive motion (no control; from
qpos0 with every limited joint at 35 % or 65 % of its range, free hinges turned 0.3 rad,
joint speeds 0.4-0.7 rad/s or m/s, the walkers lifted 0.5 m so that nothing touches) over
SPAN = 0.06 s at the file's dt is compared with MuJoCo's RK4 at dt 1e-5 (the exact motion,
~1e-9): planarsim's position error is at most 2x MuJoCo's Euler's at that dt, and so is
its velocity error except where MuJoCo's own velocity error is a fluke of cancellation
(VELOCITY_RATIO: measured 3.7 on walker and 15.6 on hopper, whose Euler velocity error
is 1e-5 against 1.5e-3 in position); both engines are first order, so ours at dt / 10
errs at least 5x less than the first-order error at dt (ours or MuJoCo's Euler's; cheetah
at its dt 0.01 is not yet asymptotic in either engine). Measured ratios (position, velocity): cheetah 0.27,
0.15; walker 0.99, 3.65; hopper 1.00, 15.6; acrobot 0.99, 1.62; cartpole 1.00, 1.01;
pendulum 1.00, 1.00; reacher 1.04, 0.96; swimmer (6 links) 0.99, 1.18; point_mass 1.00,
1.00."""
from pathlib import Path

import warnings

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco", reason="mujoco is not installed (pip install -e '.[test]')")
suite = pytest.importorskip("dm_control.suite",
                            reason="dm_control is not installed (pip install dm_control): the "
                                   "DeepMind Control Suite's models are its files")

import planarsim as ps  # noqa: E402
from planarsim import ModelError  # noqa: E402
from planarsim.kernels.codes import MODE_FREE  # noqa: E402
from planarsim.mjcf import load_mjcf  # noqa: E402
from planarsim.state import make_state  # noqa: E402

SUITE = Path(suite.__file__).resolve().parent
LOADS = ["cheetah", "walker", "hopper", "acrobot", "cartpole", "pendulum", "reacher", "swimmer",
         "point_mass"]
WALKERS = ("cheetah", "walker", "hopper")      # a free root: lifted off the floor
SPAN = 0.06                                   # [s] a whole number of every file's dt
REL = 1e-9
RATIO = 2.0
VELOCITY_RATIO = {"walker": 5.0, "hopper": 20.0}   # see the module's docstring
SWIMMER_LINKS = 6


def sources(name):
    """(planarsim's loaded model, MuJoCo's compiled model) of a suite domain."""
    if name == "swimmer":
        from dm_control.suite import swimmer
        xml, assets = swimmer.get_model_and_assets(SWIMMER_LINKS)
        return load_mjcf(xml, assets=assets), mujoco.MjModel.from_xml_string(xml.decode(), assets)
    path = SUITE / f"{name}.xml"
    return load_mjcf(path), mujoco.MjModel.from_xml_path(str(path))


def plane_axes(loaded):
    return ((0, 2), 1) if loaded.plane == "x-z" else ((0, 1), 2)


@pytest.mark.parametrize("name", LOADS)
def test_suite_model_masses_and_inertias_match_mujoco(name):
    loaded, mm = sources(name)
    md = mujoco.MjData(mm)
    mujoco.mj_forward(mm, md)
    model = loaded.compile()
    (i1, i2), k = plane_axes(loaded)
    n = np.eye(3)[k]
    assert len(loaded.rigid) == len({mm.body_weldid[b] for b in range(1, mm.nbody)
                                     if mm.body_weldid[b] != 0})
    for bid, rb in loaded.rigid.items():
        ids = [mujoco.mj_name2id(mm, mujoco.mjtObj.mjOBJ_BODY, nm) for nm in rb.mjcf_bodies]
        masses = mm.body_mass[ids]
        com = (masses[:, None] * md.xipos[ids]).sum(0) / masses.sum()
        inertia = 0.0
        for i, m_i in zip(ids, masses):
            R = md.ximat[i].reshape(3, 3)
            d = md.xipos[i] - com
            inertia += n @ R @ np.diag(mm.body_inertia[i]) @ R.T @ n + m_i * (d[i1] ** 2 + d[i2] ** 2)
        assert abs(model.arrays.body_mass[bid] - masses.sum()) <= REL * masses.sum(), rb.name
        # (a body that only translates is a point mass: no inertia in the model)
        ours = rb.inertia if model.is_point(bid) else model.arrays.body_inertia[bid]
        assert abs(ours - inertia) <= REL * inertia, rb.name
        assert np.allclose(model.q0[bid, :2], (com[i1], com[i2]), rtol=0, atol=REL), rb.name


def start_state(mm, lift):
    """qpos0 with limited joints at 35 % / 65 % of their range, free hinges turned +-0.3 rad,
    speeds +-0.4 (1 + j / 10); the root's z slide raised by lift [m]."""
    qp, qv = mm.qpos0.copy(), np.zeros(mm.nv)
    for j in range(mm.njnt):
        a, sign = mm.jnt_qposadr[j], (-1.0) ** j
        if mm.jnt_limited[j]:
            lo, hi = mm.jnt_range[j]
            qp[a] = lo + (0.5 + 0.15 * sign) * (hi - lo)
        elif mm.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE:
            qp[a] += 0.3 * sign
        qv[mm.jnt_dofadr[j]] = 0.4 * sign * (1.0 + 0.1 * j)
    if lift:
        qp[mm.jnt_qposadr[mujoco.mj_name2id(mm, mujoco.mjtObj.mjOBJ_JOINT, "rootz")]] += lift
    return qp, qv


def mujoco_motion(mm, qp, qv, dt, integrator):
    """MuJoCo's (qpos, qvel) after SPAN at step dt, and its constraint rows met on the way."""
    mm.opt.timestep, mm.opt.integrator = dt, integrator
    d = mujoco.MjData(mm)
    d.qpos[:], d.qvel[:] = qp, qv
    rows = 0
    for _ in range(int(round(SPAN / dt))):
        mujoco.mj_step(mm, d)
        rows += d.nefc
    return d.qpos.copy(), d.qvel.copy(), rows


def our_motion(loaded, qp, qv, dt):
    """planarsim's (qpos, qvel) after SPAN at step dt, and whether a contact or limit acted."""
    from planarsim.envs.core import GeneralizedCoords
    loaded.builder.dt = dt
    model = loaded.compile()
    coords = GeneralizedCoords(loaded, model)
    with warnings.catch_warnings():     # (hopper's build pose has its knee outside its
        warnings.filterwarnings("ignore", message=".*outside its limit")   # range; qp is in)
        sim = ps.Simulator(model, None, make_state(model))
    sim.start_over(*coords.to_maximal(qp, qv))
    touched = False
    for _ in range(int(round(SPAN / dt))):
        sim.steps(1)
        st = sim.state
        touched |= bool(st.limit_active.any() or (st.contact_mode != MODE_FREE).any())
    assert sim.ws.audit.sum() == 0
    qpos, qvel = coords.values(sim.state.q, sim.state.v)
    return qpos, qvel, touched


@pytest.mark.parametrize("name", LOADS)
def test_suite_model_passive_motion_matches_mujoco(name):
    pytest.importorskip("gymnasium", reason="planarsim.envs (the joint coordinates) needs gymnasium")
    loaded, mm = sources(name)
    names = [mujoco.mj_id2name(mm, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(mm.njnt)]
    assert list(loaded.joint) == names              # MuJoCo's qpos order
    dt = float(mm.opt.timestep)
    qp, qv = start_state(mm, 0.5 if name in WALKERS else 0.0)
    exact_p, exact_v, rows = mujoco_motion(mm, qp, qv, 1e-5, mujoco.mjtIntegrator.mjINT_RK4)
    euler_p, euler_v, more = mujoco_motion(mm, qp, qv, dt, mujoco.mjtIntegrator.mjINT_EULER)
    p, v, touched = our_motion(loaded, qp, qv, dt)
    fine_p, fine_v, touched_fine = our_motion(loaded, qp, qv, dt / 10)
    assert rows + more == 0 and not touched and not touched_fine   # free motion in both
    err = lambda a, b: float(np.abs(a - b).max())                  # noqa: E731
    assert err(p, exact_p) <= RATIO * err(euler_p, exact_p), (err(p, exact_p), err(euler_p, exact_p))
    ratio = VELOCITY_RATIO.get(name, RATIO)
    assert err(v, exact_v) <= ratio * err(euler_v, exact_v), (err(v, exact_v), err(euler_v, exact_v))
    # first order: a tenth of the step errs at least 5x less than a first-order error at dt
    # (ours, or MuJoCo's Euler's: cheetah's stiff springs at its dt 0.01 are not yet in the
    # asymptotic range, where both errors shrink 3x to 10x at dt / 10, then 10x)
    assert 5.0 * err(fine_p, exact_p) <= max(err(p, exact_p), err(euler_p, exact_p))
    assert 5.0 * err(fine_v, exact_v) <= max(err(v, exact_v), err(euler_v, exact_v))


def test_finger_loads_with_the_spinners_frictionloss():
    loaded = load_mjcf(SUITE / "finger.xml")
    model = loaded.compile()
    hinge = loaded.joint["hinge"].coordinate
    assert model.arrays.pin_frictionloss[hinge] == 0.1
    assert model.arrays.pin_damping[hinge] == 0.5
    assert all(model.arrays.pin_frictionloss[loaded.joint[j].coordinate] == 0.0
               for j in ("proximal", "distal"))


def test_point_mass_loads_in_x_y_with_limited_damped_slides_and_tendon_motors():
    """point_mass's body on two slides (no hinge) chooses the x-y plane and becomes a point
    mass on two limited, damped slides, each pulled by a motor on a fixed tendon (t1: root_x,
    t2: root_y; the other joint's coef 0 drives nothing)."""
    loaded = load_mjcf(SUITE / "point_mass.xml")
    mm = mujoco.MjModel.from_xml_path(str(SUITE / "point_mass.xml"))
    assert loaded.plane == "x-y" and list(loaded.joint) == ["root_x", "root_y"]
    model = loaded.compile()
    bid = loaded.body["pointmass"]
    assert model.is_point(bid) and model.arrays.body_mass[bid] == pytest.approx(mm.body_mass[1], rel=REL)
    for j in ("root_x", "root_y"):
        assert tuple(model.arrays.pin_limit[loaded.joint[j].coordinate]) == (-0.29, 0.29)
        assert model.arrays.pin_damping[loaded.joint[j].coordinate] == 1.0
    assert [(a.tendon, a.joints, a.gains) for a in loaded.actuator.values()] == [
        ("t1", ("root_x",), (0.1,)), ("t2", ("root_y",), (0.1,))]


@pytest.mark.parametrize("name, ignored", [
    ("cheetah", ["<asset> in ", "<visual> in "]),
    ("acrobot", ["option flag energy='enable'"]),
    ("reacher", ["world geom that collides with nothing"]),
])
def test_suite_load_report_says_what_it_ignored(name, ignored):
    rep = load_mjcf(SUITE / f"{name}.xml").report
    for what in ignored:
        assert any(k.startswith(what) for k in rep.ignored), (what, sorted(rep.ignored))
    assert any("common/skybox.xml" in k for k in rep.ignored)


def test_suite_flags_reach_the_model():
    """acrobot: constraint off (no contact with its floor, no limits); cartpole: contact off
    but its slider's limit kept."""
    acro = load_mjcf(SUITE / "acrobot.xml")
    assert not acro.builder._collide and any("contacts are off" in n for n in acro.report.notes)
    cart = load_mjcf(SUITE / "cartpole.xml").compile()
    assert tuple(cart.arrays.pin_limit[0]) == (-1.8, 1.8)
    assert cart.arrays.contact_body.size == 0
