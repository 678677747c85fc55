"""Camera calibration helpers: closed-form initialisation (Zhang) and models."""

from boxplus.calib.zhang import (
    homography,
    init_camera,
    intrinsics_from_homographies,
    pose_from_homography,
)

__all__ = ["homography", "init_camera", "intrinsics_from_homographies", "pose_from_homography"]
