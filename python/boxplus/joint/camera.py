"""The camera model shared by the image-based 3D systems (vectorised).

A camera's intrinsics are the compound :data:`CameraIntrinsics`
``(f: Rn(1), c: Rn(2), k1: Rn(1))``: one focal length in pixels, the principal
point in pixels and one radial distortion coefficient on normalised
coordinates (OpenCV's model with fx = fy and only k1):

    π(p_in_cam) = f · x · (1 + k1 ‖x‖²) + c,   x = (p₀/p₂, p₁/p₂).

Functions take batches (``boxplus.batch``): ``cam.f.vec`` (N, 1) etc., so that
one call evaluates N rows.
"""

from __future__ import annotations

import numpy as np

from boxplus.geometry import project_pinhole
from boxplus.manifolds import Rn, make_compound

__all__ = ["CameraIntrinsics", "project", "ray"]

CameraIntrinsics = make_compound("CameraIntrinsics", f=Rn(1), c=Rn(2), k1=Rn(1))

_NEWTON_STEPS = 6  # quadratic convergence: below 1e-15 from the distorted radius after 4


def project(cam, p_in_cam: np.ndarray) -> np.ndarray:
    """Pixels (N, 2) of points p_in_cam (N, 3)."""
    return project_pinhole(p_in_cam, cam.f.vec, cam.c.vec, k1=cam.k1.vec)


def ray(cam, uv: np.ndarray) -> np.ndarray:
    """Viewing rays (N, 3) = [x, y, 1] of pixels uv (N, 2), undistorted.

    The undistorted radius s solves s (1 + k1 s²) = r_d; Newton's method from
    s = r_d, a fixed number of steps so that the result is smooth in k1 and uv
    (the solver differentiates it numerically).
    """
    xd = (uv - cam.c.vec) / cam.f.vec
    rd = np.sqrt(np.sum(xd * xd, axis=1, keepdims=True))
    k1 = cam.k1.vec
    s = rd.copy()
    for _ in range(_NEWTON_STEPS):
        s = s - (s * (1.0 + k1 * s * s) - rd) / (1.0 + 3.0 * k1 * s * s)
    x = xd / (1.0 + k1 * s * s)
    return np.column_stack([x, np.ones(len(x))])
