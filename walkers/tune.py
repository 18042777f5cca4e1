"""CMA-ES tuning of a walker's controller parameters (the `cma` package), in parallel.

A walker is tunable when it has an ``objective`` module (``walkers/<name>/objective.py``) with
``Params`` (a frozen params dataclass offering ``names(True)``, ``bounds(True)``,
``tunable_array()`` and ``with_tunable(x)``), ``evaluate(params, settings) -> dict(score=...)``
(higher is better) and ``DEFAULT_SETTINGS``.

Search space: every tunable field scaled to [0, 1] by its bounds (so one step size sigma0 fits
all), CMA-ES minimising -score with bound handling in [0, 1]. A population is evaluated with
``executor.map`` in order, so the result depends only on the seed, never on the executor:
  * default: a local ``ProcessPoolExecutor`` with `workers` processes;
  * ``scheduler="tcp://host:8786"``: a dask ``distributed.Client(scheduler).get_executor()``
    (install the extra: ``pip install planarsim[tune]``);
  * or any ``concurrent.futures``-style executor passed as `executor`.
After every generation the result (best parameters, per-generation history, settings, seed) is
written atomically to `out` (JSON), so an interrupted run keeps what was finished;
:func:`load_result` reads it back.

Command line: ``planarsim tune simbicon --budget 200 --out tuned.json`` (or ``python -m walkers.tune``).
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from planarsim.trajectory import atomic_write

FORMAT_VERSION = 1


def objective_module(walker: str):
    """The walker's objective module (walkers/<pkg>/objective.py); clear error if it has none."""
    import walkers
    if walker not in walkers.WALKERS:
        raise KeyError(f"unknown walker {walker!r}; known walkers: {sorted(walkers.WALKERS)}")
    mod = walkers.objective(walker)
    if mod is None:
        tunable = sorted(n for n in walkers.WALKERS if walkers.objective(n) is not None)
        raise ValueError(f"walker {walker!r} has no tuning objective (nothing to tune); "
                         f"tunable walkers: {', '.join(tunable)}")
    return mod


def _evaluate(job):
    """Worker entry point (picklable): (walker, unit vector, base params dict, settings)."""
    walker, z, base, settings = job
    mod = objective_module(walker)
    params = mod.Params(**base)
    if z is None:                      # the start point itself, exactly as given
        return mod.evaluate(params, settings)
    b = params.bounds(True)
    x = b[:, 0] + np.clip(z, 0.0, 1.0) * (b[:, 1] - b[:, 0])
    return mod.evaluate(params.with_tunable(x), settings)


@dataclass
class TuneResult:
    """Best parameters and the history of a tuning run (see :func:`tune`)."""
    walker: str
    best_params: dict
    best_score: float
    start_score: float
    history: list = field(default_factory=list)   # per generation: dict(gen, evals, best, median, sigma)
    settings: dict = field(default_factory=dict)
    seed: int = 0
    names: tuple = ()
    evaluations: int = 0    # candidates evaluated (the start point's evaluation not counted)
    stopped: str = ""       # why fewer than `budget` candidates were evaluated ("" if not)

    def params(self):
        """The best parameters as the walker's params dataclass."""
        return objective_module(self.walker).Params(**self.best_params)

    def to_json(self) -> dict:
        return dict(format_version=FORMAT_VERSION, walker=self.walker, best_params=self.best_params,
                    best_score=self.best_score, start_score=self.start_score, history=self.history,
                    settings=self.settings, seed=self.seed, names=list(self.names),
                    evaluations=self.evaluations, stopped=self.stopped)

    def save(self, path) -> Path:
        path = Path(path)
        text = json.dumps(self.to_json(), indent=1, default=float)
        atomic_write(path, lambda f: f.write(text), binary=False)
        return path


def load_result(path) -> TuneResult:
    """Read a result written by :func:`tune`; a clear ValueError for corrupt/newer files."""
    path = Path(path)
    try:
        data = json.loads(path.read_text())
    except json.JSONDecodeError as e:
        raise ValueError(f"{path}: not a readable tuning result (truncated or corrupted?): {e}") from None
    version = data.get("format_version") if isinstance(data, dict) else None
    if version != FORMAT_VERSION:
        raise ValueError(f"{path}: tuning-result format version {version}; this planarsim reads "
                         f"version {FORMAT_VERSION}")
    data.pop("format_version")
    missing = [k for k in ("walker", "best_params", "best_score", "start_score") if k not in data]
    unknown = sorted(k for k in data if k not in TuneResult.__dataclass_fields__)
    if missing or unknown:
        raise ValueError(f"{path}: not a tuning result: "
                         f"{f'missing {missing}' if missing else f'unknown fields {unknown}'}")
    if not isinstance(data["best_params"], dict):
        raise ValueError(f"{path}: not a tuning result: best_params is not a dict of parameters")
    data["names"] = tuple(data.get("names", ()))
    return TuneResult(**data)


_STOP_TEXT = {"tolfun": "the scores of recent generations differ by less than tolfun (converged)",
              "tolx": "the step size fell below tolx (converged)",
              "tolfunhist": "the best scores of recent generations agree (converged)",
              "tolstagnation": "no progress over many generations",
              "tolflatfitness": "every candidate of several generations scored the same",
              "maxiter": "the iteration limit", "maxfevals": "the evaluation limit"}


def _stop_reasons(stop: dict) -> str:
    """CMA-ES's reasons to stop (es.stop()), in words."""
    return "; ".join(_STOP_TEXT.get(k, k) for k in stop) or "no reason given"


def _make_executor(executor, scheduler, workers):
    """(executor, closer) from the user's choice."""
    if executor is not None:
        return executor, (lambda: None)
    if scheduler is not None:
        try:
            from distributed import Client
        except ImportError:
            raise ImportError("a dask scheduler address needs dask.distributed: "
                              "pip install 'planarsim[tune]'") from None
        client = Client(scheduler)
        return client.get_executor(), client.close
    pool = ProcessPoolExecutor(max_workers=max(1, int(workers)), initializer=_quiet_worker)
    return pool, (lambda: pool.shutdown(cancel_futures=True))


def _quiet_worker():
    """A local worker ignores Ctrl-C (the whole terminal group gets it): the tuning process
    alone answers it, ending the workers (_end_workers), so no worker prints a traceback."""
    import signal
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _end_workers(pool):
    """Terminate a local pool's worker processes at once (an interrupted tuning run does not
    wait for the evaluations under way)."""
    stop = getattr(pool, "terminate_workers", None)
    if stop is not None:
        stop()
        return
    for proc in list((getattr(pool, "_processes", None) or {}).values()):
        proc.terminate()
    pool.shutdown(wait=False, cancel_futures=True)


def tune(walker: str = "simbicon", x0=None, budget: int = 100, popsize: int | None = None,
         sigma0: float = 0.1, seed: int = 0, settings: dict | None = None, executor=None,
         scheduler: str | None = None, workers: int = 2, out=None, progress: bool = True) -> TuneResult:
    """Tune the walker's controller parameters with CMA-ES; returns a TuneResult.

    x0 : start parameters (a params dataclass; default the walker's defaults)
    budget : candidates to evaluate (besides the start point): whole generations, then the
        first candidates of one more; fewer only when CMA-ES stops first (converged), and
        then TuneResult.stopped says why
    popsize : CMA-ES population (default 4 + 3 ln n)
    sigma0 : initial step size in the unit-scaled space (fraction of each bound's width)
    seed : CMA-ES random seed (same seed, same settings -> same result)
    settings : objective settings (see the walker's objective.DEFAULT_SETTINGS)
    executor / scheduler / workers : where populations run (see the module docstring)
    out : JSON file written atomically after every generation
    """
    import cma

    if not (math.isfinite(float(sigma0)) and float(sigma0) > 0):
        raise ValueError(f"sigma0={sigma0} must be a positive number (a fraction of each "
                         "bound's width)")
    if popsize is not None and int(popsize) < 2:
        raise ValueError(f"popsize={popsize} must be at least 2")
    mod = objective_module(walker)
    params0 = x0 if x0 is not None else mod.Params()
    base = params0.as_dict()
    settings = dict(mod.DEFAULT_SETTINGS, **(settings or {}))
    b = params0.bounds(True)
    z0 = (params0.tunable_array() - b[:, 0]) / (b[:, 1] - b[:, 0])
    opts = {"seed": int(seed) + 1, "bounds": [0.0, 1.0], "verbose": -9, "maxfevals": int(budget)}
    if popsize is not None:
        opts["popsize"] = int(popsize)
    es = cma.CMAEvolutionStrategy(z0.tolist(), float(sigma0), opts)
    if int(budget) < es.popsize:
        raise ValueError(f"budget {int(budget)} is smaller than one generation of {walker}'s "
                         f"tuning ({es.popsize} evaluations): nothing would be tuned; give "
                         f"--budget >= {es.popsize} (or a smaller --popsize)")
    pool, close = _make_executor(executor, scheduler, workers)
    t_start = time.time()
    try:
        start = list(pool.map(_evaluate, [(walker, None, base, settings)]))[0]["score"]
        result = TuneResult(walker=walker, best_params=base, best_score=start, start_score=start,
                            settings=settings, seed=int(seed), names=params0.names(True))
        while not es.stop() and result.evaluations < budget:
            zs = es.ask()
            # the budget's last candidates: the first ones of a generation, evaluated, not told
            # (CMA-ES learns from whole generations only)
            zs = zs[:budget - result.evaluations]
            scores = [r["score"] for r in pool.map(_evaluate, [(walker, np.asarray(z), base, settings)
                                                                for z in zs])]
            if len(zs) == es.popsize:
                es.tell(zs, [-f for f in scores])
            result.evaluations += len(zs)
            i = int(np.argmax(scores))
            if scores[i] > result.best_score:
                xb = b[:, 0] + np.clip(zs[i], 0, 1) * (b[:, 1] - b[:, 0])
                result.best_score = float(scores[i])
                result.best_params = params0.with_tunable(xb).as_dict()
            result.history.append(dict(gen=len(result.history) + 1, evals=result.evaluations,
                                       best=float(max(scores)), median=float(np.median(scores)),
                                       best_so_far=result.best_score, sigma=float(es.sigma)))
            if out is not None:
                result.save(out)
            if progress:
                h = result.history[-1]
                print(f"[tune {walker}] gen {h['gen']:3d}  evals {h['evals']:4d}/{budget}  "
                      f"best {h['best']:9.3f}  median {h['median']:9.3f}  best so far "
                      f"{h['best_so_far']:9.3f}  sigma {h['sigma']:.3f}  "
                      f"{time.time() - t_start:6.1f} s", file=sys.stderr, flush=True)
        if result.evaluations < budget:
            result.stopped = (f"CMA-ES stopped after {result.evaluations} of {budget} evaluations: "
                              f"{_stop_reasons(es.stop())}")
            if progress:
                print(f"[tune {walker}] {result.stopped}", file=sys.stderr, flush=True)
    except KeyboardInterrupt:
        if isinstance(pool, ProcessPoolExecutor):
            _end_workers(pool)
        raise
    finally:
        close()
    return result


def _bad_tune_flags(a) -> str | None:
    """What is wrong with the command line's numbers, before any candidate runs (None: all
    right)."""
    if not (math.isfinite(a.sigma0) and a.sigma0 > 0):
        return f"--sigma0 {a.sigma0} must be a positive number (a fraction of each bound's width)"
    if a.popsize is not None and a.popsize < 2:
        return f"--popsize {a.popsize} must be at least 2 (CMA-ES recombines two or more)"
    if a.workers is not None and a.workers < 1:
        return f"--workers {a.workers} must be at least 1"
    if a.budget < 1:
        return f"--budget {a.budget} must be at least 1"
    if a.duration is not None and not (math.isfinite(a.duration) and a.duration > 0):
        return f"--duration {a.duration} must be a positive number of seconds"
    if a.start is not None and not Path(a.start).is_file():
        return (f"--start {a.start}: no such file (a JSON result written by 'planarsim tune "
                "--out FILE.json')")
    return None


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="planarsim tune", description="CMA-ES tuning of a walker",
                                 formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("walker", help="a tunable walker (marked [tunable] by 'planarsim list')")
    ap.add_argument("--budget", type=int, default=200,
                    help="candidates evaluated (besides the start point); fewer only if CMA-ES "
                         "converges first, which the output says")
    ap.add_argument("--popsize", type=int, default=None,
                    help="candidates per generation (None: CMA-ES's 4 + 3 ln n)")
    ap.add_argument("--sigma0", type=float, default=0.1,
                    help="initial step, a fraction of each parameter's bounds")
    ap.add_argument("--seed", type=int, default=0, help="CMA-ES random seed")
    ap.add_argument("--workers", type=int, default=2, help="local processes")
    ap.add_argument("--scheduler", default=None, help="dask scheduler address (tcp://host:port)")
    ap.add_argument("--start", default=None, help="JSON result to start from (its best params)")
    ap.add_argument("--duration", type=float, default=None,
                    help="simulated seconds per objective run (None: the objective's own)")
    ap.add_argument("--out", default="tuned.json", help="result file, written after every generation")
    a = ap.parse_args(argv)
    bad = _bad_tune_flags(a)
    if bad:
        ap.error(bad)
    try:
        objective_module(a.walker)
    except (KeyError, ValueError) as e:
        # (a KeyError's str is its message's repr, quotes and all)
        print(f"planarsim tune: {e.args[0] if e.args else e}", file=sys.stderr)
        return 2
    x0 = load_result(a.start).params() if a.start else None
    settings = {"duration": a.duration} if a.duration is not None else None
    try:
        r = tune(a.walker, x0=x0, budget=a.budget, popsize=a.popsize, sigma0=a.sigma0,
                 seed=a.seed, workers=a.workers, scheduler=a.scheduler, out=a.out,
                 settings=settings)
    except ValueError as e:
        print(f"planarsim tune: {e}", file=sys.stderr)
        return 2
    print(json.dumps(dict(start_score=r.start_score, best_score=r.best_score,
                          evaluations=r.evaluations, budget=a.budget, stopped=r.stopped or None,
                          out=a.out)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
