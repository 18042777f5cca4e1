"""Pictures of planarsim runs: drawing, tracking camera, animation export, plots, viewer.

>>> from planarsim.render import export_animation, plot_summary   # doctest: +SKIP
>>> export_animation(traj, model, "walk.mp4", fps=30, speed=0.5)   # slow motion
>>> plot_summary(traj, model, "walk.png")

Nothing here uses numba; matplotlib is imported lazily where a GUI could be involved.
"""
from .camera import Camera, step_overshoot
from .draw import Scene, Style, make_figure, render_state, shape_outline
from .animate import (animation_html, export_animation, ffmpeg_exe, frame_indices, frame_times,
                      show_inline)
from .plots import (cost_of_transport, joint_series, plot_contact_modes, plot_energy,
                    plot_joint_angles, plot_phase_portraits, plot_power, plot_summary, save_figure)
from .viewer import FrameTimer, Viewer, view, view_walker

__all__ = ["Camera", "step_overshoot", "Scene", "Style", "make_figure", "render_state", "shape_outline",
           "animation_html", "export_animation", "ffmpeg_exe", "frame_indices", "frame_times", "show_inline",
           "cost_of_transport", "joint_series", "plot_contact_modes", "plot_energy", "plot_joint_angles",
           "plot_phase_portraits", "plot_power", "plot_summary", "save_figure", "FrameTimer", "Viewer", "view", "view_walker"]
