"""pymunk peer of the benchmark scenes (`pip install planarsim[compare]`).

Bodies from a SceneSpec with the same masses, inertias and start poses (body origin at the
centre of mass); pins are PivotJoints at the local anchors; boxes are Poly boxes (radius 0) in
one ShapeFilter group (no collisions between the character's own bodies); the ground is a
static Segment at y = 0. Friction 1, elasticity 0, gravity 9.81, dt 1 ms, sleeping off
(pymunk's default sleep_time_threshold = inf), default 10 solver iterations. pymunk's default
collision_slop (0.1) is meant for pixel units; for metres it is set to 0.5 mm here.
Effort (the accuracy ladder of pareto.py): `iterations` solver iterations and `substeps`
space.step(dt / substeps) calls per frame of the scene's dt; contact softness: `slop` (the
overlap pymunk leaves uncorrected) [m] and `bias` (the fraction of an overlap left after one
second of correction; pymunk's default 0.9^60 = 0.0018).
Timing: a Python loop of chipmunk's cpSpaceStep called through cffi (pymunk's own Space.step
adds 1-1.5 us of Python per call around the same C call: its post-step callbacks, none here),
from a freshly built space (build not timed); `empty_step_s` measures that loop's cost per step
on an empty space.
"""
from __future__ import annotations

import numpy as np

ENGINE = "pymunk"
PACKAGE = "pymunk"
COLLISION_SLOP = 5e-4  # [m]
COLLISION_BIAS = (1.0 - 0.1) ** 60   # pymunk's default


def _stepper(space):
    """f(h): one chipmunk step of `space` by h [s] through cffi, without pymunk's Python
    wrapper (pymunk's Space.step makes the same C call and then runs its post-step callbacks,
    which these scenes do not use)."""
    from pymunk._chipmunk_cffi import lib
    step, ptr = lib.cpSpaceStep, space._space
    return lambda h: step(ptr, h)


def empty_step_s(calls: int = 20000) -> float:
    """Wall time of one step of an empty space by the timed call path [s] (median of 5): the
    part of every timed step that is the call, not the scene."""
    import pymunk
    from benchmarks.peers import median_call_s
    return median_call_s(_stepper(pymunk.Space()), (1e-3,), calls)


def version() -> str:
    import pymunk
    return pymunk.version


def _release(world):
    """Empty `world`'s old space (if any) before it is dropped: its bodies, shapes and
    constraints are removed through pymunk's own remove() with the cyclic garbage collector
    paused. pymunk frees a space by walking its bodies from C and freeing each; a collection
    that starts inside that walk can free the same body a second time and abort the process
    (seen under pytest-xdist), so nothing is left in the space for that walk to find."""
    import gc
    space = getattr(world, "space", None)
    if space is None:
        return
    paused = gc.isenabled()
    gc.disable()
    try:
        space.remove(*space.constraints, *space.shapes, *space.bodies)
        world.space, world.bodies, world.step = None, [], None
        del space
    finally:
        if paused:
            gc.enable()


class World:
    """A pymunk space of the scene with run(n) (timed), reset() and record(n)."""

    def __init__(self, spec, iterations: int = 10, substeps: int = 1, slop: float = COLLISION_SLOP,
                 bias: float = COLLISION_BIAS):
        import pymunk
        if int(iterations) < 1 or int(substeps) < 1:
            raise ValueError(f"pymunk peer: iterations {iterations} and substeps {substeps} must be >= 1")
        if not (slop >= 0.0 and 0.0 <= bias < 1.0):
            raise ValueError(f"pymunk peer: slop {slop} m must be >= 0 and bias {bias} in [0, 1)")
        self.pm, self.spec = pymunk, spec
        self.iterations, self.substeps = int(iterations), int(substeps)
        self.slop, self.bias = float(slop), float(bias)
        self.timing = "Python loop of cpSpaceStep (cffi)"
        self.reset()

    def reset(self):
        _release(self)
        pm, spec = self.pm, self.spec
        space = pm.Space()
        space.gravity = (0.0, -9.81)
        space.collision_slop, space.collision_bias = self.slop, self.bias
        space.iterations = self.iterations
        bodies = []
        # one group: the character's own bodies do not collide; a stack's boxes do
        group = pm.ShapeFilter() if spec.bodies_collide else pm.ShapeFilter(group=1)
        for b in range(spec.n_body):
            body = pm.Body(float(spec.mass[b]), float(spec.inertia[b]))
            body.position = float(spec.q0[b, 0]), float(spec.q0[b, 1])
            body.angle = float(spec.q0[b, 2])
            space.add(body)
            w, h = spec.box[b]
            if not np.isnan(w):
                box = pm.Poly.create_box(body, (float(w), float(h)), radius=0.0)
                box.mass = 0.0  # no mass from the shape: the body's mass and moment stand
                box.friction, box.elasticity, box.filter = 1.0, 0.0, group
                space.add(box)
            bodies.append(body)
        # the body was created with its mass and moment; a shape with a density would change them
        for b, body in enumerate(bodies):
            body.mass, body.moment = float(spec.mass[b]), float(spec.inertia[b])
        for j, (a, b) in enumerate(spec.pin_body):
            ba = space.static_body if a < 0 else bodies[a]
            bb = space.static_body if b < 0 else bodies[b]
            la, lb = (tuple(float(x) for x in spec.pin_anchor[j, e]) for e in (0, 1))
            space.add(pm.PivotJoint(ba, bb, la, lb))
        if spec.ground:
            ground = pm.Segment(space.static_body, (-100.0, 0.0), (100.0, 0.0), 0.0)
            ground.friction, ground.elasticity = 1.0, 0.0
            space.add(ground)
        self.space, self.bodies = space, bodies
        self.step = _stepper(space)

    def run(self, n: int):
        """n frames of the scene's dt (n * substeps steps)."""
        step, h = self.step, self.spec.dt / self.substeps
        for _ in range(n * self.substeps):
            step(h)

    def pose(self, q, v, k):
        for b, body in enumerate(self.bodies):
            p, u = body.position, body.velocity
            q[k, b] = p.x, p.y, body.angle
            v[k, b] = u.x, u.y, body.angular_velocity

    def record(self, n: int):
        """Poses and velocities (n + 1, n_body, 3) of an n-frame run from the start state."""
        self.reset()
        q = np.zeros((n + 1, self.spec.n_body, 3))
        v = np.zeros_like(q)
        self.pose(q, v, 0)
        step, h, sub = self.step, self.spec.dt / self.substeps, self.substeps
        for k in range(1, n + 1):
            for _ in range(sub):
                step(h)
            self.pose(q, v, k)
        return q, v


class ShapeWorld:
    """A pymunk space of a stress scene (benchmarks/stress_scenes.Scene: boxes, circles and
    capsules, static boxes, pins) with run(n) (timed), reset() and positions().

    Bodies with the scene's mass and inertia (shapes without mass); boxes are Poly boxes, a
    circle a Circle, a capsule a Segment with its radius; static boxes are Polys of the static
    body; flat ground a static Segment at y = 0; pins PivotJoints at their world anchors;
    pinned bodies in one ShapeFilter group (they collide with nothing there). Friction the
    scene's mu, elasticity 0, `iterations` solver iterations (default 10), collision_slop
    COLLISION_SLOP, sleeping off."""

    def __init__(self, scene, iterations: int = 10):
        import pymunk
        self.pm, self.scene, self.iterations = pymunk, scene, int(iterations)
        self.timing = f"Python loop of cpSpaceStep (cffi; {self.iterations} iterations)"
        self.reset()

    def _shape(self, body, shape):
        pm = self.pm
        if shape[0] == "box":
            return pm.Poly.create_box(body, (shape[1], shape[2]), radius=0.0)
        if shape[0] == "circle":
            return pm.Circle(body, shape[1])
        return pm.Segment(body, (-shape[1], 0.0), (shape[1], 0.0), shape[2])

    def reset(self):
        _release(self)
        pm, scene = self.pm, self.scene
        space = pm.Space()
        space.gravity = (0.0, -9.81)
        space.collision_slop = COLLISION_SLOP
        space.iterations = self.iterations
        statics = []
        if scene.ground:
            statics.append(pm.Segment(space.static_body, (-100.0, 0.0), (100.0, 0.0), 0.0))
        for (cx, cy), w, h in scene.statics:
            statics.append(pm.Poly(space.static_body, [(cx - w / 2, cy - h / 2), (cx + w / 2, cy - h / 2),
                                                       (cx + w / 2, cy + h / 2), (cx - w / 2, cy + h / 2)]))
        for s in statics:
            s.friction, s.elasticity = scene.mu, 0.0
        space.add(*statics)
        pinned = scene.pinned
        bodies = []
        for k, (part, inertia) in enumerate(zip(scene.parts, scene.inertias)):
            body = pm.Body(float(part.mass), float(inertia))
            body.position, body.angle = tuple(part.pos), float(part.angle)
            body.velocity, body.angular_velocity = tuple(part.vel), float(part.omega)
            shape = self._shape(body, part.shape)
            shape.friction, shape.elasticity = scene.mu, 0.0
            if k in pinned:
                shape.filter = pm.ShapeFilter(group=1)
            space.add(body, shape)
            bodies.append(body)
        for a, b, anchor in scene.pins:
            space.add(pm.PivotJoint(space.static_body if a < 0 else bodies[a],
                                    space.static_body if b < 0 else bodies[b], tuple(anchor)))
        self.space, self.bodies = space, bodies
        self.step = _stepper(space)

    def run(self, n: int):
        step, h = self.step, self.scene.dt
        for _ in range(n):
            step(h)

    def positions(self) -> np.ndarray:
        """(n_body, 2) COM positions [m] now."""
        return np.array([tuple(b.position) for b in self.bodies])
