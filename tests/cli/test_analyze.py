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
