"""Closed-form initialisation of a camera from views of a planar target.

Z. Zhang, "A flexible new technique for camera calibration", IEEE PAMI 22(11),
2000: a homography per view (normalised DLT), the intrinsic matrix from the
constraints each homography puts on B = K⁻ᵀK⁻¹ (Sec. 3.1), and each view's pose
from K⁻¹H (Sec. 3.1, eq. 12), projected onto SO(3). Views whose board planes
are all parallel (translations and turns of the board in its own plane only)
are the degenerate configuration of Zhang's paper (a plane parallel to an
earlier one adds no constraint): they are refused.

Frames: the target's points are ``p_in_board`` with z = 0; a pose returned as
``cam_from_board`` maps them into the camera frame (p_in_cam = R p + t).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from boxplus.geometry import project_to_so3
from boxplus.manifolds import SE3, SO3

__all__ = ["board_normals", "check_board_planes", "homography", "init_camera",
           "intrinsics_from_homographies", "pose_from_homography", "PARALLEL_PLANES_RAD",
           "SOLVED_PARALLEL_PLANES_RAD"]

# Boards whose planes are turned by less than this are parallel. The normals
# from the homographies of distorted pixels are off by several degrees (lens
# distortion bends the board's image), so before the solve only nearly exact
# repeats are caught; after it the poses are accurate, and parallel boards
# come out at most ~3° apart (measured over translation-only and in-plane-turn
# view sets), well below a usable set's spread (≥ 10°).
PARALLEL_PLANES_RAD = np.radians(1.0)
SOLVED_PARALLEL_PLANES_RAD = np.radians(5.0)


def _normaliser(p: np.ndarray) -> np.ndarray:
    """Similarity moving p's centroid to 0 and its mean distance to √2 (Hartley)."""
    c = p.mean(axis=0)
    d = np.mean(np.linalg.norm(p - c, axis=1))
    s = np.sqrt(2) / max(d, 1e-12)
    return np.array([[s, 0, -s * c[0]], [0, s, -s * c[1]], [0, 0, 1]])


def homography(src: np.ndarray, dst: np.ndarray) -> np.ndarray:
    """H with dst ~ H src, from ≥ 4 point pairs (N, 2), by normalised DLT."""
    src = np.asarray(src, dtype=float)
    dst = np.asarray(dst, dtype=float)
    if src.shape != dst.shape or src.ndim != 2 or src.shape[1] != 2 or len(src) < 4:
        raise ValueError(f"homography needs two (N, 2) arrays with N >= 4, got {src.shape}, {dst.shape}")
    Ts, Td = _normaliser(src), _normaliser(dst)
    s = (Ts @ np.column_stack([src, np.ones(len(src))]).T).T
    d = (Td @ np.column_stack([dst, np.ones(len(dst))]).T).T
    A = np.zeros((2 * len(src), 9))
    A[0::2, 0:3] = s
    A[0::2, 6:9] = -d[:, 0:1] * s
    A[1::2, 3:6] = s
    A[1::2, 6:9] = -d[:, 1:2] * s
    _, sv, Vt = np.linalg.svd(A)
    if sv[-2] < 1e-12 * sv[0]:
        raise ValueError("homography: the points are degenerate (collinear or repeated)")
    H = np.linalg.solve(Td, Vt[-1].reshape(3, 3) @ Ts)
    return H / H[2, 2]


def _v(H: np.ndarray, i: int, j: int) -> np.ndarray:
    h = H.T  # rows h_i = columns of H
    return np.array([
        h[i, 0] * h[j, 0],
        h[i, 0] * h[j, 1] + h[i, 1] * h[j, 0],
        h[i, 1] * h[j, 1],
        h[i, 2] * h[j, 0] + h[i, 0] * h[j, 2],
        h[i, 2] * h[j, 1] + h[i, 1] * h[j, 2],
        h[i, 2] * h[j, 2],
    ])


def intrinsics_from_homographies(
    Hs: Sequence[np.ndarray], image_size: tuple[int, int] | None = None
) -> np.ndarray:
    """K (3×3, zero skew) from board→image homographies (Zhang, Sec. 3.1).

    With fewer than 3 views the principal point is fixed at the image centre
    (``image_size`` = (width, height) is then required) and only fx, fy are solved.
    """
    if len(Hs) >= 3:
        # zero skew adds the row [0 1 0 0 0 0] b = 0
        V = [np.array([0, 1, 0, 0, 0, 0.0])]
        for H in Hs:
            H = H / np.linalg.norm(H)
            V.append(_v(H, 0, 1))
            V.append(_v(H, 0, 0) - _v(H, 1, 1))
        _, _, Vt = np.linalg.svd(np.array(V))
        b = Vt[-1]
        B11, B12, B22, B13, B23, B33 = b
        v0 = (B12 * B13 - B11 * B23) / (B11 * B22 - B12**2)
        lam = B33 - (B13**2 + v0 * (B12 * B13 - B11 * B23)) / B11
        if lam / B11 > 0 and lam * B11 / (B11 * B22 - B12**2) > 0:
            alpha = np.sqrt(lam / B11)
            beta = np.sqrt(lam * B11 / (B11 * B22 - B12**2))
            u0 = -B13 * alpha**2 / lam
            return np.array([[alpha, 0, u0], [0, beta, v0], [0, 0, 1.0]])
        if image_size is None:
            raise ValueError("Zhang's closed form failed (views too similar); give image_size")
    if image_size is None:
        raise ValueError("fewer than 3 views: image_size is needed to fix the principal point")
    cx, cy = image_size[0] / 2.0, image_size[1] / 2.0
    C = np.array([[1, 0, -cx], [0, 1, -cy], [0, 0, 1.0]])
    # With the principal point known, h1ᵀBh2 = 0 and h1ᵀBh1 = h2ᵀBh2 are linear in
    # (1/fx², 1/fy²).
    rows, rhs = [], []
    for H in Hs:
        G = C @ H
        g1, g2 = G[:, 0], G[:, 1]
        rows.append([g1[0] * g2[0], g1[1] * g2[1]])
        rhs.append(-g1[2] * g2[2])
        rows.append([g1[0] ** 2 - g2[0] ** 2, g1[1] ** 2 - g2[1] ** 2])
        rhs.append(-(g1[2] ** 2 - g2[2] ** 2))
    x, *_ = np.linalg.lstsq(np.array(rows), np.array(rhs), rcond=None)
    if np.any(x <= 0):
        f = float(max(image_size))  # a plain guess: 90° field of view order
        return np.array([[f, 0, cx], [0, f, cy], [0, 0, 1.0]])
    return np.array([[1 / np.sqrt(x[0]), 0, cx], [0, 1 / np.sqrt(x[1]), cy], [0, 0, 1.0]])


def pose_from_homography(K: np.ndarray, H: np.ndarray) -> SE3:
    """cam_from_board from K and the board→image homography (Zhang, eq. 12)."""
    A = np.linalg.solve(K, H)
    lam = 1.0 / np.linalg.norm(A[:, 0])
    if A[2, 2] * lam < 0:  # the board must be in front of the camera
        lam = -lam
    r1, r2, t = lam * A[:, 0], lam * A[:, 1], lam * A[:, 2]
    R = project_to_so3(np.column_stack([r1, r2, np.cross(r1, r2)]), "pose_from_homography")
    return SE3(SO3(R), t)


def board_normals(K: np.ndarray, Hs: Sequence[np.ndarray]) -> np.ndarray:
    """Unit normals (N, 3) of the board planes in the camera frame: r1 × r2 of
    K⁻¹H (eq. 12), sign-free.

    Not orthonormalised on purpose: r1 × r2 ∝ Kᵀ H⁻ᵀ e3, Kᵀ times the image of
    the board's line at infinity, which parallel planes share. Parallel boards
    therefore give equal normals for any K, also for the wrong K that Zhang's
    closed form returns from exactly such views.
    """
    out = []
    for H in Hs:
        A = np.linalg.solve(K, H)
        n = np.cross(A[:, 0], A[:, 1])
        out.append(n / np.linalg.norm(n))
    return np.array(out).reshape(-1, 3)


def check_board_planes(normals: np.ndarray, camera: str = "camera",
                       tolerance_rad: float = PARALLEL_PLANES_RAD) -> None:
    """Raises ValueError, naming the views, when all board planes are parallel.

    ``normals`` (N, 3) are the planes' normals in the camera frame, one per
    view; they are parallel when no two are more than ``tolerance_rad`` apart.
    That is the degenerate configuration of Zhang's paper: a view whose board
    plane is parallel to another's adds no constraint on B = K⁻ᵀK⁻¹ —
    repeated views, views that differ by a translation only, or by a turn of
    the board in its own plane (e.g. all fronto-parallel). Such a set fixes K
    like one view: 2 constraints for the 4 intrinsics of zero skew, and the
    refinement after it "converges" to a focal length off by a factor. Two
    plane orientations give the 4 (with zero skew).
    """
    N = np.asarray(normals, float).reshape(-1, 3)
    if len(N) == 0:
        return
    # |cos|: a plane's normal and its negative are one orientation
    spread = float(np.arccos(np.clip(np.abs(N @ N.T), 0.0, 1.0)).max())
    if spread < tolerance_rad:
        views = ", ".join(str(i) for i in range(len(N)))
        raise ValueError(
            f"{camera}: the board has the same orientation in every view ({views}), up to "
            f"translations and turns in its own plane: the board planes are parallel (at most "
            f"{np.degrees(spread):.2g}° apart, tolerance {np.degrees(tolerance_rad):.0f}°), which "
            f"leaves the intrinsics undetermined (Zhang's degenerate configuration); take views "
            f"with the board tilted in at least two different directions")


def init_camera(
    object_points: np.ndarray | Sequence[np.ndarray], image_points: Sequence[np.ndarray],
    image_size: tuple[int, int], camera: str = "camera"
) -> tuple[np.ndarray, list[SE3]]:
    """K and one cam_from_board pose per view, from a planar target (z = 0).

    Raises ValueError naming ``camera`` and the views when all board planes
    are parallel (:func:`check_board_planes`).

    Parameters
    ----------
    object_points : (M, 3), or a sequence of (M_i, 3), one per view
        Target points in the board frame, all with z = 0; per view when each
        view sees a different part of the board (partial views).
    image_points : sequence of (M, 2) (or (M_i, 2))
        Their detections in each view (pixels).
    image_size : (width, height)
    camera : str
        The camera's name in error messages.
    """
    try:
        shared = np.asarray(object_points, dtype=float)
    except ValueError:  # ragged: one set per view
        shared = None
    if shared is not None and shared.ndim == 2:
        objs = [shared] * len(image_points)
    else:
        objs = list(object_points)
        if len(objs) != len(image_points):
            raise ValueError(f"init_camera: {len(objs)} object point sets for {len(image_points)} views")
    Hs = []
    for obj, p in zip(objs, image_points):
        obj = np.asarray(obj, dtype=float)
        if obj.ndim != 2 or obj.shape[1] != 3 or np.abs(obj[:, 2]).max() > 1e-9 * max(1.0, np.abs(obj).max()):
            raise ValueError("init_camera: object_points must be (M, 3) with z = 0 (a planar target)")
        Hs.append(homography(obj[:, :2], np.asarray(p, dtype=float)))
    K = intrinsics_from_homographies(Hs, image_size)
    check_board_planes(board_normals(K, Hs), camera)
    return K, [pose_from_homography(K, H) for H in Hs]
