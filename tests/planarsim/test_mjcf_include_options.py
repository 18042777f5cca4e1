"""MJCF <include>, <option><flag>, the plane of motion from slides, walls and the world's own
geoms: what the loader makes of them, the errors that name the culprit, and the motion
against MuJoCo where the flags change physics."""
import math
from pathlib import Path

import numpy as np
import pytest

import planarsim as ps
from planarsim import ModelError
from planarsim.mjcf import load_mjcf

mujoco = pytest.importorskip("mujoco", reason="mujoco is not installed (pip install -e '.[test]')")

BODY = ("<body name='arm' pos='0 0 1'><joint name='j' type='hinge' axis='0 1 0' range='-30 30' "
        "stiffness='4' damping='0.3'/><geom name='rod' type='capsule' fromto='0 0 0 0.5 0 0' "
        "size='0.05'/></body>")


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


# includes -------------------------------------------------------------------------------------
def test_nested_includes_resolve_next_to_the_including_file(tmp_path):
    """main.xml includes parts/a.xml (option, a default class), which includes b.xml next to
    itself (the arm, inside <worldbody>): the model is MuJoCo's."""
    write(tmp_path, "parts/b.xml", f"<mujoco>{BODY}</mujoco>")
    write(tmp_path, "parts/a.xml", "<mujoco>\n<option timestep='0.004'/>\n<asset><texture "
                                   "name='t' type='2d' builtin='checker' width='8' height='8'/>"
                                   "</asset></mujoco>")
    main = write(tmp_path, "main.xml", "<mujoco>\n<include file='parts/a.xml'/>\n<worldbody>"
                                       "<include file='parts/b.xml'/></worldbody></mujoco>")
    loaded = load_mjcf(main)
    mm = mujoco.MjModel.from_xml_path(str(main))
    model = loaded.compile()
    assert model.arrays.dt == mm.opt.timestep == 0.004
    assert model.arrays.body_mass[loaded.body["arm"]] == pytest.approx(mm.body_mass[1], rel=1e-12)
    assert loaded.report.ignored["<asset> in " + str(tmp_path / "parts/a.xml")] == [3]


def test_an_include_inside_an_included_file_looks_next_to_the_main_file_then_next_to_it(tmp_path):
    """MuJoCo's order: the main file's directory first, then the including file's."""
    write(tmp_path, "parts/inner.xml", "<mujoco><option timestep='0.003'/></mujoco>")
    write(tmp_path, "parts/outer.xml", "<mujoco><include file='inner.xml'/></mujoco>")
    main = write(tmp_path, "main.xml", f"<mujoco><include file='parts/outer.xml'/><worldbody>"
                                       f"{BODY}</worldbody></mujoco>")
    assert load_mjcf(main).compile().arrays.dt == 0.003             # only next to outer.xml
    assert mujoco.MjModel.from_xml_path(str(main)).opt.timestep == 0.003
    write(tmp_path, "inner.xml", "<mujoco><option timestep='0.007'/></mujoco>")
    assert load_mjcf(main).compile().arrays.dt == 0.007             # next to main.xml wins
    assert mujoco.MjModel.from_xml_path(str(main)).opt.timestep == 0.007


def test_a_missing_include_names_the_file_and_who_includes_it(tmp_path):
    write(tmp_path, "parts/outer.xml", "<mujoco>\n\n<include file='gone.xml'/></mujoco>")
    main = write(tmp_path, "main.xml", f"<mujoco><include file='parts/outer.xml'/><worldbody>"
                                       f"{BODY}</worldbody></mujoco>")
    outer = str(tmp_path / "parts" / "outer.xml")
    with pytest.raises(ModelError, match=rf"{outer}:3: <include> \(line 3\): included file "
                                         rf"'gone.xml' not found \(included by {outer}; "
                                         rf"looked in: {tmp_path / 'gone.xml'}; {tmp_path / 'parts' / 'gone.xml'}\)"):
        load_mjcf(main)


def test_an_include_cycle_is_an_error_naming_the_chain(tmp_path):
    write(tmp_path, "a.xml", "<mujoco><include file='b.xml'/></mujoco>")
    write(tmp_path, "b.xml", "<mujoco><include file='a.xml'/></mujoco>")
    main = write(tmp_path, "main.xml", f"<mujoco><include file='a.xml'/><worldbody>{BODY}"
                                       f"</worldbody></mujoco>")
    with pytest.raises(ModelError, match=r"includes itself: .*main.xml -> .*a.xml -> .*b.xml -> "
                                         r".*a.xml"):
        load_mjcf(main)


def test_includes_from_an_assets_dict_as_mujoco_takes_them():
    xml = (f"<mujoco><include file='./common/skybox.xml'/><include file='opts.xml'/>"
           f"<worldbody>{BODY}</worldbody></mujoco>")
    assets = {"common/skybox.xml": b"<mujoco><asset><texture name='s' type='skybox' "
                                   b"builtin='gradient' width='8' height='8'/></asset></mujoco>",
              "opts.xml": "<mujoco><option timestep='0.005' gravity='0 0 -3'/></mujoco>"}
    loaded = load_mjcf(xml, assets=assets)
    mm = mujoco.MjModel.from_xml_string(xml, {k: v.encode() if isinstance(v, str) else v
                                              for k, v in assets.items()})
    a = loaded.compile().arrays
    assert a.dt == mm.opt.timestep == 0.005 and tuple(a.gravity) == (0.0, -3.0)
    assert "<asset> in common/skybox.xml" in loaded.report.ignored
    with pytest.raises(ModelError, match=r"<string>:1: <include> \(line 1\): included file "
                                         r"'opts.xml' not found .*assets \['opts.xml'\] \(assets "
                                         r"has \['common/skybox.xml'\]\)"):
        load_mjcf(xml, assets={"common/skybox.xml": assets["common/skybox.xml"]})


def test_an_error_in_an_included_file_names_that_file_and_line(tmp_path):
    write(tmp_path, "body.xml", "<mujoco>\n<body name='b'><joint type='hinge' axis='0 1 0'/>\n"
                                "<geom type='mesh' mesh='m'/></body></mujoco>")
    main = write(tmp_path, "main.xml", "<mujoco><worldbody><include file='body.xml'/>"
                                       "</worldbody></mujoco>")
    with pytest.raises(ModelError, match=rf"^{tmp_path / 'body.xml'}:3: <geom> \(line 3\): "
                                         rf"attribute\(s\) \['mesh'\] not supported on <geom>"):
        load_mjcf(main)


# option flags ------------------------------------------------------------------------------------
PENDULUM = ("<mujoco><option timestep='{dt}'><flag {flags}/></option><worldbody>"
            "<geom name='floor' type='plane' size='5 5 .1'/>"
            "<body name='arm' pos='0 0 1'><joint name='j' type='hinge' axis='0 1 0' "
            "range='{range}' stiffness='6' damping='0.4'/><geom name='rod' type='capsule' "
            "fromto='0 0 0 0.5 0 0' size='0.05'/></body></worldbody></mujoco>")


def motion(xml, qp, qv, span=0.1):
    """(ours at dt 1e-4, MuJoCo RK4 at 1e-5): the hinge's (angle, speed) after span [s]."""
    pytest.importorskip("gymnasium", reason="planarsim.envs (the joint coordinates) needs gymnasium")
    from planarsim.envs.core import GeneralizedCoords
    from planarsim.state import make_state
    loaded = load_mjcf(xml.format(dt=1e-4))
    model = loaded.compile()
    coords = GeneralizedCoords(loaded, model)
    sim = ps.Simulator(model, None, make_state(model))
    sim.start_over(*coords.to_maximal([qp], [qv]))
    sim.steps(int(round(span / 1e-4)))
    p, v = coords.values(sim.state.q, sim.state.v)
    ours = (p[0], v[0])
    mm = mujoco.MjModel.from_xml_string(xml.format(dt=1e-5))
    mm.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    d = mujoco.MjData(mm)
    d.qpos[0], d.qvel[0] = qp, qv
    for _ in range(int(round(span / 1e-5))):
        mujoco.mj_step(mm, d)
    return np.array(ours), np.array([d.qpos[0], d.qvel[0]])


@pytest.mark.parametrize("flags", ["gravity='disable'", "spring='disable'", "damper='disable'",
                                   "limit='disable'", "constraint='disable'",
                                   "spring='disable' damper='disable' gravity='disable'"])
def test_flags_change_the_motion_as_in_mujoco(flags):
    """From 15 deg at 2 rad/s: planarsim at dt 1e-4 within 1 % of MuJoCo's exact motion after
    0.1 s; and the hinge moves differently without the flag (the flag did something: where
    it turns limits off, the hinge passes 20 deg, the limit it would stop at)."""
    limits = "limit" in flags or "constraint" in flags
    xml = PENDULUM.replace("{flags}", flags).replace("{range}", "-20 20" if limits else "-80 80")
    qp, qv = math.radians(15), 2.0
    ours, theirs = motion(xml, qp, qv)
    scale = np.abs(theirs).max()
    assert np.abs(ours - theirs).max() <= 0.01 * scale, (ours, theirs)
    if limits:
        assert theirs[0] > math.radians(20) + 0.01
    else:
        plain = mujoco.MjModel.from_xml_string(PENDULUM.format(dt=1e-5, flags="", range="-80 80"))
        d = mujoco.MjData(plain)
        d.qpos[0], d.qvel[0] = qp, qv
        for _ in range(10000):
            mujoco.mj_step(plain, d)
        assert abs(d.qvel[0] - theirs[1]) > 0.05 * scale


def test_flags_reach_the_model_arrays():
    loaded = load_mjcf(PENDULUM.format(dt=0.01, range="-20 20",
                                      flags="constraint='disable' spring='disable' "
                                            "gravity='disable' warmstart='disable' energy='enable'"))
    a = loaded.compile().arrays
    pid = loaded.pin["j"]
    assert tuple(a.gravity) == (0.0, 0.0)
    assert tuple(a.pin_limit[pid]) == (-math.inf, math.inf)
    assert a.pin_stiffness[pid] == 0.0 and a.pin_damping[pid] == 0.4
    assert not loaded.builder._collide                  # the rod would touch the floor
    rep = loaded.report
    assert rep.ignored["option flag warmstart='disable'"] == [1]
    assert rep.ignored["option flag energy='enable'"] == [1]
    assert any(n.startswith("contacts are off") for n in rep.notes)


@pytest.mark.parametrize("flags, match", [
    ("clampctrl='disable'", r"flag clampctrl='disable' is not supported: MuJoCo would then pass "
                            r"controls outside ctrlrange"),
    ("actuation='disable'", r"flag actuation='disable' is not supported"),
    ("sleep='enable'", r"flag sleep='enable' is not supported"),
    ("override='enable'", r"flag override='enable' is not supported"),
    ("passive='disable'", r"flag passive='disable' is not one of MuJoCo's flags"),
    ("gravity='off'", r"flag gravity='off' must be 'enable' or 'disable'"),
])
def test_flags_without_planarsim_physics_are_errors_naming_the_flag(flags, match):
    xml = PENDULUM.format(dt=0.01, flags=flags, range="-20 20").replace("<flag", "\n<flag")
    with pytest.raises(ModelError, match=r"<string>:2: <flag> \(line 2\): " + match):
        load_mjcf(xml)


def test_override_loads_where_contacts_are_off():
    rep = load_mjcf(PENDULUM.format(dt=0.01, flags="override='enable' contact='disable'",
                                    range="-20 20")).report
    assert "option flag override='enable' (contacts are off)" in rep.ignored


def test_frictionloss_loads_onto_the_joint_unless_switched_off_and_a_negative_one_is_an_error():
    xml = PENDULUM.format(dt=0.01, flags="{f}", range="-20 20").replace(
        "damping='0.4'", "damping='0.4'\nfrictionloss='{v}'")
    loaded = load_mjcf(xml.format(f="", v="0.25"))
    assert loaded.compile().arrays.pin_frictionloss[loaded.joint["j"].coordinate] == 0.25
    assert load_mjcf(xml.format(f="", v="0")).compile().arrays.pin_frictionloss.max() == 0.0
    with pytest.raises(ModelError, match=r"<string>:1: <joint name='j'> \(line 1\): joint 'j' has "
                                         r"frictionloss=-0.25: it must be >= 0"):
        load_mjcf(xml.format(f="", v="-0.25"))
    for off in ("frictionloss='disable'", "constraint='disable'"):
        loaded = load_mjcf(xml.format(f=off, v="0.25"))
        assert any(k.startswith("joint frictionloss") for k in loaded.report.ignored)
        assert loaded.compile().arrays.pin_frictionloss.max() == 0.0


def test_filterparent_disabled_is_an_error_where_parent_and_child_may_touch():
    xml = ("<mujoco><option><flag filterparent='disable'/></option><worldbody>"
           "<body name='a' pos='0 0 1'><joint name='ja' type='hinge' axis='0 1 0'/>"
           "<geom name='ga' type='sphere' size='0.1' contype='{c}'/>"
           "<body name='b' pos='0.15 0 0'><joint name='jb' type='hinge' axis='0 1 0'/>"
           "<geom name='gb' type='sphere' size='0.1' contype='{c}'/></body></body>"
           "</worldbody></mujoco>")
    with pytest.raises(ModelError, match=r"filterparent='disable' lets geoms 'gb' \(body 'b'\) and "
                                         r"'ga' \(its parent 'a'\) collide in MuJoCo"):
        load_mjcf(xml.format(c=1))
    rep = load_mjcf(xml.format(c=0)).report
    assert any(k.startswith("option flag filterparent") for k in rep.ignored)


# plane of motion, walls, world geoms ------------------------------------------------------------
@pytest.mark.parametrize("axes, plane", [(("1 0 0", "0 1 0"), "x-y"), (("1 0 0", "0 0 1"), "x-z"),
                                         (("0 1 0",), "x-y"), (("1 0 0",), "x-z")])
def test_the_plane_of_motion_follows_the_slides_without_hinges(axes, plane):
    joints = "".join(f"<joint name='s{i}' type='slide' axis='{a}'/>" for i, a in enumerate(axes))
    xml = (f"<mujoco><worldbody><body name='p' pos='0 0 0.5'>{joints}"
           f"<geom type='sphere' size='0.05' contype='0' conaffinity='0'/></body></worldbody></mujoco>")
    assert load_mjcf(xml).plane == plane


def settle(xml, seconds):
    """(our body's in-plane position, MuJoCo's qpos) after `seconds` of each at the file's dt."""
    loaded = load_mjcf(xml)
    model = loaded.compile()
    sim = ps.Simulator(model)
    sim.steps(int(round(seconds / model.arrays.dt)))
    mm = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(mm)
    for _ in range(int(round(seconds / mm.opt.timestep))):
        mujoco.mj_step(mm, d)
    return loaded, sim.state.q[loaded.root, :2].copy(), d.qpos.copy()


@pytest.mark.parametrize("normal, pos, gravity, at", [
    ("1 0 0", "-1 0 0", "-9.81 0 0", (-0.9, 1.0)),       # a wall on the left
    ("-1 0 0", "1 0 0", "9.81 0 0", (0.9, 1.0)),         # on the right
    ("0 0 -1", "0 0 2", "0 0 9.81", (0.0, 1.9)),         # a ceiling
])
def test_a_plane_whose_normal_lies_in_the_plane_of_motion_is_a_wall(normal, pos, gravity, at):
    """A disk (radius 0.1) on a free root pushed by gravity into a wall rests against it where
    MuJoCo's (soft, a few mm into it) does."""
    xml = (f"<mujoco><option timestep='0.002' gravity='{gravity}'/><worldbody>"
           f"<geom name='wall' type='plane' pos='{pos}' zaxis='{normal}' size='1 1 .1'/>"
           f"<body name='disk' pos='0 0 1'><joint name='x' type='slide' axis='1 0 0'/>"
           f"<joint name='z' type='slide' axis='0 0 1'/><joint name='r' type='hinge' "
           f"axis='0 1 0'/><geom name='disk' type='sphere' size='0.1'/></body>"
           f"</worldbody></mujoco>")
    loaded, ours, theirs = settle(xml, 1.0)
    assert np.abs(ours - at).max() <= 1e-6, ours
    assert np.abs(np.array([theirs[0], 1.0 + theirs[1]]) - at).max() <= 5e-3, theirs
    assert any("is a wall" in n for n in loaded.report.notes)


def test_walls_with_contacts_on_in_the_x_y_plane():
    """reacher's arena with contacts on: its arm's tip, turned by a spring toward the wall at
    x = 0.3, stops there (the tip sphere touches the wall plane as in MuJoCo)."""
    xml = ("<mujoco><option timestep='0.002'/><worldbody>"
           "<geom name='wall_neg_x' type='plane' pos='.3 0 .02' zaxis='-1 0 0' size='.02 .3 .02'/>"
           "<body name='arm' pos='0 0 .01'><joint name='j' type='hinge' axis='0 0 1' stiffness='1' "
           "springref='0' ref='90' damping='0.05'/><geom name='arm' type='capsule' "
           "fromto='0 0 0 0 0.35 0' size='.01' contype='0' conaffinity='0'/>"
           "<geom name='tip' type='sphere' pos='0 0.35 0' size='.02'/></body></worldbody></mujoco>")
    loaded, _, theirs = settle(xml, 1.5)
    model = loaded.compile()
    sim = ps.Simulator(model)
    sim.steps(750)
    tip = sim.state.q[loaded.root]
    # the tip's centre: 0.35 m from the hinge at the body's angle
    mm = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(mm)
    d.qpos[:] = theirs
    mujoco.mj_forward(mm, d)
    tip_mj = d.geom_xpos[mujoco.mj_name2id(mm, mujoco.mjtObj.mjOBJ_GEOM, "tip")]
    assert abs(tip_mj[0] - 0.28) <= 5e-3                # MuJoCo: against the wall
    angle = tip[2] - model.q0[loaded.root, 2] + math.pi / 2
    ours_x = 0.35 * math.cos(angle)
    assert abs(ours_x - 0.28) <= 1e-6, ours_x


def test_geoms_directly_under_worldbody_collide():
    """A box directly under <worldbody> (no body of its own) is a static shape: a disk drops
    onto it and rests on its top (they were silently left out)."""
    xml = ("<mujoco><option timestep='0.002'/><worldbody>"
           "<geom name='ledge' type='box' pos='0 0 0.5' size='1 1 0.1'/>"
           "<body name='disk' pos='0 0 1'><joint name='x' type='slide' axis='1 0 0'/>"
           "<joint name='z' type='slide' axis='0 0 1'/><joint name='r' type='hinge' axis='0 1 0'/>"
           "<geom name='disk' type='sphere' size='0.1'/></body></worldbody></mujoco>")
    _, ours, theirs = settle(xml, 1.0)
    assert abs(ours[1] - 0.7) <= 1e-6, ours
    assert abs(1.0 + theirs[1] - 0.7) <= 5e-3, theirs


def test_separate_trees_collide_and_are_not_noted_as_missed_self_collisions():
    """finger's layout: two trees hinged to the world (a finger and a spinner) collide in
    planarsim as in MuJoCo, so the report does not list them among the pairs it misses."""
    xml = ("<mujoco><worldbody>"
           "<body name='a' pos='-0.2 0 1'><joint name='ja' type='hinge' axis='0 1 0'/>"
           "<geom name='ga' type='capsule' fromto='0 0 0 0.2 0 0' size='0.05'/></body>"
           "<body name='b' pos='0.2 0 1'><joint name='jb' type='hinge' axis='0 1 0'/>"
           "<geom name='gb' type='capsule' fromto='0 0 0 -0.2 0 0' size='0.05'/>"
           "<body name='c' pos='0 0 0.3'><joint name='jc' type='hinge' axis='0 1 0'/>"
           "<geom name='gc' type='sphere' size='0.05'/></body></body></worldbody></mujoco>")
    loaded = load_mjcf(xml)
    model = loaded.compile()
    assert model.arrays.n_shape_pair == 2               # a-b and a-c (b-c: parent and child)
    assert not any("may touch" in n for n in loaded.report.notes)
