"""Divergence guards, snapshots, damaged files, corrupted models, cache hits."""
import hashlib
import math
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import planarsim as ps
from planarsim import ModelError, SimulationDiverged, terrain
from planarsim.compile import FAST, MODE


def two_link_on_hills():
    """A box on hills with a pendulum hanging from it: pins, contacts, an actuator."""
    ter = terrain.hills([0.1], [3.0], [0.4])
    b = ps.ModelBuilder(dt=1e-3, terrain=ter)
    box = b.add_body("box", 3.0, 0.05, pos=(0.0, 0.4), vel=(1.0, 0.0), omega=1.0)
    b.add_box_contacts("box", box, (0.0, 0.0), 0.4, 0.2, mu=0.6)
    arm = b.add_body("arm", 1.0, 0.02, pos=(0.25, 0.4), angle=0.0)
    b.add_pin("elbow", box, arm, anchor_world=(0.1, 0.4), limit=(-1.5, 1.5))
    b.add_arc_contact("hand", arm, (0.15, 0.0), 0.05, mu=0.6)
    b.add_pin_motor("elbow_motor", "elbow", limit=(-20.0, 20.0))
    return b.compile()


def state_hash(state):
    h = hashlib.blake2b(digest_size=16)
    for a in state:
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


def test_nan_torque_is_named_as_a_command_at_its_step_and_nothing_steps():
    model = two_link_on_hills()
    sim = ps.Simulator(model)
    u = np.array([3.0])
    for _ in range(137):
        sim.step(u)
    before = sim.snapshot()
    with pytest.raises(ValueError, match=rf"command u\[0\] for actuator {model.act_names[0]!r} is nan"):
        sim.step(np.array([math.nan]))
    assert state_hash(sim.state) == state_hash(before)


def test_huge_velocity_fires_at_its_step():
    model = two_link_on_hills()
    sim = ps.Simulator(model)
    for _ in range(137):
        sim.step(np.array([3.0]))
    sim.state.v[1, 0] = 1e11  # inject a velocity of 1e11 m/s into the arm
    before = sim.snapshot()
    with pytest.raises(SimulationDiverged) as e:
        sim.step(np.array([3.0]))
    assert e.value.step == 137
    assert e.value.body == "arm" and e.value.field == "vx"
    assert e.value.value == 1e11
    assert state_hash(e.value.last_state) == state_hash(before)


def test_huge_push_fires_at_its_step():
    b = ps.ModelBuilder(dt=1e-3)
    ball = b.add_body("ball", 1.0, 0.01, pos=(0.0, 1.0))
    sim = ps.Simulator(b.compile())
    for _ in range(137):
        sim.step()
    before = sim.snapshot()
    sim.state.ext_force[0, 0] = 1e11 / 1e-3  # a push that gives it 1e11 m/s within the step
    with pytest.raises(SimulationDiverged) as e:
        sim.step()
    assert e.value.step == 137 and e.value.body == "ball"
    assert abs(e.value.value) > 1e10
    assert np.array_equal(e.value.last_state.q, before.q) and np.array_equal(e.value.last_state.v, before.v)


def test_snapshot_restore_continues_bit_for_bit(tmp_path):
    model = two_link_on_hills()
    u = np.array([2.0])
    ref = ps.Simulator(model)
    ref.steps(500, u)
    path = ps.save_snapshot(tmp_path / "snap.npz", ref.state, memory={"phase": np.array([3])})
    hashes = []
    for _ in range(1000):
        ref.step(u)
        hashes.append(state_hash(ref.state))
    state, memory = ps.load_snapshot(path)
    assert int(memory["phase"][0]) == 3
    again = ps.Simulator(model, state=state)
    for k in range(1000):
        again.step(u)
        assert state_hash(again.state) == hashes[k]


def test_a_snapshot_saved_before_contact_dependent_existed_loads_with_none_dependent(tmp_path):
    """A snapshot without State.contact_dependent (written before the field existed) loads,
    with no contact row known dependent, and steps as a state that has the field."""
    model = two_link_on_hills()
    ref = ps.Simulator(model)
    ref.steps(50)
    path = ps.save_snapshot(tmp_path / "snap.npz", ref.state)
    with np.load(path) as data:
        old = {k: data[k] for k in data.files if k != "state__contact_dependent"}
    np.savez(tmp_path / "old.npz", **old)
    state, _ = ps.load_snapshot(tmp_path / "old.npz", model)
    assert state.contact_dependent.shape == (model.n_contact,)
    assert not state.contact_dependent.any()
    again = ps.Simulator(model, state=state)
    again.steps(20)
    ref.steps(20)
    assert state_hash(again.state) == state_hash(ref.state)


def test_two_runs_hash_alike_in_process_and_in_a_fresh_process():
    model = two_link_on_hills()

    def run():
        sim = ps.Simulator(model)
        h = hashlib.blake2b(digest_size=16)
        for _ in range(2000):
            sim.step(np.array([1.0]))
            h.update(state_hash(sim.state).encode())
        return h.hexdigest()

    a, b = run(), run()
    assert a == b
    code = textwrap.dedent("""
        import hashlib, numpy as np, planarsim as ps
        from tests.planarsim.test_reliability import two_link_on_hills, state_hash
        sim = ps.Simulator(two_link_on_hills())
        h = hashlib.blake2b(digest_size=16)
        for _ in range(2000):
            sim.step(np.array([1.0]))
            h.update(state_hash(sim.state).encode())
        print(h.hexdigest())
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == a


@pytest.mark.skipif(MODE != FAST, reason="the step and its parts are C functions of their own "
                    "in the fast mode only")
def test_a_second_process_loads_the_step_kernel_from_the_cache():
    sim = ps.Simulator(two_link_on_hills())   # make sure this process compiled (or loaded) them
    sim.step()
    sim.run(n_steps=2)
    code = textwrap.dedent("""
        import planarsim as ps
        from planarsim.link.step import _ENGINE, run_recorded, run_steps
        from tests.planarsim.test_reliability import two_link_on_hills
        sim = ps.Simulator(two_link_on_hills())
        sim.step()            # the Python step path (run_steps, which calls the step)
        sim.run(n_steps=2)    # the recorded path (run_recorded)
        for kernel in (run_steps, run_recorded):
            print(sum(kernel.stats.cache_hits.values()), sum(kernel.stats.cache_misses.values()))
        step = _ENGINE["cfunc"]   # the step itself, a C function every caller calls
        print(step.cache_hits, 0 if step.cache_hits else 1)
        from planarsim.compile.parts import PARTS   # and its parts (a C function too)
        print(PARTS.cfunc.cache_hits, 0 if PARTS.cfunc.cache_hits else 1)
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    for line in out.stdout.strip().splitlines():
        hits, misses = map(int, line.split())
        assert hits >= 1 and misses == 0, out.stdout


@pytest.mark.parametrize("damage", ["truncate", "garbage", "newer"])
def test_damaged_files_give_clear_errors(tmp_path, damage):
    model = two_link_on_hills()
    sim = ps.Simulator(model)
    traj = sim.run(0.05)
    tpath = traj.save(tmp_path / "t.npz")
    spath = ps.save_snapshot(tmp_path / "s.npz", sim.state)
    for path in (tpath, spath):
        raw = path.read_bytes()
        if damage == "truncate":
            path.write_bytes(raw[: len(raw) // 2])
        elif damage == "garbage":
            path.write_bytes(b"not a zip at all" + raw[100:200])
        else:
            key = "format_version" if path == tpath else "snapshot_version"
            data = dict(np.load(path))
            data[key] = np.array(99)
            np.savez(path, **data)
    with pytest.raises(ValueError, match="trajectory"):
        ps.Trajectory.load(tpath)
    with pytest.raises(ValueError, match="snapshot"):
        ps.load_snapshot(spath)


def test_interrupted_save_leaves_no_file(tmp_path, monkeypatch):
    traj = ps.Simulator(two_link_on_hills()).run(0.05)
    target = tmp_path / "t.npz"

    def boom(*a, **k):
        raise KeyboardInterrupt
    monkeypatch.setattr(np, "savez_compressed", boom)
    with pytest.raises(KeyboardInterrupt):
        traj.save(target)
    assert list(tmp_path.iterdir()) == []


# a valid model description, and one corrupted field at a time --------------------------------
CORRUPTIONS = [
    ("body", "mass", -1.0), ("body", "mass", 0.0), ("body", "mass", math.nan),
    ("body", "inertia", 0.0), ("body", "inertia", -2.0), ("body", "pos", (0.0, math.inf)),
    ("body", "vel", (math.nan, 0.0)), ("pin", "body_b", "ghost"), ("pin", "name", "hip"),
    ("pin", "limit", (1.0, -1.0)), ("pin", "anchor_b", (0.0, 0.3)), ("contact", "mu", -0.1),
    ("contact", "body", 99), ("actuator", "limit", (3.0, -3.0)), ("rod", "length", 0.0),
    ("model", "dt", 0.0), ("model", "dt", -1e-3), ("model", "gravity", (0.0, math.nan)),
    ("terrain", "coef", math.nan),
]


def build_described(corrupt=None):
    kind, field, value = corrupt if corrupt else (None, None, None)
    def pick(k, f, default):
        return value if (kind, field) == (k, f) else default
    ter = terrain.hills([0.1], [3.0]) if kind != "terrain" else None
    if kind == "terrain":
        ter = terrain.hills([value], [3.0])
    b = ps.ModelBuilder(dt=pick("model", "dt", 1e-3), gravity=pick("model", "gravity", (0.0, -9.81)),
                        terrain=ter)
    b.add_body("torso", pick("body", "mass", 5.0), pick("body", "inertia", 0.3),
               pos=pick("body", "pos", (0.0, 1.0)), vel=pick("body", "vel", (0.0, 0.0)))
    b.add_body("leg", 1.0, 0.1, pos=(0.0, 0.5))
    b.add_pin("hip", "torso", "leg", anchor_a=(0.0, -0.25), anchor_b=pick("pin", "anchor_b", (0.0, 0.25)),
              limit=pick("pin", "limit", (-1.0, 1.0)))
    b.add_pin(pick("pin", "name", "knee_dummy"), None, pick("pin", "body_b", "leg"),
              anchor_world=(0.0, 0.25))
    b.add_point_mass("foot", 0.5, pos=(0.0, 0.0))
    b.add_rod("shank", "leg", "foot", anchor_a=(0.0, -0.25), length=pick("rod", "length", 0.25))
    b.add_point_contact("toe", pick("contact", "body", "foot"), mu=pick("contact", "mu", 0.8))
    b.add_pin_motor("hip_motor", "hip", limit=pick("actuator", "limit", (-5.0, 5.0)))
    return b.compile()


def test_the_uncorrupted_description_builds():
    assert build_described().n_body == 3


@settings(max_examples=60, deadline=None)
@given(st.sampled_from(CORRUPTIONS))
def test_one_corrupted_field_always_gives_a_model_error(corrupt):
    with pytest.raises(ModelError):
        build_described(corrupt)


def test_simulation_diverged_survives_pickling():
    import pickle
    model = two_link_on_hills()
    sim = ps.Simulator(model)
    sim.state.v[0, 0] = math.nan
    with pytest.raises(SimulationDiverged) as e:
        sim.step(np.array([0.0]))
    back = pickle.loads(pickle.dumps(e.value))
    assert (back.step, back.body, back.field, str(back)) == (e.value.step, e.value.body, e.value.field, str(e.value))
    assert np.array_equal(back.last_state.q, e.value.last_state.q)
