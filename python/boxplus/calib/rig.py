"""Standard rigs in a few calls: cameras as variables with named intrinsics,
mono and stereo calibration built from the C++ board factor, with closed-form
initial values (:mod:`boxplus.calib.init`).

Frames: ``world`` is the board frame; ``world_from_cam_i`` is the reference
camera's pose in the board frame for view i; ``right_from_left`` takes points
of the left camera into the right camera. Camera models: see
``cpp/include/boxplus/factors/camera/models.h`` ("opencv5" is OpenCV's default
k1 k2 p1 p2 k3; "radial2" k1 k2; "radial1" k1).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from boxplus import problem as _problem
from boxplus._core import SolveSummary
from boxplus.calib.init import (
    CAMERA_LABELS,
    camera_matrix,
    check_solved_views,
    check_views,
    init_camera,
    intrinsics_vector,
    relative_pose_init,
)
from boxplus.manifolds import SE3, Rn

__all__ = ["add_camera", "Calibration", "calibrate_mono", "calibrate_stereo", "detect_corners"]


def add_camera(o: _problem.OptimizationProblem, name: str, K: np.ndarray, model: str = "opencv5",
               dist: Sequence[float] = (), fixed: bool = False) -> int:
    """Adds the intrinsics of a camera (an Rn of the model's size, labelled fx, fy, ...)."""
    k = intrinsics_vector(np.asarray(K, float), model, dist)
    return o.add_random_var(Rn(k), fixed=fixed, name=name, labels=CAMERA_LABELS[model])


@dataclass
class Calibration:
    """A solved calibration: the problem, ids of its variables, the solve result."""

    problem: _problem.OptimizationProblem
    model: str
    ids: dict[str, int]
    view_ids: dict[str, list[int]] = field(default_factory=dict)
    result: SolveSummary | None = None

    def camera(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """(K, OpenCV distortion) of a camera."""
        return camera_matrix(self.problem[self.ids[name]].vec, self.model)

    def rms(self) -> float:
        """OpenCV's RMS: sqrt(Σ‖2-D error‖² / number of points), over all boards."""
        E = np.concatenate([self.problem.measurement_errors(m) for ms in self.view_ids.values() for m in ms])
        return float(np.sqrt(np.mean(np.sum(E**2, axis=1))))

    def report(self, rescale: bool = True):
        from boxplus.calib.report import report

        return report(self.problem, rescale=rescale)


def _camera_init(image_points, object_points, image_size, camera):
    pts = check_views(image_points, object_points, image_size, camera)
    K, cam_from_board = init_camera(object_points, pts, image_size, camera)
    return pts, K, cam_from_board


def calibrate_mono(image_points: Sequence[np.ndarray], object_points: np.ndarray,
                   image_size: tuple[int, int], model: str = "opencv5", sigma: Any = None,
                   name: str = "camera", solve: bool = True, covariance: Any = None) -> Calibration:
    """One camera from views of a planar board (Zhang's initial values, then ML).

    The corner noise is ``sigma`` (σ or [σu, σv], pixels) or a 2×2 ``covariance``
    (none: σ = 1). Raises ValueError naming the camera and view for bad
    detections, and when the board planes are parallel in every view (the
    intrinsics are then undetermined); warns when the solved focal length is
    barely determined (:func:`boxplus.calib.init.check_solved_views`)."""
    pts, K, cam_from_board = _camera_init(image_points, object_points, image_size, name)
    o = _problem.OptimizationProblem()
    cam = add_camera(o, name, K, model)
    ident = o.add_random_var(SE3(), fixed=True, name="identity")
    mids, views = [], []
    for i, (p, pose) in enumerate(zip(pts, cam_from_board)):
        views.append(o.add_random_var(pose.inverse(), name=f"world_from_{name}_{i}"))
        mids.append(o.add_board(p, cam, views[-1], ident, object_points, sigma=sigma,
                                covariance=covariance, model=model, group=name))
    cal = Calibration(o, model, {name: cam}, {name: mids})
    if solve:
        cal.result = o.solve()
        check_solved_views(o, [cam], views, name)
    return cal


def calibrate_stereo(left_points: Sequence[np.ndarray], right_points: Sequence[np.ndarray],
                     object_points: np.ndarray, image_size: tuple[int, int],
                     model: str = "opencv5", sigma: Any = None,
                     fixed_intrinsics: tuple[np.ndarray, np.ndarray] | None = None,
                     solve: bool = True, covariance: Any = None) -> Calibration:
    """A stereo pair seeing the same boards: intrinsics of both cameras, right_from_left
    and one world_from_left per view, jointly (or with ``fixed_intrinsics`` =
    (k_left, k_right) model vectors held constant, like OpenCV's
    CALIB_FIX_INTRINSIC). Refuses parallel boards and warns of a barely determined
    focal length like :func:`calibrate_mono`."""
    if len(left_points) != len(right_points):
        raise ValueError(f"stereo: {len(left_points)} left and {len(right_points)} right views")
    pl, Kl, left_from_board = _camera_init(left_points, object_points, image_size, "left")
    pr, Kr, right_from_board = _camera_init(right_points, object_points, image_size, "right")
    o = _problem.OptimizationProblem()
    if fixed_intrinsics is None:
        left = add_camera(o, "left", Kl, model)
        right = add_camera(o, "right", Kr, model)
    else:
        left = o.add_random_var(Rn(np.asarray(fixed_intrinsics[0], float)), fixed=True,
                                name="left", labels=CAMERA_LABELS[model])
        right = o.add_random_var(Rn(np.asarray(fixed_intrinsics[1], float)), fixed=True,
                                 name="right", labels=CAMERA_LABELS[model])
    ident = o.add_random_var(SE3(), fixed=True, name="identity")
    right_from_left = o.add_random_var(relative_pose_init(left_from_board, right_from_board),
                                       name="right_from_left")
    ml, mr, views = [], [], []
    for i, (zl, zr, pose) in enumerate(zip(pl, pr, left_from_board)):
        world_from_left = o.add_random_var(pose.inverse(), name=f"world_from_left_{i}")
        views.append(world_from_left)
        ml.append(o.add_board(zl, left, world_from_left, ident, object_points, sigma=sigma,
                              covariance=covariance, model=model, group="left"))
        mr.append(o.add_board(zr, right, world_from_left, right_from_left, object_points,
                              sigma=sigma, covariance=covariance, model=model, group="right"))
    cal = Calibration(o, model, {"left": left, "right": right, "right_from_left": right_from_left},
                      {"left": ml, "right": mr})
    if solve:
        cal.result = o.solve()
        # the right camera sees the same boards turned by one rotation: the
        # same spread of planes
        check_solved_views(o, [left, right], views, "stereo")
    return cal


def detect_corners(images: Sequence[np.ndarray], pattern_size: tuple[int, int]) -> list[np.ndarray | None]:
    """Chessboard corners per image with OpenCV (the optional extra
    opencv-python-headless): (N, 2) float arrays, None where no board was found."""
    try:
        import cv2
    except ImportError:
        raise ImportError("corner detection needs opencv-python-headless: pip install "
                          "'opencv-python-headless<5'") from None
    out: list[np.ndarray | None] = []
    crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 30, 0.01)
    for img in images:
        # Any: cv2's stubs take only integer/floating dtypes, an image arrives as any array.
        gray: Any = img if img.ndim == 2 else cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)
        # flags by keyword: the third positional argument is the output array `corners`.
        ok, c = cv2.findChessboardCorners(gray, tuple(pattern_size),
                                          flags=cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE)
        if not ok:
            out.append(None)
            continue
        c = cv2.cornerSubPix(gray, c, (7, 7), (-1, -1), crit)
        out.append(c.reshape(-1, 2).astype(float))
    return out
