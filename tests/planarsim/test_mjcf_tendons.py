"""MJCF fixed tendons (L = sum coef_i q_i) and the motors on them, against MuJoCo.

A motor on a fixed tendon pulls with gear * ctrl along L: every joint of the tendon takes the
generalized force coef_i * gear * ctrl (MuJoCo's transmission, moment arm = coef), so one
MJCF actuator (one action entry) drives one planarsim motor per joint whose coefficient is
not 0. Models: dm_control's point_mass as shipped (each tendon one slide, the other at coef
0), the same with its tendons turned (each motor pulls on both slides: 0.8 / -0.6 and
0.6 / 0.8) and a double pendulum in the x-z plane (hinges about +y: planarsim's sign -1)
whose shoulder and elbow one tendon couples (1, -0.5).

From random states (joints within the middle 60 % of their ranges, speeds up to 1 rad/s or
m/s) under constant controls (0.3 and 1.0 on each motor, mixed signs), the joint velocities
after SPAN = 0.02 s are compared with MuJoCo's RK4 at dt 1e-5 (the exact motion): planarsim
at the file's dt errs at most RATIO times what MuJoCo's Euler errs at that dt (3 on
point_mass; 8 on the double pendulum, test_envs_under_torque.py's bound for hinge chains),
and at a tenth of it at least 5x less than that first-order error. Measured ratios (six
states each): point_mass 1.000 on every state (a linear damped mass: the same step as
MuJoCo's Euler), turned point_mass 1.000, double pendulum 0.57-4.71 (4.71 where MuJoCo's
error is 1.8e-4 rad/s, ours 8.3e-4); ours falls 10x per decade of dt on every state. At
the walls (the slides' limits +-0.29 m) the mass stays within the range to 1e-9 m. Tendon
physics the loader does not model (limits,
spring, damper, friction, armature, margin) and spatial tendons are ModelErrors naming the
file, line, tendon and attribute."""
from pathlib import Path

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco", reason="mujoco is not installed (pip install -e '.[test]')")
suite = pytest.importorskip("dm_control.suite",
                            reason="dm_control is not installed (pip install dm_control): it "
                                   "ships point_mass.xml")
pytest.importorskip("gymnasium", reason="planarsim.envs (the joint coordinates) needs gymnasium")

from planarsim import ModelError  # noqa: E402
from planarsim.envs.core import PlanarMujocoEnv  # noqa: E402
from planarsim.mjcf import load_mjcf  # noqa: E402

SUITE = Path(suite.__file__).resolve().parent
POINT_MASS = SUITE / "point_mass.xml"
ASSETS = {f"./common/{f}": (SUITE / "common" / f).read_bytes()
          for f in ("skybox.xml", "visual.xml", "materials.xml")}
SPAN = 0.02                    # [s]
# point_mass: a damped mass on two slides, on which planarsim's step is MuJoCo's Euler step
# (1.000 measured): the 3x would hide a wrong gear or coefficient of up to 3x
RATIO = {"point_mass": 1.001, "turned point_mass": 1.001,
         # test_envs_under_torque.py's bound for hinge chains: single states where MuJoCo's
         # Euler error cancels (here 1.8e-4 rad/s against ours 8.3e-4: 4.7)
         "double pendulum": 8.0}
LIMIT_TOL = 1e-9               # [m]


def turned_point_mass() -> str:
    """point_mass.xml with each tendon pulling on both slides (unit directions)."""
    text = POINT_MASS.read_text()
    for old, new in (('joint="root_x" coef="1"', 'joint="root_x" coef="0.8"'),
                     ('joint="root_y" coef="0"', 'joint="root_y" coef="-0.6"'),
                     ('joint="root_x" coef="0"', 'joint="root_x" coef="0.6"'),
                     ('joint="root_y" coef="1"', 'joint="root_y" coef="0.8"')):
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    return text


DOUBLE_PENDULUM = """<mujoco model="coupled">
  <option timestep="0.01"/>
  <default><geom contype="0" conaffinity="0"/><joint type="hinge" axis="0 1 0"/></default>
  <worldbody>
    <body name="upper" pos="0 0 2">
      <joint name="shoulder" range="-90 90" damping="0.05"/>
      <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.05"/>
      <body name="lower" pos="0.5 0 0">
        <joint name="elbow" range="-120 120"/>
        <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.04"/>
      </body>
    </body>
  </worldbody>
  <tendon>
    <fixed name="coupled"><joint joint="shoulder" coef="1"/><joint joint="elbow" coef="-0.5"/></fixed>
    <fixed name="elbow_only"><joint joint="shoulder" coef="0"/><joint joint="elbow" coef="1"/></fixed>
  </tendon>
  <actuator>
    <motor tendon="coupled" gear="2" ctrlrange="-1 1"/>
    <motor name="elbow_motor" tendon="elbow_only" gear="0.5" ctrlrange="-1 1"/>
  </actuator>
</mujoco>"""

MODELS = {"point_mass": str(POINT_MASS), "turned point_mass": turned_point_mass(),
          "double pendulum": DOUBLE_PENDULUM}


def mujoco_model(source):
    if source.lstrip().startswith("<"):
        return mujoco.MjModel.from_xml_string(source, ASSETS)
    return mujoco.MjModel.from_xml_path(source)


def our_env(source, dt=None):
    kw = {} if dt is None else {"dt": dt}
    return PlanarMujocoEnv(source, 1, assets=ASSETS, **kw)


def mujoco_qvel(mm, qp, qv, u, dt, integrator):
    """MuJoCo's qvel after SPAN at step dt, and its constraint rows met on the way."""
    from mujoco_oracle import mujoco_qvel as oracle
    return oracle(mujoco, mm, qp, qv, u, dt, integrator, SPAN)


def our_qvel(source, qp, qv, u, dt):
    """planarsim's qvel after SPAN at step dt (through the env's action mapping), and
    whether a joint limit acted."""
    env = our_env(source, dt)
    env.set_state(qp, qv)
    touched = False
    for _ in range(int(round(SPAN / dt))):
        env.do_simulation(u, 1)
        touched |= bool(env.sim.state.limit_active.any())
    assert env.sim.ws.audit.sum() == 0
    return env.data.qvel.copy(), touched


def random_cases(mm, n, rng):
    """n (qpos, qvel, ctrl): joints in the middle 60 % of their ranges, speeds in [-1, 1],
    controls 0.3 or 1.0 with random signs."""
    lo, hi = mm.jnt_range.T
    for _ in range(n):
        qp = lo + rng.uniform(0.2, 0.8, mm.nq) * (hi - lo)
        qv = rng.uniform(-1.0, 1.0, mm.nv)
        u = rng.choice([0.3, 1.0], mm.nu) * rng.choice([-1.0, 1.0], mm.nu)
        yield qp, qv, u


def test_point_mass_loads_with_a_motor_on_each_slide():
    loaded = load_mjcf(POINT_MASS)
    assert loaded.plane == "x-y" and list(loaded.joint) == ["root_x", "root_y"]
    for motor, joint in (("t1", "root_x"), ("t2", "root_y")):
        act = loaded.actuator[motor]
        assert (act.tendon, act.joints, act.gains, act.ctrlrange) == (motor, (joint,), (0.1,),
                                                                        (-1.0, 1.0))
    model = loaded.compile()
    assert model.act_names == ("t1", "t2")
    assert [tuple(r) for r in model.arrays.act_range] == [(-0.1, 0.1)] * 2


def test_a_motor_on_a_tendon_drives_each_joint_with_a_coefficient():
    """Turned point_mass: each motor drives both slides (gear 0.1 * coef); double pendulum:
    the coupled tendon drives both hinges in planarsim's sign (-1 about +y), the elbow-only
    one the elbow alone (coef 0 drives nothing); the env's action maps to every drive."""
    turned = load_mjcf(turned_point_mass(), assets=ASSETS)
    assert turned.actuator["t1"].joints == ("root_x", "root_y")
    assert np.allclose(turned.actuator["t1"].gains, (0.08, -0.06), rtol=0, atol=1e-15)
    assert np.allclose(turned.actuator["t2"].gains, (0.06, 0.08), rtol=0, atol=1e-15)
    assert turned.compile().act_names == ("t1:root_x", "t1:root_y", "t2:root_x", "t2:root_y")
    with pytest.raises(ValueError, match=r"drives 2 joints \['root_x', 'root_y'\]"):
        turned.actuator["t1"].gear
    pend = load_mjcf(DOUBLE_PENDULUM)
    assert pend.actuator["coupled"].gains == (-2.0, 1.0)
    assert pend.actuator["elbow_motor"].joints == ("elbow",)
    assert pend.actuator["elbow_motor"].gear == -0.5
    env = our_env(DOUBLE_PENDULUM)
    env.do_simulation(np.array([1.7, -0.25]), 1)          # the first clamped to 1
    assert env._u.tolist() == [-2.0, 1.0, 0.125] and env.sim.ws.act_u.tolist() == env._u.tolist()


@pytest.mark.parametrize("name", MODELS)
def test_motion_under_tendon_motors_matches_mujoco(name):
    source = MODELS[name]
    mm = mujoco_model(source)
    dt = float(mm.opt.timestep)
    worst = 0.0
    for qp, qv, u in random_cases(mm, 6, np.random.default_rng(7)):
        exact, rows = mujoco_qvel(mm, qp, qv, u, 1e-5, mujoco.mjtIntegrator.mjINT_RK4)
        euler, more = mujoco_qvel(mm, qp, qv, u, dt, mujoco.mjtIntegrator.mjINT_EULER)
        coarse, touched = our_qvel(source, qp, qv, u, dt)
        fine, touched_fine = our_qvel(source, qp, qv, u, dt / 10)
        assert rows + more == 0 and not touched and not touched_fine     # no limit reached
        ours = np.abs(coarse - exact).max()
        theirs = np.abs(euler - exact).max()
        finer = np.abs(fine - exact).max()
        worst = max(worst, ours / theirs)
        assert ours <= RATIO[name] * theirs, (ours, theirs)
        assert 5.0 * finer <= max(ours, theirs), (finer, ours, theirs)
    print(f"{name}: worst error over MuJoCo Euler's {worst:.3f}")


@pytest.mark.parametrize("name", ["point_mass", "turned point_mass"])
def test_point_mass_pushed_into_the_walls_stays_within_its_slides_range(name):
    """Full control toward a corner for 1 s from near the middle: the slides reach their
    limits (+-0.29 m) and stay within them to 1e-9 m; pulled back, the mass leaves them."""
    env = our_env(MODELS[name])
    mm = mujoco_model(MODELS[name])
    lo, hi = mm.jnt_range.T
    env.set_state(np.array([0.2, -0.2]), np.array([0.5, -0.5]))
    # the control whose generalized force points to the corner (+x, -y)
    push = np.sign(np.linalg.solve(
        np.array([[a.gains[a.joints.index(j)] if j in a.joints else 0.0 for a in env._act]
                  for j in ("root_x", "root_y")]), [1.0, -1.0]))
    reached = False
    for _ in range(50):
        env.do_simulation(push, 1)
        assert np.all(env.data.qpos >= lo - LIMIT_TOL) and np.all(env.data.qpos <= hi + LIMIT_TOL)
        reached |= bool(env.sim.state.limit_active.any(axis=1).all())   # both slides
    assert reached and np.allclose(env.data.qpos, (hi[0], lo[1]), rtol=0, atol=LIMIT_TOL)
    for _ in range(25):
        env.do_simulation(-push, 1)
    assert np.all(np.abs(env.data.qpos) < 0.29 - 1e-3)


GOOD = "<fixed name='t'><joint joint='root_x' coef='1'/></fixed>"


def with_tendon(tendon, defaults="", motor="<motor tendon='t'/>"):
    """point_mass.xml with its <tendon> section (line 34 on) replaced by `tendon` (the
    <fixed> element on line 35) and its actuators by `motor` (line 37)."""
    text = POINT_MASS.read_text()
    head = text[:text.index("<tendon>")].replace("<default>", "<default>" + defaults)
    return head + f"<tendon>\n{tendon}\n</tendon>\n<actuator>{motor}</actuator>\n</mujoco>"


@pytest.mark.parametrize("tendon, defaults, match", [
    ("<fixed name='t' limited='true' range='-1 1'><joint joint='root_x' coef='1'/></fixed>", "",
     r"<fixed name='t'> \(line 35\): limited='true' with range='-1 1': tendon limits are "
     r"not supported"),
    ("<fixed name='t' range='-1 1'><joint joint='root_x' coef='1'/></fixed>", "",
     r"<fixed name='t'> \(line 35\): limited='auto' with range='-1 1'"),
    ("<fixed name='t' stiffness='3'><joint joint='root_x' coef='1'/></fixed>", "",
     r"<fixed name='t'> \(line 35\): stiffness='3' changes physics"),
    ("<fixed name='t' damping='0.5'><joint joint='root_x' coef='1'/></fixed>", "",
     r"<fixed name='t'> \(line 35\): damping='0.5' changes physics"),
    ("<fixed name='t' frictionloss='0.1'><joint joint='root_x' coef='1'/></fixed>", "",
     r"<fixed name='t'> \(line 35\): frictionloss='0.1' changes physics"),
    ("<fixed name='t' springlength='0.2 0.2'><joint joint='root_x' coef='1'/></fixed>", "",
     r"<fixed name='t'> \(line 35\): springlength='0.2 0.2' changes physics"),
    ("<fixed name='t' margin='0.01'><joint joint='root_x' coef='1'/></fixed>", "",
     r"<fixed name='t'> \(line 35\): margin='0.01' changes physics"),
    (GOOD, "<tendon armature='0.2'/>",
     r"<fixed name='t'> \(line 35\): armature='0.2' changes physics"),
    ("<spatial name='t'><site site='a'/><site site='b'/></spatial>", "",
     r"<spatial name='t'> \(line 35\): spatial tendons .* are not supported; a fixed tendon"),
    ("<fixed name='t'></fixed>", "", r"<fixed name='t'> \(line 35\): tendon 't' has no <joint>"),
    ("<fixed name='t'><joint joint='root_x'/></fixed>", "",
     r"<joint> \(line 35\): attribute 'coef' is required"),
    ("<fixed name='t'><joint joint='root_x' coef='1'/><joint joint='root_x' coef='2'/></fixed>",
     "", r"<joint> \(line 35\): joint='root_x' is already in tendon 't'"),
    ("<fixed name='t'><joint joint='root_z' coef='1'/></fixed>", "",
     r"<joint> \(line 35\): joint='root_z' names no joint of the model"),
])
def test_tendon_physics_not_modelled_is_a_model_error_naming_it(tendon, defaults, match):
    with pytest.raises(ModelError, match=r"<string>:35: " + match):
        load_mjcf(with_tendon(tendon, defaults), assets=ASSETS)


@pytest.mark.parametrize("motor, match", [
    ("<motor name='m' tendon='nope'/>",
     r"tendon='nope' names no fixed tendon of the model \(\['t'\]\)"),
    ("<motor name='m' tendon='t' joint='root_x'/>",
     "a motor needs exactly one of joint= and tendon="),
])
def test_a_motor_on_an_unknown_tendon_is_a_model_error(motor, match):
    with pytest.raises(ModelError, match=r"<motor name='m'> \(line 37\): " + match):
        load_mjcf(with_tendon(GOOD, motor=motor), assets=ASSETS)


def test_drawn_tendon_attributes_are_ignored_and_reported():
    """rgba, width and material (a class's, for spatial tendons) and group draw only; a range
    without limits does nothing."""
    text = with_tendon("<fixed name='t' group='2' limited='false' range='-1 1'>"
                       "<joint joint='root_x' coef='1'/></fixed>",
                       defaults="<tendon rgba='1 0 0 1' width='0.01' material='self'/>")
    rep = load_mjcf(text, assets=ASSETS).report
    for what in ("fixed rgba", "fixed width", "fixed material", "fixed group",
                 "fixed range (not limited)"):
        assert rep.ignored.get(what) == [35], (what, rep.ignored)
