"""What to capture next: board poses ranked by how much they would sharpen a camera.

A calibration in progress knows its intrinsics k up to a covariance Σ_k (the
marginal of the solved problem, given-noise convention). One more view of the
board, at a pose T that is itself unknown, adds the information the view's
corners carry about k once its own pose is eliminated (the Schur complement of
the view's Gauss–Newton block, the same elimination the solver performs):

    I_T = J_kᵀ J_k − J_kᵀ J_T (J_Tᵀ J_T)⁻¹ J_Tᵀ J_k,

with J_k, J_T the whitened Jacobians of the view's corner projections with
respect to k and to T (central differences; σ the corner noise the calibration
was given). After the view, Σ_k' = (Σ_k⁻¹ + I_T)⁻¹ — exact for the linearised
problem, since a new view couples to the rest only through k.

The quantity ranked is the one :mod:`boxplus.calib.uncertainty` draws: the σ
of the projection of a point at the boards' typical distance along each pixel's
ray, worst direction, over a grid of the image, here from the intrinsics alone
(``poses=False``: the camera frame taken as exact); the score is its maximum
over the image (or a user-given function of Σ_k). Candidates are the board
centred at a 3 × 3 grid of image positions, at 0.7, 1 and 1.4 times the boards'
median distance, facing the camera or tilted by ±40° about the board's x or y
axis; a candidate whose corners do not all land in the image (2 % from its border)
is dropped. The N
suggestions are chosen greedily, each after the previous ones are counted as
captured, so they complement each other.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from boxplus._plain import fields_todict
from boxplus.calib.models import project, rays
from boxplus.manifolds import SE3, SO3

__all__ = ["ViewSuggestion", "image_grid_jacobians", "rank_candidates", "rotation_onto", "suggest_views",
           "suggestions_csv", "worst_projection_sigma"]


@dataclass
class ViewSuggestion:
    """One board pose to capture next (``cam_from_board``; the board's points as the
    calibration had them), where it lands in the image and what it would do."""

    rank: int
    camera: str
    cam_from_board: SE3
    center_px: np.ndarray       # where the board's centre lands (px)
    distance: float             # of the board's centre from the camera (board units)
    tilt_deg: tuple[float, float]  # about the board's x and y axes
    footprint_px: np.ndarray    # the board's outer corners in the image (4, 2)
    score_before: float         # the score (px) before this view...
    score_after: float          # ...and after it (and the better-ranked ones)

    def todict(self) -> dict[str, Any]:
        """Plain Python values (``json.dumps`` takes them; the pose as [p, q])."""
        return fields_todict(self)

    def __str__(self) -> str:
        return (f"{self.rank}. {self.camera}: board centre at ({self.center_px[0]:.0f}, "
                f"{self.center_px[1]:.0f}) px, {self.distance:.3g} away, tilted "
                f"{self.tilt_deg[0]:+.0f}° about x, {self.tilt_deg[1]:+.0f}° about y: worst "
                f"projection σ {self.score_before:.4f} → {self.score_after:.4f} px")


def _k_jacobian(k: np.ndarray, p: np.ndarray, model: str, h: float = 1e-6) -> np.ndarray:
    """∂π(k, p)/∂k, (M, 2, len(k)), by central differences."""
    cols = []
    for j in range(len(k)):
        d = np.zeros(len(k))
        d[j] = h * max(1.0, abs(k[j]))
        cols.append((project(k + d, p, model) - project(k - d, p, model)) / (2 * d[j]))
    return np.stack(cols, axis=-1)


def image_grid_jacobians(k: np.ndarray, model: str, size: tuple[int, int], distance: float,
                         grid: tuple[int, int]) -> np.ndarray:
    """∂π/∂k at the points ``distance`` along the rays of a pixel grid inside the
    lens' valid field, (G, 2, len(k))."""
    u = np.linspace(0, size[0] - 1, grid[0])
    v = np.linspace(0, size[1] - 1, grid[1])
    q = np.stack(np.meshgrid(u, v), -1).reshape(-1, 2)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        r = rays(k, q, model)
        valid = np.all(np.isfinite(r), axis=1)
        valid[valid] &= np.linalg.norm(project(k, r[valid], model) - q[valid], axis=1) < 0.05
    r = r[valid]
    p = distance * r / np.linalg.norm(r, axis=1, keepdims=True)
    return _k_jacobian(k, p, model)


def worst_projection_sigma(G: np.ndarray, cov: np.ndarray) -> float:
    """max over the grid of √λ_max(G Σ Gᵀ) for grid Jacobians G (G, 2, n)."""
    S = np.einsum("gij,jk,glk->gil", G, cov, G)
    return float(np.sqrt(np.linalg.eigvalsh(S)[:, -1].max()))


def _pose_jacobian(k: np.ndarray, T: SE3, board: np.ndarray, model: str, h: float = 1e-6) -> np.ndarray:
    """∂π(k, T ⊞ δ · p)/∂δ over the board points, (M, 2, 6)."""
    cols = []
    for j in range(6):
        d = np.zeros(6)
        d[j] = h
        plus, minus = T + d, T + (-d)
        cols.append((project(k, board @ plus.rot.R.T + plus.pos, model)
                     - project(k, board @ minus.rot.R.T + minus.pos, model)) / (2 * h))
    return np.stack(cols, axis=-1)


def rotation_onto(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The smallest rotation taking unit vector a to unit vector b."""
    axis = np.cross(a, b)
    s, c = np.linalg.norm(axis), float(a @ b)
    if s < 1e-12:
        return np.eye(3) if c > 0 else SO3.exp(np.array([np.pi, 0.0, 0.0])).R
    return SO3.exp(axis / s * np.arctan2(s, c)).R


def _candidates(k: np.ndarray, model: str, size: tuple[int, int], board: np.ndarray,
                distance: float) -> list[tuple[SE3, np.ndarray, float, tuple[float, float]]]:
    """(cam_from_board, centre pixel, distance, tilts) of the candidate grid."""
    center = board.mean(axis=0)
    out = []
    tilts = [(0.0, 0.0), (40.0, 0.0), (-40.0, 0.0), (0.0, 40.0), (0.0, -40.0)]
    for fu in (0.2, 0.5, 0.8):
        for fv in (0.2, 0.5, 0.8):
            px = np.array([fu * (size[0] - 1), fv * (size[1] - 1)])
            with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
                r = rays(k, px[None], model)[0]
            if not np.all(np.isfinite(r)):
                continue
            r = r / np.linalg.norm(r)
            for scale in (0.7, 1.0, 1.4):
                for tx, ty in tilts:
                    R = (rotation_onto(np.array([0.0, 0.0, 1.0]), r)
                         @ SO3.exp(np.radians([tx, 0.0, 0.0])).R @ SO3.exp(np.radians([0.0, ty, 0.0])).R)
                    t = scale * distance * r - R @ center
                    out.append((SE3(SO3(R), t), px, scale * distance, (tx, ty)))
    return out


def _corner_sigma(cal: Any, camera: str) -> float:
    """The corner noise σ (px) the calibration gave this camera's measurements."""
    mids = cal.view_ids.get(camera, [])
    if not mids:
        raise ValueError(f"suggest_views: camera '{camera}' has no views")
    W = np.asarray(cal.problem._core.noise(mids[0]).sqrt_information_matrix)
    return float(1.0 / W[0, 0])


def suggest_views(cal: Any, camera: str | None = None, n: int = 3, distance: float | None = None,
                  grid: tuple[int, int] = (16, 12),
                  score: Callable[[np.ndarray], float] | None = None,
                  sigma_factor: float = 1.0) -> list[ViewSuggestion]:
    """The ``n`` board poses that would lower the worst projection σ of ``camera`` most
    (a :class:`boxplus.calib.Calibration`; default: its reference camera), greedily.

    ``distance``: of the points whose projection σ is scored and of the candidate
    boards (default: the median distance of the boards already seen). ``score``:
    any function of the intrinsics' covariance to minimise instead (e.g. a
    parameter's variance). ``sigma_factor``: σ̂ of the calibration report, to score
    with the fitted noise (σ·σ̂, the command line's convention) rather than the given
    one; the ranking is the same. Raises ValueError when the intrinsics are held
    fixed or are not determined yet (the message says which directions are free).
    """
    camera = camera or cal.reference
    if camera not in cal.ids:
        raise ValueError(f"suggest_views: no camera '{camera}' (have {list(cal.view_ids)})")
    if n < 1:
        raise ValueError(f"suggest_views: n must be >= 1, got {n}")
    o = cal.problem
    kid = cal.ids[camera]
    if o.is_fixed(kid):
        raise ValueError(f"suggest_views: the intrinsics of '{camera}' are held fixed: no view can "
                         f"improve them")
    model = cal.models.get(camera, cal.model)
    k = np.asarray(o[kid].vec, dtype=float)
    w, h = cal.image_size[camera]
    size = (int(w), int(h))
    cov = np.asarray(o.covariance(kid)) * sigma_factor**2
    obs = [ob for ob in cal.observations if ob.camera == camera]
    board = max((ob.obj for ob in obs), key=len)
    if distance is None:
        # the boards' centres in the camera frame: world_from_ref_i, and the camera's
        # offset from the reference for a rig
        ref = cal.reference
        cam_from_ref = None if camera == ref else o[cal.ids[f"{camera}_from_{ref}"]]
        dists = []
        for i in cal.view_index[camera]:
            wr = o[cal.world_from_ref[i]]
            T = wr if cam_from_ref is None else wr * cam_from_ref.inverse()
            dists.append(np.linalg.norm(T.tolocal(board.mean(axis=0))))
        distance = float(np.median(dists))
    sigma = _corner_sigma(cal, camera) * sigma_factor
    G = image_grid_jacobians(k, model, size, distance, grid)
    measure = score or (lambda c: worst_projection_sigma(G, c))

    info = []
    for T, px, d, tilt in _candidates(k, model, size, board, distance):
        pc = board @ T.rot.R.T + T.pos
        if np.any(pc[:, 2] <= 0):
            continue
        with np.errstate(invalid="ignore", over="ignore"):
            uv = project(k, pc, model)
        # a margin: corners on the border are often lost to detection
        margin = 0.02 * max(size)
        if not (np.all(np.isfinite(uv)) and np.all((uv >= margin) & (uv < np.array(size) - margin))):
            continue
        Jk = _k_jacobian(k, pc, model).reshape(-1, len(k)) / sigma
        Jt = _pose_jacobian(k, T, board, model).reshape(-1, 6) / sigma
        A = Jt.T @ Jt
        I_T = Jk.T @ Jk - Jk.T @ Jt @ np.linalg.solve(A, Jt.T @ Jk)
        corners = [board[np.argmin(board[:, 0] + board[:, 1])], board[np.argmax(board[:, 0] - board[:, 1])],
                   board[np.argmax(board[:, 0] + board[:, 1])], board[np.argmin(board[:, 0] - board[:, 1])]]
        foot = project(k, np.array(corners) @ T.rot.R.T + T.pos, model)
        info.append((T, px, d, tilt, 0.5 * (I_T + I_T.T), foot))
    if not info:
        raise ValueError(f"suggest_views: no candidate board pose of '{camera}' fits in the image "
                         f"at distance {distance:g}")
    out: list[ViewSuggestion] = []
    used: set[int] = set()
    current = measure(cov)
    for rank in range(1, min(n, len(info)) + 1):
        Lambda = np.linalg.inv(cov)
        best, best_score, best_cov = -1, np.inf, cov
        for i, (_, _, _, _, I_T, _) in enumerate(info):
            if i in used:
                continue
            c = np.linalg.inv(Lambda + I_T)
            s = measure(0.5 * (c + c.T))
            if s < best_score:
                best, best_score, best_cov = i, s, c
        T, px, d, tilt, _, foot = info[best]
        used.add(best)
        out.append(ViewSuggestion(rank, camera, T, px, d, tilt, foot, current, best_score))
        cov, current = 0.5 * (best_cov + best_cov.T), best_score
    return out


def suggestions_csv(suggestions: list[ViewSuggestion]) -> str:
    """The suggestions as CSV: where the board goes and the pose itself
    (cam_from_board, position and quaternion [x, y, z, w])."""
    lines = ["camera,rank,center_u_px,center_v_px,distance,tilt_x_deg,tilt_y_deg,"
             "worst_sigma_before_px,worst_sigma_after_px,px,py,pz,qx,qy,qz,qw"]
    for s in suggestions:
        a = np.asarray(s.cam_from_board.ambient, dtype=float)
        lines.append(",".join([s.camera, str(s.rank), f"{s.center_px[0]:.1f}", f"{s.center_px[1]:.1f}",
                               f"{s.distance:.6g}", f"{s.tilt_deg[0]:.0f}", f"{s.tilt_deg[1]:.0f}",
                               f"{s.score_before:.6g}", f"{s.score_after:.6g}",
                               *(f"{x:.9g}" for x in a)]))
    return "\n".join(lines) + "\n"


def rank_candidates(problem: Any, candidates: Sequence[Callable[[Any], None]], variables: Sequence[int],
                    score: Callable[[np.ndarray], float] | None = None) -> list[tuple[int, float]]:
    """Ranks candidate captures of any problem by the covariance they would leave.

    Each candidate is a function that adds to a copy of ``problem`` what the capture
    would bring — its new variables and its measurements, at the values predicted
    from the current estimate (noise-free; only the Jacobians matter to the
    covariance). The joint covariance of ``variables`` (e.g. a hand–eye
    transform) after each is scored (default: the largest σ of its tangent
    directions) and the candidates are returned as ``(index, score)``, best first.
    The generic counterpart of :func:`suggest_views`, for robot poses of a hand–eye
    calibration, a joint rig's next arm pose, ...: one copy and one sparse
    covariance per candidate.
    """
    measure = score or (lambda c: float(np.sqrt(np.max(np.diag(c)))))
    out = []
    for i, add in enumerate(candidates):
        q = problem.copy()
        add(q)
        out.append((i, measure(np.asarray(q.joint_covariance(list(variables))))))
    return sorted(out, key=lambda r: r[1])
