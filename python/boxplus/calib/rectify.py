"""Stereo rectification of a calibrated pair, as OpenCV and ROS compute and read it.

A stereo pipeline (ROS ``stereo_image_proc``, OpenCV ``initUndistortRectifyMap`` +
``StereoSGBM``) needs more than K, distortion and right_from_left: each camera's
rectification rotation R₁, R₂ (raw camera frame → rectified frame, both image
planes coplanar with rows on the epipolar lines) and projection P₁, P₂ of the
rectified cameras,

    P₁ = [f′ 0 c′x 0; 0 f′ c′y 0; 0 0 1 0],  P₂ = [f′ 0 c′x Tx; 0 f′ c′y 0; 0 0 1 0],

with Tx = −f′·B for a baseline B (metres, or the target's unit) — the depth of
a disparity d is Z = −Tx / d — and OpenCV's reprojection matrix Q. This module
computes them with OpenCV's own functions (Bouguet's method, ``cv2.stereoRectify``
for the pinhole family and the rational model, ``cv2.fisheye.stereoRectify`` for
Kannala–Brandt), with ``CALIB_ZERO_DISPARITY`` as ROS' ``camera_calibration``
uses, so the files boxplus writes mean what those tools think they mean.
OpenCV and ROS have no double-sphere model: such a pair is refused by name.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from boxplus._optional import require

__all__ = ["StereoRectification", "rectify_stereo"]


@dataclass
class StereoRectification:
    """R1, R2 (3×3), P1, P2 (3×4), Q (4×4) of a rectified pair (OpenCV's names and
    meaning) and the image size. A horizontal pair has Tx = P2[0, 3] = −f′B; a vertical
    one (OpenCV rectifies it too) Ty = P2[1, 3] = −f′B instead."""

    R1: np.ndarray
    R2: np.ndarray
    P1: np.ndarray
    P2: np.ndarray
    Q: np.ndarray
    image_size: tuple[int, int]

    @property
    def vertical(self) -> bool:
        return bool(abs(self.P2[1, 3]) > abs(self.P2[0, 3]))

    @property
    def baseline(self) -> float:
        """B in the unit of the calibration (from Tx, or Ty for a vertical pair)."""
        return float(-self.P2[1 if self.vertical else 0, 3] / self.P2[0, 0])

    def todict(self) -> dict[str, Any]:
        return {"R1": self.R1.tolist(), "R2": self.R2.tolist(), "P1": self.P1.tolist(),
                "P2": self.P2.tolist(), "Q": self.Q.tolist(), "image_size": list(self.image_size),
                "baseline": self.baseline}

    def __repr__(self) -> str:
        return (f"StereoRectification(baseline={self.baseline:.6g}, f={self.P1[0, 0]:.6g}, "
                f"image_size={self.image_size})")


def rectify_stereo(left: Any, right: Any, alpha: float = 0.0) -> StereoRectification:
    """The rectification of two :class:`boxplus.calib.io.CalibratedCamera` (``right.cam_from_ref``
    relative to ``left.cam_from_ref``); ``alpha`` as in ``cv2.stereoRectify`` (0: only
    valid pixels, 1: all pixels; ROS' default 0)."""
    cv2 = require("cv2", "stereo rectification")
    if left.model != right.model and "kannala_brandt" in (left.model, right.model):
        raise ValueError(f"stereo pair '{left.name}', '{right.name}': OpenCV rectifies a "
                         f"Kannala-Brandt camera only with another ({left.model}, {right.model})")
    for c in (left, right):
        if c.model == "double_sphere":
            raise ValueError(f"camera '{c.name}': OpenCV and ROS have no double-sphere model, "
                             f"so they cannot rectify it (write a Kalibr camchain)")
    if tuple(left.image_size) != tuple(right.image_size):
        raise ValueError(f"stereo pair '{left.name}', '{right.name}': images of different sizes "
                         f"{left.image_size} and {right.image_size}")
    right_from_left = right.cam_from_ref * left.cam_from_ref.inverse()
    R = np.ascontiguousarray(right_from_left.rot.R)
    T = np.ascontiguousarray(right_from_left.pos.reshape(3, 1))
    size = (int(left.image_size[0]), int(left.image_size[1]))
    if left.model == "kannala_brandt":
        R1, R2, P1, P2, Q = cv2.fisheye.stereoRectify(
            left.K, left.dist.reshape(4, 1), right.K, right.dist.reshape(4, 1), size, R, T,
            cv2.CALIB_ZERO_DISPARITY, balance=alpha)
    else:
        R1, R2, P1, P2, Q, _, _ = cv2.stereoRectify(
            left.K, left.dist, right.K, right.dist, size, R, T, flags=cv2.CALIB_ZERO_DISPARITY,
            alpha=alpha)
    return StereoRectification(R1, R2, P1, P2, Q, size)
