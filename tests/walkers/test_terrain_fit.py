"""A walker whose start pose does not fit the terrain says so, naming the terrain."""
import pytest

import planarsim as ps
from walkers.ranger.model import standing_pose
from walkers.ranger.params import RangerParams


@pytest.mark.parametrize("spec", ["hills", "slope:-2"])
def test_ranger_names_the_terrain_its_stand_pose_misses(spec):
    with pytest.raises(ValueError, match=f"terrain '{spec}'") as err:
        standing_pose(RangerParams(), ps.terrain.parse(spec))
    assert "rises" in str(err.value) and "flat ground" in str(err.value)


def test_ranger_blames_the_parameters_on_flat_ground():
    with pytest.raises(ValueError, match="^RangerParams: the rear foot"):
        standing_pose(RangerParams(stand_rear_angle=-0.3), ps.terrain.flat())
