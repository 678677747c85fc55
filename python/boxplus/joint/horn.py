"""Horn's closed-form absolute orientation with unit quaternions.

B. K. P. Horn, "Closed-form solution of absolute orientation using unit
quaternions", J. Opt. Soc. Am. A 4(4), 1987: the rotation that best maps the
centred points a'ᵢ onto b'ᵢ is the eigenvector of the largest eigenvalue of
the symmetric 4×4 matrix N built from M = Σ wᵢ a'ᵢ b'ᵢᵀ (Sec. 4), and the
translation is t = b̄ − R ā (Sec. 2.C). No scale is estimated.

Frames: the result is ``b_from_a``, an SE3 with ``b_from_a.fromlocal(a) ≈ b``
(SE(3) = R³ × SO(3), tangent [translation, rotation]).
"""

from __future__ import annotations

from typing import Optional

import numpy as np

from boxplus.manifolds import SE3, SO3

__all__ = ["horn"]


def horn(p_in_a: np.ndarray, p_in_b: np.ndarray, weights: Optional[np.ndarray] = None) -> SE3:
    """The rigid transform b_from_a minimising Σ wᵢ ‖R aᵢ + t − bᵢ‖².

    Parameters
    ----------
    p_in_a, p_in_b : (N, 3) arrays
        The same N ≥ 3 points in frames a and b, not all on one line.
    weights : (N,) array, optional
        Non-negative weights (default: all 1).

    Returns
    -------
    SE3
        ``b_from_a``: ``b_from_a.fromlocal(p_in_a[i]) ≈ p_in_b[i]``.

    Raises
    ------
    ValueError
        On bad shapes, fewer than 3 points, or points on one line (the rotation
        about that line is then undetermined).
    """
    a = np.asarray(p_in_a, dtype=float)
    b = np.asarray(p_in_b, dtype=float)
    if a.ndim != 2 or a.shape[1] != 3 or a.shape != b.shape:
        raise ValueError(f"horn: need two (N, 3) arrays of corresponding points, got {a.shape} and {b.shape}")
    if len(a) < 3:
        raise ValueError(f"horn: need at least 3 corresponding points, got {len(a)}")
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        raise ValueError("horn: points have non-finite entries")
    w = np.ones(len(a)) if weights is None else np.asarray(weights, dtype=float).reshape(-1)
    if w.shape != (len(a),) or np.any(w < 0) or w.sum() <= 0:
        raise ValueError(f"horn: weights must be {len(a)} non-negative numbers with a positive sum")
    ca = w @ a / w.sum()
    cb = w @ b / w.sum()
    A, B = a - ca, b - cb
    # Degenerate (collinear or coincident) points leave a rotation free.
    sv = np.linalg.svd(np.sqrt(w)[:, None] * A, compute_uv=False)
    if sv[1] <= 1e-9 * max(sv[0], 1e-300):
        raise ValueError("horn: the points in frame a lie on one line; the rotation is undetermined")
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
    t = cb - R.R @ ca
    return SE3(R, t)
