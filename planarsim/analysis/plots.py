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


def plot_bifurcation_diagram(diagram, coordinate: int = 0, path=None, ax=None, branches=(),
                             label=None, title="bifurcation diagram", bifurcations=()):
    """Kept section values against the parameter (dots), fixed-point branches on top
    (solid where stable, dashed where unstable), bifurcations marked; `diagram` may be None."""
    fig, ax = _axes(ax, figsize=(7.0, 4.5))
    if diagram is not None:
        for p, orb in zip(diagram.p, diagram.orbits):
            if len(orb):
                ax.plot(np.full(len(orb), p), orb[:, coordinate], ".", ms=1.5, color="k")
        onset = diagram.fall_onset()
        if onset is not None:
            ax.axvline(onset, color="C3", lw=1.0, ls=":", label=f"falls from {onset:.5g}")
    for i, br in enumerate(branches):
        if not br.points:
            continue
        p, x = br.p, br.x[:, coordinate]
        stable = np.array([b.stable for b in br.points])
        for mask, ls in ((stable, "-"), (~stable, "--")):
            y = np.where(mask, x, np.nan)
            ax.plot(p, y, ls, color=f"C{i % 10}", lw=1.2,
                    label=f"period {br.period}" + (" (stable)" if ls == "-" else " (unstable)"))
    for bf in bifurcations:
        short = {"period-doubling": "PD", "fold": "F", "neimark-sacker": "NS"}.get(bf.kind, bf.kind)
        ax.plot(bf.p, bf.x[coordinate], "o", mfc="none", color="C3", ms=7)
        ax.annotate(f"{short} {bf.p:.5f}", (bf.p, bf.x[coordinate]), fontsize=7, rotation=90,
                    xytext=(-3, -48), textcoords="offset points")
    ax.set_xlabel(getattr(diagram, "param", None) or (branches[0].param if branches else "p"))
    ax.set_ylabel(label or f"x[{coordinate}] at touchdown")
    ax.set_title(title)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=7, loc="best")
    return _finish(fig, path)


def plot_branch_multipliers(branch, path=None, ax=None, title=None):
    """Multipliers of every point of a branch in the complex plane, coloured by the
    parameter, against the unit circle."""
    fig, ax = _axes(ax, figsize=(5.5, 4.5))
    th = np.linspace(0.0, 2.0 * np.pi, 361)
    ax.plot(np.cos(th), np.sin(th), color="0.5", lw=1.0)
    ax.axhline(0.0, color="0.85", lw=0.8)
    ax.axvline(0.0, color="0.85", lw=0.8)
    lam = branch.multipliers
    p = np.repeat(branch.p[:, None], lam.shape[1], axis=1)
    sc = ax.scatter(lam.real.ravel(), lam.imag.ravel(), c=p.ravel(), s=12, cmap="viridis")
    fig.colorbar(sc, ax=ax, label=branch.param)
    lim = max(1.2, 1.1 * float(np.max(np.abs(lam))) if lam.size else 1.2)
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_aspect("equal")
    ax.set_xlabel("Re")
    ax.set_ylabel("Im")
    ax.set_title(title or f"multipliers along the period-{branch.period} branch")
    return _finish(fig, path)


def plot_basin(basin, path=None, ax=None, attractor=None, title="basin of attraction"):
    """Steps survived over the grid (grey levels), cells that reach the attractor in colour."""
    fig, ax = _axes(ax, figsize=(5.5, 4.5))
    ext = [basin.b[0], basin.b[-1], basin.a[0], basin.a[-1]]
    img = np.where(basin.reached, np.nan, basin.steps.astype(float))
    ax.imshow(img, origin="lower", extent=ext, aspect="auto", cmap="Greys", interpolation="nearest")
    ax.imshow(np.where(basin.reached, 1.0, np.nan), origin="lower", extent=ext, aspect="auto",
              cmap="summer", vmin=0, vmax=2, interpolation="nearest")
    if attractor is not None:
        ax.plot(attractor[1], attractor[0], "r*", ms=10, label="gait")
        ax.legend(fontsize=8)
    ax.set_xlabel(basin.names[1])
    ax.set_ylabel(basin.names[0])
    ax.set_title(f"{title} ({100 * basin.fraction:.0f}% of the grid)")
    return _finish(fig, path)
