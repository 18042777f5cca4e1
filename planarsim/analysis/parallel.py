"""Step-map evaluations on every core.

A MapPool evaluates a family of step maps P(x; p) (a parameter value p gives a map) at many
points at once: the columns of a finite-difference Jacobian, the predictor / corrector points
of a continuation, the slopes of a bifurcation diagram, the cells of a basin. Each worker
builds and keeps its own maps (its own walker and simulator), so nothing is shared.

Backends: "process" (forked workers; for maps whose evaluation runs Python between compiled
rollouts and so holds the GIL, as the passive walkers' touchdown refinement does), "thread"
(planarsim.batch's thread pool; for maps that run entirely in compiled code, which releases
the GIL), "serial", and a dask cluster (MapPool(family, scheduler="tcp://host:8786") or a
distributed.Client: the family is pickled to its workers, each of which keeps its own maps,
as the tuner's dask runs do). Results do not depend on the backend or the number of workers.
"""
from __future__ import annotations

import multiprocessing as mp
import threading
import uuid
from collections import OrderedDict
import signal
from concurrent.futures import ThreadPoolExecutor
from typing import Callable, Sequence

import numpy as np

from ..batch import _check_workers
from .stepmap import StepMapError

BACKENDS = ("process", "thread", "serial", "dask")

_WORKER = {}          # in a forked worker: family and its map cache
_DASK_MAPS = {}       # in a dask worker: {(pool token, thread): that thread's maps}
_LOCAL = threading.local()


class _Maps:
    """Maps of one family by parameter value (the `size` most recent kept)."""

    def __init__(self, family, size=8):
        self.family, self.size, self.maps = family, size, OrderedDict()

    def get(self, p):
        key = float(p)
        m = self.maps.get(key)
        if m is None:
            m = self.maps[key] = self.family(key)
            while len(self.maps) > self.size:
                self.maps.popitem(last=False)
        else:
            self.maps.move_to_end(key)
        return m


def compose(f, x, period: int):
    """P^period(x) (StepMapError if any step fails)."""
    for _ in range(int(period)):
        x = np.asarray(f(x), dtype=np.float64)
    return x


def jacobian_task(maps: _Maps, item):
    """(P^period(x), its exact Jacobian (d, d)) at item = (p, x, period), the chain rule
    through the steps (StepMap.value_and_jacobian), or None where the walker fails."""
    from .stepmap import StepMapError
    p, x, period = item
    f = maps.get(p)
    y, J = np.asarray(x, dtype=np.float64), np.eye(len(x))
    try:
        for _ in range(int(period)):
            y, Jk = f.value_and_jacobian(y)
            J = Jk @ J
    except StepMapError:
        return None
    return y, J


def evaluate_task(maps: _Maps, item):
    """Worker task: item (p, x, period) -> (P^period(x; p) or None when the walker fails)."""
    p, x, period = item
    try:
        return compose(maps.get(p), np.asarray(x, dtype=np.float64), period)
    except StepMapError:
        return None


def iterate_task(maps: _Maps, item):
    """Worker task: item (p, x0, n, keep, target, tol): iterate up to n steps from x0; return
    (orbit of the last `keep` section points (k, d), steps taken before a fall or n,
    fell bool, distance of the last point to target (NaN without one)). With a target, stops
    as soon as a point comes within tol of it (counted as reaching it)."""
    p, x, n, keep, target, tol = item
    f = maps.get(p)
    x = np.asarray(x, dtype=np.float64)
    kept, fell, k = [], False, 0
    for k in range(1, int(n) + 1):
        try:
            x = np.asarray(f(x), dtype=np.float64)
        except StepMapError:
            fell, k = True, k - 1
            break
        if keep and k > n - keep:
            kept.append(x)
        if target is not None and np.max(np.abs(x - target)) <= tol:
            break
    dist = float(np.max(np.abs(x - target))) if (target is not None and not fell) else np.nan
    return np.array(kept).reshape(len(kept), x.size), k, fell, dist


def _process_init(family, cache):
    # Ctrl-C reaches every process of the terminal's group: the caller alone answers it (and
    # ends the workers), so a worker prints no traceback of its own
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _WORKER["maps"] = _Maps(family, cache)


def _process_run(args):
    task, item = args
    return task(_WORKER["maps"], item)


def _dask_run(token, family, cache, task, items):
    """A chunk of items on a dask worker, on the maps its thread keeps for the pool `token`
    (a walker's simulator is not shared between threads)."""
    key = (token, threading.get_ident())
    maps = _DASK_MAPS.get(key)
    if maps is None:
        maps = _DASK_MAPS[key] = _Maps(family, cache)
    return [task(maps, item) for item in items]


def _dask_forget(token):
    """Drop the maps a dask worker keeps for the pool `token` (its close())."""
    for key in list(_DASK_MAPS):
        if key[0] == token:
            _DASK_MAPS.pop(key, None)


def _dask_client(scheduler):
    """A distributed.Client for an address, or the client given."""
    if not isinstance(scheduler, str):
        return scheduler, False
    try:
        from distributed import Client
    except ImportError:
        raise ImportError("MapPool(scheduler=...) needs dask.distributed: "
                          "pip install 'planarsim[tune]'") from None
    return Client(scheduler), True


class MapPool:
    """Evaluate a family of step maps on `workers` workers (default: every core).

    family : callable p -> step map (a callable x (d,) -> (d,) raising StepMapError when the
        walker fails; a StepMap, or a walker's ``step_map()``). Called in each worker.
    backend : "process" (default), "thread" or "serial" (see the module docstring).
    cache : maps kept per worker (one per parameter value).
    exact : the continuation's multipliers from the maps' exact Jacobians (StepMap.derivative)
        where they have them (None, the default), always (True: an error where one has none)
        or never (False: polynomial fits).
    scheduler : a dask scheduler's address ("tcp://host:8786") or a distributed.Client: the
        evaluations run on its workers' threads (backend "dask"; workers: the chunks a run is
        cut into per thread, default 4). The family must pickle.
    Use as a context manager (or call close()).
    """

    def __init__(self, family: Callable, workers: int | None = None, backend: str | None = None,
                 cache: int = 8, exact: bool | None = None, scheduler=None):
        if backend is None:
            backend = "process" if scheduler is None else "dask"
        if backend not in BACKENDS:
            raise ValueError(f"backend={backend!r} must be one of {BACKENDS}")
        if (backend == "dask") != (scheduler is not None):
            raise ValueError(f"backend={backend!r} with scheduler={scheduler!r}: a dask pool "
                             "is made by giving its scheduler (backend 'dask' or left out)")
        from ..checks import whole       # (cache="8" failed in int() raw, 0 kept no map)
        self.family, self.cache = family, whole("cache", cache, 1)
        self._client, self._own_client = None, False
        if scheduler is not None:
            if workers is not None:
                workers = whole("workers", workers, 1, error=ValueError)
            self._client, self._own_client = _dask_client(scheduler)
            info = self._client.scheduler_info().get("workers", {})
            self.workers = max(1, sum(int(w.get("nthreads", 1)) for w in info.values()))
            self._chunks = 4 if workers is None else int(workers)
            self._token = f"mappool-{uuid.uuid4().hex}"
        else:
            self.workers = _check_workers(workers)
        if self.workers == 1 and backend != "dask":
            backend = "serial"
        if backend == "process" and "fork" not in mp.get_all_start_methods():
            backend = "thread"   # pragma: no cover (no fork on this platform)
        self.backend = backend
        self._local = _Maps(family, cache)    # the caller's own maps (first task, serial)
        self._pool = None
        self.evaluations = 0
        self.use_exact = exact

    # pools --------------------------------------------------------------------------------
    def _ensure(self):
        if self._pool is None:
            if self.backend == "process":
                ctx = mp.get_context("fork")
                self._pool = ctx.Pool(self.workers, initializer=_process_init,
                                      initargs=(self.family, self.cache))
            elif self.backend == "thread":
                self._pool = ThreadPoolExecutor(self.workers)
        return self._pool

    def _thread_maps(self):
        maps = getattr(_LOCAL, "maps", None)
        if maps is None or maps.get("family") is not self.family:
            _LOCAL.maps = {"family": self.family, "maps": _Maps(self.family, self.cache)}
        return _LOCAL.maps["maps"]

    def close(self):
        if self._client is not None:
            try:
                self._client.run(_dask_forget, self._token)
            except Exception:       # (a cluster already gone keeps nothing)
                pass
            if self._own_client:
                self._client.close()
            self._client = None
        if self._pool is not None:
            if self.backend == "process":
                self._pool.terminate()
                self._pool.join()
            else:
                self._pool.shutdown()
            self._pool = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        try:
            self.close()
        except Exception:
            pass

    # running ------------------------------------------------------------------------------
    def run(self, task: Callable, items: Sequence, progress: Callable | None = None) -> list:
        """[task(maps, item) for item in items] on the workers, in order; task must be a
        module-level function (it is sent to the workers by name). progress(done, total) is
        called as results arrive. Until the workers start, the first item runs here first, so
        that a cold numba cache compiles once (and forked workers inherit the compiled code)."""
        items = list(items)
        n = len(items)
        if not n:
            return []
        out = []
        if self.backend == "dask":
            return self._run_dask(task, items, progress)
        if self.backend == "serial" or self._pool is None or n == 1:
            out.append(task(self._local, items[0]))   # warms the numba cache before forking
            if progress:
                progress(1, n)
        rest = items[len(out):]
        if not rest:
            return out
        if self.backend == "serial":
            for i, it in enumerate(rest):
                out.append(task(self._local, it))
                if progress:
                    progress(i + 2, n)
            return out
        pool = self._ensure()
        chunk = max(1, len(rest) // (2 * self.workers))
        k0 = len(out)
        if self.backend == "process":
            it = pool.imap(_process_run, [(task, r) for r in rest], chunksize=chunk)
        else:
            it = pool.map(lambda r: task(self._thread_maps(), r), rest)
        for i, r in enumerate(it):
            out.append(r)
            if progress:
                progress(k0 + i + 1, n)
        return out

    def _run_dask(self, task, items, progress):
        """run() on the dask cluster: the items in chunks (workers x self._chunks of them),
        results in order."""
        from distributed import as_completed
        n = len(items)
        size = max(1, -(-n // (self.workers * self._chunks)))
        chunks = [items[k:k + size] for k in range(0, n, size)]
        futures = [self._client.submit(_dask_run, self._token, self.family, self.cache, task,
                                       c, pure=False) for c in chunks]
        where = {f.key: i for i, f in enumerate(futures)}
        parts, done = [None] * len(chunks), 0
        try:
            for f in as_completed(futures):
                i = where[f.key]
                parts[i] = f.result()
                done += len(parts[i])
                if progress:
                    progress(done, n)
        except BaseException:
            self._client.cancel(futures)      # (an error or Ctrl-C: the rest is not wanted)
            raise
        return [r for part in parts for r in part]

    def evaluate(self, X, p, period: int = 1):
        """P^period(x; p) for every row of X: (Y (n, d) with NaN rows where the walker fell,
        ok (n,) bool)."""
        X = np.atleast_2d(np.asarray(X, dtype=np.float64))
        ps = np.broadcast_to(np.asarray(p, dtype=np.float64), (len(X),))
        res = self.run(evaluate_task, [(float(pi), x, int(period)) for pi, x in zip(ps, X)])
        self.evaluations += len(X) * int(period)
        Y = np.full(X.shape, np.nan)
        ok = np.array([r is not None for r in res], bool)
        for i, r in enumerate(res):
            if r is not None:
                Y[i] = r
        return Y, ok

    def exact(self, p) -> bool:
        """Whether the multipliers at p come from the map's exact Jacobian (the pool's
        `exact` and the map's StepMap.derivative)."""
        if self.use_exact is False:
            return False
        has = bool(getattr(self._local.get(p), "exact", False))
        if self.use_exact and not has:
            raise ValueError(f"MapPool(exact=True): the map at p={p} has no exact Jacobian")
        return has

    def jacobian(self, p, x, period: int = 1):
        """(P^period(x; p), its exact Jacobian), on a worker; StepMapError where the walker
        fails."""
        from .stepmap import StepMapError
        r = self.run(jacobian_task, [(float(p), np.asarray(x, dtype=np.float64), int(period))])[0]
        self.evaluations += int(period)
        if r is None:
            raise StepMapError(f"the step map fails at p={p}, x={x}")
        return r

    def evaluator(self, p, period: int = 1):
        """evaluate(X) -> (Y, ok) at parameter p (for multipliers_with_error)."""
        return lambda X: self.evaluate(X, p, period)

    def map(self, p, period: int = 1):
        """The single map x -> P^period(x; p), evaluated here (StepMapError on a fall)."""
        def f(x):
            return compose(self._local.get(p), np.asarray(x, dtype=np.float64), period)
        return f
