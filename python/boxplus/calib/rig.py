"""Standard rigs in a few calls: cameras as variables with named intrinsics,
mono and stereo calibration built from the C++ board factor, with closed-form
initial values (:mod:`boxplus.calib.init`).

Frames: ``world`` is the board frame; ``cam2world_i`` is the reference
camera's pose in the board frame for view i; ``left2right`` takes points of
the left camera into the right camera. Camera models: see
``cpp/include/boxplus/factors/pinhole.h`` ("opencv5" is OpenCV's default
k1 k2 p1 p2 k3; "radial2" k1 k2; "radial1" k1).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from boxplus.manifolds import SE3, Rn
from boxplus._core import SolveSummary
from boxplus.problem import OptimizationProblem
from boxplus.calib.init import (
    CAMERA_LABELS, camera_matrix, check_views, init_camera, intrinsics_vector, relative_pose_init,
)

__all__ = ["add_camera", "Calibration", "calibrate_mono", "calibrate_stereo", "detect_corners"]


def add_camera(o: OptimizationProblem, name: str, K: np.ndarray, model: str = "opencv5",
               dist: Sequence[float] = (), fixed: bool = False) -> int:
    """Adds the intrinsics of a camera (an Rn of the model's size, labelled fx, fy, ...)."""
    k = intrinsics_vector(np.asarray(K, float), model, dist)
    return o.add_random_var(Rn(k), fixed=fixed, name=name, labels=CAMERA_LABELS[model])


@dataclass
class Calibration:
    """A solved calibration: the problem, ids of its variables, the solve result."""

    problem: OptimizationProblem
    model: str
    ids: Dict[str, int]
    view_ids: Dict[str, List[int]] = field(default_factory=dict)
    result: Optional[SolveSummary] = None

    def camera(self, name: str) -> Tuple[np.ndarray, np.ndarray]:
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
    K, board2cam = init_camera(object_points, pts, image_size)
    return pts, K, board2cam


def calibrate_mono(image_points: Sequence[np.ndarray], object_points: np.ndarray,
                   image_size: Tuple[int, int], model: str = "opencv5", sigma: Any = 1.0,
                   name: str = "camera", solve: bool = True, covariance: Any = None) -> Calibration:
    """One camera from views of a planar board (Zhang's initial values, then ML)."""
    pts, K, board2cam = _camera_init(image_points, object_points, image_size, name)
    o = OptimizationProblem()
    cam = add_camera(o, name, K, model)
    ident = o.add_random_var(SE3(), fixed=True, name="identity")
    mids = []
    for i, (p, pose) in enumerate(zip(pts, board2cam)):
        x2world = o.add_random_var(pose.inverse(), name=f"{name}2world_{i}")
        mids.append(o.add_board(p, cam, x2world, ident, object_points,
                                sigma=None if covariance is not None else sigma,
                                covariance=covariance, model=model, group=name))
    cal = Calibration(o, model, {name: cam}, {name: mids})
    if solve:
        cal.result = o.solve()
    return cal


def calibrate_stereo(left_points: Sequence[np.ndarray], right_points: Sequence[np.ndarray],
                     object_points: np.ndarray, image_size: Tuple[int, int],
                     model: str = "opencv5", sigma: float = 1.0,
                     fixed_intrinsics: Optional[Tuple[np.ndarray, np.ndarray]] = None,
                     solve: bool = True) -> Calibration:
    """A stereo pair seeing the same boards: intrinsics of both cameras, left2right
    and one left2world per view, jointly (or with ``fixed_intrinsics`` =
    (k_left, k_right) model vectors held constant, like OpenCV's
    CALIB_FIX_INTRINSIC)."""
    if len(left_points) != len(right_points):
        raise ValueError(f"stereo: {len(left_points)} left and {len(right_points)} right views")
    pl, Kl, b2l = _camera_init(left_points, object_points, image_size, "left")
    pr, Kr, b2r = _camera_init(right_points, object_points, image_size, "right")
    o = OptimizationProblem()
    if fixed_intrinsics is None:
        left = add_camera(o, "left", Kl, model)
        right = add_camera(o, "right", Kr, model)
    else:
        left = o.add_random_var(Rn(np.asarray(fixed_intrinsics[0], float)), fixed=True,
                                name="left", labels=CAMERA_LABELS[model])
        right = o.add_random_var(Rn(np.asarray(fixed_intrinsics[1], float)), fixed=True,
                                 name="right", labels=CAMERA_LABELS[model])
    ident = o.add_random_var(SE3(), fixed=True, name="identity")
    left2right = o.add_random_var(relative_pose_init(b2l, b2r), name="left2right")
    ml, mr = [], []
    for i, (zl, zr, pose) in enumerate(zip(pl, pr, b2l)):
        l2w = o.add_random_var(pose.inverse(), name=f"left2world_{i}")
        ml.append(o.add_board(zl, left, l2w, ident, object_points, sigma=sigma, model=model, group="left"))
        mr.append(o.add_board(zr, right, l2w, left2right, object_points, sigma=sigma, model=model,
                              group="right"))
    cal = Calibration(o, model, {"left": left, "right": right, "left2right": left2right},
                      {"left": ml, "right": mr})
    if solve:
        cal.result = o.solve()
    return cal


def detect_corners(images: Sequence[np.ndarray], pattern_size: Tuple[int, int]) -> List[Optional[np.ndarray]]:
    """Chessboard corners per image with OpenCV (the optional extra
    opencv-python-headless): (N, 2) float arrays, None where no board was found."""
    try:
        import cv2
    except ImportError:
        raise ImportError("corner detection needs opencv-python-headless: pip install "
                          "'opencv-python-headless<5'") from None
    out = []
    crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 30, 0.01)
    for img in images:
        gray = img if img.ndim == 2 else cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)
        ok, c = cv2.findChessboardCorners(gray, tuple(pattern_size),
                                          cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE)
        if not ok:
            out.append(None)
            continue
        c = cv2.cornerSubPix(gray, c, (7, 7), (-1, -1), crit)
        out.append(c.reshape(-1, 2).astype(float))
    return out
