"""The render tests draw with Agg (no display) and share one short sliding-box run."""
import matplotlib

matplotlib.use("Agg")

import pytest  # noqa: E402

import planarsim as ps  # noqa: E402
from tests.render.helpers import box_model  # noqa: E402


@pytest.fixture(scope="module")
def sliding_run():
    model = box_model(pos=(0.0, 0.1), vel=(1.5, 0.0), mu=0.3)
    traj = ps.Simulator(model).run(2.0, record_every=10)
    return model, traj
