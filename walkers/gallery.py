"""Make one small GIF per registered walker (for the README), with the walkers' own simulate().

    python -m walkers.gallery docs/gifs --duration 6 --fps 15 --width 480

Each walker package registered in ``walkers.WALKERS`` is run with its first gait that walks
(``walk`` if it has one) on flat ground and rendered with the tracking camera. The files are
outputs: regenerate them with this command rather than committing large media.
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from planarsim.progress import stderr_is_terminal
from planarsim.render.animate import export_animation


def gait_names(module) -> dict:
    """{label: {value: name}} for the overlay, from the walker's Gait/State enums if present."""
    names = {}
    for label, attr in (("gait", "Gait"), ("state", "State")):
        enum = getattr(module, attr, None)
        if enum is not None:
            try:
                names[label] = {int(e): e.name for e in enum}
            except (TypeError, ValueError):
                pass
    return names


def make_gif(name, out_dir, duration=6.0, fps=15.0, width_px=480, speed=1.0, progress=True) -> Path:
    """Simulate walker `name` for `duration` [s] and write ``out_dir/<name>.gif``."""
    import walkers
    module = walkers.load(name)
    gaits = tuple(getattr(module, "GAITS", ()))
    gait = "walk" if "walk" in gaits else (gaits[0] if gaits else None)
    kwargs = {"gait": gait} if gait is not None else {}
    traj, summary, model = module.simulate(duration, **kwargs)
    dpi = 80
    size = (width_px / dpi, width_px * 9 / 16 / dpi)
    out = Path(out_dir) / f"{name}.gif"
    export_animation(traj, model, out, fps=fps, speed=speed, size=size, dpi=dpi, progress=progress,
                     label_names=gait_names(module))
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m walkers.gallery", description=__doc__.splitlines()[0])
    ap.add_argument("out_dir", type=Path)
    ap.add_argument("--duration", type=float, default=6.0, help="simulated seconds per walker")
    ap.add_argument("--fps", type=float, default=15.0)
    ap.add_argument("--width", type=int, default=480, help="GIF width in pixels (height 9/16 of it)")
    ap.add_argument("--walker", action="append", help="only these walkers (repeatable)")
    args = ap.parse_args(argv)
    import walkers
    if not args.out_dir.is_dir():
        ap.error(f"output folder {str(args.out_dir)!r} does not exist")
    for flag, value in (("--duration", args.duration), ("--fps", args.fps)):
        if not (math.isfinite(value) and value > 0.0):
            ap.error(f"{flag} {value} must be a positive number")
    from planarsim.render.gif import check_gif_fps
    try:
        check_gif_fps(args.fps, "--fps ")
    except ValueError as e:
        ap.error(str(e))
    if args.width < 16:
        ap.error(f"--width {args.width} must be at least 16 pixels")
    names = args.walker or sorted(walkers.WALKERS)
    unknown = [n for n in names if n not in walkers.WALKERS]
    if unknown:
        ap.error(f"unknown walker(s) {unknown}; known: {sorted(walkers.WALKERS)}")
    failed = 0
    for name in names:
        try:
            out = make_gif(name, args.out_dir, args.duration, args.fps, args.width,
                           progress=stderr_is_terminal())
            print(f"{name}: {out} ({out.stat().st_size / 1024:.0f} KiB)")
        except Exception as e:  # one broken walker should not stop the others
            failed += 1
            print(f"{name}: failed: {type(e).__name__}: {e}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
