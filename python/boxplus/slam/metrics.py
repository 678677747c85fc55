"""How far an estimated trajectory is from the truth.

``ate(estimate, truth)`` is the absolute trajectory error: the RMS of the
position errors after the rigid motion that best aligns the estimate's
positions to the truth's (Horn / Umeyama without scale; a pose graph's gauge
is free, so an unaligned comparison would measure the gauge). Poses are rows
of SE(2) ``[x, y, θ]`` or SE(3) ``[t, qx, qy, qz, qw]``, or bare positions.
"""

from __future__ import annotations

import numpy as np

__all__ = ["align_positions", "ate", "outlier_scores"]


def _positions(poses: np.ndarray) -> np.ndarray:
    p = np.asarray(poses, float)
    if p.ndim != 2 or p.shape[1] not in (2, 3, 7):
        raise ValueError(f"poses must be (N, 3) SE(2), (N, 7) SE(3) or (N, 2|3) positions, "
                         f"got shape {p.shape}")
    return p[:, :2] if p.shape[1] == 3 else p[:, :3]


def align_positions(estimate: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """The estimate's positions moved by the rotation and translation that
    minimise the sum of squared distances to the truth's (Umeyama, 1991)."""
    a, b = _positions(estimate), _positions(truth)
    if a.shape != b.shape:
        raise ValueError(f"estimate and truth differ in shape: {a.shape} vs {b.shape}")
    ma, mb = a.mean(0), b.mean(0)
    u, _, vt = np.linalg.svd((a - ma).T @ (b - mb))
    d = np.eye(a.shape[1])
    d[-1, -1] = np.sign(np.linalg.det(vt.T @ u.T))
    r = vt.T @ d @ u.T
    return (a - ma) @ r.T + mb


def ate(estimate: np.ndarray, truth: np.ndarray) -> float:
    """Absolute trajectory error (metres, RMS over the poses) after alignment."""
    e = align_positions(estimate, truth) - _positions(truth)
    return float(np.sqrt(np.mean(np.sum(e * e, axis=1))))


def outlier_scores(judged: np.ndarray, wrong: np.ndarray) -> tuple[float, float]:
    """(precision, recall) of boolean outlier decisions against the truth.

    Precision is 1 when nothing was judged wrong, recall 1 when nothing was."""
    judged, wrong = np.asarray(judged, bool), np.asarray(wrong, bool)
    hits = int(np.count_nonzero(judged & wrong))
    precision = hits / judged.sum() if judged.any() else 1.0
    recall = hits / wrong.sum() if wrong.any() else 1.0
    return float(precision), float(recall)
