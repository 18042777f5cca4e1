"""The accuracy-matched comparison (`planarsim bench --parts pareto`) on a tiny ladder, and the
Pareto-front arithmetic on fronts whose answer is known. No timing is asserted."""
import csv
import math
import sys

import numpy as np
import pytest

from benchmarks import runner as bench
from benchmarks.metrics import accuracy, spec_from_model
from benchmarks.scenes import chain as build_chain
from benchmarks.pareto import cost_at, crossing, front, ladder, matched, order
from benchmarks.peers import available_peers

TINY = ["chain2", "--parts", "pareto", "--quick", "--repeats", "1", "--timing-seconds", "0.02",
        "--accuracy-seconds", "0.05"]


def _rows(curve, pts, engine="x"):
    return [dict(scene="s", engine=engine, curve=curve, k=k, dt=1e-3 / k, cost_s_per_s=c, energy_err_max=e)
            for k, (c, e) in zip((1, 2, 4, 8), pts)]


def test_quick_ladder_prints_tables_plot_and_csv(tmp_path, capsys):
    assert bench.main([*TINY, "--pareto-out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    found, missing = available_peers()
    for msg in missing:
        assert msg in out
    rows = list(csv.DictReader(open(tmp_path / "pareto.csv")))
    curves = [(r["curve"], float(r["k"])) for r in rows]
    expected = [(label, k) for engine in ("planarsim", *found) for label, _, k in ladder(engine, quick=True)]
    assert curves == expected
    for r in rows:
        assert float(r["cost_s_per_s"]) > 0 and float(r["energy_err_max"]) >= 0
    # planarsim's pins hold at every step of its ladder (physics, not timing): docs/benchmarks.md's
    # 'within 2e-12 m on every curve'
    assert all(float(r["pin_error_m"]) <= 2e-12 for r in rows if r["engine"] == "planarsim")
    assert "pareto chain2: cost = wall s per simulated s" in out
    assert "planarsim speed-up = peer cost / planarsim cost" in out
    for label, _, _ in [c for engine in found for c in ladder(engine, quick=True)]:
        assert label in out
    assert (tmp_path / "pareto_chain2.png").stat().st_size > 1000


def test_missing_peer_is_named_and_the_ladder_runs_without_it(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "pymunk", None)  # import pymunk now raises ImportError
    assert bench.main([*TINY, "--peers", "pymunk", "--pareto-out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "peer pymunk: not installed" in out and "pareto: no peer installed" in out
    engines = {r["engine"] for r in csv.DictReader(open(tmp_path / "pareto.csv"))}
    assert engines == {"planarsim"}


def test_scene_without_peer_version_is_named():
    from benchmarks.pareto import build_model
    with pytest.raises(ValueError, match="boxes_on_hills"):
        build_model("boxes_on_hills", 1e-3)


def test_front_drops_dominated_points_and_interpolates_log_log():
    # error = 1e-3 / cost^2 on the front; (3, 1e-3) costs more and is less accurate than (2, ...)
    pts = [(1.0, 1e-3), (2.0, 2.5e-4), (3.0, 1e-3), (4.0, 6.25e-5)]
    f = front([dict(cost_s_per_s=c, energy_err_max=e) for c, e in pts], "energy_err_max")
    assert f == [(1.0, 1e-3), (2.0, 2.5e-4), (4.0, 6.25e-5)]
    cost, note = cost_at(f, 1e-3 / 3.0 ** 2)
    assert note == "interpolated" and cost == pytest.approx(3.0, rel=1e-12)
    assert cost_at(f, 1e-2) == (1.0, "cheapest")
    cost, note = cost_at(f, 1e-6)
    assert math.isnan(cost) and note is None


def test_crossing_of_a_first_and_a_fourth_order_method():
    # ours: cost = 1e-3 / err (first order); theirs: cost = a err^(-1/4) (fourth order), with a
    # chosen so that the two cost the same at err = 1e-5: theirs is dearer below, cheaper above
    errs = [1e-3, 1e-4, 1e-5, 1e-6, 1e-7]
    a = (1e-3 / 1e-5) * 1e-5 ** 0.25
    ours = front([dict(cost_s_per_s=1e-3 / e, energy_err_max=e) for e in errs], "energy_err_max")
    theirs = front([dict(cost_s_per_s=a * e ** -0.25, energy_err_max=e) for e in errs], "energy_err_max")
    cross = crossing(ours, theirs)
    assert len(cross) == 1 and cross[0] == pytest.approx(1e-5, rel=0.2)
    assert crossing(ours, [(c * 1e3, e) for c, e in theirs]) == []


def test_matched_ratio_and_order_against_a_known_ladder():
    ours = _rows("planarsim", [(1.0, 1e-3), (2.0, 5e-4), (4.0, 2.5e-4), (8.0, 1.25e-4)], "planarsim")
    # a second-order peer at twice our cost per k: our error 1e-3 is its k = 2 point (cost 4)
    theirs = _rows("peer", [(2.0, 4e-3), (4.0, 1e-3), (8.0, 2.5e-4), (16.0, 6.25e-5)], "peer")
    [s] = matched(ours + theirs, metrics=("energy_err_max",))
    assert s["raw_ratio"] == pytest.approx(2.0)
    m = s["energy_err_max"]
    assert m["target"] == 1e-3 and m["ratio"] == pytest.approx(4.0) and m["note"] == "interpolated"
    assert m["order"] == pytest.approx(2.0) and m["our_order"] == pytest.approx(1.0)
    assert order(ours, "energy_err_max") == pytest.approx(1.0)


def test_contact_scene_is_matched_on_contact_error_not_energy():
    from benchmarks.pareto import figures, measure_scene
    rows = measure_scene("rod_drop", {}, quick=True, repeats=1, timing_seconds=0.02, accuracy_seconds=0.6)
    # the rod hits the ground at 0.32 s and loses its energy there by physics: no energy figure
    assert figures(rows) == ["contact_error_m"]
    for r in rows:
        assert r["contact_error_m"] == max(r["penetration_m"], abs(r["rest_gap_m"]))
        # planarsim's contacts neither sink nor hover: docs/benchmarks.md's 'contact error below 1e-9 m
        # at every step of its ladder' (4.3e-13 m measured on the full ladder)
        assert r["contact_error_m"] < 1e-9


def test_a_diverged_run_is_not_on_the_front():
    rows = [dict(cost_s_per_s=1.0, energy_err_max=1e-1), dict(cost_s_per_s=2.0, energy_err_max=1e-6,
                                                            warning="unstable (frame 10)")]
    assert front(rows, "energy_err_max") == [(1.0, 1e-1)]


def test_a_peer_that_diverged_at_dt_is_not_matched_at_its_error():
    ours = _rows("planarsim", [(1.0, 1e-3), (2.0, 5e-4)], "planarsim")
    theirs = _rows("peer", [(0.5, 1e9), (1.0, 1e-4)], "peer")
    theirs[0]["warning"] = "unstable (frame 10)"
    [s] = matched(ours + theirs, metrics=("energy_err_max",))
    m = s["energy_err_max"]
    assert m["note_at_peer"] == "diverged" and math.isnan(m["ratio_at_peer"])
    assert m["ratio"] == pytest.approx(1.0) and m["note"] == "cheapest"   # its k = 2 point


def test_accurate_curves_run_on_chains_and_are_skipped_with_contacts(monkeypatch):
    from benchmarks import pareto
    assert [label for label, _, _ in ladder("planarsim")][::7] == ["planarsim", "planarsim-rattle",
                                                                   "planarsim-rattle4", "planarsim-rattle6"]
    two = [("planarsim", {}, 1), ("planarsim-rattle", {"integrator": "rattle"}, 1)]
    monkeypatch.setattr(pareto, "ladder", lambda engine, quick=False: two)
    short = dict(quick=True, repeats=1, timing_seconds=0.01, accuracy_seconds=0.05)
    rows = pareto.measure_scene("chain2", {}, **short)
    assert [r["curve"] for r in rows] == ["planarsim", "planarsim-rattle"]
    # RATTLE is second order: its energy error is below the default step's at the same step
    assert rows[1]["energy_err_max"] < rows[0]["energy_err_max"] and rows[1]["pin_error_m"] <= 2e-12
    # the rod drop has contacts, which the accurate integrators refuse: only the default runs
    assert [r["curve"] for r in pareto.measure_scene("rod_drop", {}, **short)] == ["planarsim"]


def test_matched_against_each_planarsim_curve():
    from benchmarks.pareto import our_curves
    ours = _rows("planarsim", [(1.0, 1e-3), (2.0, 5e-4)], "planarsim")
    accurate = _rows("planarsim-rattle", [(1.5, 1e-4), (3.0, 2.5e-5)], "planarsim")
    theirs = _rows("peer", [(2.0, 4e-3), (4.0, 1e-3), (8.0, 2.5e-4), (16.0, 6.25e-5)], "peer")
    rows = ours + accurate + theirs
    assert our_curves(rows) == ["planarsim", "planarsim-rattle"]
    [s] = matched(rows, metrics=("energy_err_max",), ours="planarsim-rattle")
    assert s["ours"] == "planarsim-rattle" and s["curve"] == "peer"
    # the peer reaches 1e-4 between its k = 4 (2.5e-4, cost 8) and k = 8 (6.25e-5, cost 16) points
    m = s["energy_err_max"]
    assert m["target"] == 1e-4 and m["ratio"] == pytest.approx(8.0 * 2 ** (math.log(2.5) / math.log(4)) / 1.5)
    [d] = matched(rows, metrics=("energy_err_max",))
    assert d["ours"] == "planarsim" and d["energy_err_max"]["ratio"] == pytest.approx(4.0)


def _peer_or_skip(name):
    import os
    found, _ = available_peers([name])
    if name not in found:
        if os.environ.get("CI"):
            pytest.fail(f"{name} is not installed in CI (the test extra lists it)")
        pytest.skip(f"{name} not installed (compare extra)")
    return found[name]


@pytest.mark.parametrize("peer, stiff, default_err, stiff_err", [
    # (peer, the ladder's stiff keywords, the default's resting error at least, the stiff
    # one's at most [m]): pymunk leaves its slop (0.5 mm) and rests exactly with none;
    # Box2D rests a skin-and-a-half above (15-20 mm) and within half its 5 mm slop when
    # compensated; MuJoCo's default contact sinks 20 mm under the rod (its penetration), its
    # stiff one rests within 1e-7 m
    ("pymunk", {"iterations": 40, "slop": 0.0, "bias": 1e-12}, 4e-4, 1e-12),
    ("box2d", {"velocity_iterations": 30, "position_iterations": 10, "skin": "compensated"}, 1e-2, 2.5e-3),
    ("mujoco", {"integrator": "Euler", "contact": "stiff"}, 1e-2, 1e-7),
])
def test_a_peers_stiff_contact_takes_its_resting_error_down_but_not_its_impact(peer, stiff, default_err,
                                                                               stiff_err):
    """docs/benchmarks.md: each peer's contact made as stiff as it allows rests far closer to
    the ground than its default, yet the rod still sinks at its impact by about the distance
    its last step carried it (0.70 mm at 1 m/s and dt 1 ms; Box2D finds it one step ahead
    through its skin), where planarsim's contact error stays below 1e-9 m."""
    from dataclasses import replace
    from benchmarks.pareto import CURVES, build_model
    mod = _peer_or_skip(peer)
    assert any(kw == stiff for _, kw in CURVES[peer])        # the ladder runs these settings
    dt, seconds = 1e-3, 2.0                                  # the scene's accuracy run
    spec = spec_from_model("rod_drop", build_model("rod_drop", dt), seconds)
    n = int(round(seconds / dt))
    soft = accuracy(spec, *mod.World(spec).record(n))
    hard = accuracy(spec, *mod.World(replace(spec), **stiff).record(n))
    rest = {k: abs(r["rest_gap_m"]) for k, r in (("soft", soft), ("hard", hard))}
    assert max(rest["soft"], soft["penetration_m"]) >= default_err, soft
    assert rest["hard"] <= stiff_err, hard
    if peer != "box2d":
        assert hard["penetration_m"] == pytest.approx(7.0e-4, rel=0.05), hard


def test_each_peer_times_its_empty_step_by_the_call_it_is_timed_with(monkeypatch):
    """The peers part reports each peer's empty-world step (the call's own cost) and the ratio
    with it taken off; pymunk is stepped through cffi's cpSpaceStep, whose motion is
    pymunk's Space.step's to the bit."""
    from benchmarks.peers import PEER_MODULES, net_rate
    import importlib
    for name in PEER_MODULES:
        mod = importlib.import_module(PEER_MODULES[name])
        _peer_or_skip(name)
        r = net_rate(mod, 1e5)
        assert 0.0 < r["empty_step_s"] < 1e-5 and r["steps_per_s_net"] > 1e5
    mod = importlib.import_module(PEER_MODULES["pymunk"])
    spec = spec_from_model("chain2", build_chain(2), 0.2)
    fast = mod.World(spec)
    q_fast, _ = fast.record(200)
    monkeypatch.setattr(mod, "_stepper", lambda space: space.step)     # pymunk's own Space.step
    q_slow, _ = mod.World(spec).record(200)
    assert np.array_equal(q_fast, q_slow)


def test_a_planarsim_run_the_engine_stops_is_reported_as_a_peers_warning():
    """chain8 under RATTLE at 8 ms steps whips faster than a step resolves: the engine stops
    it (its jump check) at 6.3 s. The ladder keeps the frames before it and the message as a
    warning (off the front), as it does for a peer that diverges, instead of failing."""
    from benchmarks.pareto import _Planarsim
    world = _Planarsim("chain8", 8e-3, 1, integrator="rattle")
    q, v = world.record(1250)                      # 10 s of 8 ms frames
    assert world.warnings and len(q) == world.warnings[0][0] < 1251
    assert "stopped" in world.warnings[0][1]
    world.reset()
    world.run(1250)                                # the timed run: no error either
    assert world.warnings


def test_pareto_tables_from_a_known_ladder(tmp_path, capsys):
    """benchmarks/pareto_tables.py on a written pareto.csv: RK4's cost on its front at our
    error over our cost, and the fronts' ratio at each error, for ladders whose answer is
    known (ours first order, cost 1 / error 1e-3 at k = 1; RK4 fourth order at 4x the cost
    per k)."""
    from benchmarks import pareto_tables
    rows = []
    for label, engine, cost0, err0, p in (("planarsim", "planarsim", 1e-3, 1e-3, 1),
                                          ("planarsim-rattle", "planarsim", 1.2e-3, 5e-4, 2),
                                          ("planarsim-rattle4", "planarsim", 5e-3, 1e-6, 4),
                                          ("mujoco RK4", "mujoco", 4e-3, 1e-3, 4)):
        for k in (1, 2, 4, 8):
            rows.append(dict(scene="chain4", engine=engine, curve=label, k=k, dt=1e-3 / k,
                             cost_s_per_s=cost0 * k, energy_err_max=err0 / k ** p, pin_error_m=1e-12))
    path = tmp_path / "pareto.csv"
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    assert pareto_tables.main([str(path)]) == 0
    out = capsys.readouterr().out.splitlines()
    first = next(line for line in out if line.startswith("| 4 | 1, 1.0e-03"))
    # RK4 reaches 1e-3 at its cheapest point (cost 4e-3): 4x our cost at dt; orders 1 and 4
    assert "| 4x / " in first and first.endswith("| 1.0 / 2.0 / 4.0 / 4.0 |")
    default = next(line for line in out if line.startswith("| 4 | default only |"))
    assert default.split(" | ")[2:4] == ["4x", "4x"]          # at 1e-2 and 1e-3: both cheapest
    assert pareto_tables.main([]) == 2
