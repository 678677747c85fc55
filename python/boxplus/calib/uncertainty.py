"""How well a calibration projects: the σ of the projected pixel over the image
for points at a given distance, and the coverage of the image by the corners.

Projection uncertainty (mrcal's method, "Projection uncertainty" in its
documentation): take the pixel q on a grid, its viewing ray, and the point p at
``distance`` along it (p = distance · ray/‖ray‖, camera frame). That point is
fixed in the world, not in the camera: the world is known only through the
board poses, so p is carried into each view's board frame with the solved
pose, p_i = world_from_cam_i · p, and back with the perturbed poses and
averaged, p' = (1/N) Σᵢ (world_from_cam_i ⊞ δᵢ)⁻¹ p_i, then projected with
the perturbed intrinsics, q' = π(k ⊞ δk, p'). With J = ∂q'/∂(δk, δ₁ … δ_N) (central
differences) and Σ the joint covariance of those variables from the
calibration report, Σ_q = J Σ Jᵀ; the σ shown is √λ_max(Σ_q), the worst
direction (mrcal's default). ``poses=False`` propagates the intrinsics'
covariance alone (the camera frame taken as exact).

The σ convention is the report's (:func:`boxplus.calib.report`): from the
given corner noise unless ``rescale=True``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from boxplus._plain import fields_todict
from boxplus.calib.models import project, rays

__all__ = ["ProjectionUncertainty", "coverage", "projection_sigma", "projection_uncertainty"]


@dataclass
class ProjectionUncertainty:
    """σ (px, worst direction) of the projection on a grid of pixels ``u`` × ``v``
    (``sigma[j, i]`` at pixel (u[i], v[j])) for points ``distance`` away."""

    camera: str
    distance: float
    u: np.ndarray
    v: np.ndarray
    sigma: np.ndarray
    poses: bool
    rescaled: bool

    def todict(self) -> dict[str, Any]:
        """Plain Python values (``json.dumps`` takes them; NaN outside the valid field)."""
        return fields_todict(self)

    def at_center(self) -> float:
        j, i = len(self.v) // 2, len(self.u) // 2
        return float(self.sigma[j, i])

    def __str__(self) -> str:
        s = self.sigma[np.isfinite(self.sigma)]
        if s.size == 0:
            return f"projection σ of {self.camera}: no pixel of the image is in the lens' valid field"
        return (f"projection σ of {self.camera} at {self.distance:g} (board units): centre "
                f"{self.at_center():.4f} px, median {np.median(s):.4f}, max {s.max():.4f} px "
                f"({'intrinsics and board poses' if self.poses else 'intrinsics only'}, "
                f"{'rescaled by σ̂' if self.rescaled else 'from the given corner noise'})")


def _joint(rep: Any, o: Any, ids: list[int]) -> np.ndarray:
    cols = [rep.columns.index((vid, t)) for vid in ids for t in range(o.codec(vid).dof)]
    return rep.covariance[np.ix_(cols, cols)]


def projection_uncertainty(cal: Any, camera: str, distance: float, grid: tuple[int, int] = (24, 18),
                           poses: bool = True, rescale: bool = False) -> ProjectionUncertainty:
    """σ of the projection of ``camera`` (a :class:`boxplus.calib.Calibration`) over a
    ``grid`` (columns × rows) of pixels spanning the image, for points at
    ``distance`` (in the board's unit) along each pixel's ray (see the module
    docstring; :func:`projection_sigma` at the grid's pixels)."""
    w, hgt = cal.image_size[camera] if camera in cal.image_size else (0, 0)
    u = np.linspace(0, w - 1, grid[0])
    v = np.linspace(0, hgt - 1, grid[1])
    q = np.stack(np.meshgrid(u, v), -1).reshape(-1, 2)
    sig = projection_sigma(cal, camera, q, distance, poses, rescale)
    return ProjectionUncertainty(camera, float(distance), u, v, sig.reshape(len(v), len(u)), poses,
                                 rescale)


def projection_sigma(cal: Any, camera: str, pixels: np.ndarray, distance: float,
                     poses: bool = True, rescale: bool = False, h: float = 1e-6) -> np.ndarray:
    """σ (px, worst direction) of the projection at ``pixels`` (N, 2) of ``camera`` for
    points at ``distance`` along their rays (the module docstring's method)."""
    if not distance > 0:
        raise ValueError(f"projection_uncertainty: distance must be > 0, got {distance}")
    if camera not in cal.view_ids:
        raise ValueError(f"projection_uncertainty: no camera '{camera}' (have {list(cal.view_ids)})")
    o = cal.problem
    model = cal.models.get(camera, cal.model)
    q = np.atleast_2d(np.asarray(pixels, dtype=float))
    kid = cal.ids[camera]
    k = o[kid].vec
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        r = rays(k, q, model)
        # the lens model's valid field: pixels whose ray projects back onto them (outside a
        # fisheye's image circle, or where a model folds over, there is no such ray)
        valid = np.all(np.isfinite(r), axis=1)
        valid[valid] &= np.linalg.norm(project(k, r[valid], model) - q[valid], axis=1) < 0.05
    r[~valid] = [0.0, 0.0, 1.0]
    p = distance * r / np.linalg.norm(r, axis=1, keepdims=True)  # camera frame
    # the camera's pose per view: world_from_cam_i = world_from_ref_i · (cam_from_ref)⁻¹
    ref = cal.reference
    cam_from_ref = None if camera == ref else o[cal.ids[f"{camera}_from_{ref}"]]
    view_vars = sorted({cal.world_from_ref[i] for i in cal.view_index[camera]}) if poses else []
    rig_vars = [cal.ids[f"{camera}_from_{ref}"]] if poses and cam_from_ref is not None else []

    def world_from_cam(wr, cr):
        return wr if cr is None else wr * cr.inverse()

    W = [world_from_cam(o[vid], cam_from_ref) for vid in view_vars]
    p_world = [p @ T.rot.R.T + T.pos for T in W]

    def predict(kk, wr_vals, cr):
        if not wr_vals:
            return project(kk, p, model)
        pc = np.zeros_like(p)
        for wr, pw in zip(wr_vals, p_world):
            T = world_from_cam(wr, cr)
            pc += (pw - T.pos) @ T.rot.R  # Rᵀ (p_w − t), row-wise
        return project(kk, pc / len(wr_vals), model)

    base_w = [o[vid] for vid in view_vars]
    columns = []
    free_k = not o.is_fixed(kid)  # known intrinsics held fixed have no σ to propagate
    for j in range(len(k) if free_k else 0):
        d = np.zeros(len(k))
        d[j] = h * max(1.0, abs(k[j]))
        columns.append((predict(k + d, base_w, cam_from_ref) - predict(k - d, base_w, cam_from_ref)) / (2 * d[j]))
    for n in range(len(view_vars)):
        for j in range(6):
            d = np.zeros(6)
            d[j] = h
            plus = list(base_w)
            minus = list(base_w)
            plus[n] = base_w[n] + d
            minus[n] = base_w[n] + (-d)
            columns.append((predict(k, plus, cam_from_ref) - predict(k, minus, cam_from_ref)) / (2 * h))
    if rig_vars:
        assert cam_from_ref is not None
        for j in range(6):
            d = np.zeros(6)
            d[j] = h
            columns.append((predict(k, base_w, cam_from_ref + d)
                            - predict(k, base_w, cam_from_ref + (-d))) / (2 * h))
    J = np.stack(columns, axis=-1)  # (M, 2, n)
    rep = cal.report(rescale=rescale)
    S = _joint(rep, o, [*([kid] if free_k else []), *view_vars, *rig_vars])
    if not np.all(np.isfinite(S)):
        raise ValueError(f"projection_uncertainty: the covariance of {camera}'s intrinsics or "
                         "poses is undetermined (see the calibration report's warnings)")
    Sq = np.einsum("mij,jk,mlk->mil", J, S, J)
    sig = np.sqrt(np.linalg.eigvalsh(Sq)[:, -1])
    sig[~valid] = np.nan
    return sig


def coverage(cal: Any, camera: str, grid: tuple[int, int] = (8, 6)) -> np.ndarray:
    """Corners used per cell of a ``grid`` (columns × rows) over the image of
    ``camera``: (rows, columns) counts. Empty cells are where the lens model is
    extrapolated."""
    w, h = cal.image_size[camera]
    Z = np.concatenate([ob.z for ob in cal.observations if ob.camera == camera])
    H, _, _ = np.histogram2d(Z[:, 1], Z[:, 0], bins=[grid[1], grid[0]], range=[[0, h], [0, w]])
    return H.astype(int)
