"""Pictures of planarsim runs: drawing, tracking camera, animation export, plots, viewer.

>>> from planarsim.render import export_animation, plot_summary, show_inline, view   # doctest: +SKIP
>>> export_animation(traj, model, "walk.mp4", fps=30, speed=0.5)   # slow motion; .gif, .html too
>>> plot_summary(traj, model, "walk.png")                          # .png, .svg or .pdf
>>> show_inline(traj, model)                                       # in a Jupyter notebook
>>> view(sim, controller, gains={"kp": (0, 100, get_kp, set_kp)}, on_gait=set_gait)   # live

Modules: draw (Scene: a model drawn from its own shapes), camera (damped second-order
tracking), animate (GIF/MP4/HTML export), plots, viewer (interactive, PI frame timer),
gallery (README GIFs: ``python -m walkers.gallery OUTDIR``); helpers: frames (sampling,
per-frame pixels, worker processes), writers, gif, html, stamps (cached text bitmaps), sides
(which leg a part belongs to), legend. No numba here; pyplot is imported only by the
on-screen viewer.
"""
from .camera import Camera, step_overshoot
from .draw import Scene, Style, make_figure, render_state, shape_outline
from .animate import (animation_html, export_animation, ffmpeg_exe, frame_indices, frame_times,
                      show_inline)
from .plots import (cost_of_transport, joint_series, plot_contact_modes, plot_energy,
                    plot_joint_angles, plot_phase_portraits, plot_position, plot_power, plot_speed,
                    plot_summary, save_figure)
from .viewer import FrameTimer, Viewer, view, view_walker

__all__ = ["Camera", "step_overshoot", "Scene", "Style", "make_figure", "render_state", "shape_outline",
           "animation_html", "export_animation", "ffmpeg_exe", "frame_indices", "frame_times", "show_inline",
           "cost_of_transport", "joint_series", "plot_contact_modes", "plot_energy", "plot_joint_angles",
           "plot_phase_portraits", "plot_position", "plot_power", "plot_speed", "plot_summary", "save_figure", "FrameTimer", "Viewer", "view", "view_walker"]
