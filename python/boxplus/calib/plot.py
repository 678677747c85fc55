"""Pictures of a calibration, saved as PNG (matplotlib, Agg backend):
reprojection errors per image, and the rig in 3-D (sensor frames, board
poses, IMU, hand markers)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from boxplus.manifolds import SE3

__all__ = ["plot_reprojection_errors", "plot_rig"]


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_reprojection_errors(o, path: str, mids: Mapping[str, Sequence[int]] | None = None,
                             title: str = "reprojection errors") -> None:
    """Per image (one built-in board/marker measurement each) the RMS error, and
    all error vectors as a scatter, one colour per group.

    ``mids``: {label: measurement ids}; default every built-in factor by group.
    """
    plt = _plt()
    if mids is None:
        groups: dict[str, list[int]] = {}
        for mid in o.builtin_measurements():
            if o.measurement_group(mid) != "prior":
                groups.setdefault(o.measurement_group(mid), []).append(mid)
        mids = groups
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.5))
    x0 = 0
    for label, ids in mids.items():
        E = [o.measurement_errors(m) for m in ids]
        per = [np.sqrt(np.mean(np.sum(e**2, axis=1))) for e in E]
        ax1.bar(np.arange(x0, x0 + len(per)), per, label=label)
        x0 += len(per) + 1
        allE = np.concatenate(E)
        ax2.scatter(allE[:, 0], allE[:, 1], s=4, alpha=0.6, label=label)
    ax1.set_xlabel("image (measurement)")
    ax1.set_ylabel("RMS error")
    ax1.legend()
    ax2.set_aspect("equal")
    ax2.set_xlabel("error u")
    ax2.set_ylabel("error v")
    ax2.axhline(0, color="k", lw=0.5)
    ax2.axvline(0, color="k", lw=0.5)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def _axes(ax, pose, length: float, label: str) -> None:
    R, t = pose.rot.R, pose.pos
    for k, c in enumerate("rgb"):
        e = t + length * R[:, k]
        ax.plot([t[0], e[0]], [t[1], e[1]], [t[2], e[2]], c)
    ax.text(*t, label, fontsize=8)


def plot_rig(path: str, frames: Mapping[str, SE3], boards: Sequence[tuple[SE3, np.ndarray]] = (),
             points: dict[str, np.ndarray] | None = None, length: float = 1.0,
             title: str = "rig") -> None:
    """The rig in one reference frame: ``frames`` {name: ref_from_frame (SE3)} drawn as
    axes (x red, y green, z blue), ``boards`` [(ref_from_board, p_in_board (N, 3))]
    as point grids, ``points`` {name: (N, 3) in ref} (e.g. hand markers)."""
    plt = _plt()
    fig = plt.figure(figsize=(7, 6))
    ax = fig.add_subplot(projection="3d")
    allp = []
    for name, pose in frames.items():
        _axes(ax, pose, length, name)
        allp.append(pose.pos[None])
    for pose, p in boards:
        q = p @ pose.rot.R.T + pose.pos
        ax.scatter(q[:, 0], q[:, 1], q[:, 2], s=2, c="gray")
        allp.append(q)
    for name, p in (points or {}).items():
        p = np.atleast_2d(p)
        ax.scatter(p[:, 0], p[:, 1], p[:, 2], s=12, label=name)
        allp.append(p)
    if points:
        ax.legend()
    P = np.concatenate(allp)
    c, r = P.mean(axis=0), max(np.ptp(P, axis=0).max() / 2, length)
    ax.set_xlim(c[0] - r, c[0] + r)
    ax.set_ylim(c[1] - r, c[1] + r)
    ax.set_zlim(c[2] - r, c[2] + r)
    ax.set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
