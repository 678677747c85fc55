"""Geometry written once: rotations, absolute orientation, triangulation and
look-at poses, in numpy, for :mod:`boxplus.calib` and :mod:`boxplus.joint`
(camera models: :mod:`boxplus.calib.models`).

Frames follow the library's scheme: ``b_from_a`` maps a-coordinates to b,
``p_in_b = b_from_a.fromlocal(p_in_a) = R p_in_a + t``; poses are SE3 values,
SE(3) = R³ × SO(3), tangent order [translation, rotation].
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from boxplus.manifolds import SE3, SO3

__all__ = ["absolute_orientation", "look_at", "project_to_so3", "triangulate_midpoint"]


# ---- rotations -----------------------------------------------------------------------

def project_to_so3(M: np.ndarray, what: str = "project_to_so3") -> np.ndarray:
    """The rotation nearest to M in the Frobenius norm (orthogonal Procrustes).

    With the SVD M = U Σ Vᵀ, R = U diag(1, 1, det(U Vᵀ)) Vᵀ: the sign flip of
    the last singular direction keeps det R = +1 where U Vᵀ would be a
    reflection (Umeyama 1991, eq. 39–43).

    Parameters
    ----------
    M : (3, 3) or (..., 3, 3) array
    what : str
        Named in error messages.

    Returns
    -------
    (3, 3) or (..., 3, 3) array
        Rotations (RᵀR = I, det R = +1).

    Raises
    ------
    ValueError
        For non-finite entries or a matrix of rank < 2, whose nearest rotation
        is not unique.
    """
    M = np.asarray(M, dtype=float)
    if M.shape[-2:] != (3, 3):
        raise ValueError(f"{what}: need (..., 3, 3) matrices, got shape {M.shape}")
    if not np.all(np.isfinite(M)):
        raise ValueError(f"{what}: the matrix has non-finite entries")
    U, s, Vt = np.linalg.svd(M)
    if np.any(s[..., 1] <= 1e-12 * np.maximum(s[..., 0], 1e-300)):
        raise ValueError(f"{what}: the matrix has rank < 2; its nearest rotation is not unique")
    d = np.sign(np.linalg.det(U @ Vt))
    return (U * np.stack([np.ones_like(d), np.ones_like(d), d], axis=-1)[..., None, :]) @ Vt


def absolute_orientation(
    p_in_a: np.ndarray,
    p_in_b: np.ndarray,
    weights: np.ndarray | None = None,
    scale: bool = False,
    translation: bool = True,
    what: str = "absolute_orientation",
) -> SE3 | tuple[SE3, float]:
    """``b_from_a`` minimising Σ wᵢ ‖s R aᵢ + t − bᵢ‖² (Horn 1987, unit quaternions).

    Horn, "Closed-form solution of absolute orientation using unit
    quaternions", J. Opt. Soc. Am. A 4(4), 1987: with the centred points a'ᵢ,
    b'ᵢ and M = Σ wᵢ a'ᵢ b'ᵢᵀ, the rotation is the unit quaternion of the
    largest eigenvalue of the symmetric 4×4 matrix N(M) (Sec. 4); the
    translation is t = b̄ − s R ā (Sec. 2.C); the scale, when asked for, is
    Umeyama's s = Σ wᵢ b'ᵢᵀ R a'ᵢ / Σ wᵢ ‖a'ᵢ‖² (Umeyama 1991, eq. 42). Without
    ``translation`` the points are not centred and t = 0: Wahba's problem for
    paired directions.

    Parameters
    ----------
    p_in_a, p_in_b : (N, 3) arrays
        The same N points in frames a and b (N ≥ 3, or N ≥ 2 directions without
        ``translation``), not all on one line (through the origin without
        ``translation``).
    weights : (N,) array, optional
        Non-negative weights with a positive sum (default: all 1).
    scale : bool
        Also estimate the similarity scale s (default: s = 1).
    translation : bool
        Estimate t (default); False fixes t = 0.
    what : str
        Named in error messages.

    Returns
    -------
    SE3, or (SE3, float) with ``scale``
        ``b_from_a`` (and s): ``s · b_from_a.rot.R @ p_in_a[i] + b_from_a.pos ≈ p_in_b[i]``.

    Raises
    ------
    ValueError
        On bad shapes, too few points, non-finite entries, bad weights, or
        points on one line (the rotation about it is then undetermined).
    """
    a = np.asarray(p_in_a, dtype=float)
    b = np.asarray(p_in_b, dtype=float)
    if a.ndim != 2 or a.shape[1] != 3 or a.shape != b.shape:
        raise ValueError(f"{what}: need two (N, 3) arrays of corresponding points, got {a.shape} and {b.shape}")
    need = 3 if translation else 2
    if len(a) < need:
        raise ValueError(f"{what}: need at least {need} corresponding points, got {len(a)}")
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        raise ValueError(f"{what}: points have non-finite entries")
    w = np.ones(len(a)) if weights is None else np.asarray(weights, dtype=float).reshape(-1)
    if w.shape != (len(a),) or np.any(w < 0) or w.sum() <= 0:
        raise ValueError(f"{what}: weights must be {len(a)} non-negative numbers with a positive sum")
    ca = w @ a / w.sum() if translation else np.zeros(3)
    cb = w @ b / w.sum() if translation else np.zeros(3)
    A, B = a - ca, b - cb
    # Collinear (or coincident) points leave the rotation about their line free.
    An = A / np.maximum(np.linalg.norm(A, axis=1, keepdims=True), 1e-300) if not translation else A
    sv = np.linalg.svd(np.sqrt(w)[:, None] * An, compute_uv=False)
    if sv[1] <= 1e-9 * max(sv[0], 1e-300):
        where = "lie on one line" if translation else "are all parallel"
        raise ValueError(f"{what}: the points in frame a {where}; the rotation about it is undetermined")
    M = (w[:, None] * A).T @ B  # M[i, j] = Σ w a'_i b'_j  (Horn's S_xy etc.)
    (Sxx, Sxy, Sxz), (Syx, Syy, Syz), (Szx, Szy, Szz) = M
    N = np.array([
        [Sxx + Syy + Szz, Syz - Szy, Szx - Sxz, Sxy - Syx],
        [Syz - Szy, Sxx - Syy - Szz, Sxy + Syx, Szx + Sxz],
        [Szx - Sxz, Sxy + Syx, -Sxx + Syy - Szz, Syz + Szy],
        [Sxy - Syx, Szx + Sxz, Syz + Szy, -Sxx - Syy + Szz],
    ])
    _, V = np.linalg.eigh(N)
    q_wxyz = V[:, -1]  # eigenvector of the largest eigenvalue, [w, x, y, z] in Horn's paper
    R = SO3.from_quat(np.r_[q_wxyz[1:], q_wxyz[0]])  # boxplus stores [x, y, z, w]
    s = 1.0
    if scale:
        s = float(np.sum(w * np.sum(B * (A @ R.R.T), axis=1)) / np.sum(w * np.sum(A * A, axis=1)))
    t = cb - s * (R.R @ ca)
    return (SE3(R, t), s) if scale else SE3(R, t)


def look_at(eye: np.ndarray, target: np.ndarray, up: Sequence[float] | np.ndarray = (0.0, 0.0, 1.0)) -> SE3:
    """``world_from_cam`` of a camera at ``eye`` whose optical axis (z) points at ``target``.

    Camera axes: z = (target − eye)/‖·‖, x = z × up (normalised, image right),
    y = z × x (image down, against ``up``).

    Raises
    ------
    ValueError
        When ``eye`` = ``target`` or ``up`` is parallel to the optical axis.
    """
    eye = np.asarray(eye, dtype=float)
    z = np.asarray(target, dtype=float) - eye
    if np.linalg.norm(z) == 0:
        raise ValueError("look_at: eye and target coincide")
    z = z / np.linalg.norm(z)
    x = np.cross(z, np.asarray(up, dtype=float))
    if np.linalg.norm(x) < 1e-9:
        raise ValueError(f"look_at: up {tuple(up)} is parallel to the optical axis; choose another up")
    x /= np.linalg.norm(x)
    return SE3(SO3(np.column_stack([x, np.cross(z, x), z])), eye)


# ---- triangulation ---------------------------------------------------------------

def triangulate_midpoint(c1: np.ndarray, d1: np.ndarray, c2: np.ndarray, d2: np.ndarray,
                         what: str = "triangulate_midpoint") -> np.ndarray:
    """Midpoints of the shortest segments between rays cᵢ + λ dᵢ, row by row.

    With w = c1 − c2, a = d1·d1, b = d1·d2, c = d2·d2, d = d1·w, e = d2·w the
    closest points are at λ1 = (b e − c d)/(a c − b²) and λ2 = (a e − b d)/(a c − b²)
    (the normal equations of min ‖c1 + λ1 d1 − c2 − λ2 d2‖²); the result is
    ½ (c1 + λ1 d1 + c2 + λ2 d2).

    Parameters
    ----------
    c1, d1, c2, d2 : (N, 3) arrays (or (3,), broadcast)
        Ray origins and directions (not necessarily unit) in one frame.

    Returns
    -------
    (N, 3) array

    Raises
    ------
    ValueError
        When a pair of rays is parallel (a c − b² ≤ 1e-14 a c): no unique point.
    """
    c1, d1, c2, d2 = (np.atleast_2d(np.asarray(v, dtype=float)) for v in (c1, d1, c2, d2))
    w = c1 - c2
    a = np.sum(d1 * d1, -1)
    b = np.sum(d1 * d2, -1)
    c = np.sum(d2 * d2, -1)
    d = np.sum(d1 * w, -1)
    e = np.sum(d2 * w, -1)
    den = a * c - b * b
    bad = ~(den > 1e-14 * a * c)
    if np.any(bad):
        raise ValueError(f"{what}: the rays of row(s) {np.flatnonzero(bad)[:5].tolist()} are parallel "
                         "(or zero); their point is undetermined")
    l1 = (b * e - c * d) / den
    l2 = (a * e - b * d) / den
    return 0.5 * (c1 + l1[:, None] * d1 + c2 + l2[:, None] * d2)
