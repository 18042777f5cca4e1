"""Plots of gait analysis: multipliers against the unit circle, limit cycles, bifurcation
diagrams, multipliers along a branch, basins of attraction (matplotlib, Agg when saving)."""
from __future__ import annotations

import numpy as np


# plots ---------------------------------------------------------------------------------------
def _axes(ax, figsize=(4.5, 4.5)):
    import matplotlib
    if ax is not None:
        return ax.figure, ax
    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=figsize)
    return fig, ax


def _finish(fig, path):
    if path is not None:
        fig.tight_layout()
        fig.savefig(path, dpi=120)
        import matplotlib.pyplot as plt
        plt.close(fig)
    return fig


def plot_multipliers(multipliers, path=None, ax=None, title="Floquet multipliers", label=None):
    """Multipliers in the complex plane against the unit circle; saved to `path` if given."""
    lam = np.asarray(multipliers, dtype=complex)
    fig, ax = _axes(ax)
    th = np.linspace(0.0, 2.0 * np.pi, 361)
    ax.plot(np.cos(th), np.sin(th), color="0.5", lw=1.0, label="unit circle")
    ax.axhline(0.0, color="0.85", lw=0.8)
    ax.axvline(0.0, color="0.85", lw=0.8)
    ax.plot(lam.real, lam.imag, "x", ms=9, mew=2, color="C3", label=label or "multipliers")
    lim = max(1.2, 1.1 * float(np.max(np.abs(lam))) if lam.size else 1.2)
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_aspect("equal")
    ax.set_xlabel("Re")
    ax.set_ylabel("Im")
    ax.set_title(title)
    ax.legend(loc="upper right", fontsize=8)
    return _finish(fig, path)


def plot_limit_cycle(angle, rate, path=None, ax=None, section=None, labels=("angle [rad]", "rate [rad/s]"),
                     title="limit cycle", **style):
    """Phase portrait (angle vs rate) of a recorded gait; `section` (n, 2) marks the
    Poincare-section points (touchdowns). Saved to `path` if given."""
    fig, ax = _axes(ax, figsize=(5.5, 4.2))
    ax.plot(np.asarray(angle), np.asarray(rate), lw=1.0, **style)
    if section is not None and len(section):
        sec = np.asarray(section)
        ax.plot(sec[:, 0], sec[:, 1], "o", ms=4, color="C3", label="touchdown section")
        ax.legend(fontsize=8)
    ax.set_xlabel(labels[0])
    ax.set_ylabel(labels[1])
    ax.set_title(title)
    return _finish(fig, path)
