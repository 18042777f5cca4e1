"""The `planarsim` command: list, run, view, bench, tune, analyze, info.

    planarsim run simple-biped                 # walk, write out/simple-biped.gif + summary
    planarsim run ranger --duration 20 --out ranger.mp4 --plot ranger.png --json
    planarsim list
    planarsim analyze simplest-walker --param slope --range 0.009:0.019 --csv gaits.csv

User errors (unknown walker, bad terrain, negative duration, unwritable path) exit with
code 2 and one line saying what was wrong and what is allowed; no traceback.
"""
from __future__ import annotations

import argparse
import inspect
import json
import math
import os
import re
import sys
import time
from pathlib import Path

ANIMATION_EXTS = (".gif", ".mp4", ".html")
PLOT_EXTS = (".png", ".svg", ".pdf")


class UsageError(Exception):
    """A user mistake: reported in one line, exit code 2."""


def _walkers():
    import walkers
    return walkers


def _load_walker(name):
    w = _walkers()
    if name not in w.WALKERS:
        raise UsageError(f"unknown walker {name!r}; choose one of: {', '.join(sorted(w.WALKERS))}")
    return w.load(name)


def _compile_note() -> str:
    """What the first compile takes on this machine: the last one measured, or, where none was,
    what it takes on a quiet two-core machine."""
    from planarsim.compiled import TYPICAL_COMPILE_S, measured_compile
    last = measured_compile()
    if last is None:
        return (f"about {TYPICAL_COMPILE_S:.0f} s on a quiet two-core machine, longer on a busy "
                "one; not yet measured on this machine")
    return f"the last one measured on this machine took {last:.0f} s"


def _say_if_compiling() -> bool:
    """Before the first simulation on a cold cache: a note on stderr (the engine compiles
    once, and what that took here last time); True when the cache is cold."""
    from planarsim.compiled import kernel_cache     # (NUMBA_CACHE_DIR's, where set)
    if kernel_cache()[1]:
        return False
    print(f"compiling the engine (first run only; {_compile_note()})", file=sys.stderr, flush=True)
    return True


def _said_compiled(seconds: float) -> None:
    """After a first compile: what it took, on stderr, and kept for the next one."""
    from planarsim.compiled import record_compile
    record_compile(seconds)
    print(f"first compile: measured {seconds:.0f} s on this machine (later runs load it from "
          f"numba's cache)", file=sys.stderr, flush=True)


def _check_out(path, exts, what):
    """path as a Path, or a UsageError naming `what` (the flag) unless the file can be written
    there: its extension one of exts, its folder one a file can be made in now."""
    from planarsim.files import folder_refuses
    if path is None:
        return None
    p = Path(path)
    if p.suffix.lower() not in exts:
        raise UsageError(f"{what} {str(p)!r}: extension must be one of {', '.join(exts)}")
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise UsageError(f"{what} {str(p)!r}: folder {str(parent)!r} does not exist")
    if p.is_dir():
        raise UsageError(f"{what} {str(p)!r}: is a folder")
    if not os.access(parent, os.W_OK) or (p.exists() and not os.access(p, os.W_OK)):
        raise UsageError(f"{what} {str(p)!r}: not writable")
    refused = folder_refuses(p)      # (root passes os.access almost everywhere: /proc too)
    if refused:
        raise UsageError(f"{what} {str(p)!r}: not writable ({refused.lower()})")
    return p


def _check_dt(dt):
    """UsageError naming --dt when it is above walkers.base.MAX_DT [s] (None: the walker's
    own). (Imported here: at the module's top it brought numpy in before main could catch
    an interrupt.)"""
    from walkers.base import MAX_DT
    if dt is not None and dt > MAX_DT:
        raise UsageError(f"--dt {dt:g} s is too large; use a step of at most {MAX_DT:g} s (1e-3 "
                         "is usual): the walkers are tuned at 1e-3 s, and at 0.02 s some "
                         "already lose their impacts or stop (Ranger at once)")


def _check_gif_fps(fps):
    """UsageError naming --fps when a GIF at that rate would play slow (render.gif.MAX_GIF_FPS)."""
    from planarsim.render.gif import check_gif_fps
    try:
        check_gif_fps(fps, "--fps ")
    except ValueError as e:
        raise UsageError(str(e)) from None


def _positive(text):
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not (math.isfinite(x) and x > 0):
        raise argparse.ArgumentTypeError(f"{text} must be a finite number > 0")
    return x


def _seed(text):
    """--seed: a whole number >= 0 (numpy's generators take no other)."""
    try:
        x = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if x < 0:
        raise argparse.ArgumentTypeError(f"{text} must be a whole number >= 0")
    return x


# commands -------------------------------------------------------------------------------------
def cmd_list(args):
    from planarsim import terrain
    w = _walkers()
    print("walkers (gaits):")
    for name in sorted(w.WALKERS):
        try:
            mod = w.load(name)
            default = inspect.signature(mod.simulate).parameters["gait"].default
            gaits = ", ".join(f"{g} (default)" if g == default else g for g in mod.GAITS)
        except Exception as e:  # a broken walker must not hide the others
            gaits = f"unavailable: {e}"
        try:
            tunable = w.objective(name) is not None
        except Exception:
            tunable = False
        print(f"  {name:16s} {gaits}{'   [tunable]' if tunable else ''}")
        for gait, doc in getattr(mod, "GAIT_DOCS", {}).items():
            print(f"  {'':16s}   {gait + ':':8s} {doc}")
    print("  (planarsim params WALKER lists a walker's parameters; [tunable]: planarsim tune WALKER)")
    print("terrains:")
    print("  flat             level ground")
    print("  slope:DEG        constant slope, DEG degrees (negative: downhill toward +x)")
    print(f"  hills            rolling hills, max slope {terrain.max_slope_deg(terrain.default_hills()):.1f} deg")
    print("  hills:A,L[,PHI][;A,L[,PHI]...]  sum of sines: amplitude m, wavelength m, phase rad")
    return 0


def _params_path(given, mod):
    """The file of --params: a path, or the name of a set shipped beside the walker's module
    (walkers/<walker>/<name>.json, e.g. ranger's 'efficient')."""
    path = Path(given)
    if path.suffix != ".json" and not path.exists():
        shipped = Path(mod.__file__).resolve().parent / f"{given}.json"
        if shipped.exists():
            return shipped
        names = sorted(p.stem for p in shipped.parent.glob("*.json"))
        raise ValueError(f"--params {given}: no such file, nor a parameter set of this walker "
                         f"(its sets: {', '.join(names) or 'none'})")
    return path


def cmd_run(args):
    from planarsim import terrain as T
    t_load = time.perf_counter()
    mod = _load_walker(args.walker)
    load_s = time.perf_counter() - t_load     # importing the walker (compiles nothing)
    if args.gait is not None and args.gait not in mod.GAITS:
        raise UsageError(f"walker {args.walker!r} has no gait {args.gait!r}; gaits: {', '.join(mod.GAITS)}")
    try:
        ter = T.parse(args.terrain) if args.terrain else None
    except ValueError as e:
        raise UsageError(str(e)) from None
    _check_dt(args.dt)
    changed = _walker_params(mod, args)     # bad parameters are refused before anything is made
    if "slope" in changed and args.terrain:
        raise UsageError("--set slope and --terrain both set the slope; give one of them")
    out = args.out
    summary_path = None
    # --json alone is for scripts: the summary, nothing rendered (ask with --out for a file)
    if out is None and not args.no_animation and not args.json:
        out = f"out/{args.walker}.gif"
        try:
            Path("out").mkdir(exist_ok=True)
        except OSError as e:
            raise UsageError(f"cannot write the default animation {out!r}: no folder 'out' can be "
                             f"made in {os.getcwd()!r} ({e.strerror}); run from a writable folder, "
                             "or give --out FILE.gif, or --no-animation") from None
        summary_path = Path(f"out/{args.walker}_summary.json")
    out = _check_out(out, ANIMATION_EXTS, "--out")
    if out is not None and out.suffix.lower() == ".gif":
        _check_gif_fps(args.fps)
    plot = _check_out(args.plot, PLOT_EXTS, "--plot")
    save = _check_out(args.save, (".npz",), "--save")
    csv = _check_out(args.csv, (".csv",), "--csv")
    _check_out(summary_path, (".json",), "the summary")
    kw = dict(duration=args.duration, seed=args.seed)
    if changed:
        kw["params"] = mod.Params(**{**mod.Params().as_dict(), **changed})
    if args.gait is not None:
        kw["gait"] = args.gait
    if ter is not None:
        kw["terrain"] = ter
    if args.dt is not None:
        kw["dt"] = args.dt
    _check_duration_fits(mod, kw, args.duration)
    from planarsim.progress import Elapsed, stderr_is_terminal
    bars = not args.json and stderr_is_terminal()      # progress only where someone watches
    from walkers.common.summary import walker_summary
    if not args.json:
        print(f"running {args.walker} for {args.duration:g} s", file=sys.stderr, flush=True)
    # a 10 ms run first: compiling (or loading from numba's cache) and building the model,
    # timed apart from the simulation itself
    cold = _say_if_compiling()
    t0 = time.perf_counter()
    import warnings
    with Elapsed("compiling or loading the compiled code", enabled=bars), warnings.catch_warnings():
        warnings.simplefilter("ignore")      # said once, by the run itself
        mod.simulate(**{**kw, "duration": 0.01})
    t1 = time.perf_counter()
    if cold:
        _said_compiled(load_s + t1 - t0)
    with Elapsed(f"simulating {args.duration:g} s", enabled=bars), \
            warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("default")
        traj, raw, model = _simulate_in_chunks(mod, kw)
    for w in said:
        print(f"planarsim run: warning: {w.message}", file=sys.stderr)
    t2 = time.perf_counter()
    wall = {"compile": round(load_s + t1 - t0, 3), "run": round(t2 - t1, 3)}
    gait = args.gait or inspect.signature(mod.simulate).parameters["gait"].default
    terrain_name = getattr(model.terrain, "name", None) or args.terrain or "flat"
    summary = walker_summary(mod, traj, model, raw, walker=args.walker, gait=gait,
                             terrain=terrain_name, duration=args.duration,
                             params_changed=changed, wall=wall)
    title = f"{args.walker} ({gait} gait) on {terrain_name} terrain"
    written = []
    if save:
        traj.save(save)
        written.append(str(save))
    if csv:
        with Elapsed(f"writing {csv.name}", enabled=bars):
            traj.to_csv(csv, model)
        written.append(str(csv))
    if plot:
        from planarsim.render import plot_summary
        with Elapsed(f"plotting {plot.name}", enabled=bars):
            plot_summary(traj, model, plot, title=title)
        written.append(str(plot))
    if out:
        from planarsim.render import export_animation
        from walkers.gallery import gait_names
        export_animation(traj, model, out, fps=args.fps, speed=args.speed, progress=bars,
                         label_names=gait_names(mod), summary=summary, title=title)
        written.append(str(out))
    summary["wall_time_s"]["output"] = round(time.perf_counter() - t2, 3)
    if summary_path is not None:
        written.append(str(summary_path))
    summary["files"] = written     # the summary file lists itself too: the same summary everywhere
    if summary_path is not None:
        from planarsim.trajectory import atomic_write
        atomic_write(summary_path, lambda f: f.write(json.dumps(summary, indent=2) + "\n"), binary=False)
    if args.json:
        print(json.dumps(summary))
    else:
        for k, v in summary.items():
            if isinstance(v, dict) and v:
                print(f"  {k}")
                for sub, x in v.items():
                    print(f"    {sub:32s} {_show(x)}")
            else:
                print(f"  {k:34s} {_show(v)}")
    return 0


RUN_CHUNK_S = 10.0   # [s] simulated per compiled call of `run`: Ctrl-C is answered between calls


def _simulate_in_chunks(mod, kw):
    """mod.simulate(**kw), run RUN_CHUNK_S at a time (bit for bit the same: a walker run
    continues exactly), so that an interrupt is answered within one chunk rather than at the
    end of a long compiled run. Returns (Trajectory, raw summary, Model)."""
    kw = dict(kw)
    duration = float(kw.pop("duration"))
    run = mod.Run(**kw)
    steps = int(round(duration / run.dt))
    chunk = max(1, int(round(RUN_CHUNK_S / run.dt)))
    done = 0
    while done < steps and not run.fell:
        n = min(chunk, steps - done)
        run.run(n * run.dt)
        done += n
    if not run.chunks:
        run.run(0.0)
    traj = run.trajectory()
    gait = kw.get("gait", inspect.signature(mod.simulate).parameters["gait"].default)
    traj.info.update(gait=gait, seed=kw.get("seed", 0))
    return traj, run.summary(), run.model


def _check_duration_fits(mod, kw, duration):
    """UsageError naming --duration (and --dt) when the run would take no step, more than
    walkers.base.MAX_RUN_STEPS, or a recording that cannot fit in this machine's memory
    (checked on the walker's run before anything is compiled or allocated)."""
    from planarsim.errors import RecordingTooLarge
    run = mod.Run(**{k: v for k, v in kw.items() if k != "duration"})
    try:
        run.check_memory(duration, f"--duration {duration:g} s", "; give a longer --duration",
                         "; give a larger --dt or a shorter --duration")
    except RecordingTooLarge as e:
        raise UsageError(f"--duration {duration:g} s at dt={run.dt:g} s would record {e.frames:,} frames, which need "
                         f"{e.nbytes / 2 ** 30:.3g} GiB of memory (this machine has "
                         f"{e.available / 2 ** 30:.3g} GiB); give a shorter --duration") from None
    except ValueError as e:         # walkers.base.run_steps: no step, or more than MAX_RUN_STEPS
        raise UsageError(str(e)) from None


def _show(v):
    """A summary value for people: floats to 4 significant digits."""
    return f"{v:.4g}" if isinstance(v, float) else v


def _walker_params(mod, args) -> dict:
    """{name: value} of the walker's parameters changed by --params FILE, then --set NAME=VALUE
    (later wins); ValueError naming the culprit (the CLI prints it and exits 2)."""
    from walkers.common.params import load_values, parse_assignments
    changed = {}
    if args.params:
        changed.update(load_values(_params_path(args.params, mod), mod.Params))
    changed.update(parse_assignments(args.set or (), mod.Params))
    defaults = mod.Params().as_dict()
    return {k: v for k, v in changed.items() if v != defaults[k]}


def cmd_params(args):
    mod = _load_walker(args.walker)
    rows = mod.Params.table()
    if args.json:
        print(json.dumps(rows))
        return 0
    print(f"{args.walker} parameters ({mod.Params.__name__}); change with "
          f"'planarsim run {args.walker} --set NAME=VALUE' or '--params FILE.json'; "
          "* = varied by planarsim tune")
    width = max(len(r["name"]) for r in rows)
    for r in rows:
        bounds = f"[{r['lower']:g}, {r['upper']:g}]"
        print(f"  {'*' if r['tunable'] else ' '} {r['name']:{width}s} {r['default']!s:>10} "
              f"{r['unit']:10s} {bounds:20s} {r['doc']}")
    return 0


def _plain(v):
    """JSON-friendly value: numpy scalars and arrays to Python, NaN and inf to None."""
    if isinstance(v, float) and not math.isfinite(v):
        return None
    try:
        import numpy as np
        if isinstance(v, np.generic):
            return _plain(v.item())
        if isinstance(v, np.ndarray):
            return v.tolist()
    except ImportError:
        pass
    return v


def _has_display() -> bool:
    """Whether an interactive window can open: on Linux a DISPLAY or WAYLAND_DISPLAY, and a
    matplotlib backend that is not a file-only one (MPLBACKEND=Agg, say)."""
    if sys.platform.startswith("linux") and not (os.environ.get("DISPLAY")
                                                 or os.environ.get("WAYLAND_DISPLAY")):
        return False
    backend = os.environ.get("MPLBACKEND", "").lower()
    return backend not in ("agg", "pdf", "ps", "svg", "pgf", "cairo", "template")


def cmd_view(args):
    mod = _load_walker(args.walker)
    if not _has_display():
        raise UsageError(f"no display to open the viewer on (no DISPLAY, or a file-only "
                         f"matplotlib backend); use 'planarsim run {args.walker} --out "
                         f"{args.walker}.gif' to watch it")
    from planarsim import terrain as T
    from planarsim.render.viewer import view_walker
    try:
        ter = T.parse(args.terrain) if args.terrain else None
    except ValueError as e:
        raise UsageError(str(e)) from None
    try:
        view_walker(mod, gait=args.gait, terrain=ter)
    except NotImplementedError as e:
        raise UsageError(f"{e}; use 'planarsim run {args.walker} --out FILE.gif' to watch it") from None
    return 0


def cmd_bench(args):
    from benchmarks.runner import main
    return main(args.rest) or 0


def cmd_tune(args):
    from walkers.tune import main
    return main(args.rest)


def cmd_info(args):
    import numba
    import numpy
    import matplotlib
    from planarsim import __version__
    from planarsim.compiled import kernel_cache
    folder, cached = kernel_cache()
    print(f"planarsim {__version__}")
    print(f"python {sys.version.split()[0]}, numpy {numpy.__version__}, numba {numba.__version__}, "
          f"matplotlib {matplotlib.__version__}")
    print(f"numba cache: {len(cached)} kernel index files in {folder}"
          f"{f' (cold: the first run compiles; {_compile_note()})' if not cached else ' (warm)'}")
    try:
        from planarsim.render import ffmpeg_exe
        print(f"ffmpeg: {ffmpeg_exe()}")
    except Exception as e:
        print(f"ffmpeg: unavailable ({e})")
    print(f"walkers: {', '.join(sorted(_walkers().WALKERS))}")
    return 0


# analyze ---------------------------------------------------------------------------------------
def _analysis_family(args):
    """The walker's step-map family in --param (one-line UsageError on bad input)."""
    w = _walkers()
    if args.walker not in w.WALKERS:
        raise UsageError(f"unknown walker {args.walker!r}; choose one of: {', '.join(sorted(w.WALKERS))}")
    from walkers.passive import family as fam
    if args.walker not in fam.PARAMS:
        raise UsageError(f"walker {args.walker!r} has no step-to-step map family for analysis; "
                         f"walkers with one: {', '.join(sorted(fam.PARAMS))}")
    if args.param not in fam.param_names(args.walker):
        raise UsageError(f"{args.walker} has no parameter {args.param!r}; parameters: "
                         f"{', '.join(fam.param_names(args.walker))}")
    try:
        a, b = (float(v) for v in args.range.split(":"))
    except ValueError:
        raise UsageError(f"--range {args.range!r} must be A:B, two numbers (e.g. 0.009:0.019)") from None
    lo, hi = fam.param_bounds(args.walker, args.param)
    if not (math.isfinite(a) and math.isfinite(b)) or a == b:
        raise UsageError(f"--range {args.range!r} must be two different finite numbers")
    if not (lo <= min(a, b) and max(a, b) <= hi):
        raise UsageError(f"--range {args.range!r} leaves the bounds of {args.param}: [{lo}, {hi}]")
    _check_dt(args.dt)
    from walkers.passive.gait import check_map_dt
    try:       # a step map evaluation runs up to 20 s: at --dt 1e-9 that never ends
        dt = check_map_dt(args.dt or 1e-3, "--dt")
    except ValueError as e:
        raise UsageError(str(e)) from None
    return fam.WalkerFamily(args.walker, args.param, dt=dt), a, b


def cmd_analyze(args):
    """Continuation of the period-one gait in one parameter (multipliers, bifurcations,
    period-2 after a doubling) or a brute-force bifurcation diagram; CSV and plot."""
    import numpy as np
    from planarsim.analysis import (MapPool, StepMapError, bifurcation_diagram, continue_branch,
                           period_doubling_branch, plot_bifurcation_diagram, plot_branch_multipliers)
    from planarsim.render.animate import TextProgress
    family, a, b = _analysis_family(args)
    if args.points < 2:
        raise UsageError(f"--points {args.points} must be at least 2")
    if args.transient < 0:
        raise UsageError(f"--transient {args.transient} must be >= 0 (steps dropped before the "
                         "section values are kept)")
    if args.keep < 2:
        raise UsageError(f"--keep {args.keep} must be at least 2 (a period is found among the "
                         "section values kept)")
    csv = _check_out(args.csv, (".csv",), "--csv")
    plot = _check_out(args.plot, PLOT_EXTS, "--plot")
    bar = TextProgress(args.points, "points")
    progress = None if args.quiet else (lambda done, total: bar(min(done, bar.total)))
    x0 = family.guess(a)
    t0 = time.perf_counter()
    with MapPool(family, workers=args.workers, exact=bool(args.exact)) as pool:
        if args.diagram:
            # each value started from the period-1 gait nearest to it, continued over the range
            # (from one guess at the range's start, a slope past the first doubling fell)
            try:
                start = continue_branch(pool, x0, a, b, args.points, method=args.method,
                                        param=args.param).nearest
            except StepMapError:
                start = family.guess
            d = bifurcation_diagram(pool, np.linspace(a, b, args.points), start, args.transient,
                                    args.keep, param=args.param, progress=progress)
            periods = d.periods()
            for p, k, fell in zip(d.p, periods, d.fell):
                print(f"  {args.param} = {p:.6g}: " + ("fell" if fell else
                      f"period {k}" if k > 0 else f"no period up to {args.keep // 2} (chaos?)"))
            onset = d.fall_onset()
            print(f"falls from {args.param} = {onset:.6g}" if onset is not None else "no falls in the range")
            if csv:
                d.to_csv(csv, 0, family.names[0])
            if plot:
                plot_bifurcation_diagram(d, 0, plot, label=f"{family.names[0]} at touchdown",
                                         title=f"{args.walker}: bifurcation diagram")
        else:
            try:
                br = continue_branch(pool, x0, a, b, args.points, method=args.method,
                                     param=args.param, progress=progress)
            except StepMapError as e:
                raise UsageError(f"no gait to continue: {e}") from None
            branches = [br]
            pd = br.first("period-doubling")
            if pd is not None and args.follow:
                try:
                    branches.append(period_doubling_branch(pool, pd, b, max(4, args.points // 2),
                                                           param=args.param))
                except StepMapError as e:
                    print(f"  period-2 orbit not followed: {e}", file=sys.stderr)
            for k in branches:
                print(f"period-{k.period} branch: {len(k.points)} points, {k.end}")
                for bf in k.bifurcations:
                    print(f"  {bf.kind} at {args.param} = {bf.p:.9g}"
                          f"{'' if bf.located else f' (not located: within {bf.bracket:.2g})'}"
                          f"{f' (+- {bf.p_error:.1g} from the multipliers error)' if bf.located and math.isfinite(bf.p_error) and bf.p_error > bf.bracket else ''}")
                    if bf.note:
                        print(f"    {bf.note}")
            if csv:
                from planarsim.analysis import write_csv
                write_csv(csv, [r for k in branches for r in k.rows(family.names)])
            if plot:
                if plot.with_suffix("").name.endswith("_multipliers"):
                    plot_branch_multipliers(br, plot)
                else:
                    allb = [bf for k in branches for bf in k.bifurcations]
                    plot_bifurcation_diagram(None, 0, plot, branches=branches, bifurcations=allb,
                                             label=f"{family.names[0]} at touchdown",
                                             title=f"{args.walker}: gaits along {args.param}")
    print(f"({time.perf_counter() - t0:.1f} s, {pool.evaluations} step-map evaluations on "
          f"{pool.workers} worker{'s' if pool.workers != 1 else ''})" + (f"; wrote {', '.join(str(p) for p in (csv, plot) if p)}" if csv or plot else ""))
    return 0


# parser ---------------------------------------------------------------------------------------
class _Parser(argparse.ArgumentParser):
    """argparse, but a bad argument is one line and a pointer to --help (exit 2), not the whole
    usage first."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        # "-1e-3" is a (negative) number, not an option, as newer Pythons' argparse reads it:
        # "--dt -1e-3" is then refused by --dt's own check, naming it
        self._negative_number_matcher = re.compile(r"^-\.?\d")

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def make_parser():
    from planarsim import __version__
    ap = _Parser(prog="planarsim", description="Planar physics for walking machines.")
    ap.add_argument("--version", action="version", version=f"planarsim {__version__}")
    sub = ap.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    p = sub.add_parser("list", help="walkers, gaits and terrains")
    p.set_defaults(func=cmd_list)
    p = sub.add_parser("run", help="simulate a walker; write animation, plots, data, summary")
    p.add_argument("walker", help="walker name (see 'planarsim list')")
    p.add_argument("--gait", default=None,
                   help="gait (default: the walker's default, marked in 'planarsim list')")
    p.add_argument("--terrain", default=None, help="flat | slope:DEG | hills | hills:A,L[,PHI][;...]")
    p.add_argument("--duration", type=_positive, default=10.0, help="simulated seconds (default 10)")
    p.add_argument("--dt", type=_positive, default=None, help="step size [s] (default: walker's)")
    p.add_argument("--out", default=None, help="animation .gif | .mp4 | .html (default out/WALKER.gif)")
    p.add_argument("--no-animation", action="store_true",
                   help="skip the default animation (out/WALKER.gif; --json alone skips it too)")
    p.add_argument("--fps", type=_positive, default=20.0, help="animation frames per second")
    p.add_argument("--speed", type=_positive, default=1.0, help="playback speed (0.25 slow motion)")
    p.add_argument("--plot", default=None, help="summary plot .png | .svg | .pdf")
    p.add_argument("--save", default=None, help="trajectory .npz")
    p.add_argument("--csv", default=None, help="trajectory .csv (SI units in the column names)")
    p.add_argument("--seed", type=_seed, default=0,
                   help="seed of the start perturbation of walkers that have one (simple-biped, quadruped), a whole number >= 0 (0: none)")
    p.add_argument("--json", action="store_true", help="print the summary as one JSON object")
    p.add_argument("--set", action="append", metavar="NAME=VALUE",
                   help="change a walker parameter (repeatable; see 'planarsim params WALKER')")
    p.add_argument("--params", default=None, metavar="FILE.json|NAME",
                   help="walker parameters from a file: a 'planarsim tune' result or "
                        "{\"name\": value, ...}, or a set shipped with the walker by name "
                        "(ranger: efficient) (--set wins over it)")
    p.set_defaults(func=cmd_run)
    p = sub.add_parser("params", help="a walker's parameters: units, bounds, defaults")
    p.add_argument("walker", help="walker name (see 'planarsim list')")
    p.add_argument("--json", action="store_true", help="as one JSON list")
    p.set_defaults(func=cmd_params)
    p = sub.add_parser("view", help="interactive viewer (needs a display)")
    p.add_argument("walker")
    p.add_argument("--gait", default=None)
    p.add_argument("--terrain", default=None, help="flat | slope:DEG | hills | hills:A,L[,PHI][;...]")
    p.set_defaults(func=cmd_view)
    p = sub.add_parser("bench", help="engine benchmarks (planarsim bench --help)", add_help=False)
    p.add_argument("rest", nargs=argparse.REMAINDER)
    p.set_defaults(func=cmd_bench)
    p = sub.add_parser("tune", help="CMA-ES tuning of a walker (planarsim tune --help)", add_help=False)
    p.add_argument("rest", nargs=argparse.REMAINDER)
    p.set_defaults(func=cmd_tune)
    p = sub.add_parser("analyze", help="gaits along a parameter: continuation, bifurcations, diagram")
    p.add_argument("walker", help="walker with a step-to-step map (the passive walkers)")
    p.add_argument("--param", required=True, help="parameter to vary (e.g. slope)")
    p.add_argument("--range", required=True, help="A:B, the parameter's range")
    p.add_argument("--points", type=int, default=20, help="points along the range (default 20)")
    p.add_argument("--method", choices=("natural", "arclength"), default="natural",
                   help="continuation method (arclength passes folds)")
    p.add_argument("--diagram", action="store_true",
                   help="brute-force bifurcation diagram instead (iterate, keep the last values)")
    p.add_argument("--transient", type=int, default=200, help="--diagram: steps dropped")
    p.add_argument("--keep", type=int, default=32, help="--diagram: section values kept")
    p.add_argument("--no-follow", dest="follow", action="store_false",
                   help="do not follow the period-2 orbit after a period doubling")
    p.add_argument("--dt", type=_positive, default=None, help="step size [s] (default 1e-3)")
    p.add_argument("--workers", type=int, default=None, help="worker processes (default: all cores)")
    p.add_argument("--exact", action="store_true",
                   help="multipliers from the step map's exact Jacobian (slower: seconds a "
                        "point) instead of polynomial fits")
    p.add_argument("--csv", default=None, help="results .csv")
    p.add_argument("--plot", default=None,
                   help="plot .png | .svg | .pdf (a name ending in _multipliers: the multipliers)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_analyze)
    p = sub.add_parser("info", help="versions and numba cache state")
    p.set_defaults(func=cmd_info)
    return ap


# commands that leave no thread, process or buffered file behind: as a program of their own they
# end without the interpreter's teardown (freeing numba's compiled code and matplotlib takes
# about 0.35 s, longer than the Simple Biped's whole simulation)
QUICK_EXIT = ("run", "list", "info")


class _ReaderMayLeave:
    """stdout whose reader may stop reading (planarsim analyze ... | head): the text it no
    longer wants is dropped and the command carries on, so the files it was asked for are
    still written. Any other write error is raised."""

    def __init__(self, stream):
        self._stream = stream
        self.reader_left = False

    def write(self, text):
        if not self.reader_left:
            try:
                return self._stream.write(text)
            except BrokenPipeError:
                self.reader_left = True
        return len(text)

    def flush(self):
        if not self.reader_left:
            try:
                self._stream.flush()
            except BrokenPipeError:
                self.reader_left = True

    def __getattr__(self, name):
        return getattr(self._stream, name)


def main(argv=None) -> int:
    """The command line; `argv` None reads sys.argv (and, as the program itself, ends the
    process for the QUICK_EXIT commands once their output is flushed). Ctrl-C at any moment,
    the imports and the first compile included, prints one line and returns (as the program:
    exits with) 130."""
    program = argv is None
    argv = list(sys.argv[1:] if argv is None else argv)
    stdout = sys.stdout
    if program:
        _exit_on_interrupt(argv, stdout)
    try:
        code = _serve(argv, stdout)
    except KeyboardInterrupt:
        code = _interrupted(argv, stdout, program)
    if program and (code == INTERRUPTED or argv and argv[0] in QUICK_EXIT):
        sys.stderr.flush()
        os._exit(code)
    return code


INTERRUPTED = 130       # the exit code of a command ended by Ctrl-C (128 + SIGINT)


def _exit_on_interrupt(argv, stdout) -> None:
    """As the program: Ctrl-C writes its one line and ends the process at once, from wherever
    it lands. A KeyboardInterrupt raised inside a callback from compiled code (numba's
    compiler calls Python back through ctypes) would be printed and swallowed there, and the
    command would go on."""
    import signal

    def handler(signum, frame):
        _interrupted(argv, stdout, True)
        os._exit(INTERRUPTED)
    signal.signal(signal.SIGINT, handler)


def _interrupted(argv, stdout, program) -> int:
    """One line for an interrupt, wherever it came; as the program, later interrupts are
    ignored while that line is written (the process then ends without its teardown)."""
    if program:
        import signal
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    sys.stdout = stdout
    command = argv[0] if argv and not argv[0].startswith("-") else None
    print(f"planarsim{' ' + command if command else ''}: interrupted", file=sys.stderr, flush=True)
    return INTERRUPTED


def _serve(argv, stdout) -> int:
    """_main with stdout guarded against a reader that leaves (_ReaderMayLeave)."""
    sys.stdout = _ReaderMayLeave(stdout)
    code = 1
    try:
        code = _main(argv)
        sys.stdout.flush()
    except OSError as e:      # stdout itself failed (a full disk under > file): not silent
        print(f"planarsim: error: cannot write the output: {e}", file=sys.stderr)
        code = code if code else 1
    finally:
        left = sys.stdout.reader_left
        sys.stdout = stdout
    if left:
        # nothing more may reach the closed pipe, not even at the interpreter's exit
        os.dup2(os.open(os.devnull, os.O_WRONLY), stdout.fileno())
    return code


def _main(argv) -> int:
    # bench and tune own their options (including --help)
    if argv and argv[0] in ("bench", "tune"):
        argv = [argv[0], "--", *argv[1:]] if len(argv) > 1 and argv[1].startswith("-") else argv
    ap = make_parser()
    args = ap.parse_args(argv)
    if getattr(args, "rest", None) and args.rest[:1] == ["--"]:
        args.rest = args.rest[1:]
    try:
        return int(args.func(args) or 0)
    except UsageError as e:
        print(f"planarsim {args.command}: error: {e}", file=sys.stderr)
        return 2
    except (OSError, ValueError) as e:
        # bad input detected deeper down (ModelError is a ValueError): one line, exit 2
        print(f"planarsim {args.command}: error: {e}", file=sys.stderr)
        return 2
    except MemoryError as e:
        # an allocation no check foresaw: one line, not numpy's traceback
        print(f"planarsim {args.command}: error: not enough memory: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
