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


@pytest.mark.parametrize("dt", [0.0, -1e-3, float("nan"), float("inf")])
def test_bad_dt(dt):
    b = base()
    b.dt = dt
    with pytest.raises(ModelError, match=r"model: dt=.* must be finite and > 0"):
        b.compile()


def test_bad_terrain_coefficients():
    with pytest.raises(ModelError, match=r"terrain: coef\[3\]=nan must be finite"):
        terrain.hills([float("nan")], [2.0])
    with pytest.raises(ModelError, match=r"wavelength=0.0 must be > 0"):
        terrain.hills([0.1], [0.0])
    with pytest.raises(ModelError, match=r"terrain spec 'bumpy' not understood"):
        terrain.parse("bumpy")


def test_model_error_is_a_value_error():
    assert issubclass(ModelError, ValueError)


def test_valid_model_compiles_and_is_read_only():
    m = base().compile()
    assert m.n_body == 1
    with pytest.raises(ValueError):
        m.arrays.body_mass[0] = 2.0
