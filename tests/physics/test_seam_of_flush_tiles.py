"""A floor of static boxes laid edge to edge, their tops flush: bodies sliding across the seams.

The tiles' upright faces at a seam are inside the floor (builder.covered_edges): they are
never a reference face, and a tile's corner there is pressed only along its top's normal
(kernels/geometry/collide.py). Before, a box sliding at 2 m/s over the seam of two flush
tiles met the second tile's covered face: the speculative contact stopped it (v from
(2, 0, 0) to (0.30, 0.59, -5.9)), it tipped up and lost 85 % of its kinetic energy, with no
audit; of a 10-tile floor's seams, rounding decided which caught (Box2D's chain shapes and
their ghost vertices answer the same problem)."""
import numpy as np
import pytest

import planarsim as ps
from planarsim.compiled import audit_counts


def floor(b, tiles, width, x0=0.0, top=0.0, thick=0.1, step=None):
    """`tiles` static boxes `width` [m] wide side by side from x0, tops at `top` [m] (tile
    `step[0]` and those after it `step[1]` higher)."""
    for k in range(tiles):
        lift = step[1] if step is not None and k >= step[0] else 0.0
        b.add_shape(None, "box", (x0 + (k + 0.5) * width, top + lift - thick / 2), width, thick,
                    mu=0.0)


def slider(b, kind, speed, x, top=0.0):
    """A 1 kg body resting on the floor's top at x, sliding at speed [m/s]: a 0.2 x 0.1 m box,
    a capsule lying flat (0.2 m core, radius 0.04 m) or a 0.05 m disk."""
    if kind == "box":
        shape, inertia, y = ("box", (0, 0), 0.2, 0.1, {"mu": 0.0}), 0.05 / 12, 0.05
    elif kind == "capsule":
        shape, inertia, y = ("capsule", (-0.1, 0.0), (0.1, 0.0), 0.04, {"mu": 0.0}), 5e-3, 0.04
    else:
        shape, inertia, y = ("circle", (0, 0), 0.05, {"mu": 0.0}), 1.25e-3, 0.05
    b.add_body("slider", 1.0, inertia, pos=(x, top + y), vel=(speed, 0.0), shapes=[shape])


def test_a_box_slides_across_the_seam_of_two_flush_static_tiles():
    """The case first found: two 0.5 m tiles meeting at x = 2.25, a box at 2 m/s."""
    b = ps.ModelBuilder(dt=1e-3, ground=None)
    b.add_shape(None, "box", (2.0, -0.05), 0.5, 0.1, mu=0.0)
    b.add_shape(None, "box", (2.5, -0.05), 0.5, 0.1, mu=0.0)
    b.add_body("box", 1.0, 0.05 / 12, pos=(2.0, 0.05), vel=(2.0, 0.0),
               shapes=[("box", (0, 0), 0.2, 0.1, {"mu": 0.0})])
    model = b.compile()
    # the covered faces: the first tile's right side, the second's left side
    assert model.arrays.core_cover.tolist() == [0, 1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0]
    sim = ps.Simulator(model)
    sim.steps(200)                    # 0.2 s: past the seam, onto the second tile
    assert np.allclose(sim.state.v[0], (2.0, 0.0, 0.0), atol=1e-9), sim.state.v[0]
    assert abs(sim.state.q[0, 2]) < 1e-9


@pytest.mark.parametrize("kind", ["box", "capsule", "circle"])
@pytest.mark.parametrize("speed,dt", [(0.5, 1e-3), (3.0, 1e-3), (3.0, 5e-3), (12.0, 2e-3),
                                      (-4.0, 1e-3)])
@pytest.mark.parametrize("width,x0,top", [(0.3, 0.0, 0.0), (0.37, -1.234567, 0.71),
                                          (0.5, 1e4 / 3, -2.2)])
def test_a_body_slides_over_every_seam_of_a_tiled_floor_unchecked(kind, speed, dt, width, x0,
                                                                   top):
    """Ten tiles whose centres are sums of floats (seams where rounding falls either way), a
    body sliding without friction across all of them, either way: it keeps its velocity and
    stays level, with no audit."""
    b = ps.ModelBuilder(dt=dt, ground=None)
    floor(b, 10, width, x0, top)
    start = x0 + (0.5 if speed > 0 else 9.5) * width
    slider(b, kind, speed, start, top)
    sim = ps.Simulator(b.compile())
    steps = int(8 * width / abs(speed) / dt)       # across eight tiles
    sim.steps(steps)
    assert abs(sim.state.q[0, 0] - start) > 7 * width
    assert np.allclose(sim.state.v[0], (speed, 0.0, 0.0), atol=1e-8 * (1 + abs(speed))), \
        sim.state.v[0]
    assert abs(sim.state.q[0, 1] - sim.model.q0[0, 1]) < 1e-8
    assert sum(audit_counts(sim.ws).values()) == 0


@pytest.mark.parametrize("rise", [0.01, 1e-4])
def test_a_step_in_the_floor_still_stops_a_box(rise):
    """The negative control: the fourth tile `rise` [m] higher; its upright face is not
    covered (the third tile holds only part of it) and stops a box sliding into it, which
    does not pass through."""
    b = ps.ModelBuilder(dt=1e-3, ground=None)
    floor(b, 6, 0.5, step=(3, rise))
    slider(b, "box", 1.0, 0.5)
    model = b.compile()
    cover = model.arrays.core_cover[:24].reshape(6, 4)
    assert cover[2, 1] == 0 and cover[3, 3] == 0      # the step's faces are open
    assert cover[1, 1] == 1 and cover[2, 3] == 1      # a flush seam's are covered
    sim = ps.Simulator(model)
    sim.steps(1500)
    assert sim.state.q[0, 0] < 1.5 - 0.1 + 1e-6           # its front at most at the step
    assert sim.state.v[0, 0] <= 1.0 - 1e-3                # the step took its speed
