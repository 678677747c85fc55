"""NumPy twins of the C++ joint terms (factors/joint/terms.h), for data and evaluation.

* :func:`dh_pose` — base_from_target of a Denavit–Hartenberg chain, standard
  (Rot_z(θ) Trans_z(d) Trans_x(a) Rot_x(α)) or modified (Craig: Rot_x(α)
  Trans_x(a) Rot_z(θ) Trans_z(d)); a table is n × 4 rows [θ offset, d, a, α];
* :func:`project` / :func:`ray` — every camera model of ``camera/models.h`` and
  its inverse on pixels, through :mod:`boxplus.calib.models` (argument order
  model first, as the joint API names a camera's model before its numbers);
* :func:`sheet_points` — light-sheet triangulation p = s·x̂, s = d / (n·x̂);
* :func:`triangulate` — the two-view point minimising the reprojection error in
  both images (Gauss–Newton from the midpoint), the stereo system's I(α, u).

Poses are :class:`boxplus.SE3` (b_from_a maps a-coordinates to b).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from boxplus.calib import models
from boxplus.geometry import triangulate_midpoint
from boxplus.manifolds import SE3, SO3

__all__ = ["dh_pose", "project", "ray", "sheet_points", "triangulate", "plane_in"]


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


def project(model: str, k: Any, p_in_cam: np.ndarray) -> np.ndarray:
    """Pixels (N, 2) of points (N, 3) in the camera frame, any model of
    :mod:`boxplus.calib.models` (the C++ terms' own maths, in one home)."""
    return models.project(np.asarray(k, float), np.atleast_2d(p_in_cam), model)


def ray(model: str, k: Any, uv: np.ndarray) -> np.ndarray:
    """Viewing rays (N, 3) of pixels (N, 2): [x, y, 1] for the pinhole family, unit
    vectors for the wide-angle models (:func:`boxplus.calib.models.rays`)."""
    return models.rays(np.asarray(k, float), np.atleast_2d(uv), model)


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
    X = triangulate_midpoint(np.zeros(3), d1, o2, d2, what="triangulate")
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

