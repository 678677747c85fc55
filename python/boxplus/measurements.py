"""The Python-measurement engine behind :class:`boxplus.OptimizationProblem`.

Measurements whose function f is written in Python are kept in groups (one
per function and kind of variables) and evaluated together: before each
solver step the C++ problem calls the group's ``_prepare``, which computes
every error e = f(Y) ⊟ z and, when asked, its Jacobians in the tangent spaces
of the variables by central differences through ⊞:

    ∂e/∂δⱼ ≈ (f(Y ⊞ hⱼ eⱼ) ⊟ z − f(Y ⊞ (−hⱼ) eⱼ) ⊟ z) / (2 hⱼ),

with hⱼ = 1e-6 × ``Codec.tangent_scale`` (relative for Rⁿ coordinates, absolute
for rotations). C++ whitens them with each measurement's NoiseModel
(r = W e, :mod:`boxplus.noise`), as it does for its own factors, and serves
Ceres from the arrays returned (python/bindings/cached_cost.h); the noise
never comes back to Python.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Callable

import numpy as np

from boxplus import _core, batch
from boxplus.manifolds import Codec

__all__ = ["EvaluationError", "batch_errors", "vector_error"]

_REL_STEP = 1e-6  # finite-difference step, relative to Codec.tangent_scale


class EvaluationError(ValueError):
    """A measurement function produced a non-finite or malformed result."""


def note(e: BaseException, text: str) -> None:
    """Adds ``text`` to the traceback of ``e`` (Python ≥ 3.11)."""
    if hasattr(e, "add_note"):
        e.add_note(text)


def _real_array(y: Any, what: str, expected: str) -> np.ndarray:
    """``y`` as a float array, or an EvaluationError saying what came back instead."""
    bad = isinstance(y, (str, bytes, dict)) or np.iscomplexobj(y)
    if not bad:
        try:
            return np.asarray(y, dtype=float)
        except (TypeError, ValueError):
            pass
    kind = type(y).__name__ + (f" of {y.dtype}" if isinstance(y, np.ndarray) else "")
    raise EvaluationError(f"{what}: f returned a {kind} {y!r:.80}, expected {expected}")


def vector_error(y: Any, z: np.ndarray, what: str) -> np.ndarray:
    """y − z for a function value ``y`` that must be a vector of z.size real numbers."""
    a = _real_array(y, what, f"a vector of {z.size} real numbers like z")
    if a.size != z.size:
        raise EvaluationError(f"{what}: f returned {a.size} numbers (shape {a.shape}), expected "
                              f"a vector of {z.size} numbers like z")
    return a.reshape(z.size) - z


def batch_errors(name: str, z_codec: Codec | None, m: int, Y: Any, Z: np.ndarray,
                 n: int) -> np.ndarray:
    """Y ⊟ Z row by row for the output Y of a vectorised function (N predictions)."""
    what = f"measurement group '{name}'"
    if z_codec is None:
        Ya = _real_array(Y, what, f"an ({n}, {m}) array")
        if Ya.shape != (n, m):
            raise EvaluationError(f"{what}: the vectorised function returned shape "
                                  f"{Ya.shape}, expected ({n}, {m})")
        return Ya - Z
    Ya = _real_array(getattr(Y, "ambient", Y), what, f"a batch of {n} {z_codec.name}")
    if Ya.shape != Z.shape:
        raise EvaluationError(f"{what}: the vectorised function returned values of "
                              f"ambient shape {Ya.shape}, expected {Z.shape}")
    return z_codec.manifold.minus_batch(Ya, Z)


class Group:
    """Measurements that share one Python function; evaluated together.

    ``problem`` is the owning OptimizationProblem (its ``_core`` Problem names
    variables and measurements in messages).
    """

    def __init__(self, problem: Any, f: Callable, name: str, vectorized: bool,
                 z_codec: Codec | None, m: int, slot_codecs: Sequence[Codec]) -> None:
        self.problem = problem
        self.f = f
        self.name = name
        self.vectorized = vectorized
        self.z_codec = z_codec  # None: z is a plain vector, ⊟ is subtraction
        self.m = m
        self.slots = list(slot_codecs)
        self.ids: list[tuple[int, ...]] = []
        self.z_rows: list[np.ndarray] = []
        self.const_rows: list[tuple[Any, ...]] = []  # unbatched: per measurement
        self.const_chunks: list[tuple[Any, ...]] = []  # vectorized: per add call
        self.meas_ids: list[int] = []
        self.keepalive: list[Any] = []  # shared constants, whose ids are part of the group key
        self._packed: tuple[np.ndarray, np.ndarray, tuple[Any, ...]] | None = None
        self._X: list[np.ndarray] | None = None
        self._R: np.ndarray | None = None
        self._J: list[np.ndarray] | None = None
        self.cache = _core.ResidualCache(self._prepare, m, [c.dof for c in self.slots], name)
        problem._core.add_residual_cache(self.cache)

    # ---- bookkeeping -----------------------------------------------------------------
    def append(self, ids, z_rows, noises: Sequence[_core.NoiseModel], consts, loss,
               names) -> list[int]:
        """Adds measurements (rows of ids, z, noise; constants per row or per chunk)."""
        core = self.problem._core
        out = []
        for k in range(len(ids)):
            what = f"measurement '{names[k] or self.name}'"
            factor = _core.cached_factor(core, self.cache, list(ids[k]), noises[k], what)
            mid = core.add_factor(factor, loss, names[k])
            self.ids.append(tuple(ids[k]))
            self.z_rows.append(z_rows[k])
            self.meas_ids.append(mid)
            out.append(mid)
        if self.vectorized:
            self.const_chunks.append(consts)
        else:
            self.const_rows.extend(consts)
        self._packed = None
        return out

    def _pack(self):
        if self._packed is None:
            ids = np.asarray(self.ids, dtype=int).reshape(len(self.ids), len(self.slots))
            Z = np.asarray(self.z_rows, dtype=float)
            if self.vectorized and self.const_chunks:
                C = tuple(
                    np.concatenate([ch[i] for ch in self.const_chunks], axis=0)
                    if isinstance(self.const_chunks[0][i], np.ndarray)
                    else self.const_chunks[0][i]
                    for i in range(len(self.const_chunks[0]))
                )
            else:
                C = ()
            self._packed = (ids, Z, C)
        return self._packed

    def _what(self, i: int) -> str:
        mid = self.meas_ids[i]
        name = self.problem._core.measurement_name(mid)
        return f"measurement '{name or self.name}' (id {mid}, function {self.name})"

    # ---- evaluation ------------------------------------------------------------------
    def errors(self, Xs: Sequence[np.ndarray], views: list[Any] | None = None) -> np.ndarray:
        """Unwhitened errors f(Y) ⊟ z, one row per measurement, at ambient values Xs
        (``views``: batches of Xs already built, None where still to build)."""
        _, Z, C = self._pack()
        if self.vectorized:
            views = [
                v if v is not None else batch.view(c, X)
                for c, X, v in zip(self.slots, Xs, views or [None] * len(Xs))
            ]
            Y = self.f(*views, *C)
            return batch_errors(self.name, self.z_codec, self.m, Y, Z, len(Z))
        E = np.empty((Xs[0].shape[0], self.m))
        for i in range(E.shape[0]):
            values = [c.from_ambient(X[i]) for c, X in zip(self.slots, Xs)]
            y = self.f(*values, *self.const_rows[i])
            E[i] = self._minus_one(y, Z[i], i)
        return E

    def _minus_one(self, y: Any, z: np.ndarray, i: int) -> np.ndarray:
        if self.z_codec is None:
            return vector_error(y, z, self._what(i))
        try:
            ya = self.z_codec.to_ambient(y)
        except Exception:
            raise EvaluationError(f"{self._what(i)}: f returned a {type(y).__name__}, expected a "
                                  f"{self.z_codec.name} like z") from None
        return self.z_codec.manifold.minus(ya, z)

    def current_values(self) -> list[np.ndarray]:
        ids, *_ = self._pack()
        return [self.problem._core.values(ids[:, k].tolist()) for k in range(len(self.slots))]

    def _check_finite(self, A: np.ndarray, Xs: Sequence[np.ndarray], what: str) -> None:
        bad = ~np.all(np.isfinite(A.reshape(A.shape[0], -1)), axis=1)
        if bad.any():
            i = int(np.argmax(bad))
            values = ", ".join(
                f"{self.problem._core.variable_name(v)}={c.from_ambient(X[i])!r}"
                for v, c, X in zip(self.ids[i], self.slots, Xs)
            )
            raise EvaluationError(
                f"measurement '{self.problem._core.measurement_name(self.meas_ids[i])}' "
                f"(id {self.meas_ids[i]}, function {self.name}) produced a non-finite {what} "
                f"at {values}"
            )

    def _prepare(self, jacobians: bool, new_point: bool):
        if new_point or self._R is None:
            Xs = self.current_values()
            E = self.errors(Xs)
            self._check_finite(E, Xs, "residual")
            self._X = Xs
            self._R = E
            self._J = None
        if jacobians and self._J is None:
            self._J = self._jacobians()
        return self._R, self._J

    def _jacobians(self) -> list[np.ndarray]:
        Xs = self._X
        assert Xs is not None
        # The batches of the slots not being perturbed are built once.
        base = [batch.view(c, X) for c, X in zip(self.slots, Xs)] if self.vectorized else None
        out = []
        for k, codec in enumerate(self.slots):
            X = Xs[k]
            h = _REL_STEP * codec.tangent_scale(X)
            J = np.empty((X.shape[0], self.m, codec.dof))
            for j in range(codec.dof):
                D = np.zeros((X.shape[0], codec.dof))
                D[:, j] = h[:, j]
                E = []
                for sign in (1.0, -1.0):
                    moved = list(Xs)
                    views = None
                    if base is not None:
                        views = list(base)
                        views[k] = batch.perturbed_view(codec, base[k], j, sign * h[:, j])
                    if views is None or views[k] is None:
                        moved[k] = codec.manifold.plus_batch(X, sign * D)
                    E.append(self.errors(moved, views))
                J[:, :, j] = (E[0] - E[1]) / (2 * h[:, j : j + 1])
            self._check_finite(J, Xs, f"Jacobian (variable {k})")
            out.append(J)
        return out
