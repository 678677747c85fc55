"""Lens models that fold over: a fitted projection that stops moving outwards.

A real lens maps a ray further from the optical axis to a pixel further from the
principal point. A distortion polynomial (or rational function) fitted to corners
can violate this inside the very field it was fitted on: OpenCV's rational model
on a wide lens reached the lowest RMS and folded over at 43°, 48 px off there,
with nothing to warn. Along each of 24 azimuths φ, the pixel's distance from the
principal point, ρ(θ) = ‖π(k, [sin θ cos φ, sin θ sin φ, cos θ]) − c‖ for the
incidence angle θ from 0 to the largest angle at which the camera saw a corner,
must increase; the first θ where it does not is the fold. The check costs one
projection of 24 × 400 rays per camera.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from boxplus.calib.models import model_labels, project

__all__ = ["LensFoldWarning", "check_fold_over", "fold_angle", "observed_field"]


class LensFoldWarning(UserWarning):
    """A fitted lens model folds over inside the field its corners covered."""


def fold_angle(k: np.ndarray, model: str, theta_max: float, azimuths: int = 24,
               steps: int = 400) -> float | None:
    """The smallest incidence angle (radians, ≤ ``theta_max``) at which the projection
    stops moving away from the principal point along some azimuth; None when it never
    does."""
    labels = model_labels(model)
    c = np.array([k[labels.index("cx")], k[labels.index("cy")]])
    theta = np.linspace(0.0, theta_max, steps)[1:]
    first = None
    for phi in np.linspace(0.0, 2 * np.pi, azimuths, endpoint=False):
        rays = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], axis=1)
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            rho = np.linalg.norm(project(k, rays, model) - c, axis=1)
        bad = np.flatnonzero(~(np.diff(rho) > 0))
        if bad.size:
            t = float(theta[bad[0]])
            first = t if first is None else min(first, t)
    return first


def observed_field(cal: Any, camera: str) -> float:
    """The largest incidence angle (radians) of a corner ``camera`` saw, from the
    solved board poses."""
    o = cal.problem
    ref = cal.reference
    cam_from_ref = None if camera == ref else o[cal.ids[f"{camera}_from_{ref}"]]
    largest = 0.0
    for ob in cal.observations:
        if ob.camera != camera or cal.world_from_ref[ob.view] is None:
            continue
        world_from_ref = o[cal.world_from_ref[ob.view]]
        world_from_cam = world_from_ref if cam_from_ref is None else world_from_ref * cam_from_ref.inverse()
        p = (ob.obj - world_from_cam.pos) @ world_from_cam.rot.R
        largest = max(largest, float(np.max(np.arctan2(np.hypot(p[:, 0], p[:, 1]), p[:, 2]))))
    return largest


def check_fold_over(cal: Any) -> list[str]:
    """Warns (:class:`LensFoldWarning`) for every camera of a solved calibration whose
    model folds over inside the field its corners covered; returns the messages."""
    out = []
    for camera in cal.view_ids:
        model = cal.models.get(camera, cal.model)
        field = observed_field(cal, camera)
        if field <= 0:
            continue
        t = fold_angle(np.asarray(cal.problem[cal.ids[camera]].vec, dtype=float), model, field)
        if t is not None:
            msg = (f"{camera}: the fitted {model} model folds over at {np.degrees(t):.1f}° from the "
                   f"optical axis, inside the field its corners covered (up to "
                   f"{np.degrees(field):.1f}°): pixels there project wrongly although the RMS is "
                   f"low; use a model with fewer distortion terms, a distortion prior "
                   f"(regularize=True, or a smaller width; boxplus-calib --regularize), or "
                   f"views with the board near the image border")
            warnings.warn(LensFoldWarning(msg), stacklevel=3)
            out.append(msg)
    return out
