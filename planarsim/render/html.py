"""A self-contained HTML page that plays an animation: centred, titled, with the run's
summary beside the player, starting to play when it opens.

The player is matplotlib's JavaScript animation player (play/pause, frame slider, speed,
loop modes) with its frames embedded as base64 PNG; its buttons' Font Awesome icons (fetched
from the net) become plain characters, so the page works offline.
"""
from __future__ import annotations

import html
import re
import uuid

# matplotlib's player draws its buttons with icons from a CDN; the page must work offline
_ICONS = {"fa-minus": "&minus;", "fa-fast-backward": "|&#9664;&#9664;", "fa-step-backward": "|&#9664;",
          "fa-play fa-flip-horizontal": "&#9664;", "fa-pause": "&#10074;&#10074;", "fa-play": "&#9654;",
          "fa-step-forward": "&#9654;|", "fa-fast-forward": "&#9654;&#9654;|", "fa-plus": "+"}

_PAGE_STYLE = """<style>
body { font-family: sans-serif; margin: 1.5em; color: #222; }
h1 { text-align: center; font-size: 1.4em; font-weight: normal; }
.planarsim-run { display: flex; justify-content: center; align-items: flex-start; gap: 2em; }
@media (max-width: 60em) { .planarsim-run { flex-wrap: wrap; } }
.planarsim-summary { border-collapse: collapse; font-size: 0.9em; max-width: 24em; }
.planarsim-summary td { overflow-wrap: anywhere; }
.planarsim-summary th { text-align: left; padding: 2px 1em 2px 0; font-weight: normal; color: #555; }
.planarsim-summary td { text-align: right; padding: 2px 0; font-family: monospace; }
</style>"""


def self_contained(fragment: str) -> str:
    """matplotlib's HTML animation without its external stylesheet (icons as characters)."""
    fragment = re.sub(r'<link rel="stylesheet"\s+href="[^"]*font-awesome[^"]*">', "", fragment)
    for cls, text in _ICONS.items():
        fragment = fragment.replace(f'<i class="fa {cls}"></i>', text)
    return fragment


def player_fragment(frames_b64, fps: float, autoplay: bool = True, mode: str = "loop") -> str:
    """The player (a <div> and its scripts) for frames given as base64 PNG strings."""
    from matplotlib._animation_data import DISPLAY_TEMPLATE, JS_INCLUDE, STYLE_INCLUDE
    uid = uuid.uuid4().hex
    fill = "\n" + "".join(f'  frames[{i}] = "data:image/png;base64,{b}"\n' for i, b in enumerate(frames_b64))
    checked = {f"{m}_checked": ("checked" if m == mode else "") for m in ("once", "loop", "reflect")}
    body = DISPLAY_TEMPLATE.format(id=uid, Nframes=len(frames_b64), fill_frames=fill,
                                   interval=max(1, int(round(1000.0 / fps))), **checked)
    start = ""
    if autoplay:   # after the player's own setTimeout(0) has made anim<id>
        start = (f'<script language="javascript">\n  setTimeout(function() {{ if (typeof anim{uid} !== '
                 f'"undefined") anim{uid}.play_animation(); }}, 20);\n</script>\n')
    return self_contained(JS_INCLUDE + STYLE_INCLUDE + body + start)


def summary_table(summary: dict) -> str:
    """The summary as a two-column HTML table (nested values as JSON)."""
    rows = []
    for key, val in summary.items():
        if isinstance(val, float):
            text = f"{val:.4g}"
        elif isinstance(val, dict):
            text = ", ".join(f"{k} {v}" for k, v in val.items())
        elif isinstance(val, (list, tuple)):
            text = ", ".join(str(v) for v in val)
        else:
            text = str(val)
        rows.append(f"<tr><th>{html.escape(str(key))}</th><td>{html.escape(text)}</td></tr>")
    return '<table class="planarsim-summary">\n' + "\n".join(rows) + "\n</table>"


def player_page(frames_b64, fps: float, title: str = "planarsim", summary: dict | None = None,
                autoplay: bool = True) -> str:
    """A complete offline page: heading `title`, the player and, beside it, the summary."""
    side = summary_table(summary) if summary else ""
    return ("<!DOCTYPE html>\n<html>\n<head>\n<meta charset=\"utf-8\">\n"
            f"<title>{html.escape(title)} - planarsim</title>\n{_PAGE_STYLE}\n</head>\n<body>\n"
            f"<h1>{html.escape(title)}</h1>\n<div class=\"planarsim-run\">\n"
            f"<div class=\"planarsim-player\">\n{player_fragment(frames_b64, fps, autoplay)}\n</div>\n"
            f"{side}\n</div>\n</body>\n</html>\n")
