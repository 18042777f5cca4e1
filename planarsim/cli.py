"""The `planarsim` command: list, run, view, bench, tune, info.

    planarsim run simple-biped                 # walk, write out/simple-biped.gif + summary
    planarsim run ranger --duration 20 --out ranger.mp4 --plot ranger.png --json
    planarsim list

User errors (unknown walker, bad terrain, negative duration, unwritable path) exit with
code 2 and one line saying what was wrong and what is allowed; no traceback.
"""
from __future__ import annotations

import argparse
import inspect
import json
import math
import os
import sys
import time
from pathlib import Path

from . import __version__

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


def _check_out(path, exts, what):
    if path is None:
        return None
    p = Path(path)
    if p.suffix.lower() not in exts:
        raise UsageError(f"{what} {str(p)!r}: extension must be one of {', '.join(exts)}")
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise UsageError(f"{what} {str(p)!r}: folder {str(parent)!r} does not exist")
    if not os.access(parent, os.W_OK) or (p.exists() and not os.access(p, os.W_OK)):
        raise UsageError(f"{what} {str(p)!r}: not writable")
    return p


def _positive(text):
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not (math.isfinite(x) and x > 0):
        raise argparse.ArgumentTypeError(f"{text} must be a finite number > 0")
    return x


# commands -------------------------------------------------------------------------------------
def cmd_list(args):
    from . import terrain
    w = _walkers()
    print("walkers (gaits):")
    for name in sorted(w.WALKERS):
        try:
            mod = w.load(name)
            default = inspect.signature(mod.simulate).parameters["gait"].default
            gaits = ", ".join(f"{g} (default)" if g == default else g for g in mod.GAITS)
        except Exception as e:  # a broken walker must not hide the others
            gaits = f"unavailable: {e}"
        print(f"  {name:16s} {gaits}")
    print("terrains:")
    print("  flat             level ground")
    print("  slope:DEG        constant slope, DEG degrees (negative: downhill toward +x)")
    print(f"  hills            rolling hills, max slope {terrain.max_slope_deg(terrain.default_hills()):.1f} deg")
    print("  hills:A,L[,PHI][;A,L[,PHI]...]  sum of sines: amplitude m, wavelength m, phase rad")
    return 0


def cmd_run(args):
    from . import terrain as T
    mod = _load_walker(args.walker)
    if args.gait is not None and args.gait not in mod.GAITS:
        raise UsageError(f"walker {args.walker!r} has no gait {args.gait!r}; gaits: {', '.join(mod.GAITS)}")
    try:
        ter = T.parse(args.terrain) if args.terrain else None
    except ValueError as e:
        raise UsageError(str(e)) from None
    if args.dt is not None and args.dt > 0.01:
        raise UsageError(f"--dt {args.dt} is too large; use a step of at most 0.01 s (1e-3 is usual)")
    out = args.out
    summary_path = None
    # --json alone is for scripts: the summary, nothing rendered (ask with --out for a file)
    if out is None and not args.no_animation and not args.json:
        Path("out").mkdir(exist_ok=True)
        out = f"out/{args.walker}.gif"
        summary_path = Path(f"out/{args.walker}_summary.json")
    out = _check_out(out, ANIMATION_EXTS, "--out")
    plot = _check_out(args.plot, PLOT_EXTS, "--plot")
    save = _check_out(args.save, (".npz",), "--save")
    csv = _check_out(args.csv, (".csv",), "--csv")
    kw = dict(duration=args.duration, seed=args.seed)
    if args.gait is not None:
        kw["gait"] = args.gait
    if ter is not None:
        kw["terrain"] = ter
    if args.dt is not None:
        kw["dt"] = args.dt
    from .progress import Elapsed, stderr_is_terminal
    bars = not args.json and stderr_is_terminal()      # progress only where someone watches
    t0 = time.perf_counter()
    if not args.json:
        print(f"running {args.walker} for {args.duration:g} s", file=sys.stderr, flush=True)
    with Elapsed(f"simulating {args.duration:g} s", enabled=bars):
        traj, summary, model = mod.simulate(**kw)
    wall = time.perf_counter() - t0
    default_gait = inspect.signature(mod.simulate).parameters["gait"].default
    own = {"walker": args.walker, "gait": args.gait or default_gait,
           "terrain": args.terrain or "default", "duration_s": args.duration}
    summary = {**own, **{k: _plain(v) for k, v in summary.items() if k not in own},
               "wall_time_s": round(wall, 3)}
    title = f"{args.walker} ({own['gait']} gait) on {getattr(model.terrain, 'name', 'its')} terrain"
    written = []
    if save:
        traj.save(save)
        written.append(str(save))
    if csv:
        with Elapsed(f"writing {csv.name}", enabled=bars):
            traj.to_csv(csv, model)
        written.append(str(csv))
    if plot:
        from .render import plot_summary
        with Elapsed(f"plotting {plot.name}", enabled=bars):
            plot_summary(traj, model, plot, title=title)
        written.append(str(plot))
    if out:
        from .render import export_animation
        from .render.gallery import gait_names
        export_animation(traj, model, out, fps=args.fps, speed=args.speed, progress=bars,
                         label_names=gait_names(mod), summary=summary, title=title)
        written.append(str(out))
    if summary_path is not None:
        from .trajectory import atomic_write
        atomic_write(summary_path, lambda f: f.write(json.dumps(summary, indent=2) + "\n"), binary=False)
        written.append(str(summary_path))
    summary["files"] = written
    if args.json:
        print(json.dumps(summary))
    else:
        for k, v in summary.items():
            print(f"  {k:22s} {v}")
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
    from . import terrain as T
    from .render.viewer import view_walker
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
    from .bench import main
    return main(args.rest) or 0


def cmd_tune(args):
    from .tune import main
    return main(args.rest)


def cmd_info(args):
    import numba
    import numpy
    import matplotlib
    from .kernels import _jit
    kernels = Path(_jit.__file__).resolve().parent
    cached = sorted(kernels.glob("__pycache__/*.nbi"))
    print(f"planarsim {__version__}")
    print(f"python {sys.version.split()[0]}, numpy {numpy.__version__}, numba {numba.__version__}, "
          f"matplotlib {matplotlib.__version__}")
    print(f"numba cache: {len(cached)} kernel index files in {kernels / '__pycache__'}"
          f"{' (cold: the first run compiles, about half a minute)' if not cached else ' (warm)'}")
    try:
        from .render import ffmpeg_exe
        print(f"ffmpeg: {ffmpeg_exe()}")
    except Exception as e:
        print(f"ffmpeg: unavailable ({e})")
    print(f"walkers: {', '.join(sorted(_walkers().WALKERS))}")
    return 0


# parser ---------------------------------------------------------------------------------------
class _Parser(argparse.ArgumentParser):
    """argparse, but a bad argument is one line and a pointer to --help (exit 2), not the whole
    usage first."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def make_parser():
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
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--json", action="store_true", help="print the summary as one JSON object")
    p.set_defaults(func=cmd_run)
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
    p = sub.add_parser("info", help="versions and numba cache state")
    p.set_defaults(func=cmd_info)
    return ap


# commands that leave no thread, process or buffered file behind: as a program of their own they
# end without the interpreter's teardown (freeing numba's compiled code and matplotlib takes
# about 0.35 s, longer than the Simple Biped's whole simulation)
QUICK_EXIT = ("run", "list", "info")


def main(argv=None) -> int:
    """The command line; `argv` None reads sys.argv (and, as the program itself, ends the
    process for the QUICK_EXIT commands once their output is flushed)."""
    program = argv is None
    argv = list(sys.argv[1:] if argv is None else argv)
    code = _main(argv)
    if program and argv and argv[0] in QUICK_EXIT:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):    # a closed pipe (planarsim list | head)
                pass
        os._exit(code)
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
    except KeyboardInterrupt:
        print(f"planarsim {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
