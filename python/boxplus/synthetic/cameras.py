"""Board views with known ground truth, for tests and examples: a board,
camera poses looking at it, OpenCV-model projection with pixel noise.

Frames as everywhere in :mod:`boxplus.calib`: ``world_from_cam`` is a camera's
pose in the board ("world") frame; ``p_in_cam = world_from_cam.tolocal(p_in_world)``.
"""

from __future__ import annotations

import numpy as np

from boxplus.calib.models import project
from boxplus.geometry import look_at
from boxplus.manifolds import SE3, SO3

__all__ = ["TRUE_K", "board_points", "errors_in_sigma", "numeric_jacobian", "observe", "random_views"]

# fx fy cx cy k1 k2 p1 p2 k3 of a 640×480 camera (opencv5 layout)
TRUE_K = np.array([520.0, 515.0, 322.0, 245.0, -0.28, 0.08, 0.001, -0.0005, 0.0])
# the board's +y appears up in the images of random_views (x = z × up, geometry.look_at)
_BOARD_UP = np.array([0.0, 1.0, 0.0])


def board_points(cols: int = 9, rows: int = 6, square: float = 0.04) -> np.ndarray:
    """Inner corners of a chessboard in its own frame (z = 0), metres."""
    g = np.stack(np.meshgrid(np.arange(cols), np.arange(rows)), -1).reshape(-1, 2) * square
    return np.column_stack([g, np.zeros(len(g))])


def random_views(n: int, rng: np.random.Generator, center: np.ndarray, distance: float = 0.6,
                 spread: float = 0.35, roll: float = 0.4) -> list[SE3]:
    """n world_from_cam poses around the board, looking at ``center`` from above (z < 0)."""
    out = []
    for _ in range(n):
        d = np.array([rng.uniform(-spread, spread), rng.uniform(-spread, spread), -1.0])
        eye = center + distance * d / np.linalg.norm(d)
        pose = look_at(eye, center + rng.normal(0, 0.02, 3), up=_BOARD_UP)
        out.append(SE3(SO3(pose.rot.R @ SO3.exp(np.array([0, 0, rng.uniform(-roll, roll)])).R), pose.pos))
    return out


def observe(k: np.ndarray, world_from_cam: SE3, p_in_world: np.ndarray, sigma: float,
            rng: np.random.Generator, model: str = "opencv5",
            image_size: tuple[int, int] | None = (640, 480)) -> tuple[np.ndarray, np.ndarray]:
    """Noisy pixels of the board points a camera sees: (z (M, 2), visible mask (N,))."""
    p_in_cam = np.stack([world_from_cam.tolocal(p) for p in p_in_world])
    uv = project(k, p_in_cam, model)
    vis = p_in_cam[:, 2] > 0
    if image_size is not None:
        vis &= (uv[:, 0] >= 0) & (uv[:, 0] < image_size[0]) & (uv[:, 1] >= 0) & (uv[:, 1] < image_size[1])
    return uv[vis] + rng.normal(0, sigma, (vis.sum(), 2)), vis


def errors_in_sigma(o, rep, ids, truth) -> dict:
    """{name: abs(estimate ⊟ truth) / σ per tangent direction} for the variables
    ``ids`` {name: variable id} of a solved problem, ``truth`` {name: value}, σ
    from the report ``rep``; a pose's error is [p − p_true, Log(R_trueᵀ R)], the
    tangent order of SE3."""
    out = {}
    for name, vid in ids.items():
        est, t = o[vid], truth[name]
        if isinstance(est, SE3):
            d = np.concatenate([est.pos - t.pos, (t.rot.inverse() * est.rot).log()])
        else:
            d = np.asarray(est.vec) - np.asarray(t)
        out[name] = np.abs(d) / rep.std(o.variable_name(vid))
    return out


def numeric_jacobian(o, mids, h: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """(the problem's whitened Jacobian, its central differences) over the free
    variables (``o.jacobian()``'s columns), for the residuals of the measurements
    ``mids`` (their rows must be all of the problem's). Each direction j of a
    variable x is stepped through ⊞: (r(x ⊞ hⱼeⱼ) − r(x ⊞ −hⱼeⱼ)) / 2hⱼ, with
    hⱼ = h · max(1, abs(xⱼ)) for Rⁿ variables (intrinsics in pixels) and h otherwise."""
    def residuals():
        return np.concatenate([o.residual(m) for m in mids])

    jac = o.jacobian()
    J = np.asarray(jac["jacobian"])
    if not np.allclose(jac["residuals"], residuals()):
        raise ValueError("numeric_jacobian: mids must be every measurement of the problem, in order")
    cols = []
    for vid in jac["variables"]:
        x0 = o[vid]
        for j in range(o.codec(vid).dof):
            d = np.zeros(o.codec(vid).dof)
            d[j] = h * (max(1.0, abs(np.asarray(x0.vec)[j])) if hasattr(x0, "vec") else 1.0)
            o.set_value(vid, x0 + d)
            rp = residuals()
            o.set_value(vid, x0 + (-d))
            rm = residuals()
            o.set_value(vid, x0)
            cols.append((rp - rm) / (2 * d[j]))
    return J, np.column_stack(cols)
