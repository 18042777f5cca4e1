"""The frame a step's checks measure motion and energy in.

A model that touches the world nowhere (no joint to the world, no shape on it, no contact with
the ground: ws.frame_free) is a free system: nothing in it depends on how fast it drifts as a
whole, so its checks measure the bodies' motion about their centre of mass. Every other model
is measured in the world's frame, where its ground and anchors rest. Measured in the world's
frame, a free model drifting fast was judged differently from the same model at rest: a
rebound's rounding allowance and the joints' energy share grew with the drift's energy, and
a correction's move was "explained" by the drift's speed (benchmarks/galilean_corpus.py).
"""
import math

from ...compile import kernel


@kernel
def frame_velocity(m, ws, v):
    """(V_x, V_y) [m/s]: the velocity of the frame of the step's checks under body velocities
    v (n_body, 3): zero for a model that touches the world, else its centre of mass's."""
    if ws.frame_free[0] == 0:
        return 0.0, 0.0
    px = 0.0
    py = 0.0
    mass = 0.0
    for i in range(v.shape[0]):
        px += m.body_mass[i] * v[i, 0]
        py += m.body_mass[i] * v[i, 1]
        mass += m.body_mass[i]
    if not mass > 0.0:
        return 0.0, 0.0
    return px / mass, py / mass


@kernel
def frame_displacement(m, ws, q, start_q):
    """(D_x, D_y) [m]: how far the frame of the step's checks moved from positions start_q to
    q: zero for a model that touches the world, else its centre of mass's displacement."""
    if ws.frame_free[0] == 0:
        return 0.0, 0.0
    dx = 0.0
    dy = 0.0
    mass = 0.0
    for i in range(q.shape[0]):
        dx += m.body_mass[i] * (q[i, 0] - start_q[i, 0])
        dy += m.body_mass[i] * (q[i, 1] - start_q[i, 1])
        mass += m.body_mass[i]
    if not mass > 0.0:
        return 0.0, 0.0
    return dx / mass, dy / mass


@kernel(inline="always")
def speed_in_frame(v, i, vx, vy):
    """Body i's speed [m/s] (its centre of mass's) under velocities v seen from a frame
    moving at (vx, vy) [m/s] (the same bits as |v_i| in the world's frame)."""
    ux = v[i, 0] - vx
    uy = v[i, 1] - vy
    return math.sqrt(ux * ux + uy * uy)


@kernel
def kinetic_in_frame(m, v, vx, vy):
    """The kinetic energy [J] of velocities v (n_body, 3) seen from a frame moving at (vx, vy)
    [m/s] (checks.work.kinetic_energy's sum, the same bits in the world's frame)."""
    total = 0.0
    for i in range(v.shape[0]):
        ux = v[i, 0] - vx
        uy = v[i, 1] - vy
        total += m.body_mass[i] * (ux * ux + uy * uy)
        total += m.body_inertia[i] * v[i, 2] * v[i, 2]
    return 0.5 * total
