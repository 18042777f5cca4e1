"""Test models and picture helpers of the render tests (a box, a pendulum; pixels of a drawn
scene)."""
import os

import numpy as np

import planarsim as ps
from planarsim.render import Scene, Style, make_figure

RED = (1.0, 0.0, 0.0)
BLUE = (0.0, 0.0, 1.0)


def box_model(pos=(0.0, 0.1), vel=(0.0, 0.0), mu=0.8, width=0.8, height=0.2, push=False):
    b = ps.ModelBuilder(dt=1e-3)
    box = b.add_body("box", mass=2.0, inertia=2.0 * (width ** 2 + height ** 2) / 12, pos=pos, vel=vel)
    b.add_box_contacts("corner", box, (0.0, 0.0), width, height, mu=mu)
    if push:
        b.add_body_force("push", box, direction=(1.0, 0.0))
    return b.compile()


def pendulum_model(length=1.0, pivot=(0.0, 1.5), motor=True):
    b = ps.ModelBuilder(dt=1e-3)
    rod = b.add_body("rod", mass=1.0, inertia=length ** 2 / 12, pos=(pivot[0] + length / 2, pivot[1]),
                     shapes=[("capsule", (-length / 2, 0.0), (length / 2, 0.0), 0.03)])
    b.add_pin("pivot", None, rod, anchor_world=pivot)
    if motor:
        b.add_pin_motor("motor", "pivot", limit=(-100.0, 100.0))
    return b.compile()


def red_style(**kw):
    return Style(body_colors=("#ff0000",), edge_color="#ff0000", body_alpha=1.0, tick_color="#0000ff",
                 terrain_color="#00ff00", ground_fill="#ffffff", **kw)


def render(model, q, center, view_width=4.0, size=(6.4, 3.6), dpi=100, **kw):
    fig, ax = make_figure(size, dpi)
    # geometry only: the legend's force arrow is red too
    scene = Scene(model, ax, view_width=view_width, show_com=False, show_text=False, show_legend=False,
                  style=red_style(), **kw)
    scene.draw_state(q, center=center)
    fig.canvas.draw()
    img = np.asarray(fig.canvas.buffer_rgba())[:, :, :3].astype(int)
    return img, scene


def to_pixels(scene, xy):
    """Data -> image pixel (column, row from the top)."""
    x0, x1 = scene.ax.get_xlim()
    y0, y1 = scene.ax.get_ylim()
    fig = scene.ax.figure
    w, h = fig.canvas.get_width_height()
    xy = np.asarray(xy, float).reshape(-1, 2)
    return np.column_stack([(xy[:, 0] - x0) / (x1 - x0) * w, (y1 - xy[:, 1]) / (y1 - y0) * h])


def default_file_mode():
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask


def mask(img, rgb):
    target = np.array(rgb) * 255
    return np.all(np.abs(img - target) < 60, axis=2)


def _legged_model():
    b = ps.ModelBuilder(dt=1e-3)
    hip = b.add_point_mass("hip", 5.0, pos=(0.0, 1.0), radius=0.05)
    f0 = b.add_point_mass("foot_left", 0.5, pos=(-0.2, 0.05), radius=0.04)
    f1 = b.add_point_mass("foot_right", 0.5, pos=(0.2, 0.05), radius=0.04)
    b.add_axial("leg_left", hip, f0)
    b.add_axial("leg_right", hip, f1)
    return b.compile()


def _two_body_model():
    b = ps.ModelBuilder()
    b.add_point_mass("a", 1.0, pos=(0, 1))
    b.add_point_mass("b", 1.0, pos=(1, 1))
    return b.compile()
