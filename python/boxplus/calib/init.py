"""Closed-form initial values for standard rigs: no user guesses a start.

* camera intrinsics and board poses: Zhang's method (:mod:`boxplus.calib.zhang`);
* a board pose from a calibrated camera (PnP for a planar board via the
  homography of undistorted normalised points);
* rigid transforms between sensors that see the same boards (stereo):
  the chordal mean of the per-view transforms;
* rotation between two sensors from paired directions (camera–IMU from
  gravity): Kabsch/Wahba;
* hand-eye AX = XB (Park & Martin 1994) and robot-world/hand-eye AX = ZB;
* stereo triangulation of points (midpoint of the two rays);
* a camera's mount on a robot link and the markers on its hands from
  triangulated marker positions and forward kinematics (linear, then
  projected onto SO(3)).

Frames: ``b_from_a`` maps points of frame a into frame b (p_in_b = R p_in_a + t).
Poses are boxplus SE3 values, tangent order [translation, rotation].
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from typing import Any

import numpy as np

from boxplus.calib.models import CAMERA_LABELS, camera_matrix, intrinsics_vector, rays
from boxplus.calib.report import report
from boxplus.calib.zhang import (
    SOLVED_PARALLEL_PLANES_RAD,
    check_board_planes,
    homography,
    init_camera,
    pose_from_homography,
)
from boxplus.geometry import absolute_orientation, project_to_so3, triangulate_midpoint
from boxplus.manifolds import SE3, SO3

__all__ = [
    "CAMERA_LABELS", "intrinsics_vector", "camera_matrix", "check_views", "check_solved_views",
    "init_camera",
    "board_pose", "pose_from_rays", "mean_pose", "relative_pose_init", "rotation_between",
    "hand_eye_park",
    "robot_world_hand_eye", "triangulate", "marker_hand_eye",
]

def check_views(
    image_points: Sequence[np.ndarray], object_points: np.ndarray, image_size: tuple[int, int],
    camera: str = "camera", min_views: int = 3,
) -> list[np.ndarray]:
    """Validates the detections of one camera; returns them as float arrays.

    Raises ValueError naming the camera and the view for: too few views, a view
    that is missing (None: the board was not detected), of the wrong shape, with
    non-finite points or points outside the image, or a bad image size.
    """
    size = np.asarray(image_size)
    if size.shape != (2,) or np.any(size <= 0):
        raise ValueError(f"{camera}: image_size must be (width, height) > 0, got {image_size}")
    obj = np.asarray(object_points, float)
    out = []
    for i, p in enumerate(image_points):
        if p is None:
            raise ValueError(f"{camera}, view {i}: the board was not detected (drop the view)")
        p = np.asarray(p, float)
        if p.ndim != 2 or p.shape[1] != 2 or len(p) < 4:
            raise ValueError(f"{camera}, view {i}: image points must be (N >= 4, 2), got {p.shape}")
        if len(p) != len(obj):
            raise ValueError(f"{camera}, view {i}: {len(p)} image points for {len(obj)} board points")
        if not np.all(np.isfinite(p)):
            raise ValueError(f"{camera}, view {i}: non-finite image points")
        if np.any(p < -0.5) or np.any(p > size - 0.5):
            raise ValueError(f"{camera}, view {i}: points outside the {size[0]}×{size[1]} image "
                             "(wrong image_size, or images of different sizes for one camera?)")
        out.append(p)
    if len(out) < min_views:
        raise ValueError(f"{camera}: {len(out)} views, at least {min_views} are needed to calibrate "
                         "a camera from a planar board")
    return out


# A focal length whose σ exceeds this fraction of it is barely determined.
FOCAL_REL_STD = 0.1


def check_solved_views(problem: Any, cameras: Sequence[int], world_from_cam: Sequence[int],
                       camera: str = "camera") -> None:
    """The degenerate-view checks on a solved board calibration.

    ``world_from_cam`` are the pose variables of the views (in their order),
    ``cameras`` the intrinsics variables. Raises ValueError naming the views
    when the solved board planes are parallel (within
    ``SOLVED_PARALLEL_PLANES_RAD``; the closed form's poses are bent by lens
    distortion, the solved ones are not), and warns (UserWarning) when the
    solve leaves a focal length with σ above ``FOCAL_REL_STD`` of its value:
    nearly parallel or nearly fronto-parallel boards, whose refinement can
    converge to a focal length off by a factor with only its σ to tell.
    """
    # the board's normal e3 in camera coordinates: (world_from_cam.R)ᵀ e3
    N = np.array([problem[v].rot.R[2, :] for v in world_from_cam])
    check_board_planes(N, camera, SOLVED_PARALLEL_PLANES_RAD)
    if len(N) == 0:
        return
    rep = report(problem)
    spread = np.degrees(np.arccos(np.clip(np.abs(N @ N.T), 0.0, 1.0)).max())
    for cam in cameras:
        name = problem.variable_name(cam)
        for p in rep.parameters:
            if p.variable == name and p.label in ("f", "fx", "fy") and p.value > 0 \
                    and not p.std <= FOCAL_REL_STD * p.value:
                warnings.warn(
                    f"{camera}: {name}.{p.label} = {p.value:.1f} ± {p.std:.1f} px is barely "
                    f"determined by views {', '.join(str(i) for i in range(len(N)))} (their board "
                    f"planes are at most {spread:.1f}° apart); take views with the board tilted "
                    f"further in different directions", stacklevel=3)


def board_pose(K: np.ndarray, image_points: np.ndarray, object_points: np.ndarray,
               dist: Sequence[float] | np.ndarray = (0, 0, 0, 0, 0), model: str = "opencv5") -> SE3:
    """cam_from_board of a planar board (z = 0) seen by a calibrated camera (PnP by the
    homography of the viewing rays' normalised points, Zhang eq. 12). ``dist`` is
    in OpenCV's order for ``model`` (:data:`boxplus.calib.models.OPENCV_DISTORTION`)."""
    return pose_from_rays(rays(intrinsics_vector(K, model, dist), np.asarray(image_points, float), model),
                          object_points)


def pose_from_rays(r: np.ndarray, object_points: np.ndarray) -> SE3:
    """cam_from_board of a planar board (z = 0) from its corners' viewing rays (N, 3) in
    the camera frame, any lens model (the homography of the normalised rays)."""
    obj = np.asarray(object_points, float)
    if np.any(r[:, 2] <= 1e-6):
        raise ValueError("board_pose: a corner's ray is 90° or more off the optical axis; the "
                         "homography needs points in front of the camera")
    return pose_from_homography(np.eye(3), homography(obj[:, :2], r[:, :2] / r[:, 2:3]))


def mean_pose(poses: Sequence[SE3]) -> SE3:
    """Chordal L2 mean of poses (mean translation, rotation projected to SO(3))."""
    if not poses:
        raise ValueError("mean_pose: no poses")
    R = project_to_so3(np.sum([p.rot.R for p in poses], axis=0), "mean_pose")
    return SE3(SO3(R), np.mean([p.pos for p in poses], axis=0))


def relative_pose_init(a_from_board: Sequence[SE3], b_from_board: Sequence[SE3]) -> SE3:
    """b_from_a from views of the same boards by sensors a and b (stereo): the mean of
    b_from_board_i ∘ a_from_board_i⁻¹."""
    if len(a_from_board) != len(b_from_board) or not a_from_board:
        raise ValueError("relative_pose_init: need the same (≥ 1) number of views from both sensors")
    return mean_pose([b * a.inverse() for a, b in zip(a_from_board, b_from_board)])


def rotation_between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """R minimising Σ‖b_i − R a_i‖² (Kabsch / Wahba); a, b (N, 3). Raises when the
    directions are all parallel (the rotation about them is then undetermined)."""
    try:
        b_from_a = absolute_orientation(a, b, translation=False, what="rotation_between")
        assert isinstance(b_from_a, SE3)  # without scale= it is a pose, not (pose, scale)
        return b_from_a.rot.R
    except ValueError as e:
        if "parallel" not in str(e):
            raise
        raise ValueError(f"{e} (e.g. an IMU's yaw from gravity with one board orientation)") from None


def hand_eye_park(base_from_gripper: Sequence[SE3], cam_from_target: Sequence[SE3]) -> SE3:
    """gripper_from_cam X from A X = X B (Park & Martin 1994), eye-in-hand.

    With G_i = base_from_gripper_i, T_i = cam_from_target_i and a fixed target:
    G_i X T_i = const, so A = G_j⁻¹ G_i and B = T_j T_i⁻¹ for all pairs i < j.
    """
    n = len(base_from_gripper)
    if n < 3 or len(cam_from_target) != n:
        raise ValueError(f"hand-eye needs ≥ 3 pose pairs, got {n} and {len(cam_from_target)}")
    As, Bs = [], []
    for i in range(n):
        for j in range(i + 1, n):
            As.append(base_from_gripper[j].inverse() * base_from_gripper[i])
            Bs.append(cam_from_target[j] * cam_from_target[i].inverse())
    alpha = np.array([A.rot.log() for A in As])
    beta = np.array([B.rot.log() for B in Bs])
    M = beta.T @ alpha  # Σ β αᵀ
    w, V = np.linalg.eigh(M.T @ M)
    if w.min() < 1e-12 * max(w.max(), 1e-300):
        raise ValueError("hand-eye: the rotations are about parallel axes (≥ 2 axes are needed)")
    R = project_to_so3(V @ np.diag(w**-0.5) @ V.T @ M.T, "hand-eye")
    C = np.vstack([A.rot.R - np.eye(3) for A in As])
    d = np.concatenate([R @ B.pos - A.pos for A, B in zip(As, Bs)])
    t, *_ = np.linalg.lstsq(C, d, rcond=None)
    return SE3(SO3(R), t)


def robot_world_hand_eye(base_from_gripper: Sequence[SE3], cam_from_target: Sequence[SE3]) -> tuple[SE3, SE3]:
    """(gripper_from_cam X, base_from_target Z) from G_i X T_i = Z: X by Park–Martin, then
    Z as the mean of G_i X T_i."""
    X = hand_eye_park(base_from_gripper, cam_from_target)
    Z = mean_pose([G * X * T for G, T in zip(base_from_gripper, cam_from_target)])
    return X, Z


def triangulate(z_a: np.ndarray, z_b: np.ndarray, k_a: np.ndarray, k_b: np.ndarray, b_from_a: SE3,
                model: str = "opencv5") -> np.ndarray:
    """Points (N, 3) in frame a from their pixels (N, 2) in two calibrated cameras
    a and b (intrinsics vectors of ``model``; ``b_from_a`` maps points of a into b): the
    midpoint of the closest points of the two undistorted rays."""
    za, zb = np.atleast_2d(np.asarray(z_a, float)), np.atleast_2d(np.asarray(z_b, float))
    if za.shape != zb.shape or za.shape[1] != 2:
        raise ValueError(f"triangulate: z_a and z_b must be the same (N, 2), got {za.shape}, {zb.shape}")
    R, t = b_from_a.rot.R, b_from_a.pos
    # camera a at the origin of a; camera b's centre −Rᵀt and rays Rᵀ r_b in a
    return triangulate_midpoint(np.zeros(3), rays(k_a, za, model), -R.T @ t,
                                rays(k_b, zb, model) @ R, "triangulate")


def marker_hand_eye(p_in_rig: Sequence[np.ndarray], base_from_hand: Sequence[Sequence[SE3]]
                    ) -> tuple[SE3, list[np.ndarray]]:
    """(base_from_rig, [p_in_hand per hand]) from markers seen in a sensor frame x.

    For hand h and arm pose i the marker p_h (fixed on the hand, unknown) is
    measured at ``p_in_rig[h][i]`` (e.g. triangulated by a stereo head) while
    forward kinematics gives ``base_from_hand[h][i]`` = (R_hi, t_hi):

        R_x p_in_rig[h][i] + t_x − R_hi p_h = t_hi,

    linear in (R_x as 9 numbers, t_x, p_h for every hand). It is solved by least
    squares, R_x projected onto SO(3), then t_x and the p_h solved again with R_x
    fixed. Needs the marker positions to span 3-D and the hands to rotate.
    """
    if len(p_in_rig) != len(base_from_hand) or not p_in_rig:
        raise ValueError("marker_hand_eye: one list of points and one of poses per hand")
    nh = len(p_in_rig)
    rows, rhs = [], []
    for h, (P, poses) in enumerate(zip(p_in_rig, base_from_hand)):
        P = np.asarray(P, float).reshape(-1, 3)
        if len(P) != len(poses):
            raise ValueError(f"marker_hand_eye: hand {h}: {len(P)} points for {len(poses)} poses")
        for p, H in zip(P, poses):
            A = np.zeros((3, 12 + 3 * nh))
            A[:, :9] = np.kron(np.eye(3), p)      # R_x p, R_x row-major
            A[:, 9:12] = np.eye(3)
            A[:, 12 + 3 * h:15 + 3 * h] = -H.rot.R
            rows.append(A)
            rhs.append(H.pos)
    A, b = np.vstack(rows), np.concatenate(rhs)
    s = np.linalg.svd(A, compute_uv=False)
    if s[-1] < 1e-9 * s[0]:
        raise ValueError("marker_hand_eye: degenerate poses (markers in a plane, or hands that do not rotate)")
    x, *_ = np.linalg.lstsq(A, b, rcond=None)
    R = project_to_so3(x[:9].reshape(3, 3), "marker_hand_eye")
    # with R fixed: t_x and the p_h
    A2 = A[:, 9:]
    b2 = b - A[:, :9] @ R.reshape(-1)
    y, *_ = np.linalg.lstsq(A2, b2, rcond=None)
    return SE3(SO3(R), y[:3]), [y[3 + 3 * h:6 + 3 * h] for h in range(nh)]
