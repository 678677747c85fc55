"""Images of a calibration target through any boxplus lens model, with known truth.

:func:`render_view` traces each pixel's viewing ray through the lens (the
model's exact inverse, :func:`boxplus.calib.models.rays`), intersects it with
the target plane z = 0 and samples the printed target
(:meth:`boxplus.calib.targets.Target.image`, bilinear), averaging
``supersample²`` rays per pixel so that edges are antialiased like a real
sensor's. The image is what the camera with intrinsics ``k`` and pose
``cam_from_board`` sees, for every model — pinhole family, rational,
Kannala–Brandt at 180° and beyond, double sphere — so that calibrations and
the command line can be checked against the truth on images nobody tuned on.

:func:`board_views` draws board poses that cover the image (near, far, tilted,
off-centre) in front of a camera; :func:`write_views` renders and writes them
as PNG files, the form a user brings.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from boxplus.manifolds import SE3, SO3

__all__ = ["RenderedView", "RigCamera", "board_views", "render_view", "write_rig_views", "write_views"]


def render_view(target: Any, model: str, k: np.ndarray, image_size: tuple[int, int],
                cam_from_board: SE3 | Sequence[SE3], supersample: int = 2, noise_sigma: float = 0.0,
                rng: np.random.Generator | None = None, pixels_per_unit: float | None = None,
                background: int = 255) -> np.ndarray:
    """The uint8 grey image of ``target`` seen by camera (model, k) at ``cam_from_board``.

    Parameters
    ----------
    target : boxplus.calib.targets.Target
    image_size : (width, height)
    cam_from_board : SE3, or one SE3 per image row
        Maps board points (z = 0, the target's units) into the camera frame. One pose
        per row (``height`` of them) renders a rolling shutter: row v is exposed while
        the camera is at its own pose (the rows read out one after the other as it
        moves).
    supersample : int
        Rays per pixel along each axis (antialiasing).
    noise_sigma : float
        Standard deviation of additive Gaussian noise in grey levels.
    pixels_per_unit : float, optional
        Resolution of the printed target (default: 8 pixels per square width… enough
        that its texture is finer than the camera's pixels).
    """
    w, h = int(image_size[0]), int(image_size[1])
    ppu = pixels_per_unit or 60.0 / target.square
    tex = target.image(ppu).astype(float)
    origin = target.image_origin(ppu)
    n = int(supersample)
    acc = np.zeros(w * h)
    # the camera's origin in the board frame, o (3,) or one per pixel (N, 3), and the
    # rotation of a ray into the board frame
    if isinstance(cam_from_board, SE3):
        board_from_cam = cam_from_board.inverse()
        R, o = board_from_cam.rot.R, board_from_cam.pos

        def to_board(ray: np.ndarray) -> np.ndarray:
            return ray @ R.T
    else:
        rows = list(cam_from_board)
        if len(rows) != h:
            raise ValueError(f"render_view: {len(rows)} row poses for an image of {h} rows")
        per_row = [pose.inverse() for pose in rows]
        # each pixel's ray leaves from its own row's pose (pixels are row-major)
        row_of = np.repeat(np.arange(h), w)
        R_px = np.array([p.rot.R for p in per_row])[row_of]
        o = np.array([p.pos for p in per_row])[row_of]

        def to_board(ray: np.ndarray) -> np.ndarray:
            return np.einsum("nij,nj->ni", R_px, ray)
    for ray in _pixel_rays(model, tuple(np.asarray(k, float)), (w, h), n):
        with np.errstate(invalid="ignore", divide="ignore"):
            d = to_board(ray)
            s = -o[..., 2] / d[:, 2]
            p = o[..., :2] + s[:, None] * d[:, :2]
        ok = np.isfinite(s) & (s > 0) & np.all(np.isfinite(d), axis=1)
        val = np.full(w * h, float(background))
        val[ok] = _bilinear(tex, origin + p[ok] * ppu, background)
        acc += val
    img = acc.reshape(h, w) / (n * n)
    if noise_sigma > 0:
        img = img + (rng or np.random.default_rng(0)).normal(0.0, noise_sigma, img.shape)
    return np.clip(np.round(img), 0, 255).astype(np.uint8)


@functools.lru_cache(maxsize=4)
def _pixel_rays(model: str, k: tuple[float, ...], size: tuple[int, int], n: int) -> list[np.ndarray]:
    """The viewing rays of every pixel's n × n sub-pixel samples (one array per sample
    offset), computed once per camera: the lens inverse is most of a render's time."""
    from boxplus.calib.models import rays

    w, h = size
    offs = (np.arange(n) + 0.5) / n - 0.5
    out = []
    for du in offs:
        for dv in offs:
            u, v = np.meshgrid(np.arange(w) + du, np.arange(h) + dv)
            with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
                out.append(rays(np.asarray(k), np.column_stack([u.ravel(), v.ravel()]), model))
    return out


def _bilinear(tex: np.ndarray, xy: np.ndarray, background: float) -> np.ndarray:
    """Texture values at pixel positions xy (N, 2) (pixel centres at integers)."""
    h, w = tex.shape
    x, y = xy[:, 0], xy[:, 1]
    inside = (x >= 0) & (x <= w - 1) & (y >= 0) & (y <= h - 1)
    out = np.full(len(xy), background)
    x0 = np.clip(np.floor(x[inside]).astype(int), 0, w - 2)
    y0 = np.clip(np.floor(y[inside]).astype(int), 0, h - 2)
    fx, fy = x[inside] - x0, y[inside] - y0
    out[inside] = ((1 - fx) * (1 - fy) * tex[y0, x0] + fx * (1 - fy) * tex[y0, x0 + 1]
                   + (1 - fx) * fy * tex[y0 + 1, x0] + fx * fy * tex[y0 + 1, x0 + 1])
    return out


@dataclass
class RenderedView:
    """One view: the board's pose in the camera and the file it was written to."""

    cam_from_board: SE3
    path: Path | None = None


def board_views(target: Any, model: str, k: np.ndarray, image_size: tuple[int, int], n: int,
                rng: np.random.Generator, distance: float | None = None,
                max_tilt_deg: float = 40.0, fill: float = 0.8) -> list[SE3]:
    """``n`` board poses (cam_from_board) whose whole target is in the image: at
    0.6–1.4 × ``distance`` (default: where the target spans about half the image),
    tilted up to ``max_tilt_deg``, its centre spread over ``fill`` of the image."""
    from boxplus.calib.models import project, rays

    pts = target.points()
    centre = pts.mean(axis=0)
    # the printed board's outline (a chessboard's outer squares lie one square beyond its
    # inner corners): all of it must be in the image, or detection may flip the corners
    lo, hi = pts[:, :2].min(axis=0), pts[:, :2].max(axis=0)
    pad = target.square if target.kind == "chessboard" else 0.0
    outline = np.array([[x, y, 0.0] for x in np.linspace(lo[0] - pad, hi[0] + pad, 5)
                        for y in np.linspace(lo[1] - pad, hi[1] + pad, 5)])
    extent = float(np.ptp(outline[:, :2], axis=0).max())
    w, h = image_size
    f = float(k[0])
    dist = distance or 2.5 * f * extent / w
    out: list[SE3] = []
    tries = 0
    while len(out) < n:
        tries += 1
        if tries > 200 * n:
            raise ValueError(f"board_views: found {len(out)} of {n} poses with the target in the "
                             f"image; move it farther (distance) or reduce fill")
        uv = np.array([w, h]) * (0.5 + (rng.uniform(size=2) - 0.5) * fill)
        ray = rays(k, uv[None], model)[0]
        if not np.all(np.isfinite(ray)):
            continue  # a pixel outside the lens's field (a wide lens's image corners)
        ray = ray / np.linalg.norm(ray)
        depth = dist * rng.uniform(0.6, 1.4)
        tilt = np.radians(max_tilt_deg) * rng.uniform(-1, 1, 2)
        # OpenCV's board frame: z into the board, away from the camera that sees its printed
        # side (a pose with z towards the camera would show the print mirrored); tilted and
        # spun about the normal
        rot = SO3.exp([tilt[0], tilt[1], rng.uniform(-0.5, 0.5)])
        pose = SE3(rot, ray * depth - rot.R @ centre)
        p_in_cam = pose.fromlocal(outline)
        if np.any(p_in_cam[:, 2] <= 0.05 * dist):
            continue
        z = project(k, p_in_cam, model)
        margin = 0.02 * min(w, h)
        if np.all(np.isfinite(z)) and np.all((z > margin) & (z < np.array([w, h]) - margin)):
            out.append(pose)
    return out


def write_views(folder: str | Path, target: Any, model: str, k: np.ndarray,
                image_size: tuple[int, int], poses: list[SE3], prefix: str = "view",
                noise_sigma: float = 1.0, seed: int = 0, start: int = 0) -> list[RenderedView]:
    """Renders the poses and writes ``<prefix><NN>.png`` into ``folder``."""
    from boxplus._optional import require

    cv2 = require("cv2", "writing rendered images")
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    out = []
    for i, pose in enumerate(poses):
        img = render_view(target, model, k, image_size, pose, noise_sigma=noise_sigma, rng=rng)
        path = folder / f"{prefix}{start + i:02d}.png"
        if not cv2.imwrite(str(path), img):
            raise OSError(f"cannot write '{path}'")
        out.append(RenderedView(pose, path))
    return out


@dataclass
class RigCamera:
    """A camera of a simulated rig: model, intrinsics, image size and cam_from_ref."""

    model: str
    k: np.ndarray
    image_size: tuple[int, int]
    cam_from_ref: SE3


def _in_image(target: Any, cam: RigCamera, cam_from_board: SE3) -> bool:
    from boxplus.calib.models import project

    pts = target.points()
    lo, hi = pts[:, :2].min(axis=0), pts[:, :2].max(axis=0)
    pad = target.square if target.kind == "chessboard" else 0.0
    outline = np.array([[x, y, 0.0] for x in np.linspace(lo[0] - pad, hi[0] + pad, 5)
                        for y in np.linspace(lo[1] - pad, hi[1] + pad, 5)])
    p = cam_from_board.fromlocal(outline)
    if np.any(p[:, 2] <= 0):
        return False
    with np.errstate(invalid="ignore", divide="ignore"):
        z = project(cam.k, p, cam.model)
    w, h = cam.image_size
    m = 0.02 * min(w, h)
    return bool(np.all(np.isfinite(z)) and np.all((z > m) & (z < np.array([w, h]) - m)))


def write_rig_views(folder: str | Path, target: Any, cameras: dict[str, RigCamera], n_views: int,
                    rng: np.random.Generator, noise_sigma: float = 1.0,
                    max_tilt_deg: float = 35.0) -> list[SE3]:
    """Renders ``n_views`` synchronised captures of a rig into ``folder/<camera>/viewNN.png``.

    Board poses (ref_from_board) are drawn for the first camera (as :func:`board_views`),
    then kept only where at least one camera sees the whole target; a camera that does
    not see all of it writes no image for that view (partial overlap). Returns the
    ref_from_board of every view, the truth of the board poses.
    """
    names = list(cameras)
    ref = cameras[names[0]]
    out: list[SE3] = []
    tries = 0
    folder = Path(folder)
    while len(out) < n_views:
        tries += 1
        if tries > 100 * n_views:
            raise ValueError(f"write_rig_views: {len(out)} of {n_views} views seen by any camera")
        (pose,) = board_views(target, ref.model, ref.k, ref.image_size, 1, rng,
                              max_tilt_deg=max_tilt_deg, fill=0.9)
        # spread the views over the rig: a shift along the rig's extent
        span = max([float(np.linalg.norm(c.cam_from_ref.pos)) for c in cameras.values()] + [0.0])
        pose = SE3(pose.rot, pose.pos + np.r_[rng.uniform(-1, 1, 2) * span, 0.0])
        seen = [c for c in names if _in_image(target, cameras[c], cameras[c].cam_from_ref * pose)]
        if not seen:
            continue
        i = len(out)
        for c in seen:
            cam = cameras[c]
            write_views(folder / c, target, cam.model, cam.k, cam.image_size,
                        [cam.cam_from_ref * pose], prefix="view", noise_sigma=noise_sigma,
                        seed=int(rng.integers(2**31)), start=i)
        out.append(pose)
    return out
