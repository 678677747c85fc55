"""How far apart two lens models project: the pixel difference over an image,
after the rotation between their camera frames.

Two fits of one camera (or a fit and the truth of a simulation) can describe the
same lens in camera frames turned by a small rotation R: a board pose absorbs R,
and the principal point moves with it. Comparing pixels at equal rays would count
that rotation as lens error. So, as mrcal's ``projection_diff`` does, the
difference of model a from a reference model b is taken after the rotation that
fits best over the region compared:

    u_i on a grid over the image, v_i = rays_b(u_i) (b's viewing rays),
    R* = argmin_R Σ_i ‖π_a(R v_i) − u_i‖²   (Gauss–Newton on SO(3), R = Exp(δ)),
    d_i = ‖π_a(R* v_i) − u_i‖  (pixels).

The region is the image, or the pixels whose ray lies within ``theta_max`` of b's
optical axis (e.g. the field a calibration's corners covered): a fit is only
answerable for the field it saw, and outside it the difference says how far it
may be trusted when extrapolated.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from boxplus.calib.models import project, rays
from boxplus.manifolds import SO3

__all__ = ["LensDifference", "projection_difference"]


@dataclass
class LensDifference:
    """The difference of a lens model from a reference over a region of the image:
    ``pixels`` (N, 2) compared, ``difference`` (N,) in pixels, the rotation
    ``a_from_b`` between their camera frames, and the field ``theta`` (N,) of each
    pixel's ray (radians from the reference's optical axis)."""

    pixels: np.ndarray
    difference: np.ndarray
    a_from_b: SO3
    theta: np.ndarray

    @property
    def rms(self) -> float:
        return float(np.sqrt(np.mean(self.difference**2)))

    @property
    def max(self) -> float:
        return float(np.max(self.difference))

    def __str__(self) -> str:
        return (f"{len(self.pixels)} pixels: RMS {self.rms:.3f} px, max {self.max:.3f} px after "
                f"a {np.degrees(np.linalg.norm(self.a_from_b.log())):.3f}° rotation")


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def projection_difference(k_a: np.ndarray, model_a: str, k_b: np.ndarray, model_b: str,
                          image_size: tuple[int, int], theta_max: float | None = None,
                          grid: tuple[int, int] = (40, 30), align: bool = True,
                          iterations: int = 20) -> LensDifference:
    """The pixel difference of lens a (``k_a``, ``model_a``) from the reference b over a
    ``grid`` of pixels of the ``image_size`` (width, height) image, restricted to rays
    within ``theta_max`` (radians) of b's optical axis when given; after the best
    rotation between the camera frames unless ``align`` is False. Pixels whose ray b
    cannot give (outside a fisheye's circle, or where its inverse does not converge)
    are left out. Raises ValueError when no pixel is left."""
    w, h = image_size
    gu, gv = np.meshgrid(np.linspace(0.5, w - 1.5, grid[0]), np.linspace(0.5, h - 1.5, grid[1]))
    u = np.column_stack([gu.ravel(), gv.ravel()])
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        v = _unit(rays(np.asarray(k_b, float), u, model_b))
        back = project(np.asarray(k_b, float), v, model_b)
    ok = np.all(np.isfinite(v), axis=1) & (np.linalg.norm(back - u, axis=1) < 1e-6)
    theta = np.arccos(np.clip(v[:, 2], -1.0, 1.0))
    if theta_max is not None:
        ok &= theta <= theta_max
    u, v, theta = u[ok], v[ok], theta[ok]
    if not len(u):
        raise ValueError("projection_difference: no pixel of the grid lies in the reference's field")
    ka = np.asarray(k_a, float)

    def residual(R: SO3) -> np.ndarray:
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            return (project(ka, v @ R.R.T, model_a) - u).ravel()

    R = SO3()
    if align:
        h_step = 1e-6
        for _ in range(iterations):
            r = residual(R)
            J = np.column_stack([(residual(R * SO3.exp(h_step * e)) - residual(R * SO3.exp(-h_step * e)))
                                 / (2 * h_step) for e in np.eye(3)])
            good = np.isfinite(r) & np.all(np.isfinite(J), axis=1)
            step = np.linalg.lstsq(J[good], -r[good], rcond=None)[0]
            R = R * SO3.exp(step)
            if np.linalg.norm(step) < 1e-12:
                break
    d = np.linalg.norm(residual(R).reshape(-1, 2), axis=1)
    return LensDifference(u, d, R, theta)
