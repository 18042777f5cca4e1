"""CMA-ES tuning (walkers.tune) on the SIMBICON biped: a small budget started from the thesis'
Table 3/4 parameters improves the objective, the same seed gives the same result on a local
process pool and on a dask LocalCluster with 2 workers, results reload, bad files are refused."""
import json

import numpy as np
import pytest

pytest.importorskip("cma", reason="walkers.tune needs the 'cma' package (pip install cma)")

from walkers.tune import load_result, tune  # noqa: E402
from walkers.simbicon.params import THESIS  # noqa: E402

# short runs keep the test cheap: 3 s walks, no pushes, 2 generations of 6
SETTINGS = dict(duration=3.0, pushes=())
BUDGET, POP = 12, 6


@pytest.fixture(scope="module")
def local_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("tune") / "tuned.json"
    r = tune("simbicon", x0=THESIS, budget=BUDGET, popsize=POP, sigma0=0.1, seed=7,
             settings=SETTINGS, workers=2, out=out, progress=False)
    return r, out


def test_small_budget_from_the_thesis_improves_the_objective(local_run):
    r, _ = local_run
    assert r.evaluations == BUDGET
    assert r.best_score > r.start_score
    assert len(r.history) == BUDGET // POP
    # the start really is Tables 3/4
    assert r.start_score == pytest.approx(_score(THESIS))


def _score(params):
    from walkers.simbicon.objective import evaluate
    return evaluate(params, SETTINGS)["score"]


def test_best_parameters_reproduce_their_score(local_run):
    r, _ = local_run
    assert _score(r.params()) == pytest.approx(r.best_score, abs=0.0)
    # only tunable fields changed, each within its bounds
    p = r.params()
    names = set(p.names(True))
    for f, v in p.as_dict().items():
        if f not in names:
            assert v == getattr(THESIS, f)
    lo, hi = p.bounds(True).T
    assert np.all((p.tunable_array() >= lo) & (p.tunable_array() <= hi))


def test_result_file_reloads_and_bad_files_are_refused(local_run, tmp_path):
    r, out = local_run
    back = load_result(out)
    assert back.best_params == r.best_params and back.history == r.history
    assert back.seed == 7 and back.names == r.names
    bad = tmp_path / "bad.json"
    bad.write_text(out.read_text()[:50])
    with pytest.raises(ValueError, match="truncated or corrupted"):
        load_result(bad)
    newer = tmp_path / "newer.json"
    data = json.loads(out.read_text())
    data["format_version"] = 99
    newer.write_text(json.dumps(data))
    with pytest.raises(ValueError, match="format version 99"):
        load_result(newer)


def test_same_seed_same_result_on_a_dask_cluster(local_run):
    """Reproducible with the seed, and independent of where the population runs: a dask
    LocalCluster with 2 worker processes gives the identical history."""
    distributed = pytest.importorskip(
        "distributed", reason="dask.distributed not installed: pip install 'planarsim[tune]'")
    r, _ = local_run
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        r2 = tune("simbicon", x0=THESIS, budget=BUDGET, popsize=POP, sigma0=0.1, seed=7,
                  settings=SETTINGS, scheduler=cluster.scheduler_address, progress=False)
    assert r2.history == r.history
    assert r2.best_params == r.best_params


def test_unknown_walker_is_a_clear_error():
    with pytest.raises(KeyError, match="unknown walker 'nope'"):
        tune("nope", budget=1)


@pytest.mark.parametrize("flags, culprit", [
    (["--sigma0", "0"], "--sigma0"), (["--sigma0", "nan"], "--sigma0"),
    (["--sigma0", "-1"], "--sigma0"), (["--popsize", "1"], "--popsize"),
    (["--workers", "0"], "--workers"), (["--duration", "0"], "--duration"),
    (["--budget", "0"], "--budget"),
])
def test_bad_numbers_on_the_command_line_stop_before_any_run(flags, culprit, capsys, tmp_path):
    """--sigma0 0 crashed in CMA-ES after a whole generation; --duration 0 and --workers 0
    were silently replaced."""
    from walkers.tune import main
    out = tmp_path / "t.json"
    with pytest.raises(SystemExit) as e:
        main(["simple-biped", "--out", str(out), *flags])
    assert e.value.code == 2
    assert culprit in capsys.readouterr().err
    assert not out.exists()


def test_tune_refuses_a_zero_step_size():
    with pytest.raises(ValueError, match="sigma0=0"):
        tune("simple-biped", budget=4, sigma0=0.0)
