"""A plot of a pose graph's trajectory, optionally over an earlier one.

The functions here never change matplotlib's backend: given an ``ax`` they draw
into it; without one they make a figure (a pyplot figure, shown by
``plt.show()`` and in notebooks, unless the plot goes only to a file). They
return the :class:`matplotlib.figure.Figure`.
"""

from __future__ import annotations

from os import PathLike
from typing import TYPE_CHECKING, Any, Union

import numpy as np

from boxplus._optional import require
from boxplus.files import save_figure

if TYPE_CHECKING:
    from .pose_graph import PoseGraph

__all__ = ["plot_trajectory"]

PathType = Union[str, "PathLike[str]"]


def _new_axes(three_d: bool, to_file_only: bool) -> Any:
    """Axes of a new figure: a plain Figure (no pyplot state) for a file, else pyplot's."""
    kw = {"projection": "3d"} if three_d else {}
    if to_file_only:
        fig = require("matplotlib.figure", "plotting a pose graph").Figure(figsize=(7, 7))
    else:
        fig = require("matplotlib.pyplot", "plotting a pose graph").figure(figsize=(7, 7))
    return fig.add_subplot(1, 1, 1, **kw)


def _is_3d(ax: Any) -> bool:
    return getattr(ax, "name", "") == "3d"


def _equal_3d(ax: Any, points: np.ndarray) -> None:
    """Equal scale on the three axes of a 3D plot (mplot3d has no 'equal' aspect
    in every matplotlib version): a cube around the points."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre, half = (lo + hi) / 2, max(float(np.max(hi - lo)) / 2, 1e-9)
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    if hasattr(ax, "set_box_aspect"):
        ax.set_box_aspect((1, 1, 1))


def plot_trajectory(
    graph: PoseGraph,
    path: PathType | None = None,
    before: np.ndarray | None = None,
    title: str = "",
    ax: Any = None,
    unit: str = "m",
) -> Any:
    """Plots the pose positions, optionally over ``before``, and landmarks.

    A 3D graph is drawn in 3D (``projection='3d'`` axes), unless ``ax`` is a
    2D axes: then its x–y top view. The loop closures the last solve judged
    wrong (:attr:`PoseGraph.outliers`) are drawn in red between the poses they
    claim to join.

    Parameters
    ----------
    graph : PoseGraph
        The graph; its current estimate is drawn.
    path : str or path-like, optional
        Also save the figure there (the format from the suffix, e.g. ``.png``,
        ``.svg``).
    before : ndarray, optional
        Positions (N, 2 or 3) before optimisation, e.g. ``graph.positions()``
        taken before :meth:`PoseGraph.solve`.
    title : str
        The title; default ``chi2 = …`` of the current estimate (of the
        inliers, when loop closures were judged wrong).
    ax : matplotlib Axes, optional
        Draw into these axes (2D, or 3D made with ``projection='3d'``).
    unit : str
        The unit of the positions, for the axis labels (g2o files do not say;
        most use metres).

    Returns
    -------
    matplotlib.figure.Figure
        The figure of the axes.
    """
    after = graph.positions()
    three_d = graph.dimension == 3
    if ax is None:
        ax = _new_axes(three_d, to_file_only=path is not None)
    draw_3d = three_d and _is_3d(ax)
    k = 3 if draw_3d else 2

    def line(points: np.ndarray, *style: Any, **kw: Any) -> None:
        ax.plot(*(points[:, i] for i in range(k)), *style, **kw)

    if before is not None:
        before = np.asarray(before, dtype=float)
        if before.ndim != 2 or before.shape[1] < k:
            raise ValueError(f"before: expected positions of shape (N, {k}), got {before.shape}")
        line(before, "-", color="0.6", lw=0.7, label="before")
    line(after, "-", color="C0", lw=0.9, label="after")
    lm = graph.landmarks()
    if len(lm):
        line(lm, "+", color="C3", ms=4, label="landmarks")
    # The loop closures the last solve judged wrong, as segments between the
    # estimated poses they claim to join: where the front end was fooled.
    wrong = graph.outliers
    if wrong:
        ids = graph.vertex_ids
        kinds = {i: graph.vertex_kind(i) for i in ids}
        row = {i: r for r, i in enumerate(i for i in ids if kinds[i] in ("SE2", "SE3"))}
        for n, v in enumerate(wrong):
            if v.from_id in row and v.to_id in row:
                line(after[[row[v.from_id], row[v.to_id]]], "-", color="C3", lw=0.4, alpha=0.6,
                     label=f"loop closures judged wrong ({len(wrong)})" if n == 0 else None)
    ax.set_xlabel(f"x [{unit}]")
    ax.set_ylabel(f"y [{unit}]")
    if draw_3d:
        ax.set_zlabel(f"z [{unit}]")
        shown = [after] + ([before[:, :3]] if before is not None else []) + ([lm] if len(lm) else [])
        _equal_3d(ax, np.vstack(shown))
    else:
        ax.set_aspect("equal", adjustable="datalim")
    ax.legend(loc="best")
    if not title and wrong:
        inliers = graph.chi2() - sum(v.chi2 for v in wrong)
        title = f"chi2 of the inliers = {inliers:.6g} ({len(wrong)} loop closures left out)"
    ax.set_title(title or f"chi2 = {graph.chi2():.6g}")
    fig = ax.figure
    if path is not None:
        fig.tight_layout()
        save_figure(fig, path, dpi=120)
    return fig
