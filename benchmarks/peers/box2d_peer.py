"""Box2D peer of the benchmark scenes: pybox2d, PyPI package `Box2D` (2.3.10 ships manylinux
wheels for CPython 3.11 on x86_64; `box2d-py` 2.3.8 has no wheel for 3.11 and needs SWIG to
build). Installed by `pip install planarsim[compare]`.

Bodies from a SceneSpec with the same masses, inertias and start poses: polygon boxes (Box2D's
skin radius of 1 cm included, as Box2D has it) with groupIndex -1 (no collisions between the
character's own bodies), then the mass data set explicitly (centre at the body origin); pins
are revolute joints at the local anchors; the ground is a static edge at y = 0. Friction 1,
restitution 0, gravity 9.81, dt 1 ms, doSleep False, 8 velocity and 3 position iterations (the
Box2D manual's recommendation). Effort (the accuracy ladder of pareto.py): the iteration
counts and `substeps` world.Step(dt / substeps) calls per frame of the scene's dt. Contact
softness: `skin="compensated"` makes every box smaller by its skin less a quarter of Box2D's
linear slop (b2_polygonRadius - b2_linearSlop / 4 = 8.75 mm a side) and lowers the ground edge
by as much. Box2D leaves a resting contact anywhere from two skins to two skins less one slop
apart (it corrects overlaps deeper than the slop only), so the outlines then rest within half a
slop (2.5 mm) of touching, either way: the best Box2D 2.3 allows (its slop is compiled in). Timing: a Python loop of world.Step (pybox2d's SWIG call; no
lower-level path) from a freshly built world; `empty_step_s` measures that call on an empty
world.
"""
from __future__ import annotations

import numpy as np

ENGINE = "box2d"
PACKAGE = "Box2D"
VELOCITY_ITERATIONS, POSITION_ITERATIONS = 8, 3
SKINS = ("box2d", "compensated")


def empty_step_s(calls: int = 20000) -> float:
    """Wall time of one world.Step of an empty world [s] (median of 5): the part of every
    timed step that is the call, not the scene."""
    import Box2D
    from benchmarks.peers import median_call_s
    step = Box2D.b2World(gravity=(0.0, -9.81), doSleep=False).Step
    return median_call_s(step, (1e-3, VELOCITY_ITERATIONS, POSITION_ITERATIONS), calls)


def version() -> str:
    import Box2D
    return Box2D.__version__


class World:
    """A Box2D world of the scene with run(n) (timed), reset() and record(n)."""

    def __init__(self, spec, velocity_iterations: int = VELOCITY_ITERATIONS,
                 position_iterations: int = POSITION_ITERATIONS, substeps: int = 1, skin: str = "box2d"):
        import Box2D
        if min(int(velocity_iterations), int(position_iterations), int(substeps)) < 1:
            raise ValueError(f"Box2D peer: velocity_iterations {velocity_iterations}, position_iterations "
                             f"{position_iterations} and substeps {substeps} must be >= 1")
        if skin not in SKINS:
            raise ValueError(f"Box2D peer: skin {skin!r}; choose from {SKINS}")
        self.b2, self.spec = Box2D, spec
        #: how much smaller every box is a side, and how much lower the ground [m]
        self.inset = Box2D.b2_polygonRadius - Box2D.b2_linearSlop / 4 if skin == "compensated" else 0.0
        self.iterations = int(velocity_iterations), int(position_iterations)
        self.substeps = int(substeps)
        self.timing = (f"Python loop of world.Step ({self.iterations[0]} velocity, {self.iterations[1]} "
                       "position iterations)")
        self.reset()

    def reset(self):
        b2, spec = self.b2, self.spec
        world = b2.b2World(gravity=(0.0, -9.81), doSleep=False)
        ground = world.CreateStaticBody(position=(0.0, 0.0))
        if spec.ground:
            y = -self.inset
            ground.CreateEdgeFixture(vertices=[(-100.0, y), (100.0, y)], friction=1.0, restitution=0.0)
        bodies = []
        for b in range(spec.n_body):
            body = world.CreateDynamicBody(position=(float(spec.q0[b, 0]), float(spec.q0[b, 1])),
                                           angle=float(spec.q0[b, 2]))
            w, h = spec.box[b]
            if not np.isnan(w):
                body.CreatePolygonFixture(box=(float(w) / 2 - self.inset, float(h) / 2 - self.inset),
                                          density=1.0, friction=1.0,
                                          restitution=0.0,
                                          groupIndex=0 if spec.bodies_collide else -1)
            md = b2.b2MassData()
            md.mass, md.center, md.I = float(spec.mass[b]), (0.0, 0.0), float(spec.inertia[b])
            body.massData = md
            bodies.append(body)
        for j, (a, b) in enumerate(spec.pin_body):
            world.CreateRevoluteJoint(bodyA=ground if a < 0 else bodies[a], bodyB=ground if b < 0 else bodies[b],
                                      localAnchorA=tuple(float(x) for x in spec.pin_anchor[j, 0]),
                                      localAnchorB=tuple(float(x) for x in spec.pin_anchor[j, 1]),
                                      collideConnected=False)
        self.world, self.bodies = world, bodies

    def run(self, n: int):
        """n frames of the scene's dt (n * substeps steps)."""
        step, h = self.world.Step, self.spec.dt / self.substeps
        vi, pi = self.iterations
        for _ in range(n * self.substeps):
            step(h, vi, pi)

    def pose(self, q, v, k):
        for b, body in enumerate(self.bodies):
            p, u = body.position, body.linearVelocity
            q[k, b] = p[0], p[1], body.angle
            v[k, b] = u[0], u[1], body.angularVelocity

    def record(self, n: int):
        """Poses and velocities (n + 1, n_body, 3) of an n-frame run from the start state."""
        self.reset()
        q = np.zeros((n + 1, self.spec.n_body, 3))
        v = np.zeros_like(q)
        self.pose(q, v, 0)
        step, h, sub = self.world.Step, self.spec.dt / self.substeps, self.substeps
        vi, pi = self.iterations
        for k in range(1, n + 1):
            for _ in range(sub):
                step(h, vi, pi)
            self.pose(q, v, k)
        return q, v


class ShapeWorld:
    """A Box2D world of a stress scene (benchmarks/stress_scenes.Scene: boxes, circles and
    capsules, static boxes, pins) with run(n) (timed), reset() and positions().

    Each body has the scene's mass and inertia (mass data set after its fixtures); a capsule is
    a polygon box between two circles (Box2D 2.3 has no capsule); static boxes are fixtures of
    one static body; flat ground is a static edge at y = 0; pins are revolute joints at their
    world anchors; pinned bodies share groupIndex -1 (they collide with nothing there).
    Friction the scene's mu, restitution 0, VELOCITY_ITERATIONS / POSITION_ITERATIONS, doSleep
    False. Box2D keeps a skin of b2_polygonRadius (1 cm) around every polygon, so each box
    half-extent is made smaller by it (the outline then is the scene's, with rounded corners),
    but never below a quarter of itself: a 4 mm card or a 2 cm domino stays thicker than in
    the scene."""

    def __init__(self, scene, velocity_iterations: int = VELOCITY_ITERATIONS,
                 position_iterations: int = POSITION_ITERATIONS):
        import Box2D
        self.b2, self.scene = Box2D, scene
        self.iterations = int(velocity_iterations), int(position_iterations)
        self.timing = (f"Python loop of world.Step ({self.iterations[0]} velocity, {self.iterations[1]} "
                       "position iterations)")
        self.reset()

    def _inside(self, half):
        """A box half-extent [m] less Box2D's polygon skin (at least a quarter of it)."""
        return max(half - self.b2.b2_polygonRadius, 0.25 * half)

    def _fixtures(self, body, shape, mu, group):
        b2 = self.b2
        common = dict(density=1.0, friction=mu, restitution=0.0, groupIndex=group)
        if shape[0] == "box":
            body.CreatePolygonFixture(box=(self._inside(shape[1] / 2), self._inside(shape[2] / 2)), **common)
        elif shape[0] == "circle":
            body.CreateCircleFixture(radius=shape[1], pos=(0.0, 0.0), **common)
        else:
            half, r = shape[1], shape[2]
            body.CreatePolygonFixture(shape=b2.b2PolygonShape(box=(half, self._inside(r))), **common)
            for x in (-half, half):
                body.CreateCircleFixture(radius=r, pos=(x, 0.0), **common)

    def reset(self):
        b2, scene = self.b2, self.scene
        world = b2.b2World(gravity=(0.0, -9.81), doSleep=False)
        static = world.CreateStaticBody(position=(0.0, 0.0))
        if scene.ground:
            static.CreateEdgeFixture(vertices=[(-100.0, 0.0), (100.0, 0.0)], friction=scene.mu, restitution=0.0)
        for center, w, h in scene.statics:
            static.CreateFixture(shape=b2.b2PolygonShape(box=(self._inside(w / 2), self._inside(h / 2),
                                                              tuple(center), 0.0)),
                                 friction=scene.mu, restitution=0.0)
        pinned = scene.pinned
        bodies = []
        for k, (part, inertia) in enumerate(zip(scene.parts, scene.inertias)):
            body = world.CreateDynamicBody(position=tuple(part.pos), angle=float(part.angle))
            self._fixtures(body, part.shape, scene.mu, -1 if k in pinned else 0)
            md = b2.b2MassData()
            md.mass, md.center, md.I = float(part.mass), (0.0, 0.0), float(inertia)
            body.massData = md
            body.linearVelocity, body.angularVelocity = tuple(part.vel), float(part.omega)
            bodies.append(body)
        for a, b, anchor in scene.pins:
            world.CreateRevoluteJoint(bodyA=static if a < 0 else bodies[a], bodyB=static if b < 0 else bodies[b],
                                      anchor=tuple(anchor), collideConnected=False)
        self.world, self.bodies = world, bodies

    def run(self, n: int):
        step, h = self.world.Step, self.scene.dt
        vi, pi = self.iterations
        for _ in range(n):
            step(h, vi, pi)

    def positions(self) -> np.ndarray:
        """(n_body, 2) COM positions [m] now."""
        return np.array([tuple(b.worldCenter) for b in self.bodies])
