"""benchmarks/chain_floor.py's dedicated chain step: the physics of the engine's scheme
(every pin within 1e-12 m at the end of every step, the engine's energy behaviour and
trajectory); no timing is asserted."""
import numpy as np
import pytest

import planarsim as ps
from benchmarks import chain_floor as cf
from benchmarks.metrics import energy, pin_separation, spec_from_model
from benchmarks.scenes import chain


def _run_each_step(model, n, state=None):
    """(poses (n + 1, N, 3) after every step, the final state) of the dedicated step."""
    state = state or cf.fresh_state(model)
    poses = [state[0].copy()]
    for _ in range(n):
        cf.run_chain(*state, 1)
        poses.append(state[0].copy())
    return np.array(poses), state


@pytest.mark.parametrize("n_links", [2, 8, 32])
def test_pins_hold_every_step_and_energy_stays(n_links):
    model = chain(n_links, dt=cf.DT)
    spec = spec_from_model(f"chain{n_links}", model, 2.0)
    poses, state = _run_each_step(model, 2000)
    assert max(pin_separation(spec, poses[i:i + 1]) for i in range(len(poses))) <= 1e-12
    drift = (energy(spec, *state[:2]) - energy(spec, model.q0, np.zeros_like(model.q0)))
    assert abs(drift) / spec.energy_scale < 5e-3       # the scheme's: ~0.1% over 10 s


@pytest.mark.parametrize("n_links", [2, 8, 32])
def test_follows_the_engine(n_links):
    """The same scheme solved to the same tolerance: the engine's trajectory to rounding
    (300 steps, before the chain's chaos can grow the differences)."""
    model = chain(n_links, dt=cf.DT)
    sim = ps.Simulator(model)
    sim.steps(300)
    q, v, *_ = state = cf.fresh_state(model)
    cf.run_chain(*state, 300)
    assert np.max(np.abs(q - sim.state.q)) < 1e-9
    assert np.max(np.abs(v - sim.state.v)) < 1e-6


def test_calls_split_anywhere_give_the_same_bits():
    model = chain(8, dt=cf.DT)
    one = cf.fresh_state(model)
    cf.run_chain(*one, 300)
    split = cf.fresh_state(model)
    for n in (1, 99, 63, 137):
        cf.run_chain(*split, n)
    for a, b in zip(one, split):
        assert np.array_equal(a, b)


def test_fast_spin_takes_exact_trig_and_holds_the_pins():
    """Angle increments beyond the series' range (here 0.12 rad a step) turn (cos, sin) by
    math.cos/sin: the pins, measured with numpy's trig of the angles, still hold."""
    model = chain(4, dt=cf.DT)
    q, v, *_ = state = cf.fresh_state(model)
    v[:, 2] = 120.0                      # all links spinning alike: the chain turns rigidly
    v[:, 0] = -120.0 * q[:, 1]
    v[:, 1] = 120.0 * q[:, 0]
    spec = spec_from_model("chain4", model, 0.1)
    poses, _ = _run_each_step(model, 100, state)
    assert max(pin_separation(spec, poses[i:i + 1]) for i in range(len(poses))) <= 1e-12
    assert np.all(np.abs(np.diff(poses[:, :, 2], axis=0)) > cf.TAYLOR_MAX)


def test_command_prints_every_runner(capsys):
    assert cf.main(["--links", "2", "--repeats", "1"]) == 0
    out = capsys.readouterr().out
    assert "  2  engine" in out and "  2  dedicated" in out


def test_every_row_stride_gives_the_same_bits():
    """The kernels differ only in the stride of their work array's rows (run_chain picks one
    by the chain's length): the same arithmetic, the same bits."""
    model = chain(6, dt=cf.DT)
    states = [cf.fresh_state(model) for _ in range(3)]
    for kernel, state in zip((cf._run_short, cf._run_long, cf._run_any), states):
        kernel(*state, 200)
    for other in states[1:]:
        for a, b in zip(states[0], other):
            assert np.array_equal(a, b)
