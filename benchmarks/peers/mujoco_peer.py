"""MuJoCo peer of the benchmark scenes (`pip install planarsim[compare]`).

The scene is an MJCF string built from a SceneSpec: the x-z plane is planarsim's x-y plane,
hinges turn about -y so that positive angles are counter-clockwise as in planarsim. Pinned
bodies are nested (reduced coordinates: a pin is a hinge at its anchor, so MuJoCo's joint error
is zero by construction); a body without a parent pin gets slide x, slide z and a hinge. Each
body frame sits at its centre of mass with an explicit inertia (only the -y component acts).
Boxes are 3D boxes 0.1 m deep; collisions between the character's own bodies are off
(contype 2 / conaffinity 1 against a ground plane of contype 1 / conaffinity 2); friction 1;
MuJoCo's default soft contact (solref 0.02 1, no restitution parameter); Euler integrator,
timestep 1 ms, gravity 9.81. Effort (the accuracy ladder of pareto.py): `integrator` (Euler,
implicitfast, RK4) and `substeps` MuJoCo steps of dt / substeps per frame of the scene's dt.

Timing: `mujoco.rollout.rollout` with one MjData (one thread), the episode as one call from the
start state, preallocated output. Recording (accuracy): an mj_step loop reading the body poses
(xipos, xmat) and COM velocities (mj_objectVelocity); it stops at a MuJoCo warning (the
figures then cover the run up to it, and the warning is reported).
"""
from __future__ import annotations

import numpy as np

ENGINE = "mujoco"
PACKAGE = "mujoco"


def version() -> str:
    import mujoco
    return mujoco.__version__


def _parents(spec):
    """parent[b] = (pin index, parent body or -1) for every pinned body; raises if not a tree."""
    parent = {}
    for j, (a, b) in enumerate(spec.pin_body):
        if b < 0 or b in parent:
            raise ValueError(f"MuJoCo peer: scene {spec.name:.17g} is not a tree of pins (body {b})")
        parent[int(b)] = (j, int(a))
    return parent


INTEGRATORS = ("Euler", "implicitfast", "implicit", "RK4")


#: contact softness: MuJoCo's default, or as stiff as its safety clamp allows at the step (solref
#: time constant 2 h, critically damped, the clamp's bound; solimp impedance 0.99-0.9999 over
#: 1 mm, where the default is 0.9-0.95)
CONTACTS = ("default", "stiff")


def _contact_xml(contact, timestep):
    if contact not in CONTACTS:
        raise ValueError(f"MuJoCo peer: contact {contact!r}; choose from {CONTACTS}")
    if contact == "default":
        return ""
    return f' solref="{2 * timestep:.17g} 1" solimp="0.99 0.9999 0.001 0.5 2"'


def mjcf(spec, integrator: str = "Euler", timestep: float | None = None, contact: str = "default") -> str:
    """The MJCF text of the scene (timestep: default the scene's dt [s]; contact: CONTACTS)."""
    if integrator not in INTEGRATORS:
        raise ValueError(f"MuJoCo peer: integrator {integrator!r}; choose from {INTEGRATORS}")
    timestep = spec.dt if timestep is None else float(timestep)
    soft = _contact_xml(contact, timestep)
    parent = _parents(spec)
    children = {}
    for b, (j, a) in parent.items():
        children.setdefault(a, []).append(b)
    roots = [b for b in range(spec.n_body) if b not in parent]

    def body_xml(b, indent):
        pad = " " * indent
        q = spec.q0[b]
        if b in parent:
            j, a = parent[b]
            qa = spec.q0[a] if a >= 0 else np.zeros(3)
            c, s = np.cos(qa[2]), np.sin(qa[2])
            dx, dy = q[0] - qa[0], q[1] - qa[1]
            rel = (c * dx + s * dy, -s * dx + c * dy)
            ang = q[2] - qa[2]
            lx, ly = spec.pin_anchor[j, 1]
            joints = [f'<joint name="pin{j}" type="hinge" axis="0 -1 0" pos="{lx:.17g} 0 {ly:.17g}"/>']
        else:
            rel, ang = (q[0], q[1]), q[2]
            joints = [f'<joint name="b{b}x" type="slide" axis="1 0 0"/>',
                      f'<joint name="b{b}z" type="slide" axis="0 0 1"/>',
                      f'<joint name="b{b}r" type="hinge" axis="0 -1 0"/>']
        inertia = spec.inertia[b]
        lines = [f'{pad}<body name="b{b}" pos="{rel[0]:.17g} 0 {rel[1]:.17g}" axisangle="0 -1 0 {ang:.17g}">',
                 f'{pad}  <inertial pos="0 0 0" mass="{spec.mass[b]:.17g}" '
                 f'diaginertia="{inertia:.17g} {inertia:.17g} {inertia:.17g}"/>']
        lines += [f"{pad}  {jx}" for jx in joints]
        w, h = spec.box[b]
        if not np.isnan(w):
            # contype 2 / conaffinity 1: the ground only; 3 / 3: the ground and each other
            ct = 3 if spec.bodies_collide else 2
            ca = 3 if spec.bodies_collide else 1
            lines.append(f'{pad}  <geom type="box" size="{w / 2:.17g} 0.05 {h / 2:.17g}" contype="{ct}" '
                         f'conaffinity="{ca}" friction="1 0.005 0.0001" mass="0"{soft}/>')
        for child in children.get(b, []):
            lines += body_xml(child, indent + 2)
        lines.append(f"{pad}</body>")
        return lines

    world = []
    if spec.ground:
        world.append('    <geom type="plane" size="100 1 0.1" contype="1" conaffinity="2" '
                     f'friction="1 0.005 0.0001"{soft}/>')
    for b in roots + children.get(-1, []):
        world += body_xml(b, 4)
    return "\n".join([
        '<mujoco model="planarsim-bench">',
        '  <compiler angle="radian" inertiafromgeom="false"/>',
        f'  <option timestep="{timestep:.17g}" gravity="0 0 {-9.81:.17g}" integrator="{integrator}"/>',
        "  <worldbody>", *world, "  </worldbody>", "</mujoco>"])


def empty_step_s(steps: int = 20000) -> float:
    """Wall time of one step of an empty model by the timed call path (a rollout of `steps`
    steps in one call) [s] (median of 5): MuJoCo's fixed cost of a step, not the scene's."""
    from types import SimpleNamespace
    import mujoco
    from benchmarks.peers import median_call_s
    try:
        from mujoco import rollout
    except ImportError:
        rollout = None
    model = mujoco.MjModel.from_xml_string('<mujoco><worldbody/></mujoco>')
    data = mujoco.MjData(model)
    kind = mujoco.mjtState.mjSTATE_FULLPHYSICS
    x0 = np.zeros(mujoco.mj_stateSize(model, kind))
    peer = SimpleNamespace(mj=mujoco, model=model, data=data, x0=x0, _rollout=rollout, _out={})
    return median_call_s(_roll, (peer, steps), calls=1, per_call=steps)


def _roll(peer, n: int) -> bool:
    """n MuJoCo steps of peer (model, data, x0, _rollout, _out) from its start state in one
    single-threaded rollout call; where mujoco.rollout is missing, an mj_step loop from
    where the data is (after reset()). Returns True if rolled out (the last state is in
    peer._out[n][0, -1])."""
    if peer._rollout is None:
        step, m, d = peer.mj.mj_step, peer.model, peer.data
        for _ in range(n):
            step(m, d)
        return False
    if n not in peer._out:
        peer._out[n] = np.zeros((1, n, len(peer.x0)))
    peer._rollout.rollout(peer.model, peer.data, peer.x0[None, :], nstep=n, state=peer._out[n])
    return True


class World:
    """A MuJoCo model of the scene with run(n) (timed), reset() and record(n)."""

    def __init__(self, spec, integrator: str = "Euler", substeps: int = 1, contact: str = "default"):
        import mujoco
        if int(substeps) < 1:
            raise ValueError(f"MuJoCo peer: substeps {substeps} must be >= 1")
        self.substeps = int(substeps)
        try:
            from mujoco import rollout
        except ImportError:  # MuJoCo < 3.1: no rollout module
            rollout = None
        self.mj, self._rollout, self.spec = mujoco, rollout, spec
        self.timing = ("mujoco.rollout, one thread" if rollout is not None
                       else "Python loop of mj_step (this MuJoCo has no rollout module)")
        self.model = mujoco.MjModel.from_xml_string(mjcf(spec, integrator, spec.dt / self.substeps, contact))
        self.data = mujoco.MjData(self.model)
        self.kind = mujoco.mjtState.mjSTATE_FULLPHYSICS
        self.x0 = np.zeros(mujoco.mj_stateSize(self.model, self.kind))
        mujoco.mj_getState(self.model, self.data, self.x0, self.kind)
        self._out = {}
        self.body_ids = [mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, f"b{b}")
                         for b in range(spec.n_body)]

    def reset(self):
        self.mj.mj_resetData(self.model, self.data)

    def run(self, n: int):
        """n frames of the scene's dt (n * substeps steps) from the start state in one
        single-threaded rollout call (or an mj_step loop after reset() where mujoco.rollout is
        missing)."""
        _roll(self, n * self.substeps)

    def _kinematics(self):
        """Poses and COM velocities of the current state (mj_step leaves those of the step's
        start; this recomputes them without touching the solver's warm start)."""
        m, d = self.model, self.data
        self.mj.mj_kinematics(m, d)
        self.mj.mj_comPos(m, d)
        self.mj.mj_comVel(m, d)

    def pose(self, q, v, k):
        d, mj = self.data, self.mj
        res = np.zeros(6)
        for b, bid in enumerate(self.body_ids):
            mat = d.xmat[bid]
            q[k, b] = d.xipos[bid][0], d.xipos[bid][2], np.arctan2(mat[6], mat[0])
            mj.mj_objectVelocity(self.model, d, mj.mjtObj.mjOBJ_BODY, bid, res, 0)
            v[k, b] = res[3], res[5], -res[1]

    def record(self, n: int):
        """Poses and velocities (n + 1, n_body, 3) of an n-frame run from the start state. A
        MuJoCo warning (e.g. unstable QACC, after which MuJoCo resets the state) is kept in
        `self.warnings` as (step, text) and the frames stop before that step."""
        mj = self.mj
        self.reset()
        self._kinematics()
        q = np.zeros((n + 1, self.spec.n_body, 3))
        v = np.zeros_like(q)
        self.pose(q, v, 0)
        self.warnings = []
        step = [0]
        previous = mj.get_mju_user_warning()
        mj.set_mju_user_warning(lambda text: self.warnings.append((step[0], text.strip())))
        try:
            for k in range(1, n + 1):
                step[0] = k
                for _ in range(self.substeps):
                    mj.mj_step(self.model, self.data)
                if self.warnings:
                    return q[:k], v[:k]
                self._kinematics()
                self.pose(q, v, k)
        finally:
            mj.set_mju_user_warning(previous)
        return q, v


def _geom(shape, extra):
    """The MJCF geom of a stress scene's shape (x-z plane; 0.1 m deep boxes, a circle a sphere,
    a capsule a capsule along the body's x axis)."""
    if shape[0] == "box":
        return f'<geom type="box" size="{shape[1] / 2:.17g} 0.05 {shape[2] / 2:.17g}" {extra}/>'
    if shape[0] == "circle":
        return f'<geom type="sphere" size="{shape[1]:.17g}" {extra}/>'
    return (f'<geom type="capsule" fromto="{-shape[1]:.17g} 0 0 {shape[1]:.17g} 0 0" '
            f'size="{shape[2]:.17g}" {extra}/>')


def shape_mjcf(scene) -> str:
    """The MJCF text of a stress scene (benchmarks/stress_scenes.Scene): every body free in the
    plane (slide x, slide z, hinge about -y) at its centre of mass with the scene's mass and
    inertia; pins are `connect` equality constraints at their anchors (MuJoCo's soft
    equality: the bridge is a closed loop, no tree); pinned bodies' geoms collide with
    nothing (contype 0); static boxes are world geoms, flat ground a plane."""
    friction = f'friction="{scene.mu:.17g} 0.005 0.0001"'
    world = []
    if scene.ground:
        world.append(f'    <geom type="plane" size="100 1 0.1" {friction}/>')
    for (cx, cy), w, h in scene.statics:
        world.append(f'    <geom type="box" pos="{cx:.17g} 0 {cy:.17g}" size="{w / 2:.17g} 0.05 {h / 2:.17g}" '
                     f'{friction}/>')
    pinned = scene.pinned
    for k, (part, inertia) in enumerate(zip(scene.parts, scene.inertias)):
        extra = friction + (' contype="0" conaffinity="0"' if k in pinned else "") + ' mass="0"'
        world += [f'    <body name="b{k}" pos="{part.pos[0]:.17g} 0 {part.pos[1]:.17g}" '
                  f'axisangle="0 -1 0 {part.angle:.17g}">',
                  f'      <inertial pos="0 0 0" mass="{part.mass:.17g}" '
                  f'diaginertia="{inertia:.17g} {inertia:.17g} {inertia:.17g}"/>',
                  '      <joint type="slide" axis="1 0 0"/>', '      <joint type="slide" axis="0 0 1"/>',
                  '      <joint type="hinge" axis="0 -1 0"/>',
                  f"      {_geom(part.shape, extra)}", "    </body>"]
    equality = []
    for j, (a, b, anchor) in enumerate(scene.pins):
        body, other = (b, a) if a < 0 else (a, b)      # body1 a body; body2 the world or a body
        part = scene.parts[body]
        c, s = np.cos(part.angle), np.sin(part.angle)
        dx, dy = anchor[0] - part.pos[0], anchor[1] - part.pos[1]
        lx, ly = c * dx + s * dy, -s * dx + c * dy
        second = f' body2="b{other}"' if other >= 0 else ""
        equality.append(f'    <connect body1="b{body}"{second} anchor="{lx:.17g} 0 {ly:.17g}"/>')
    return "\n".join([
        '<mujoco model="planarsim-stress">',
        '  <compiler angle="radian" inertiafromgeom="false"/>',
        f'  <option timestep="{scene.dt:.17g}" gravity="0 0 {-9.81:.17g}" integrator="Euler"/>',
        "  <worldbody>", *world, "  </worldbody>",
        *(["  <equality>", *equality, "  </equality>"] if equality else []), "</mujoco>"])


class ShapeWorld:
    """A MuJoCo model of a stress scene (shape_mjcf) with run(n) (timed: one single-threaded
    rollout call from the start state, as World), reset() and positions()."""

    def __init__(self, scene):
        import mujoco
        try:
            from mujoco import rollout
        except ImportError:  # MuJoCo < 3.1: no rollout module
            rollout = None
        self.mj, self._rollout, self.scene = mujoco, rollout, scene
        self.timing = ("mujoco.rollout, one thread" if rollout is not None
                       else "Python loop of mj_step (this MuJoCo has no rollout module)")
        self.model = mujoco.MjModel.from_xml_string(shape_mjcf(scene))
        self.data = mujoco.MjData(self.model)
        self.reset()
        self.kind = mujoco.mjtState.mjSTATE_FULLPHYSICS
        self.x0 = np.zeros(mujoco.mj_stateSize(self.model, self.kind))
        mujoco.mj_getState(self.model, self.data, self.x0, self.kind)
        self._out = {}

    def reset(self):
        self.mj.mj_resetData(self.model, self.data)
        for k, part in enumerate(self.scene.parts):
            self.data.qvel[3 * k:3 * k + 3] = part.vel[0], part.vel[1], part.omega

    def run(self, n: int):
        """n steps from the start state: one rollout call (or an mj_step loop after reset())."""
        if _roll(self, n):
            self.mj.mj_setState(self.model, self.data, self._out[n][0, -1], self.kind)

    def positions(self) -> np.ndarray:
        """(n_body, 2) COM positions [m] now."""
        self.mj.mj_kinematics(self.model, self.data)
        return np.array([(self.data.xpos[k + 1][0], self.data.xpos[k + 1][2]) for k in range(self.scene.n_body)])
