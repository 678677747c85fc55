"""NumPy twins of the C++ joint terms (factors/joint/terms.h), for data and evaluation.

* :func:`dh_pose` — base_from_target of a Denavit–Hartenberg chain, standard
  (Rot_z(θ) Trans_z(d) Trans_x(a) Rot_x(α)) or modified (Craig: Rot_x(α)
  Trans_x(a) Rot_z(θ) Trans_z(d)); a table is n × 4 rows [θ offset, d, a, α];
* :func:`project` / :func:`ray` — the camera models of ``camera/models.h``
  (``simple_radial`` [f, cx, cy, k1], ``pinhole``, ``radial1``, ``radial2``,
  ``opencv5``) and their inverse on pixels (the same fixed-point undistortion);
* :func:`sheet_points` — light-sheet triangulation p = s·x̂, s = d / (n·x̂);
* :func:`triangulate` — the two-view point minimising the reprojection error in
  both images (Gauss–Newton from the midpoint), the stereo system's I(α, u).

Poses are :class:`boxplus.SE3` (b_from_a maps a-coordinates to b).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from boxplus.manifolds import SE3, SO3

__all__ = ["dh_pose", "project", "ray", "sheet_points", "triangulate", "plane_in"]

_UNDISTORT_STEPS = 20  # as kUndistortSteps in terms.h
_FOCALS = {"simple_radial": 1, "pinhole": 2, "radial1": 2, "radial2": 2, "opencv5": 2}


def dh_pose(table: np.ndarray, joints: np.ndarray, convention: str = "standard",
            base_from_chain: SE3 | None = None, end_from_target: SE3 | None = None) -> SE3:
    """base_from_target = base_from_chain · A₁(q₁ + θ₁) … Aₙ(qₙ + θₙ) · end_from_target."""
    T = base_from_chain if base_from_chain is not None else SE3()
    for (theta0, d, a, alpha), q in zip(np.asarray(table, float), np.asarray(joints, float)):
        th = q + theta0
        rz, rx = SO3.exp([0.0, 0.0, th]), SO3.exp([alpha, 0.0, 0.0])
        if convention == "standard":
            link = SE3(rz * rx, [a * np.cos(th), a * np.sin(th), d])
        elif convention == "modified":
            link = SE3(rx * rz, [a, -np.sin(alpha) * d, np.cos(alpha) * d])
        else:
            raise ValueError(f"DH convention must be 'standard' or 'modified', got '{convention}'")
        T = T * link
    return T * end_from_target if end_from_target is not None else T


def _split(model: str, k: np.ndarray) -> tuple[Any, Any, np.ndarray, np.ndarray, np.ndarray]:
    nf = _FOCALS[model]
    fx, fy = k[0], k[nf - 1]
    c = k[nf:nf + 2]
    rad = {"simple_radial": lambda: k[3:4], "pinhole": lambda: k[:0], "radial1": lambda: k[4:5],
           "radial2": lambda: k[4:6], "opencv5": lambda: k[[4, 5, 8]]}[model]()
    tang = k[6:8] if model == "opencv5" else np.zeros(2)
    return fx, fy, c, rad, tang


def _distort(model: str, k: np.ndarray, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    _, _, _, rad, (p1, p2) = _split(model, k)
    r2 = x * x + y * y
    s = 1.0 + sum(ki * r2 ** (i + 1) for i, ki in enumerate(rad))
    xd = x * s + 2 * p1 * x * y + p2 * (r2 + 2 * x * x)
    yd = y * s + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y
    return xd, yd


def project(model: str, k: Any, p_in_cam: np.ndarray) -> np.ndarray:
    """Pixels (N, 2) of points (N, 3) in the camera frame."""
    k = np.asarray(k, float)
    p = np.atleast_2d(p_in_cam)
    fx, fy, c, _, _ = _split(model, k)
    xd, yd = _distort(model, k, p[:, 0] / p[:, 2], p[:, 1] / p[:, 2])
    return np.column_stack([fx * xd + c[0], fy * yd + c[1]])


def ray(model: str, k: Any, uv: np.ndarray) -> np.ndarray:
    """Viewing rays [x, y, 1] (N, 3) of pixels (N, 2)."""
    k = np.asarray(k, float)
    uv = np.atleast_2d(uv)
    fx, fy, c, _, _ = _split(model, k)
    xd, yd = (uv[:, 0] - c[0]) / fx, (uv[:, 1] - c[1]) / fy
    x, y = xd.copy(), yd.copy()
    if len(x):
        for _ in range(_UNDISTORT_STEPS):
            dx, dy = _distort(model, k, x, y)
            ex, ey = dx - xd, dy - yd
            x, y = x - ex, y - ey
            if max(np.max(np.abs(ex)), np.max(np.abs(ey))) <= 1e-15:  # a fixed point: more steps change nothing
                break
    return np.column_stack([x, y, np.ones(len(x))])


def sheet_points(model: str, k: Any, sheet: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """Where the rays of pixels uv meet the sheet [n, d] (camera frame), (N, 3)."""
    r = ray(model, k, uv)
    sheet = np.asarray(sheet, float)
    return r * (sheet[3] / (r @ sheet[:3]))[:, None]


def plane_in(b_from_a: SE3, plane_in_a: np.ndarray) -> np.ndarray:
    """A plane [n, d] of frame a in frame b."""
    n = b_from_a.R @ plane_in_a[:3]
    return np.r_[n, plane_in_a[3] + n @ b_from_a.pos]


def triangulate(model1: str, k1: Any, model2: str, k2: Any, cam2_from_cam1: SE3,
                z1: np.ndarray, z2: np.ndarray, iterations: int = 5) -> np.ndarray:
    """Points (N, 3) in camera 1 minimising the reprojection error in both images."""
    z1, z2 = np.atleast_2d(z1), np.atleast_2d(z2)
    d1 = ray(model1, k1, z1)
    R, t = cam2_from_cam1.R, cam2_from_cam1.pos
    o2 = -R.T @ t
    d2 = ray(model2, k2, z2) @ R
    X = _midpoint(d1, o2, d2)
    h = 1e-7
    for _ in range(iterations):
        def res(P: np.ndarray) -> np.ndarray:
            return np.concatenate([project(model1, k1, P) - z1, project(model2, k2, P @ R.T + t) - z2], 1)

        r0 = res(X)
        J = np.stack([(res(X + h * np.eye(3)[i]) - r0) / h for i in range(3)], axis=2)  # (N, 4, 3)
        JtJ = np.einsum("nki,nkj->nij", J, J)
        Jtr = np.einsum("nki,nk->ni", J, r0)
        X = X - np.linalg.solve(JtJ, Jtr[..., None])[..., 0]
    return X


def _midpoint(d1: np.ndarray, o2: np.ndarray, d2: np.ndarray) -> np.ndarray:
    """Midpoint of the shortest segment between rays s·d1 and o2 + u·d2."""
    a, b, c = np.sum(d1 * d1, 1), np.sum(d1 * d2, 1), np.sum(d2 * d2, 1)
    dd, e = d1 @ o2, d2 @ o2
    den = a * c - b * b
    s = (c * dd - b * e) / den
    u = (b * dd - a * e) / den
    return 0.5 * (s[:, None] * d1 + o2 + u[:, None] * d2)
