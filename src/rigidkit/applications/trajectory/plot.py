"""Plots of trajectories and their errors (the optional extra ``plot``).

matplotlib is imported on first use, never by ``import rigidkit``; without it
each function raises :class:`ImportError` naming the extra to install. The
functions draw on a given ``matplotlib`` axes or on a new
:class:`matplotlib.figure.Figure` (no pyplot, so they work without a display);
:func:`save_report` writes a whole figure to PNG, PDF or SVG.
"""

from __future__ import annotations

import numpy as np

from .trajectory import Trajectory

__all__ = ["plot", "plot_error_colored", "plot_errors", "save_report"]

_PLANES = {"xy": (0, 1), "xz": (0, 2), "yz": (1, 2), "3d": (0, 1, 2)}


def _matplotlib():
    try:
        import matplotlib
        from matplotlib.figure import Figure
    except ImportError:
        raise ImportError(
            "rigidkit's trajectory plots need matplotlib: pip install 'rigidkit[plot]'"
        ) from None
    return matplotlib, Figure


def _axes(ax, plane):
    if plane not in _PLANES:
        raise ValueError(f"plane must be one of {', '.join(_PLANES)}; got {plane!r}")
    if ax is not None:
        return ax
    _, Figure = _matplotlib()
    fig = Figure(figsize=(6, 5), layout="constrained")
    return fig.add_subplot(projection="3d" if plane == "3d" else None)


def _coords(traj, plane):
    p = np.asarray(traj.positions)
    return [p[:, k] for k in _PLANES[plane]]


def plot(trajs, ax=None, plane="xy", labels=None):
    """Draw the paths of one or more trajectories; returns the axes.

    Parameters
    ----------
    trajs : Trajectory or sequence of Trajectory
        One-dimensional trajectories (poses of shape (N,)).
    ax : matplotlib axes, optional
        Drawn on; a new figure's axes when omitted (``ax.figure`` to save it).
    plane : {"xy", "xz", "yz", "3d"}
        The two position axes to draw, or all three (``ax`` must then be 3-D).
    labels : sequence of str, optional
        Legend entries, one per trajectory.
    """
    if isinstance(trajs, Trajectory):
        trajs = [trajs]
    ax = _axes(ax, plane)
    labels = [None] * len(trajs) if labels is None else list(labels)
    for traj, label in zip(trajs, labels, strict=True):
        ax.plot(*_coords(traj, plane), label=label)
    ax.set_xlabel(f"{plane[0]} [m]" if plane != "3d" else "x [m]")
    ax.set_ylabel(f"{plane[1]} [m]" if plane != "3d" else "y [m]")
    if plane == "3d":
        ax.set_zlabel("z [m]")
    else:
        ax.set_aspect("equal", adjustable="datalim")
    if any(label is not None for label in labels):
        ax.legend()
    return ax


def plot_error_colored(traj, errors, ax=None, plane="xy", label="error"):
    """Draw ``traj``'s path coloured by ``errors`` (one per pose); returns the axes."""
    matplotlib, _ = _matplotlib()
    from matplotlib.collections import LineCollection

    if plane == "3d":
        raise ValueError("the coloured path is drawn in a plane: xy, xz or yz")
    ax = _axes(ax, plane)
    x, y = _coords(traj, plane)
    e = np.asarray(errors, dtype=np.float64)
    segments = np.stack([np.c_[x[:-1], y[:-1]], np.c_[x[1:], y[1:]]], axis=1)
    lines = LineCollection(segments, cmap="viridis", linewidths=2)
    lines.set_array(0.5 * (e[:-1] + e[1:]))
    ax.add_collection(lines)
    ax.autoscale()
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"{plane[0]} [m]")
    ax.set_ylabel(f"{plane[1]} [m]")
    ax.figure.colorbar(lines, ax=ax, label=label)
    return ax


def plot_errors(result, ax=None, label="error"):
    """Errors over time (or index) with ``rmse``, ``mean``, ``median`` as lines and
    ``mean +- std`` as a band; ``result`` from :func:`~rigidkit.trajectory.ape` or
    :func:`~rigidkit.trajectory.rpe`. Returns the axes."""
    ax = _axes(ax, "xy")
    e = np.asarray(result.errors)
    if result.stamps is not None:
        x = np.asarray(result.stamps) - result.stamps[0]
        ax.set_xlabel("t [s]")
    else:
        x = np.arange(len(e))
        ax.set_xlabel("index")
    ax.plot(x, e, color="0.3", linewidth=1, label=label)
    s = result.stats
    for key, style in (("rmse", "-"), ("mean", "--"), ("median", ":")):
        ax.axhline(
            s[key], linestyle=style, color="C0" if key == "rmse" else "C1", label=key
        )
    ax.axhspan(
        s["mean"] - s["std"], s["mean"] + s["std"], alpha=0.15, color="C1", label="std"
    )
    ax.set_ylabel(f"{label} [{result.unit}]")
    ax.legend(loc="upper right")
    return ax


def save_report(path, ref, est, result, title=""):
    """Write the reference and estimate, the error-coloured estimate and the errors
    over time to ``path`` (the format from its extension: .png, .pdf, .svg)."""
    _, Figure = _matplotlib()
    fig = Figure(figsize=(15, 4.5), layout="constrained")
    a, b, c = fig.subplots(1, 3)
    plot([ref, est], ax=a, labels=["reference", "estimate"])
    per_pose = result.pairs is None
    if per_pose:
        plot_error_colored(est, result.errors, ax=b, label=f"error [{result.unit}]")
    else:
        plot([est], ax=b, labels=["estimate"])
    plot_errors(result, ax=c)
    if title:
        fig.suptitle(title)
    fig.savefig(path)
    return fig
