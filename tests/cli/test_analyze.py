"""planarsim analyze: bad input is one line and exit code 2; a small continuation and a small
diagram of the rimless wheel (one section coordinate, a few points at dt 2e-3) write CSV."""
import csv
import math

import pytest

from walkers.cli import main


@pytest.mark.parametrize("argv, text", [
    (["analyze", "nowalker", "--param", "slope", "--range", "0.1:0.2"], "unknown walker"),
    (["analyze", "ranger", "--param", "slope", "--range", "0.1:0.2"], "no step-to-step map"),
    (["analyze", "rimless-wheel", "--param", "slop", "--range", "0.1:0.2"], "no parameter 'slop'"),
    (["analyze", "rimless-wheel", "--param", "slope", "--range", "0.1-0.2"], "must be A:B"),
    (["analyze", "rimless-wheel", "--param", "slope", "--range", "0.1:0.1"], "different"),
    (["analyze", "rimless-wheel", "--param", "slope", "--range", "0.1:nan"], "finite"),
    (["analyze", "rimless-wheel", "--param", "slope", "--range", "0.1:0.9"], "bounds"),
    (["analyze", "rimless-wheel", "--param", "slope", "--range", "0.1:0.2", "--points", "1"], "points"),
])
def test_bad_input_is_one_line_and_exit_2(argv, text, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert text in err and len(err.splitlines()) == 1


def test_continuation_and_diagram_write_csv(tmp_path, capsys):
    out = tmp_path / "wheel.csv"
    assert main(["analyze", "rimless-wheel", "--param", "slope", "--range", "0.08:0.12", "--points", "3",
                 "--dt", "2e-3", "--workers", "1", "--quiet", "--csv", str(out)]) == 0
    rows = list(csv.DictReader(out.open()))
    assert [float(r["slope"]) for r in rows] == pytest.approx([0.08, 0.10, 0.12])
    # faster steady rolling down a steeper slope; one stable multiplier eta^2 < 1
    w = [float(r["theta_dot"]) for r in rows]
    assert w[0] > w[1] > w[2] and all(r["stable"] == "1" for r in rows)
    assert "reached slope=0.12" in capsys.readouterr().out
    d = tmp_path / "diagram.csv"
    assert main(["analyze", "rimless-wheel", "--param", "slope", "--range", "0.08:0.1", "--points", "2",
                 "--dt", "2e-3", "--workers", "1", "--quiet", "--diagram", "--transient", "40",
                 "--keep", "4", "--csv", str(d)]) == 0
    rows = list(csv.DictReader(d.open()))
    assert len(rows) == 8 and all(math.isfinite(float(r["theta_dot"])) for r in rows)
    assert "period 1" in capsys.readouterr().out


PD_1_2 = 0.0149350880   # [rad] period 1 -> 2 at foot mass ratio 1e-3 (test docstring below)
PD_2_4 = 0.0175182647   # [rad] period 2 -> 4


def _doublings(dt, rng, points, follow, capsys):
    argv = ["analyze", "simplest-walker", "--param", "slope", "--range", rng, "--points", str(points),
            "--dt", str(dt), "--workers", "1", "--quiet"] + ([] if follow else ["--no-follow"])
    assert main(argv) == 0
    out = capsys.readouterr().out
    found = [float(line.split("=")[1].split()[0]) for line in out.splitlines()
             if line.strip().startswith("period-doubling at slope") and "not located" not in line]
    return found, out


def test_analyze_finds_the_period_doublings_at_every_step_size(capsys):
    """`planarsim analyze` locates the 1 -> 2 doubling at dt 1e-3, 5e-4 and 2.5e-4 s and the
    2 -> 4 doubling at 1e-3 and 5e-4 s.

    Reference: the simplest walker at its default foot mass ratio beta = 1e-3 (hip mass M =
    1 kg, point feet beta M, massless legs of 1 m, g = 9.81 m/s^2) is Goswami et al.'s compass
    gait (walkers/passive/reference.py: compass_rhs, compass_heel_strike) with each leg's mass
    at its foot (com_from_foot a = 0, b = l) and no leg inertia (I = 0). Integrated by scipy's
    DOP853 at rtol 1e-12, atol 1e-13; fixed points of P and P^2 by Newton to 1e-12,
    multipliers by central differences of step 1e-6, and the slope where det(J + I) = 0 by
    brentq (xtol 1e-12): 1 -> 2 at 0.0149350880 rad, 2 -> 4 at 0.0175182647 rad. The same
    computation at beta = 1e-6 gives 0.0150883 and 0.0176692, the beta -> 0 values of the
    reduced model (0.0150884, 0.0176694: benchmarks/gait_analysis.py).

    The engine's error is first order in dt (semi-implicit Euler between exactly located
    touchdowns), 11 dt / 1 s relative: measured 1.10e-2, 5.98e-3, 3.05e-3 for 1 -> 2 (1.54e-3
    at dt 1.25e-4 s) and 1.10e-2, 5.5e-3 for 2 -> 4. So within 2e-3 of the reference only from
    dt 1.25e-4 s; here each halving of dt must halve the error, and the extrapolation
    2 p(dt / 2) - p(dt) must lie within 2e-3 of the reference (it does within 2e-4)."""
    first, second = {}, {}
    for dt in (1e-3, 5e-4, 2.5e-4):
        follow = dt >= 5e-4
        found, out = _doublings(dt, "0.0138:0.0182" if follow else "0.0138:0.0156", 5 if follow else 4,
                                follow, capsys)
        assert len(found) == (2 if follow else 1), out
        first[dt] = found[0]
        if follow:
            second[dt] = found[1]
    for refp, got in ((PD_1_2, first), (PD_2_4, second)):
        err = {dt: p / refp - 1.0 for dt, p in got.items()}
        dts = sorted(err, reverse=True)
        for dt in dts:
            assert 0.0 < err[dt] < 15.0 * dt, (refp, err)          # first order, ~11 dt
        for big, small in zip(dts, dts[1:]):
            assert 1.6 < err[big] / err[small] < 2.5, (refp, err)   # converging at first order
            assert abs((2 * got[small] - got[big]) / refp - 1.0) < 2e-3, (refp, got)
