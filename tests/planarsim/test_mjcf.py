"""MJCF loader: legs.xml (the SIMBICON character) reproduces its masses, joints and ranges; mass
properties match closed forms; malformed or unsupported input names the element and line."""
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import planarsim as ps
from planarsim import ModelError
from planarsim.mjcf import load_mjcf

LEGS = Path("/work/shared/reference/legs.xml")
if not LEGS.exists():
    LEGS = Path(__file__).resolve().parents[2] / "walkers" / "simbicon" / "legs.xml"


def capsule_inertia(m, r, L):
    """Perpendicular inertia of a solid capsule (cylinder + 2 hemispheres), by volume split."""
    vc, vh = math.pi * r * r * L, 4 / 3 * math.pi * r ** 3
    mc, mh = m * vc / (vc + vh), m * vh / (vc + vh)
    return mc * (r * r / 4 + L * L / 12) + mh * (83 / 320 * r * r + (L / 2 + 3 * r / 8) ** 2)


@pytest.fixture(scope="module")
def legs():
    return load_mjcf(LEGS)


def test_legs_masses_match_table_2(legs):
    # Table 2: torso 15, thigh 7, shin 5, foot 1, hip/knee/ankle spheres 0.5 kg
    m = legs.compile()
    assert m.total_mass == pytest.approx(15 + 2 * (7 + 5 + 1 + 3 * 0.5), abs=1e-12)
    expect = {"base": 16.0, "right_thigh": 7.5, "right_shin": 5.5, "right_foot": 1.0,
              "left_thigh": 7.5, "left_shin": 5.5, "left_foot": 1.0}
    for name, mass in expect.items():
        assert m.arrays.body_mass[m.body(name)] == pytest.approx(mass, abs=1e-12)
    # welded bodies map onto their rigid parent
    assert legs.body["right_hip"] == legs.body["base"]
    assert legs.body["left_knee"] == legs.body["left_thigh"]
    assert legs.body["right_ankle"] == legs.body["right_shin"]
    assert legs.free_joints == ("ignorex", "ignorez", "ignorey")


def test_legs_com_and_inertia_closed_form(legs):
    m = legs.compile()
    # thigh: capsule 7 kg centred at z = -0.65 (L = 0.3, r = 0.05) + knee sphere 0.5 kg at -0.8
    i = m.body("right_thigh")
    com = (7 * -0.65 + 0.5 * -0.8) / 7.5
    assert m.q0[i, 1] == pytest.approx(com, abs=1e-12)
    inertia = (capsule_inertia(7, 0.05, 0.3) + 7 * (com + 0.65) ** 2
               + 0.4 * 0.5 * 0.01 + 0.5 * (com + 0.8) ** 2)
    assert m.arrays.body_inertia[i] == pytest.approx(inertia, rel=1e-12)
    # torso: box 15 kg (0.2 x 0.8 m) + two hip spheres at z = -0.4
    b = m.body("base")
    com = 1.0 * -0.4 / 16
    assert m.q0[b, 1] == pytest.approx(com, abs=1e-12)
    inertia = 15 * (0.2 ** 2 + 0.8 ** 2) / 12 + 15 * com ** 2 + 2 * (0.4 * 0.5 * 0.01 + 0.5 * (0.4 + com) ** 2)
    assert m.arrays.body_inertia[b] == pytest.approx(inertia, rel=1e-12)
    # foot: box 1 kg, 0.3 x 0.15 m, centre (0.15, -1.2)
    f = m.body("left_foot")
    assert tuple(m.q0[f, :2]) == pytest.approx((0.15, -1.2), abs=1e-12)
    assert m.arrays.body_inertia[f] == pytest.approx((0.3 ** 2 + 0.15 ** 2) / 12, rel=1e-12)


def test_legs_joint_positions_ranges_and_passive_terms(legs):
    m = legs.compile()
    a = m.arrays
    # (joint, parent, child, world position (x, z), range in our sign [deg])
    expect = [("right_hip_to_right_thigh", "base", "right_thigh", (0, -0.4), (-90, 90)),
              ("right_knee_to_right_shin", "right_thigh", "right_shin", (0, -0.8), (-90, 0)),
              ("right_ankle_to_right_foot", "right_shin", "right_foot", (0, -1.2), (-90, 15)),
              ("left_hip_to_left_thigh", "base", "left_thigh", (0, -0.4), (-90, 90)),
              ("left_thigh_to_left_shin", "left_thigh", "left_shin", (0, -0.8), (-90, 0)),
              ("left_ankle_to_left_foot", "left_shin", "left_foot", (0, -1.2), (-90, 15))]
    assert len(legs.pin) == 6 and m.n_pin == 6 + len(legs.free_joints)   # + the root's coordinates
    for name, parent, child, pos, rng in expect:
        j = m.pin(name)
        assert tuple(a.pin_body[j]) == (m.body(parent), m.body(child))
        for side in range(2):
            body = a.pin_body[j, side]
            world = m.q0[body, :2] + a.pin_anchor[j, side]   # build pose: all angles zero
            assert tuple(world) == pytest.approx(pos, abs=1e-12)
        assert tuple(np.degrees(a.pin_limit[j])) == pytest.approx(rng, abs=1e-12)
        # <default><joint stiffness="5" damping="5"/> applies to the leg hinges
        assert a.pin_stiffness[j] == 5.0 and a.pin_damping[j] == 5.0


def test_a_joints_armature_loads_unless_dropped():
    """<joint armature> goes to the reflected inertia of every kind of joint coordinate (a
    free root's slides and hinge, a hinge, a slide); drop={"armature"} loads the file without
    any and says so in the report (the line of each armature left out)."""
    xml = """<mujoco><worldbody><body name="root" pos="0 0 1">
      <joint name="rx" type="slide" axis="1 0 0" armature="0.1"/>
      <joint name="rz" type="slide" axis="0 0 1" armature="0.2"/>
      <joint name="ry" type="hinge" axis="0 1 0" armature="0.3"/>
      <geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.05" mass="1"/>
      <body name="shin" pos="0 0 -0.5">
        <joint name="knee" type="hinge" axis="0 1 0" armature="0.4"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.05" mass="1"/>
        <body name="foot" pos="0 0 -0.5">
          <joint name="piston" type="slide" axis="0 0 1" armature="0.5"/>
          <geom type="sphere" size="0.05" mass="1"/>
        </body></body></body></worldbody></mujoco>"""
    kept = load_mjcf(xml)
    assert sorted(kept.compile().arrays.pin_armature) == pytest.approx([0.1, 0.2, 0.3, 0.4, 0.5])
    assert not kept.report.dropped
    dropped = load_mjcf(xml, drop={"armature"})
    assert not dropped.compile().arrays.pin_armature.any()
    assert sorted(dropped.report.dropped["joint armature"]) == [2, 3, 4, 7, 10]


def test_hinge_sign_follows_the_axis():
    """A hinge about +y turns x toward -z (clockwise in our plane): a knee flexion that moves
    the foot backward (-x) is a positive MJCF angle and a negative pin angle."""
    xml = """<mujoco><compiler coordinate="global"/><worldbody><body name="a">
      <joint type="hinge" axis="0 {s} 0" pos="0 0 0" range="0 90"/>
      <geom type="capsule" fromto="0 0 0 0 0 -1" size="0.05" mass="1"/></body></worldbody></mujoco>"""
    m_pos = load_mjcf(xml.format(s=1)).compile()
    m_neg = load_mjcf(xml.format(s=-1)).compile()
    assert tuple(np.degrees(m_pos.arrays.pin_limit[0])) == pytest.approx((-90, 0))
    assert tuple(np.degrees(m_neg.arrays.pin_limit[0])) == pytest.approx((0, 90))


def test_falling_legs_keep_their_pins(legs):
    """Loaded model runs: a ragdoll (no contacts) keeps pins closed and limits held."""
    m = legs.compile()
    sim = ps.Simulator(m)
    sim.steps(300)
    a = m.arrays
    for j in legs.pin.values():
        ba, bb = a.pin_body[j]
        q = sim.state.q
        pa = q[ba, :2] + _rot(q[ba, 2]) @ a.pin_anchor[j, 0]
        pb = q[bb, :2] + _rot(q[bb, 2]) @ a.pin_anchor[j, 1]
        assert np.hypot(*(pa - pb)) < 1e-9
        ang = q[bb, 2] - q[ba, 2] - a.pin_ref[j]
        assert a.pin_limit[j, 0] - 1e-6 <= ang <= a.pin_limit[j, 1] + 1e-6


def _rot(th):
    c, s = math.cos(th), math.sin(th)
    return np.array([[c, -s], [s, c]])


@pytest.mark.parametrize("xml, match", [
    ("<mujoco><worldbody><body name='a'>\n<geom type='sphere' size='0.1'/>\n</body>",
     r"malformed XML.*line 3"),
    ("<mujoco><compiler coordinate='global'/><worldbody>\n<body name='a'>\n"
     "<joint type='hinge' axis='0 1 0'/><geom type='mesh' size='0.1 0.2' mass='1'/></body></worldbody></mujoco>",
     r"line 3.*type='mesh' is not supported"),
    ("<mujoco><compiler coordinate='global'/><worldbody>\n<body name='a'>\n"
     "<joint type='hinge' axis='0 1 0'/><geom type='sphere' size='0.1' mass='1' spin='0 0 1'/></body></worldbody></mujoco>",
     r"<geom> \(line 3\).*\['spin'\] not supported"),
    ("<mujoco><compiler coordinate='global'/>\n<deformable/><worldbody/></mujoco>",
     r"line 2.*<deformable> is not supported inside <mujoco>"),
    ("<mujoco><compiler coordinate='polar'/><worldbody/></mujoco>",
     r"coordinate='polar' must be 'local' or 'global'"),
    ("<mujoco><compiler coordinate='global'/><worldbody><body name='a'>\n"
     "<joint type='hinge' axis='0 1 0'/>\n<geom type='sphere' size='0.1' mass='1'/>\n"
     "<body name='b'><joint name='k' type='hinge' axis='1 0 0'/>\n"
     "<geom type='sphere' size='0.1' mass='1'/></body></body></worldbody></mujoco>",
     r"<string>:4: <joint name='k'> \(line 4\).*must be \(0, \+-1, 0\)"),
    ("<mujoco><compiler coordinate='global'/><worldbody><body name='a'>\n"
     "<joint type='hinge' axis='0 1 0'/>\n<geom type='sphere' size='0.1' mass='-2'/>"
     "</body></worldbody></mujoco>",
     r"line 3.*mass=-2.0 must be > 0"),
    ("<mujoco><compiler coordinate='global'/><worldbody><body name='a'>\n"
     "<joint type='hinge' axis='0 1 0' range='30 10'/>\n<geom type='sphere' size='0.1'/>"
     "</body></worldbody></mujoco>",
     r"line 2.*lower > upper"),
    # a frame whose xyaxes are parallel: its rotation was NaN (numpy's warning, then "body
    # 'a' (0): inertia=nan must be finite" with no element nor line)
    ("<mujoco><worldbody><body name='a'>\n<joint type='hinge' axis='0 1 0'/>\n"
     "<geom type='box' size='0.1 0.1 0.1' xyaxes='1 0 0 2 0 0'/></body></worldbody></mujoco>",
     r"<geom> \(line 3\): xyaxes=\(1.0, 0.0, 0.0, 2.0, 0.0, 0.0\): its second vector must not "
     r"be zero or parallel"),
    # an <inertial> without mass: was "mass=-1.0 must be > 0", a number the file does not hold
    ("<mujoco><worldbody><body name='a'>\n<joint type='hinge' axis='0 1 0'/>\n"
     "<inertial pos='0 0 0' diaginertia='1 1 1'/></body></worldbody></mujoco>",
     r"<inertial> \(line 3\): attribute 'mass' is required"),
    # a negative armature: was the builder's "pin 'j' (0)", without the element and line
    ("<mujoco><worldbody><body name='a'>\n<joint name='j' type='hinge' axis='0 1 0' "
     "armature='-1'/>\n<geom type='sphere' size='0.1'/></body></worldbody></mujoco>",
     r"<joint name='j'> \(line 2\): armature=-1.0 must be >= 0"),
])
def test_bad_files_name_element_and_line(xml, match):
    with pytest.raises(ModelError, match=match):
        load_mjcf(xml)


LEG = ("<mujoco><worldbody><body name='a' pos='0 0 1'><joint type='hinge' axis='0 1 0'/>"
       "<geom type='sphere' size='0.1'/></body></worldbody></mujoco>")


@pytest.mark.parametrize("kw, error, match", [
    # offset (1,) was broadcast to (1, 1): the model moved up as well, silently
    (dict(offset=(1.0,)), ModelError, r"load_mjcf: offset=\(1.0,\) must be a pair \(x, y\)"),
    (dict(offset=(1.0, 2.0, 3.0)), ModelError, r"load_mjcf: offset=\(1.0, 2.0, 3.0\) must be a pair"),
    # a NaN offset was named as the first body's pos
    (dict(offset=(float("nan"), 0.0)), ModelError, r"load_mjcf: offset=\(nan, 0.0\) must be finite"),
    # drop="armature" was read letter by letter: drop=['a', 'a', 'e', 'm', ...] names [...]
    (dict(drop="armature"), TypeError, r"load_mjcf: drop='armature' must be a list of names"),
    # builder=5: AttributeError: 'int' object has no attribute 'dt'
    (dict(builder=5), TypeError, r"load_mjcf: builder=5 must be a planarsim ModelBuilder"),
])
def test_bad_load_arguments_are_named(kw, error, match):
    with pytest.raises(error, match=match):
        load_mjcf(LEG, **kw)


def test_xml_text_with_a_byte_order_mark_is_read_as_text(tmp_path):
    """The bytes of a file saved with a UTF-8 byte order mark (some editors write one), or its
    text read with encoding='utf-8', were taken for a path: "cannot read MJCF file
    '\\ufeff<mujoco>...': No such file or directory"."""
    path = tmp_path / "leg.xml"
    path.write_text(LEG, encoding="utf-8-sig")
    for source in (path, path.read_bytes(), path.read_text(encoding="utf-8")):
        assert load_mjcf(source).compile().n_body == 1
    xml = LEG.replace("<mujoco>", "<mujoco><include file='more.xml'/>")
    more = "<mujoco><option timestep='0.002'/></mujoco>".encode("utf-8-sig")
    assert load_mjcf(xml, assets={"more.xml": more}).compile().arrays.dt == 0.002


def test_missing_file_is_a_model_error(tmp_path):
    with pytest.raises(ModelError, match="cannot read MJCF file"):
        load_mjcf(tmp_path / "nope.xml")


@settings(max_examples=30, deadline=None)
@given(r=st.floats(0.01, 0.3), length=st.floats(0.01, 2.0), mass=st.floats(0.1, 50.0),
       tilt=st.floats(-math.pi, math.pi))
def test_capsule_inertia_matches_closed_form_in_any_plane_direction(r, length, mass, tilt):
    """A capsule lying anywhere in the x-z plane has the perpendicular inertia of the closed
    form (rotation invariance of the 2D inertia)."""
    dx, dz = length * math.cos(tilt), length * math.sin(tilt)
    xml = (f"<mujoco><compiler coordinate='global'/><worldbody><body name='a'>"
           f"<joint type='hinge' axis='0 1 0'/><geom type='capsule' size='{r!r}' mass='{mass!r}' "
           f"fromto='0 0 0 {dx!r} 0 {dz!r}'/></body></worldbody></mujoco>")
    m = load_mjcf(xml).compile()
    assert m.arrays.body_inertia[0] == pytest.approx(capsule_inertia(mass, r, length), rel=1e-9)
    assert tuple(m.q0[0, :2]) == pytest.approx((dx / 2, dz / 2), abs=1e-12)


def test_empty_sources_and_zero_sizes_are_named_plainly():
    """load_mjcf("") says the source is empty (not "'.': Is a directory"); a zero-size geom's
    message prints its numbers, not numpy's reprs."""
    with pytest.raises(ModelError, match="the source is empty"):
        load_mjcf("")
    with pytest.raises(ModelError, match="the source is empty"):
        load_mjcf("   ")
    xml = """<mujoco><worldbody><body name="b"><joint type="hinge" axis="0 1 0"/>
             <geom type="capsule" size="0" fromto="0 0 0 0.1 0 0"/></body></worldbody></mujoco>"""
    with pytest.raises(ModelError) as err:
        load_mjcf(xml)
    assert "size=(0.0,)" in str(err.value) and "np.float64" not in str(err.value)


@pytest.mark.parametrize("attrs, text", [
    ('diaginertia="-3 1 -3"', "not positive definite"),
    ('fullinertia="1 1 1 5 5 5"', "not positive definite"),
    ('diaginertia="1 1 1" fullinertia="1 1 1 0 0 0"', "not both"),
])
def test_inertia_that_mujoco_refuses_is_refused(attrs, text):
    """Out-of-plane inertia that MuJoCo's compiler refuses was taken silently (only the plane's
    moment is used, but the file describes no body)."""
    from planarsim.mjcf import load_mjcf
    xml = ('<mujoco><worldbody><body name="b" pos="0 0 1"><joint name="j" type="hinge" '
           f'axis="0 1 0"/><inertial pos="0 0 0" mass="1" {attrs}/></body></worldbody></mujoco>')
    with pytest.raises(ps.ModelError, match=text):
        load_mjcf(xml)
