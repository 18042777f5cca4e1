"""Which leg a part belongs to (planarsim/render/sides.py), read from its name."""

import pytest

from planarsim.render.sides import model_sides, side_of   # noqa: E402


@pytest.mark.parametrize("name, side", [
    ("left_thigh", "left"), ("right_shin", "right"), ("l_foot", "left"), ("r_knee", "right"),
    ("FL_calf", "left"), ("RR_thigh", "right"), ("HL_hip_motor", "left"), ("outer_leg", "outer"),
    ("inner_foot", "inner"), ("foot0", "leg 0"), ("leg1", "leg 1"), ("foot_a", "leg a"), ("leg_b", "leg b"),
    ("right_sole/2", "right"), ("hip", None), ("torso", None), ("base", None), ("spoke3", None),
    ("hub", None), ("hip_motor", None)])
def test_side_of_reads_the_leg_from_the_name(name, side):
    assert side_of(name) == side


def test_every_walker_has_its_two_legs_on_two_sides():
    import walkers
    for name in walkers.WALKERS:
        _, _, model = walkers.load(name).simulate(0.02)
        sides = {s for group in model_sides(model).values() for s in group} - {None}
        if name == "rimless-wheel":
            assert sides == set()                 # one rigid body: no legs to tell apart
        else:
            assert len(sides) == 2, (name, sides)
