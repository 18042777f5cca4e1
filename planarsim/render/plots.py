"""Plots of a recorded run: position and speed of the centre of mass, joint angles and rates,
energy, actuator power and cost of transport, contact-mode timeline per contact, phase
portraits; saved as PNG, SVG or PDF. The summary figure is titled with walker and terrain.

Joint angle of pin j: theta_b - theta_a - ref [rad] (the engine's definition), rate
omega_b - omega_a [rad/s]. A model without pins (point-mass walkers) shows the angle of each
rod and axial actuator segment a -> b from the downward vertical instead, with its rate
(r x (v_b - v_a)) / |r|^2.

Cost of transport (Kelly 2014, eq. 17): CoT = P / (m g v), with P the actuators' positive
mechanical power sum_i max(P_i, 0) [W] (negative work is not recovered) unless a power series
is given (e.g. Ranger's electrical power); averaged as the positive work over m g times the
distance travelled by the COM.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..measure import cost_of_transport, joint_angles as joint_series  # noqa: F401
from ..trajectory import atomic_write

FIGURE_FORMATS = ("png", "svg", "pdf")
MODE_COLORS = {-1: "#bbbbbb", 0: "#ffffff", 1: "#2ca02c", 2: "#ff7f0e"}
MODE_LABELS = {-1: "disabled", 0: "free", 1: "pinned", 2: "sliding"}


def new_figure(nrows=1, ncols=1, size=(8.0, 4.0), **kw):
    """A figure with an Agg canvas (no GUI needed) and its axes."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    fig = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(nrows, ncols, squeeze=False, **kw)
    return fig, axes


def save_figure(fig, path, dpi: int = 120) -> Path:
    """Save `fig` as PNG, SVG or PDF according to the extension of `path`, atomically."""
    path = Path(path)
    fmt = path.suffix.lower().lstrip(".")
    if fmt not in FIGURE_FORMATS:
        raise ValueError(f"cannot save a figure as {str(path)!r}: extension {path.suffix or '(none)'!r} "
                         f"unknown; use one of {', '.join('.' + f for f in FIGURE_FORMATS)}")
    atomic_write(path, lambda f: fig.savefig(f, format=fmt, dpi=dpi))
    return path


# series: planarsim.measure (joint_series is joint_angles, kept under its old name here)


# single panels -------------------------------------------------------------------------------
def plot_position(traj, model, ax=None):
    """Distance travelled x - x(0) and height y of the centre of mass [m] against time."""
    if ax is None:
        ax = new_figure()[1][0, 0]
    com = traj.com(model)
    if len(com):
        ax.plot(traj.t, com[:, 0] - com[0, 0], label="distance x - x(0)")
        ax.plot(traj.t, com[:, 1], "--", label="height y")
    ax.set_ylabel("position [m]")
    ax.set_xlabel("time [s]")
    ax.set_title("centre of mass: position")
    ax.legend(fontsize=7)
    return ax


def plot_speed(traj, model, ax=None):
    """Forward speed of the centre of mass [m/s] against time, with its mean over the run."""
    if ax is None:
        ax = new_figure()[1][0, 0]
    vx = traj.com_velocity(model)[:, 0]
    ax.plot(traj.t, vx, lw=1.0, label="forward speed")
    if len(vx):
        com = traj.com(model)
        span = traj.t[-1] - traj.t[0]
        mean = (com[-1, 0] - com[0, 0]) / span if span > 0 else float(vx.mean())
        ax.axhline(mean, color="k", lw=0.8, ls=":", label=f"mean {mean:.2f} m/s")
    ax.set_ylabel("speed [m/s]")
    ax.set_xlabel("time [s]")
    ax.set_title("centre of mass: forward speed")
    ax.legend(fontsize=7)
    return ax


def plot_joint_angles(traj, model, ax=None, rate_ax=None):
    """Joint angles [deg] on `ax` and rates [deg/s] on `rate_ax` against time."""
    if ax is None:
        fig, axes = new_figure(2, 1, size=(8, 5), sharex=True)
        ax, rate_ax = axes[0, 0], axes[1, 0]
    for name, (ang, rate) in joint_series(traj, model).items():
        ax.plot(traj.t, np.degrees(ang), label=name)
        if rate_ax is not None:
            rate_ax.plot(traj.t, np.degrees(rate), label=name)
    ax.set_ylabel("angle [deg]")
    ax.set_title("joint angles" if model.n_pin else "segment angles (from vertical)")
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=7, ncols=2)
    if rate_ax is not None:
        rate_ax.set_ylabel("rate [deg/s]")
        rate_ax.set_xlabel("time [s]")
    return ax


def plot_energy(traj, model, ax=None):
    """Kinetic, potential and total mechanical energy [J] against time."""
    if ax is None:
        ax = new_figure()[1][0, 0]
    e = traj.energy(model)
    for key, style in (("kinetic", "-"), ("potential", "--"), ("total", "-")):
        ax.plot(traj.t, e[key], style, label=key, lw=2.0 if key == "total" else 1.2)
    ax.set_ylabel("energy [J]")
    ax.set_xlabel("time [s]")
    ax.set_title("mechanical energy")
    ax.legend(fontsize=7)
    return ax


def plot_power(traj, model, ax=None, cot_ax=None, power=None):
    """Actuator power [W] per actuator and, on `cot_ax`, the instantaneous cost of transport."""
    if ax is None:
        fig, axes = new_figure(2, 1, size=(8, 5), sharex=True)
        ax, cot_ax = axes[0, 0], axes[1, 0]
    for j, name in enumerate(model.act_names):
        ax.plot(traj.t, traj.act_power[:, j], label=name, lw=1.0)
    ax.set_ylabel("power [W]")
    ax.set_title("actuator power" if model.n_act else "actuator power (no actuators)")
    if model.n_act:
        ax.legend(fontsize=7, ncols=2)
    if cot_ax is not None:
        inst, avg = cost_of_transport(traj, model, power)
        cot_ax.plot(traj.t, inst, lw=1.0, color="k")
        cot_ax.set_ylabel("CoT [-]")
        cot_ax.set_xlabel("time [s]")
        cot_ax.set_title(f"cost of transport (average {avg:.3g})" if math.isfinite(avg)
                         else "cost of transport (COM did not move)")
        finite = inst[np.isfinite(inst)]
        if finite.size:
            cot_ax.set_ylim(0, max(1e-3, 3 * np.percentile(finite, 90)))
    return ax


def plot_contact_modes(traj, model, ax=None):
    """One bar per contact coloured by mode (free, pinned, sliding, disabled) against time."""
    if ax is None:
        ax = new_figure(size=(8, 0.5 + 0.35 * max(1, model.n_contact)))[1][0, 0]
    t = traj.t
    edges = np.r_[t, t[-1] + (t[-1] - t[-2] if len(t) > 1 else model.dt)] if len(t) else np.zeros(1)
    for i in range(model.n_contact):
        modes = traj.contact_mode[:, i]
        change = np.flatnonzero(np.diff(modes)) + 1
        starts = np.r_[0, change]
        ends = np.r_[change, len(modes)]
        for s, e in zip(starts, ends):
            mode = int(modes[s])
            if mode == 0:
                continue
            ax.broken_barh([(edges[s], edges[e] - edges[s])], (i - 0.4, 0.8),
                           facecolors=MODE_COLORS.get(mode, "k"))
    ax.set_yticks(range(model.n_contact), model.contact_names, fontsize=7)
    ax.set_ylim(-0.6, model.n_contact - 0.4)
    ax.set_xlim(edges[0], edges[-1])
    ax.set_xlabel("time [s]")
    ax.set_title("contact modes")
    from matplotlib.patches import Patch
    ax.legend(handles=[Patch(facecolor=MODE_COLORS[m], edgecolor="k", label=MODE_LABELS[m]) for m in (1, 2, -1)],
              fontsize=7, loc="upper right", ncols=3)
    return ax


def plot_phase_portraits(traj, model, ax=None, names=None):
    """Rate against angle for each joint (or segment) in `names` (default: all)."""
    if ax is None:
        ax = new_figure(size=(5, 5))[1][0, 0]
    series = joint_series(traj, model)
    for name in (names or series):
        if name not in series:
            raise KeyError(f"phase portrait: no joint or segment named {name!r}; have {list(series)}")
        ang, rate = series[name]
        ax.plot(np.degrees(ang), np.degrees(rate), lw=0.9, label=name)
        if len(ang):
            ax.plot(np.degrees(ang[:1]), np.degrees(rate[:1]), "o", ms=3, color="k")
    ax.set_xlabel("angle [deg]")
    ax.set_ylabel("rate [deg/s]")
    ax.set_title("phase portraits")
    if series:
        ax.legend(fontsize=7)
    return ax


def summary_title(traj, model) -> str:
    """'<walker> on <terrain> terrain' from the trajectory's info and the model's terrain."""
    walker = str(traj.info.get("walker", "")) or "run"
    return f"{walker} on {getattr(model.terrain, 'name', 'terrain')} terrain"


def plot_summary(traj, model, path=None, power=None, size=(11, 14), title=None):
    """All panels on one figure titled `title` (default summary_title); saved to `path`
    (.png/.svg/.pdf) if given. Returns the figure."""
    if path is not None:
        _check_figure_path(path)
    fig, axes = new_figure(5, 2, size=size)
    fig.suptitle(title or summary_title(traj, model))
    plot_position(traj, model, axes[0, 0])
    plot_speed(traj, model, axes[0, 1])
    axes[0, 1].sharex(axes[0, 0])
    ang_ax, rate_ax = axes[1, 0], axes[2, 0]
    rate_ax.sharex(ang_ax)
    plot_joint_angles(traj, model, ang_ax, rate_ax)
    plot_phase_portraits(traj, model, axes[1, 1])
    plot_energy(traj, model, axes[2, 1])
    plot_power(traj, model, axes[3, 0], axes[3, 1], power=power)
    gs = axes[4, 0].get_gridspec()
    for a in axes[4]:
        a.remove()
    plot_contact_modes(traj, model, fig.add_subplot(gs[4, :]))
    if path is not None:
        save_figure(fig, path)
    return fig


def _check_figure_path(path):
    fmt = Path(path).suffix.lower().lstrip(".")
    if fmt not in FIGURE_FORMATS:
        raise ValueError(f"cannot save a figure as {str(path)!r}: extension {Path(path).suffix or '(none)'!r} "
                         f"unknown; use one of {', '.join('.' + f for f in FIGURE_FORMATS)}")
