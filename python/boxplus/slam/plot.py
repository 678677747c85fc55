"""A PNG of a pose graph's trajectory (x–y plane), optionally over an earlier one."""

from __future__ import annotations

from os import PathLike
from typing import TYPE_CHECKING, Union

import numpy as np

if TYPE_CHECKING:
    from .pose_graph import PoseGraph

__all__ = ["plot_trajectory"]

PathType = Union[str, "PathLike[str]"]


def plot_trajectory(
    graph: PoseGraph,
    path: PathType,
    before: np.ndarray | None = None,
    title: str = "",
) -> None:
    """Writes a PNG of the pose positions (x–y plane), optionally over ``before``.

    Parameters
    ----------
    before : ndarray, optional
        Positions (N, 2 or 3) before optimisation, e.g. ``graph.positions()``
        taken before :meth:`PoseGraph.solve`.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    after = graph.positions()
    fig, ax = plt.subplots(figsize=(7, 7))
    if before is not None:
        before = np.asarray(before)
        ax.plot(before[:, 0], before[:, 1], "-", color="0.6", lw=0.7, label="before")
    ax.plot(after[:, 0], after[:, 1], "-", color="C0", lw=0.9, label="after")
    lm = graph.landmarks()
    if len(lm):
        ax.plot(lm[:, 0], lm[:, 1], "+", color="C3", ms=4, label="landmarks")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.legend(loc="best")
    ax.set_title(title or f"chi2 = {graph.chi2():.6g}")
    fig.tight_layout()
    fig.savefig(str(path), dpi=120)
    plt.close(fig)
