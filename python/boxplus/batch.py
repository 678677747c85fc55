"""Batched views of manifold values, for vectorised measurement functions.

A vectorised measurement function receives, for each of its variables, one
*batch* holding that variable's value in every measurement of the batch (row
i belongs to measurement i), and returns all predictions at once. Batches
mirror the value types:

=============  ==========================================================
value          batch
=============  ==========================================================
Rn             ``RnBatch``: ``.vec`` (N, n)
SO2            ``SO2Batch``: ``.phi`` (N,), ``.R`` (N, 2, 2), ``b * p``
SO3            ``SO3Batch``: ``.quat`` (N, 4), ``.R`` (N, 3, 3), ``b * p``
SE2            ``SE2Batch``: ``.pos`` (N, 2), ``.phi``, ``.R``, ``fromlocal``, ``tolocal``
SE3            ``SE3Batch``: ``.pos`` (N, 3), ``.R``, ``.quat``, ``transform()``,
               ``fromlocal``, ``tolocal``, ``inverse()``, ``a * b``, ``a * p``
S2             ``S2Batch``: ``.vec`` (N, 3)
compound       ``CompoundBatch``: members as attributes, each a batch
other          a list of values
=============  ==========================================================

Points ``p`` are (N, d) arrays (one per row) or a single (d,) point for all rows.
Every batch has ``.ambient`` (N, ambient size), the solver's storage layout.
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from boxplus.manifolds import S2, SE2, SE3, SO2, SO3, Codec

__all__ = [
    "CompoundBatch",
    "RnBatch",
    "S2Batch",
    "SE2Batch",
    "SE3Batch",
    "SO2Batch",
    "SO3Batch",
    "builtin_view",
    "quat_to_matrix",
    "matrix_to_quat",
    "view",
]


def quat_to_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrices (N, 3, 3) from unit quaternions (N, 4) [x, y, z, w]."""
    x, y, z, w = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    R = np.empty((q.shape[0], 3, 3))
    R[:, 0, 0] = 1 - 2 * (y * y + z * z)
    R[:, 0, 1] = 2 * (x * y - z * w)
    R[:, 0, 2] = 2 * (x * z + y * w)
    R[:, 1, 0] = 2 * (x * y + z * w)
    R[:, 1, 1] = 1 - 2 * (x * x + z * z)
    R[:, 1, 2] = 2 * (y * z - x * w)
    R[:, 2, 0] = 2 * (x * z - y * w)
    R[:, 2, 1] = 2 * (y * z + x * w)
    R[:, 2, 2] = 1 - 2 * (x * x + y * y)
    return R


def matrix_to_quat(R: np.ndarray) -> np.ndarray:
    """Unit quaternions (N, 4) [x, y, z, w] from rotation matrices (N, 3, 3).

    Uses the largest of the four candidate denominators per row (Shepperd's
    method), so it is accurate for every rotation.
    """
    R = np.asarray(R, dtype=float).reshape(-1, 3, 3)
    n = R.shape[0]
    tr = np.trace(R, axis1=1, axis2=2)
    d = np.stack([R[:, 0, 0], R[:, 1, 1], R[:, 2, 2], tr], axis=1)
    k = np.argmax(d, axis=1)
    q = np.empty((n, 4))
    for case in range(4):
        m = k == case
        if not m.any():
            continue
        Rm = R[m]
        if case == 3:
            s = 2 * np.sqrt(1 + tr[m])
            q[m] = np.stack(
                [(Rm[:, 2, 1] - Rm[:, 1, 2]) / s, (Rm[:, 0, 2] - Rm[:, 2, 0]) / s,
                 (Rm[:, 1, 0] - Rm[:, 0, 1]) / s, s / 4], axis=1)
        else:
            i, j, l = case, (case + 1) % 3, (case + 2) % 3
            s = 2 * np.sqrt(1 + Rm[:, i, i] - Rm[:, j, j] - Rm[:, l, l])
            qi = s / 4
            qj = (Rm[:, j, i] + Rm[:, i, j]) / s
            ql = (Rm[:, l, i] + Rm[:, i, l]) / s
            qw = (Rm[:, l, j] - Rm[:, j, l]) / s
            out = np.empty((Rm.shape[0], 4))
            out[:, i], out[:, j], out[:, l], out[:, 3] = qi, qj, ql, qw
            q[m] = out
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def _wrap(phi: np.ndarray) -> np.ndarray:
    """Angles in [−π, π), as SO2 keeps them."""
    return (np.asarray(phi, dtype=float) + np.pi) % (2 * np.pi) - np.pi


def _points(p: Any, n: int, d: int) -> np.ndarray:
    p = np.asarray(p, dtype=float)
    if p.shape == (d,):
        return np.broadcast_to(p, (n, d))
    if p.shape == (n, d):
        return p
    raise ValueError(f"points must have shape ({d},) or ({n}, {d}), got {p.shape}")


class RnBatch:
    """N vectors of Rⁿ: ``.vec`` is (N, n)."""

    def __init__(self, vec: np.ndarray) -> None:
        self.vec = np.asarray(vec, dtype=float)

    @property
    def ambient(self) -> np.ndarray:
        return self.vec

    def perturbed(self, direction: int, h: np.ndarray) -> RnBatch | None:
        """This batch ⊞ (h · e_direction): h (N,) added to one coordinate."""
        v = self.vec.copy()
        v[:, direction] += h
        return RnBatch(v)

    def __len__(self) -> int:
        return self.vec.shape[0]


class SO2Batch:
    """N planar rotations: ``.phi`` (N,)."""

    def __init__(self, phi: np.ndarray) -> None:
        self.phi = np.asarray(phi, dtype=float).reshape(-1)

    @property
    def R(self) -> np.ndarray:
        c, s = np.cos(self.phi), np.sin(self.phi)
        return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)

    @property
    def ambient(self) -> np.ndarray:
        return self.phi[:, None]

    def inverse(self) -> SO2Batch:
        return SO2Batch(_wrap(-self.phi))

    def __mul__(self, other: Any) -> Any:
        if isinstance(other, (SO2Batch, SO2)):
            return SO2Batch(_wrap(self.phi + other.phi))
        return np.einsum("nij,nj->ni", self.R, _points(other, len(self.phi), 2))

    __matmul__ = __mul__

    def __len__(self) -> int:
        return len(self.phi)


class SO3Batch:
    """N rotations: ``.quat`` (N, 4) [x, y, z, w], ``.R`` (N, 3, 3)."""

    def __init__(self, quat: np.ndarray) -> None:
        # One of the two is always set; the other is computed when first asked for.
        self._quat: np.ndarray | None = np.asarray(quat, dtype=float)
        self._R: np.ndarray | None = None

    @classmethod
    def from_matrix(cls, R: np.ndarray) -> SO3Batch:
        """From rotation matrices (N, 3, 3); the quaternions are computed when asked for."""
        b = cls.__new__(cls)
        b._quat = None
        b._R = np.asarray(R, dtype=float)
        return b

    @property
    def quat(self) -> np.ndarray:
        if self._quat is None:
            assert self._R is not None
            self._quat = matrix_to_quat(self._R)
        return self._quat

    @property
    def R(self) -> np.ndarray:
        if self._R is None:
            self._R = quat_to_matrix(self.quat)
        return self._R

    Q = R

    @property
    def ambient(self) -> np.ndarray:
        return self.quat

    def inverse(self) -> SO3Batch:
        return SO3Batch(self.quat * np.array([-1.0, -1.0, -1.0, 1.0]))

    def __mul__(self, other: Any) -> Any:
        if isinstance(other, SO3Batch):
            return SO3Batch.from_matrix(self.R @ other.R)
        if isinstance(other, SO3):
            return SO3Batch.from_matrix(self.R @ other.R)
        return np.einsum("nij,nj->ni", self.R, _points(other, len(self), 3))

    __matmul__ = __mul__

    def perturbed(self, direction: int, h: np.ndarray) -> SO3Batch | None:
        """R · exp(h e_direction) when the step h (N,) is the same in every row; None otherwise."""
        if not np.all(h == h[0]):
            return None
        return SO3Batch.from_matrix(self.R @ _small_rotation(direction, h[0]))

    def __len__(self) -> int:
        stored = self._quat if self._quat is not None else self._R
        assert stored is not None
        return stored.shape[0]


class SE2Batch:
    """N planar poses: ``.pos`` (N, 2), ``.phi`` (N,)."""

    def __init__(self, pos: np.ndarray, phi: np.ndarray) -> None:
        self.pos = np.asarray(pos, dtype=float)
        self.phi = np.asarray(phi, dtype=float).reshape(-1)

    @property
    def R(self) -> np.ndarray:
        return SO2Batch(self.phi).R

    @property
    def ambient(self) -> np.ndarray:
        return np.column_stack([self.pos, self.phi])

    def transform(self) -> np.ndarray:
        """Homogeneous 3×3 matrices [[R, p], [0, 1]] (N, 3, 3)."""
        T = np.zeros((len(self), 3, 3))
        T[:, :2, :2] = self.R
        T[:, :2, 2] = self.pos
        T[:, 2, 2] = 1.0
        return T

    def fromlocal(self, v: Any) -> np.ndarray:
        """R v + p for each row."""
        return np.einsum("nij,nj->ni", self.R, _points(v, len(self), 2)) + self.pos

    def tolocal(self, v: Any) -> np.ndarray:
        """Rᵀ (v − p) for each row."""
        return np.einsum("nji,nj->ni", self.R, _points(v, len(self), 2) - self.pos)

    def inverse(self) -> SE2Batch:
        return SE2Batch(-np.einsum("nji,nj->ni", self.R, self.pos), _wrap(-self.phi))

    def __mul__(self, other: Any) -> Any:
        """Composition with SE2 poses (a batch or one value), else the points mapped."""
        if isinstance(other, (SE2Batch, SE2)):
            return SE2Batch(self.fromlocal(other.pos), _wrap(self.phi + other.phi))
        return self.fromlocal(other)

    __matmul__ = __mul__

    def __len__(self) -> int:
        return self.pos.shape[0]


class SE3Batch:
    """N rigid transforms (local → parent): ``.pos`` (N, 3), ``.R`` (N, 3, 3)."""

    def __init__(self, pos: np.ndarray, rot: SO3Batch) -> None:
        self.pos = np.asarray(pos, dtype=float)
        self.rot = rot

    @classmethod
    def from_ambient(cls, a: np.ndarray) -> SE3Batch:
        a = np.asarray(a, dtype=float)
        return cls(a[:, :3], SO3Batch(a[:, 3:7]))

    @classmethod
    def from_Rt(cls, R: np.ndarray, t: np.ndarray) -> SE3Batch:
        return cls(t, SO3Batch.from_matrix(R))

    @property
    def R(self) -> np.ndarray:
        return self.rot.R

    Q = R
    t = property(lambda self: self.pos)

    @property
    def quat(self) -> np.ndarray:
        return self.rot.quat

    @property
    def ambient(self) -> np.ndarray:
        return np.column_stack([self.pos, self.rot.quat])

    def transform(self) -> np.ndarray:
        T = np.zeros((len(self), 4, 4))
        T[:, :3, :3] = self.R
        T[:, :3, 3] = self.pos
        T[:, 3, 3] = 1.0
        return T

    def fromlocal(self, v: Any) -> np.ndarray:
        """R v + p for each row."""
        return np.einsum("nij,nj->ni", self.R, _points(v, len(self), 3)) + self.pos

    def tolocal(self, v: Any) -> np.ndarray:
        """Rᵀ (v − p) for each row."""
        return np.einsum("nji,nj->ni", self.R, _points(v, len(self), 3) - self.pos)

    def inverse(self) -> SE3Batch:
        Rt = np.transpose(self.R, (0, 2, 1))
        return SE3Batch.from_Rt(Rt, -np.einsum("nij,nj->ni", Rt, self.pos))

    def __mul__(self, other: Any) -> Any:
        if isinstance(other, (SE3Batch, SE3)):
            oR = other.R
            return SE3Batch.from_Rt(self.R @ oR, self.fromlocal(other.pos))
        return self.fromlocal(other)

    __matmul__ = __mul__

    def perturbed(self, direction: int, h: np.ndarray) -> SE3Batch | None:
        """This batch ⊞ (h · e_direction), tangent [translation, rotation], when the
        step h (N,) is the same in every row; None otherwise."""
        if direction < 3:
            pos = self.pos.copy()
            pos[:, direction] += h
            return SE3Batch(pos, self.rot)
        rot = self.rot.perturbed(direction - 3, h)
        return None if rot is None else SE3Batch(self.pos, rot)

    def __len__(self) -> int:
        return self.pos.shape[0]


class S2Batch(RnBatch):
    """N unit vectors: ``.vec`` (N, 3) (stored like Rⁿ rows)."""

    def perturbed(self, direction: int, h: np.ndarray) -> None:
        return None  # ⊞ of S² is not a coordinate step: the solver's ⊞ is used


class CompoundBatch:
    """N values of a compound: each member is an attribute holding a batch."""

    def __init__(self, cls: Any, ambient: np.ndarray) -> None:  # a compound class
        self._cls = cls
        self._ambient = ambient
        for m in cls._codec().parts():
            setattr(self, m.name, m.codec.view(ambient[:, m.ambient]))

    @property
    def ambient(self) -> np.ndarray:
        return self._ambient

    def __len__(self) -> int:
        return self._ambient.shape[0]


def _small_rotation(axis: int, h: float) -> np.ndarray:
    c, s = np.cos(h), np.sin(h)
    i, j = (axis + 1) % 3, (axis + 2) % 3
    E = np.eye(3)
    E[i, i] = E[j, j] = c
    E[j, i], E[i, j] = s, -s
    return E


def perturbed_view(codec: Codec, base: Any, direction: int, h: np.ndarray) -> Any:
    """The batch of base ⊞ (h · e_direction), built from the unperturbed batch
    without a round trip through quaternions where the kind allows it (Rn, SO3,
    SE3 with a step h that is the same for all rows); None otherwise
    (:meth:`Codec.perturbed_view`)."""
    return codec.perturbed_view(base, direction, h)


def view(codec: Codec, X: np.ndarray) -> Any:
    """The batch of values stored in the rows of X (N, ambient size) (:meth:`Codec.view`)."""
    return codec.view(X)


_BUILTIN_VIEWS: dict[type, Callable[[np.ndarray], Any]] = {
    SO2: lambda X: SO2Batch(X[:, 0]),
    SO3: SO3Batch,
    SE2: lambda X: SE2Batch(X[:, :2], X[:, 2]),
    SE3: SE3Batch.from_ambient,
    S2: S2Batch,
}


def builtin_view(value_type: type, X: np.ndarray) -> Any:
    """The batch of a C++ built-in kind (SO2, SO3, SE2, SE3, S2) from ambient rows X."""
    return _BUILTIN_VIEWS[value_type](X)
