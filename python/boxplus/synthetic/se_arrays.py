"""SE(2) and SE(3) on arrays of poses, vectorised in numpy (for the generator).

Ambient layouts are those of g2o files: SE(2) rows ``[x, y, θ]``, SE(3) rows
``[px, py, pz, qx, qy, qz, qw]`` (quaternion x y z w, Eigen's ``coeffs()``).
Tangent order is [translation, rotation] everywhere (STYLE.md). Every function
takes ``dim`` (2 or 3) and operates row by row on (N, 3) or (N, 7) arrays.

A pose ``x = (R, t)`` maps its own coordinates to the world's
(``world_from_x``); ``a ∘ b = (R_a R_b, t_a + R_a t_b)`` and
``a⁻¹ b = (R_aᵀ R_b, R_aᵀ (t_b − t_a))``.
"""

from __future__ import annotations

import numpy as np

from boxplus.batch import matrix_to_quat, quat_to_matrix

__all__ = [
    "between",
    "compose",
    "exp",
    "inverse",
    "matrix_from_quat",
    "prefix_compose",
    "quat_from_matrix",
    "quat_from_rotation_vector",
    "quat_multiply",
    "quat_rotate",
    "wrap_angle",
]

_CONJUGATE = np.array([-1.0, -1.0, -1.0, 1.0])


def wrap_angle(a: np.ndarray) -> np.ndarray:
    """Angles wrapped into [−π, π)."""
    return (np.asarray(a, float) + np.pi) % (2.0 * np.pi) - np.pi


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    # Column arithmetic: several times faster than np.cross on (N, 3) rows.
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)


def quat_multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product ``a b`` of (…, 4) quaternions in x y z w order."""
    va, wa = a[..., :3], a[..., 3:]
    vb, wb = b[..., :3], b[..., 3:]
    v = wa * vb + wb * va + _cross(va, vb)
    w = wa * wb - np.sum(va * vb, axis=-1, keepdims=True)
    return np.concatenate([v, w], axis=-1)


def quat_rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``R(q) v`` row by row for unit quaternions (x y z w) and (N, 3) vectors."""
    u, w = q[:, :3], q[:, 3:]
    t = 2.0 * _cross(u, v)
    return v + w * t + _cross(u, t)


def quat_from_rotation_vector(omega: np.ndarray) -> np.ndarray:
    """``exp(ω)`` of SO(3) as unit quaternions: ``[sin(‖ω‖/2) ω/‖ω‖, cos(‖ω‖/2)]``."""
    omega = np.asarray(omega, float)
    angle = np.linalg.norm(omega, axis=1, keepdims=True)
    half = 0.5 * angle
    # sin(θ/2)/θ → 1/2 − θ²/48 below 1e-4 rad, where the quotient loses digits.
    with np.errstate(invalid="ignore", divide="ignore"):
        k = np.where(angle < 1e-4, 0.5 - angle**2 / 48.0, np.sin(half) / angle)
    return np.concatenate([k * omega, np.cos(half)], axis=1)


def matrix_from_quat(q: np.ndarray) -> np.ndarray:
    """(N, 3, 3) rotation matrices of unit quaternions (x y z w)
    (:func:`boxplus.batch.quat_to_matrix`, the one conversion)."""
    return quat_to_matrix(np.asarray(q, float).reshape(-1, 4))


def quat_from_matrix(R: np.ndarray) -> np.ndarray:
    """Unit quaternions (x y z w, w ≥ 0) of (N, 3, 3) rotation matrices
    (:func:`boxplus.batch.matrix_to_quat`, Shepperd's method, with the sign fixed)."""
    q = matrix_to_quat(R)
    return np.where(q[:, 3:] < 0, -q, q)


def _rotate2(theta: np.ndarray, v: np.ndarray) -> np.ndarray:
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([c * v[:, 0] - s * v[:, 1], s * v[:, 0] + c * v[:, 1]], axis=1)


def compose(a: np.ndarray, b: np.ndarray, dim: int) -> np.ndarray:
    """``a ∘ b`` row by row."""
    if dim == 2:
        t = a[:, :2] + _rotate2(a[:, 2], b[:, :2])
        return np.column_stack([t, wrap_angle(a[:, 2] + b[:, 2])])
    q = quat_multiply(a[:, 3:], b[:, 3:])
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    return np.concatenate([a[:, :3] + quat_rotate(a[:, 3:], b[:, :3]), q], axis=1)


def inverse(a: np.ndarray, dim: int) -> np.ndarray:
    """``a⁻¹ = (Rᵀ, −Rᵀ t)`` row by row."""
    if dim == 2:
        return np.column_stack([-_rotate2(-a[:, 2], a[:, :2]), wrap_angle(-a[:, 2])])
    qc = a[:, 3:] * _CONJUGATE
    return np.concatenate([-quat_rotate(qc, a[:, :3]), qc], axis=1)


def between(a: np.ndarray, b: np.ndarray, dim: int) -> np.ndarray:
    """``a⁻¹ b`` row by row (the relative pose a g2o edge from a to b measures)."""
    if dim == 2:
        t = _rotate2(-a[:, 2], b[:, :2] - a[:, :2])
        return np.column_stack([t, wrap_angle(b[:, 2] - a[:, 2])])
    qc = a[:, 3:] * _CONJUGATE
    q = quat_multiply(qc, b[:, 3:])
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    return np.concatenate([quat_rotate(qc, b[:, :3] - a[:, :3]), q], axis=1)


def _skew(w: np.ndarray) -> np.ndarray:
    z = np.zeros(len(w))
    return np.stack([np.stack([z, -w[:, 2], w[:, 1]], 1),
                     np.stack([w[:, 2], z, -w[:, 0]], 1),
                     np.stack([-w[:, 1], w[:, 0], z], 1)], 1)


def exp(n: np.ndarray, dim: int) -> np.ndarray:
    """The SE(d) exponential of tangent rows ``n = [u, ω]`` (translation first).

    ``Exp(u, ω) = (exp(ω), V(ω) u)`` with, in 2D (ω = θ),
    ``V = [[sin θ, −(1 − cos θ)], [1 − cos θ, sin θ]] / θ``, and in 3D
    ``V = I + (1 − cos θ)/θ² [ω]× + (θ − sin θ)/θ³ [ω]×²``, θ = ‖ω‖: the inverse
    of GTSAM's ``Pose2/Pose3::Logmap`` (the 'log' error convention).
    """
    n = np.asarray(n, float)
    if dim == 2:
        th = n[:, 2]
        small = np.abs(th) < 1e-4
        with np.errstate(invalid="ignore", divide="ignore"):
            a = np.where(small, 1.0 - th**2 / 6.0, np.sin(th) / th)
            b = np.where(small, th / 2.0 - th**3 / 24.0, (1.0 - np.cos(th)) / th)
        u = n[:, :2]
        t = np.stack([a * u[:, 0] - b * u[:, 1], b * u[:, 0] + a * u[:, 1]], axis=1)
        return np.column_stack([t, wrap_angle(th)])
    w = n[:, 3:]
    th = np.linalg.norm(w, axis=1)
    small = th < 1e-4
    with np.errstate(invalid="ignore", divide="ignore"):
        b = np.where(small, 0.5 - th**2 / 24.0, (1.0 - np.cos(th)) / th**2)
        c = np.where(small, 1.0 / 6.0 - th**2 / 120.0, (th - np.sin(th)) / th**3)
    K = _skew(w)
    V = np.eye(3) + b[:, None, None] * K + c[:, None, None] * (K @ K)
    t = np.einsum("nij,nj->ni", V, n[:, :3])
    return np.concatenate([t, quat_from_rotation_vector(w)], axis=1)


def _quat_prefix(q: np.ndarray) -> np.ndarray:
    """``q₀, q₀q₁, q₀q₁q₂, …`` by a blocked scan: √N passes over √N blocks at once,
    then √N block prefixes, then one pass; about 3N products instead of N log N."""
    n = len(q)
    b = max(1, int(np.ceil(np.sqrt(n))))
    nb = -(-n // b)
    blocks = np.tile([0.0, 0.0, 0.0, 1.0], (nb * b, 1))
    blocks[:n] = q
    blocks = blocks.reshape(nb, b, 4)
    for j in range(1, b):
        blocks[:, j] = quat_multiply(blocks[:, j - 1], blocks[:, j])
    carry = np.empty((nb, 4))
    carry[0] = [0.0, 0.0, 0.0, 1.0]
    for k in range(1, nb):
        carry[k] = quat_multiply(carry[k - 1], blocks[k - 1, -1])
        carry[k] /= np.linalg.norm(carry[k])
    out = quat_multiply(carry[:, None, :], blocks).reshape(-1, 4)[:n]
    return out / np.linalg.norm(out, axis=1, keepdims=True)


def prefix_compose(first: np.ndarray, steps: np.ndarray, dim: int) -> np.ndarray:
    """Poses ``x₀, x₀∘s₁, x₀∘s₁∘s₂, …`` (N + 1 rows) from one pose and N steps.

    ``x_k = x_{k−1} ∘ s_k`` gives ``R_k = R₀ R(s₁) ⋯ R(s_k)`` and
    ``t_k = t₀ + Σ_{m ≤ k} R_{m−1} t(s_m)``: the rotations are a prefix product
    (2D: a cumulative sum of angles; 3D: a blocked quaternion scan), the
    positions a cumulative sum of rotated steps — vectorised, no loop over poses.
    """
    first = np.asarray(first, float).reshape(1, -1)
    steps = np.asarray(steps, float)
    if dim == 2:
        heading = first[0, 2] + np.concatenate([[0.0], np.cumsum(steps[:, 2])])
        moves = _rotate2(heading[:-1], steps[:, :2])
        xy = first[0, :2] + np.concatenate([np.zeros((1, 2)), np.cumsum(moves, axis=0)])
        return np.column_stack([xy, wrap_angle(heading)])
    q = _quat_prefix(np.concatenate([first[:, 3:], steps[:, 3:]]))
    moves = quat_rotate(q[:-1], steps[:, :3])
    t = first[0, :3] + np.concatenate([np.zeros((1, 3)), np.cumsum(moves, axis=0)])
    return np.concatenate([t, q], axis=1)
