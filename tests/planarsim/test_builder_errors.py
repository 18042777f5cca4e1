"""The builder rejects bad models with a ModelError naming the culprit."""
import math

import numpy as np
import pytest

import planarsim as ps
from planarsim import ModelError, terrain


def base():
    b = ps.ModelBuilder(dt=1e-3)
    b.add_body("torso", mass=10.0, inertia=1.0, pos=(0.0, 1.0))
    return b


@pytest.mark.parametrize("kw, pattern", [
    (dict(mass=-1.0, inertia=1.0), r"body 'shin_L' \(1\): mass=-1.0 must be finite and > 0"),
    (dict(mass=0.0, inertia=1.0), r"body 'shin_L' \(1\): mass=0.0 must be finite and > 0"),
    (dict(mass=float("nan"), inertia=1.0), r"body 'shin_L' \(1\): mass=nan must be finite"),
    (dict(mass=1.0, inertia=-0.1), r"body 'shin_L' \(1\): inertia=-0.1 must be finite and > 0"),
    (dict(mass=1.0, inertia=0.0), r"body 'shin_L' \(1\): inertia=0.0 must be finite and > 0"),
    (dict(mass=1.0, inertia=1.0, pos=(0.0, math.inf)), r"body 'shin_L' \(1\): pos=.* must be finite"),
    (dict(mass=1.0, inertia=1.0, omega=float("nan")), r"body 'shin_L' \(1\): omega=nan must be finite"),
])
def test_bad_body(kw, pattern):
    with pytest.raises(ModelError, match=pattern):
        base().add_body("shin_L", **kw)


def test_point_mass_of_zero_mass():
    with pytest.raises(ModelError, match=r"body 'foot' \(1\): mass=0.0 must be finite and > 0"):
        base().add_point_mass("foot", 0.0)


def test_duplicate_names():
    b = base()
    with pytest.raises(ModelError, match=r"body 'torso' \(1\): duplicate name"):
        b.add_body("torso", mass=1.0, inertia=1.0)
    b.add_body("leg", mass=1.0, inertia=1.0, pos=(0.0, 0.5))
    b.add_pin("hip", "torso", "leg", anchor_world=(0.0, 0.75))
    with pytest.raises(ModelError, match=r"pin 'hip' \(1\): duplicate name"):
        b.add_pin("hip", "torso", "leg", anchor_world=(0.0, 0.75))


def test_joint_to_missing_body():
    with pytest.raises(ModelError, match=r"pin 'knee' \(0\): body_b='shin' names no body"):
        base().add_pin("knee", "torso", "shin", anchor_world=(0.0, 0.0))
    with pytest.raises(ModelError, match=r"pin 'knee' \(0\): body_b=7 is not a body id"):
        base().add_pin("knee", 0, 7, anchor_world=(0.0, 0.0))


def test_pin_anchors_apart():
    b = base()
    b.add_body("leg", mass=1.0, inertia=1.0, pos=(0.0, 0.5))
    with pytest.raises(ModelError, match=r"pin 'hip' \(0\): anchors are 0.3 m apart"):
        b.add_pin("hip", "torso", "leg", anchor_a=(0.0, -0.2), anchor_b=(0.0, 0.0))


def test_rod_of_length_zero():
    b = base()
    b.add_point_mass("foot", 1.0, pos=(0.0, 0.0))
    with pytest.raises(ModelError, match=r"rod 'leg' \(0\): length=0.0 must be > 0"):
        b.add_rod("leg", "torso", "foot", length=0.0)


def test_limit_lower_above_upper():
    b = base()
    b.add_body("leg", mass=1.0, inertia=1.0, pos=(0.0, 0.5))
    with pytest.raises(ModelError, match=r"pin 'hip' \(0\): limit lower=1.0 > upper=-1.0"):
        b.add_pin("hip", "torso", "leg", anchor_world=(0.0, 0.75), limit=(1.0, -1.0))


def test_actuator_range_min_above_max():
    b = base()
    with pytest.raises(ModelError, match=r"actuator 'push' \(0\): limit=\(5.0, -5.0\) must have min <= max"):
        b.add_body_force("push", "torso", limit=(5.0, -5.0))


def test_negative_friction():
    with pytest.raises(ModelError, match=r"contact 'toe' \(0\): mu=-0.5 must be >= 0"):
        base().add_point_contact("toe", "torso", mu=-0.5)


@pytest.mark.parametrize("dt", [0.0, -1e-3, float("nan"), float("inf"), 5.0])
def test_bad_dt(dt):
    b = base()
    b.dt = dt
    with pytest.raises(ModelError, match=r"model: dt=.* must be a step in \(0, 1\] s"):
        b.compile()


def test_bad_terrain_coefficients():
    with pytest.raises(ModelError, match=r"terrain: amplitudes\[0\]=nan must be finite"):
        terrain.hills([float("nan")], [2.0])
    with pytest.raises(ModelError, match=r"wavelength=0.0 must be > 0"):
        terrain.hills([0.1], [0.0])
    with pytest.raises(ModelError, match=r"terrain spec 'bumpy' not understood"):
        terrain.parse("bumpy")


@pytest.mark.parametrize("make, said", [
    (lambda: terrain.slope("abc"), r"terrain: slope angle='abc' must be a number"),
    (lambda: terrain.slope(None), r"terrain: slope angle=None must be a number"),
    (lambda: terrain.slope(3.0, height=float("nan")), r"terrain: height=nan must be finite"),
    (lambda: terrain.flat("abc"), r"terrain: height='abc' must be a number"),
    (lambda: terrain.flat(float("inf")), r"terrain: height=inf must be finite"),
    (lambda: terrain.hills(["a"], [1.0]), r"terrain: amplitudes=\['a'\] must be a number or a list"),
    (lambda: terrain.hills([[0.1]], [[1.0]]), r"terrain: amplitudes=\[\[0.1\]\] must be a number or a list"),
    (lambda: terrain.hills([0.1], [1.0], phases=[float("inf")]), r"terrain: phases\[0\]=inf must be finite"),
    (lambda: terrain.hills([0.1], [1.0], grade="steep"), r"terrain: grade='steep' must be a number"),
    (lambda: terrain.parse(None), r"terrain spec None must be a string"),
])
def test_bad_terrain_arguments_are_named(make, said):
    """flat, slope, hills and parse name the argument that is not a (finite) number: not
    Python's or numpy's conversion error, nor an index into the coefficients."""
    with pytest.raises(ModelError, match=said):
        make()


def test_model_error_is_a_value_error():
    assert issubclass(ModelError, ValueError)


def test_valid_model_compiles_and_is_read_only():
    m = base().compile()
    assert m.n_body == 1
    with pytest.raises(ValueError):
        m.arrays.body_mass[0] = 2.0


# shapes: every mistake names the shape's body and its name= -----------------------------------
SQUARE = [(0.0, 0.0), (0.1, 0.0), (0.1, 0.1), (0.0, 0.1)]
NP0 = np.float64(0.0)


@pytest.mark.parametrize("kind, params, kw, words", [
    ("circle", ((0.0, 0.0),), {}, r"params=\(\(0.0, 0.0\),\) must be \(center, radius\)"),
    ("circle", ((0.0, 0.0), 0.1, 0.2), {}, r"must be \(center, radius\)"),
    ("circle", ((NP0, NP0), NP0), {}, r"radius=0.0 must be > 0 for a shape that collides"),
    ("circle", ((0.0, 0.0), -0.1), {}, r"radius=-0.1 must be >= 0"),
    ("circle", ((0.0, 0.0), "big"), {}, r"radius='big' must be a number"),
    ("circle", ((0.0, 0.0), math.inf), {}, r"radius=inf must be finite"),
    ("circle", (NP0, 0.1), {}, r"center=0.0 must be a pair \(x, y\)"),
    ("circle", ((NP0, math.nan), 0.1), {}, r"center=\[0.0, nan\] must be finite"),
    ("capsule", ((0.0, 0.0), (0.0, 0.0), 0.05), {}, r"p0 and p1 coincide; use a circle"),
    ("capsule", ((0.0, 0.0), (0.0, -0.3), 0.0), {}, r"radius=0.0 must be > 0 for a shape that collides"),
    ("box", ((0.0, 0.0), NP0, 0.1), {}, r"width=0.0 must be > 0"),
    ("box", ((0.0, 0.0), 0.1, -0.2), {}, r"height=-0.2 must be > 0"),
    ("box", ((0.0, 0.0), 0.1, 0.2, math.nan), {}, r"angle=nan must be finite"),
    ("box", ((0.0, 0.0), 0.1, 0.2, "flat"), {}, r"angle='flat' must be a number"),
    ("polygon", (3,), {}, r"vertices=3 must be a list of \(x, y\) pairs"),
    ("polygon", ([(0.0, 0.0), (1.0,), (1.0, 1.0)],), {}, r"vertices\[1\]=\(1.0,\) must be a pair"),
    ("polygon", ([(0.0, 0.0), (1.0, math.nan), (1.0, 1.0)],), {}, r"vertices\[1\]=\[1.0, nan\] must be finite"),
    ("polygon", ([(0.0, 0.0), (1.0, 0.0)],), {}, r"a polygon needs at least 3 vertices, got 2"),
    ("polygon", ([(0.0, 0.0), (0.0, 0.0), (1.0, 1.0)],), {}, r"vertices 0 and 1 coincide"),
    ("polygon", ([(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (1.0, 1.0)],), {}, r"lies on the line"),
    ("polygon", ([(0.0, 0.0), (2.0, 0.0), (1.0, 0.2), (1.0, 1.0)],), {}, r"not convex"),
    ("polygon", ([(math.cos(a), math.sin(a)) for a in np.arange(5) * 4 * math.pi / 5],), {},
     r"winds around 2 times"),
    ("blob", ((0.0, 0.0), 0.1), {}, r"kind='blob' must be one of"),
    ("circle", ((0.0, 0.0), 0.1), dict(collide="yes"), r"collide='yes' must be True or False"),
    ("circle", ((0.0, 0.0), 0.1), dict(ground=1), r"ground=1 must be True or False"),
    ("circle", ((0.0, 0.0), 0.1), dict(mu=-0.5), r"mu=-0.5 must be >= 0"),
    ("circle", ((0.0, 0.0), 0.1), dict(mu=math.nan), r"mu=nan must be finite"),
    ("circle", ((0.0, 0.0), 0.1), dict(restitution=1.5), r"restitution=1.5 must be in \[0, 1\]"),
    ("circle", ((0.0, 0.0), 0.1), dict(category=-1), r"category=-1 must be a non-negative integer"),
    ("circle", ((0.0, 0.0), 0.1), dict(mask=np.float64(2.0)), r"mask=2.0 must be a non-negative integer"),
])
@pytest.mark.parametrize("name", [None, "heel"])
def test_every_shape_mistake_names_its_body_and_name(kind, params, kw, words, name):
    b = base()
    b.add_body("shin_L", mass=1.0, inertia=0.1, pos=(0.0, 0.5))
    with pytest.raises(ModelError, match=words) as err:
        b.add_shape("shin_L", kind, *params, name=name, **kw)
    said = str(err.value)
    assert "np.float64" not in said
    shape = f"shape 'heel' ({kind} 0)" if name else f"{kind} shape (0)"
    assert said.startswith(f"{shape} of body 'shin_L': "), said
    # the same shape given with add_body(shapes=...)
    with pytest.raises(ModelError, match=words) as err:
        base().add_body("shin_L", mass=1.0, inertia=0.1, shapes=[(kind, *params, dict(kw, name=name))])
    assert str(err.value).startswith(f"{shape} of body 'shin_L': "), str(err.value)


def test_static_shape_mistakes_say_static():
    with pytest.raises(ModelError, match=r"^static shape 'ramp' \(box 0\): width=-1.0 must be > 0"):
        base().add_shape(None, "box", (0.0, 0.0), -1.0, 0.1, name="ramp")
    with pytest.raises(ModelError, match=r"^static circle shape \(0\): a static shape \(body None\) "
                                         r"must collide"):
        base().add_shape(None, "circle", (0.0, 0.0), 0.1, collide=False)


def test_a_shape_on_a_missing_body_names_the_body_given():
    with pytest.raises(ModelError, match=r"^shape 'heel' \(circle 0\): body='shin_L' names no body"):
        base().add_shape("shin_L", "circle", (0.0, 0.0), 0.1, name="heel")
    with pytest.raises(ModelError, match=r"^static circle shape \(0\): name=3 must be a non-empty"):
        base().add_shape(None, "circle", (0.0, 0.0), 0.1, name=3)


def test_vectors_in_messages_are_plain_numbers():
    """A vector the message quotes reads (0.5, 0.0), not (np.float64(0.5), np.float64(0.0))."""
    b = ps.ModelBuilder()
    p = b.add_point_mass("p", 1.0, pos=(0.0, 0.0))
    q = b.add_body("q", mass=1.0, inertia=0.1, pos=(1.0, 0.0))
    with pytest.raises(ModelError, match=r"anchor_a=\(0\.5, 0\.0\) must be \(0, 0\) on point mass 'p'"):
        b.add_pin("x", p, q, anchor_world=(0.5, 0.0))
    with pytest.raises(ModelError, match=r"axis=\(0\.0, 0\.0\) must not be zero"):
        b.add_slider("s", None, q, axis=(0.0, 0.0))


def test_a_rod_longer_or_shorter_than_its_build_pose_is_refused():
    """A rod given length 2 between anchors 0.5 m apart compiled, and its first step then
    stopped, blaming the step size."""
    b = ps.ModelBuilder(dt=1e-3)
    b.add_point_mass("a", 1.0, pos=(0.0, 1.0))
    b.add_point_mass("c", 1.0, pos=(0.5, 1.0))
    with pytest.raises(ModelError, match=r"rod 'r' \(0\): length=2 m, but its anchors are 0.5 m"):
        b.add_rod("r", "a", "c", length=2.0)
    b.add_rod("r2", "a", "c", length=0.5)         # (as built: fine)


@pytest.mark.parametrize("what, pattern", [
    ("axial_same", "the same body"), ("axial_coincide", "anchors coincide"),
    ("hip_same", "three different bodies"), ("torque_point", "is a point mass")])
def test_actuators_that_cannot_act_are_refused(what, pattern):
    """Each compiled and its commands did nothing."""
    b = ps.ModelBuilder(dt=1e-3)
    b.add_point_mass("p", 1.0, pos=(0.0, 1.0))
    b.add_point_mass("p2", 1.0, pos=(0.0, 1.0))
    b.add_point_mass("p3", 1.0, pos=(0.3, 0.5))
    with pytest.raises(ModelError, match=pattern):
        if what == "axial_same":
            b.add_axial("ax", "p", "p")
        elif what == "axial_coincide":
            b.add_axial("ax", "p", "p2")
        elif what == "hip_same":
            b.add_hip_torque("h", "p", "p3", "p3")
        else:
            b.add_body_torque("t", "p")


def motor_rig():
    """A torso, a leg pinned to it at the hip, and two point masses (a hip and a foot)."""
    b = base()
    b.add_body("leg", mass=1.0, inertia=0.1, pos=(0.0, 0.5))
    b.add_pin("hip", "torso", "leg", anchor_world=(0.0, 0.75))
    b.add_slider("rail", None, "leg", axis=(0.0, 1.0))
    b.add_point_mass("h", 1.0, pos=(0.0, 1.5))
    b.add_point_mass("fa", 1.0, pos=(-0.2, 1.0))
    b.add_point_mass("fb", 1.0, pos=(0.2, 1.0))
    return b


ACTUATORS = {
    "add_pin_motor": lambda b, limit: b.add_pin_motor("m", "hip", limit=limit),
    "add_slider_motor": lambda b, limit: b.add_slider_motor("m", "rail", limit=limit),
    "add_axial": lambda b, limit: b.add_axial("m", "h", "fa", limit=limit),
    "add_hip_torque": lambda b, limit: b.add_hip_torque("m", "h", "fa", "fb", limit=limit),
    "add_body_force": lambda b, limit: b.add_body_force("m", "torso", limit=limit),
    "add_body_torque": lambda b, limit: b.add_body_torque("m", "torso", limit=limit),
}


@pytest.mark.parametrize("limit, words", [
    (5, r"limit=5 must be a pair \(min, max\) of numbers"),
    ((1.0, 2.0, 3.0), r"limit=\(1.0, 2.0, 3.0\) must be a pair"),
    (None, r"limit=None must be a pair"),
    ((math.inf, math.inf), r"limit=\(inf, inf\) must have min < inf and max > -inf"),
    ((-math.inf, -math.inf), r"limit=\(-inf, -inf\) must have min < inf"),
    ((5, -5), r"limit=\(5.0, -5.0\) must have min <= max"),
    ((np.float64(math.nan), 1.0), r"limit=\(nan, 1.0\) must not be NaN"),
])
@pytest.mark.parametrize("method", sorted(ACTUATORS))
def test_actuator_limit_that_is_not_an_open_pair(method, limit, words):
    """limit=5 failed deep inside with "'int' object is not subscriptable", and (inf, inf) or
    (-inf, -inf) compiled: a motor whose every command saturates to an infinite force."""
    b = motor_rig()
    with pytest.raises(ModelError, match=r"^actuator 'm' \(0\): " + words) as err:
        ACTUATORS[method](b, limit)
    assert "np.float64" not in str(err.value)
    ACTUATORS[method](b, (-1.0, 1.0))     # the name was not taken by the refused one


@pytest.mark.parametrize("call, words", [
    (lambda b: b.add_arc_contact("sole", "torso", (0.0, 0.0), 0.1, span=5),
     r"contact 'sole' \(0\): span=5 must be a pair \(a0, a1\) of numbers"),
    (lambda b: b.add_arc_contact("sole", "torso", (0.0, 0.0), 0.1, span=(1.0,)),
     r"contact 'sole' \(0\): span=\(1.0,\) must be a pair"),
    (lambda b: b.add_arc_contact("sole", "torso", (0.0, 0.0), 0.1, span=(0.0, 1.0, 2.0)),
     r"contact 'sole' \(0\): span=\(0.0, 1.0, 2.0\) must be a pair"),
    (lambda b: b.add_arc_contact("sole", "torso", (0.0, 0.0), 0.1, span=(1.0, 1.0)),
     r"contact 'sole' \(0\): span=\(1.0, 1.0\) must have span\[1\] > span\[0\]"),
    (lambda b: b.add_arc_contact("sole", "torso", (0.0, 0.0), 0.1, span=(-math.inf, 1.0)),
     r"contact 'sole' \(0\): span=\(-inf, 1.0\) must be finite"),
    # vertices=5: "'int' object is not iterable"
    (lambda b: b.add_arc_contact("sole", "torso", (0.0, 0.0), 0.1, vertices=5),
     r"contact 'sole' \(0\): vertices=5 must be a list of \(x, y\) points"),
    (lambda b: b.add_fluid_box("torso", size=5),
     r"fluid box on body 'torso' \(0\): size=5 must be three lengths \(l1, l2, ln\) \[m\]"),
    (lambda b: b.add_fluid_box("torso", size=(0.1, 0.2)), r"size=\(0.1, 0.2\) must be three"),
    (lambda b: b.add_fluid_box("torso", size=(0.1, 0.0, 0.1)), r"size\[1\]=0.0 must be > 0"),
    (lambda b: b.add_fluid_box("torso", size=(0.1, 0.1, math.inf)), r"size\[2\]=inf must be finite"),
    (lambda b: b.add_fluid_box("torso", size=(0.1, 0.1, 0.1), viscosity=-1.0),
     r"viscosity=-1.0 must be >= 0"),
    (lambda b: b.add_fluid_box("torso", size=(0.1, 0.1, 0.1), density=-1.0),
     r"density=-1.0 must be >= 0"),
    (lambda b: b.add_body("shin", mass=1.0, inertia=0.1, shapes=[5]),
     r"body 'shin' \(1\): shapes\[0\]=5 must be a tuple \(kind, \*params\)"),
    (lambda b: b.add_body("shin", mass=1.0, inertia=0.1, shapes=["circle"]),
     r"body 'shin' \(1\): shapes\[0\]='circle' must be a tuple"),
    (lambda b: b.add_body("shin", mass=1.0, inertia=0.1, shapes=5),
     r"body 'shin' \(1\): shapes=5 must be a list of shapes"),
    (lambda b: b.add_body("shin", shapes=[("circle", (0.0, 0.0), 1.0)], density=1e308),
     r"circle shape \(0\) of body 'shin': density=1e\+308 kg/m\^2 on its 3.14159 m\^2 gives "
     r"body 'shin' a mass of inf kg"),
    (lambda b: b.add_body("shin", shapes=[("circle", (0.0, 0.0), 0.1, {"density": 1e308}),
                                          ("box", (0.0, 0.0), 2.0, 2.0, {"density": 1e308})]),
     r"box shape \(1\) of body 'shin': .* a mass of inf kg"),
])
def test_arc_span_fluid_box_and_shapes_that_are_not_what_they_must_be(call, words):
    """A span of 5 or (1,) failed with a raw TypeError/IndexError and (0, 1, 2) was accepted;
    a fluid box of size 5 failed in numpy's reshape; shapes=[5] with "'int' object is not
    iterable" and ['circle'] as kind 'c'; a density of 1e308 compiled a body of mass inf."""
    b = base()
    with pytest.raises(ModelError, match=words) as err:
        call(b)
    assert "np.float64" not in str(err.value)
    assert b._shapes == [] and len(b._bodies) == 1   # nothing of the refused element kept


@pytest.mark.parametrize("call, words", [
    (lambda b: b.add_body("shin", mass=True, inertia=0.1),
     r"body 'shin' \(2\): mass=True must be a number \(not True or False\)"),
    (lambda b: b.add_body("shin", mass=1.0, inertia=np.True_),
     r"body 'shin' \(2\): inertia=True must be a number"),
    (lambda b: b.add_body("shin", mass=1.0, inertia=0.1, angle=False), r"angle=False must be a number"),
    (lambda b: b.add_body("shin", mass=1.0, inertia=0.1, pos=(True, 0.0)),
     r"body 'shin' \(2\): pos=\(True, 0.0\) must be a pair \(x, y\) of numbers, not True or False"),
    (lambda b: b.add_body("shin", shapes=[("circle", (0.0, 0.0), 0.1)], density=True),
     r"density=True must be a number"),
    (lambda b: b.add_point_mass("bob", True), r"body 'bob' \(2\): mass=True must be a number"),
    (lambda b: b.add_shape("torso", "circle", (0.0, 0.0), True), r"radius=True must be a number"),
    (lambda b: b.add_shape("torso", "box", (0.0, 0.0), 0.1, True), r"height=True must be a number"),
    (lambda b: b.add_shape("torso", "circle", (0.0, 0.0), 0.1, mu=True), r"mu=True must be a number"),
    (lambda b: b.add_fluid_box("torso", size=(0.1, True, 0.1)), r"size\[1\]=True must be a number"),
    (lambda b: b.add_point_contact("toe", True), r"contact 'toe' \(0\): body=True is not a body id"),
    (lambda b: b.add_pin("hip", "torso", None, anchor_world=(0.0, 1.0), stiffness=True),
     r"pin 'hip' \(0\): stiffness=True must be a number"),
    (lambda b: b.add_pin("hip", "torso", None, anchor_world=(0.0, 1.0), limit=(False, True)),
     r"pin 'hip' \(0\): limit=\(False, True\) must be a pair \(lower, upper\) of numbers"),
])
def test_bools_are_no_numbers(call, words):
    """float(True) is 1.0: mass=True built a 1 kg body, radius=True a 1 m circle, pos=(True,
    0) a body at x = 1 m and body=True named the second body, all silently."""
    b = base()
    b.add_body("leg", mass=1.0, inertia=0.1, pos=(1.0, 1.0))     # body 1: what True named
    with pytest.raises(ModelError, match=words):
        call(b)


def test_a_bool_step_is_no_number():
    """ModelBuilder(dt=True) compiled a model stepping a whole second."""
    b = base()
    b.dt = True
    with pytest.raises(ModelError, match=r"model: dt=True must be a number"):
        b.compile()
