"""OptimizationProblem: least squares on manifolds, written like the maths.

A problem has random variables (manifold values) and measurements
(z, Σ, f, Y): the residual of a measurement is L⁻¹ (f(Y) ⊟ z) with LLᵀ = Σ,
and ``solve()`` minimises ½ Σ ρ(‖r‖²) with ⊞-steps. All book-keeping —
stacking, indices, sparsity, whitening, Jacobians — happens here.

Measurement functions written in Python are differentiated by central finite
differences through ⊞ in the tangent space of each variable. They come in two
forms:

* ``add_measurement(z, f, ids, constants)``: ``f(*values, *constants)`` for one
  measurement, called once per measurement (simple, slow for thousands);
* ``add_measurements(Z, f, ids, constants)``: ``f(*batches, *constants)`` for a
  whole batch at once (numpy in, numpy out; see :mod:`boxplus.batch`), the fast
  form.

Measurements written in C++ (``add_prior`` and the built-in factors) mix freely
with both.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from boxplus import _core, batch
from boxplus.manifolds import Codec, codec_of

__all__ = ["EvaluationError", "OptimizationProblem", "SolveResult"]

LossSpec = Union[None, str, Tuple[str, float], "_core.Loss"]

_REL_STEP = 1e-6  # finite-difference step, relative to the size of an Rⁿ coordinate


class EvaluationError(ValueError):
    """A measurement function produced a non-finite or malformed result."""


@dataclass
class SolveResult:
    """What ``OptimizationProblem.solve`` did and where it ended.

    Attributes
    ----------
    X : list
        The estimates, one value per variable id (also written back to the problem).
    termination : str
        'convergence', 'no_convergence', 'interrupted' (callback or Ctrl-C) or 'failure'.
    """

    initial_cost: float
    final_cost: float
    iterations: int
    time_s: float
    termination: str
    message: str
    usable: bool
    report: str = field(repr=False)
    X: List[Any] = field(repr=False)

    def __str__(self) -> str:
        return (
            f"{self.termination}: cost {self.initial_cost:.6g} -> {self.final_cost:.6g} "
            f"in {self.iterations} iterations, {self.time_s:.3f} s ({self.message})"
        )


def _make_loss(loss: LossSpec, what: str) -> Optional["_core.Loss"]:
    if loss is None:
        return None
    if isinstance(loss, _core.Loss):
        return loss
    try:
        if isinstance(loss, str):
            return _core.Loss(loss, 1.0)
        name, width = loss
        return _core.Loss(str(name), float(width))
    except (TypeError, ValueError) as e:
        raise ValueError(f"{what}: bad loss {loss!r}: {e}") from None


def _sqrt_info(sigma: Any, m: int, what: str) -> np.ndarray:
    """W = L⁻¹ (LLᵀ = Σ) from a scalar σ, a vector of σᵢ, or a full Σ."""
    s = np.asarray(sigma, dtype=float)
    if not np.all(np.isfinite(s)):
        raise ValueError(f"{what}: sigma has non-finite entries")
    if s.ndim == 0 or s.shape == (m,):
        if np.any(s <= 0):
            raise ValueError(f"{what}: standard deviations must be positive, got {s}")
        return np.diag(np.broadcast_to(1.0 / s, (m,)))
    if s.shape == (m, m):
        if not np.allclose(s, s.T, rtol=1e-9, atol=1e-12 * max(1.0, np.abs(s).max())):
            raise ValueError(f"{what}: covariance Σ is not symmetric")
        try:
            L = np.linalg.cholesky(s)
        except np.linalg.LinAlgError:
            raise ValueError(f"{what}: covariance Σ is not positive definite") from None
        return np.linalg.solve(L, np.eye(m))
    raise ValueError(
        f"{what}: sigma must be a scalar, a vector of {m} standard deviations or a "
        f"{m}×{m} covariance, got shape {s.shape}"
    )


def _tangent_scale(codec: Codec, X: np.ndarray) -> np.ndarray:
    """Per-row, per-tangent-direction magnitude used to size finite-difference steps."""
    from boxplus.manifolds import Rn, _CompoundBase

    t = codec.value_type
    if t is Rn:
        return np.maximum(1.0, np.abs(X))
    if isinstance(t, type) and issubclass(t, _CompoundBase):
        cols = []
        for name in t._members:
            c = t._member_codecs[name]
            start = t._ambient_offsets[name]
            cols.append(_tangent_scale(c, X[:, start : start + c.ambient_size]))
        return np.concatenate(cols, axis=1)
    return np.ones((X.shape[0], codec.dof))


def _note(e: BaseException, text: str) -> None:
    if hasattr(e, "add_note"):
        e.add_note(text)


def _batch_errors(name: str, z_codec: Optional[Codec], m: int, Y: Any, Z: np.ndarray, n: int) -> np.ndarray:
    """Y ⊟ Z row by row for the output Y of a vectorised function (N predictions)."""
    if z_codec is None:
        Y = np.asarray(Y, dtype=float)
        if Y.shape != (n, m):
            raise EvaluationError(
                f"measurement group '{name}': the vectorised function returned shape "
                f"{Y.shape}, expected ({n}, {m})"
            )
        return Y - Z
    Ya = np.asarray(getattr(Y, "ambient", Y), dtype=float)
    if Ya.shape != Z.shape:
        raise EvaluationError(
            f"measurement group '{name}': the vectorised function returned values of "
            f"ambient shape {Ya.shape}, expected {Z.shape}"
        )
    return z_codec.manifold.minus_batch(Ya, Z)


class _Group:
    """Measurements that share one Python function; evaluated together."""

    def __init__(
        self,
        problem: "OptimizationProblem",
        f: Callable,
        name: str,
        vectorized: bool,
        z_codec: Optional[Codec],
        m: int,
        slot_codecs: Sequence[Codec],
    ) -> None:
        self.problem = problem
        self.f = f
        self.name = name
        self.vectorized = vectorized
        self.z_codec = z_codec  # None: z is a plain vector, ⊟ is subtraction
        self.m = m
        self.slots = list(slot_codecs)
        self.ids: List[Tuple[int, ...]] = []
        self.z_rows: List[np.ndarray] = []
        self.W_rows: List[np.ndarray] = []
        self.const_rows: List[Tuple[Any, ...]] = []  # unbatched: per measurement
        self.const_chunks: List[Tuple[Any, ...]] = []  # vectorized: per add call
        self.meas_ids: List[int] = []
        self.keepalive: List[Any] = []  # shared constants, whose ids are part of the group key
        self._packed: Optional[Tuple[np.ndarray, np.ndarray, np.ndarray, Tuple[Any, ...]]] = None
        self._X: Optional[List[np.ndarray]] = None
        self._E: Optional[np.ndarray] = None
        self._R: Optional[np.ndarray] = None
        self.cache = _core.ResidualCache(self._prepare, m, [c.dof for c in self.slots])
        problem._core.add_residual_cache(self.cache)

    # ---- bookkeeping -----------------------------------------------------------------
    def append(self, ids, z_rows, W_rows, consts, loss, names) -> List[int]:
        out = []
        for k in range(len(ids)):
            mid = self.problem._core.add_cached_measurement(self.cache, list(ids[k]), loss, names[k])
            self.ids.append(tuple(ids[k]))
            self.z_rows.append(z_rows[k])
            self.W_rows.append(W_rows[k])
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
            W = np.asarray(self.W_rows, dtype=float)
            if self.vectorized and self.const_chunks:
                C = tuple(
                    np.concatenate([ch[i] for ch in self.const_chunks], axis=0)
                    if isinstance(self.const_chunks[0][i], np.ndarray)
                    else self.const_chunks[0][i]
                    for i in range(len(self.const_chunks[0]))
                )
            else:
                C = ()
            self._packed = (ids, Z, W, C)
            self._shared_W = W[0] if len(W) and np.all(W == W[0]) else None
        return self._packed

    # ---- evaluation ------------------------------------------------------------------
    def errors(self, Xs: Sequence[np.ndarray], views: Optional[List[Any]] = None) -> np.ndarray:
        """Unwhitened errors f(Y) ⊟ z, one row per measurement, at ambient values Xs
        (``views``: batches of Xs already built, None where still to build)."""
        _, Z, _, C = self._pack()
        if self.vectorized:
            views = [
                v if v is not None else batch.view(c, X)
                for c, X, v in zip(self.slots, Xs, views or [None] * len(Xs))
            ]
            Y = self.f(*views, *C)
            return self._minus_batch(Y, Z, len(Z))
        E = np.empty((Xs[0].shape[0], self.m))
        for i in range(E.shape[0]):
            values = [c.from_ambient(X[i]) for c, X in zip(self.slots, Xs)]
            y = self.f(*values, *self.const_rows[i])
            E[i] = self._minus_one(y, Z[i])
        return E

    def _minus_one(self, y: Any, z: np.ndarray) -> np.ndarray:
        if self.z_codec is None:
            return np.asarray(y, dtype=float).reshape(self.m) - z
        return self.z_codec.manifold.minus(self.z_codec.to_ambient(y), z)

    def _minus_batch(self, Y: Any, Z: np.ndarray, n: int) -> np.ndarray:
        return _batch_errors(self.name, self.z_codec, self.m, Y, Z, n)

    def current_values(self) -> List[np.ndarray]:
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
            self._X, self._E = Xs, E
            self._R = self._whiten(E)
            self._J = None
        if jacobians and self._J is None:
            self._J = self._jacobians()
        return self._R, self._J

    def _jacobians(self) -> List[np.ndarray]:
        from boxplus.manifolds import Rn

        Xs = self._X
        # The batches of the slots not being perturbed are built once.
        base = [batch.view(c, X) for c, X in zip(self.slots, Xs)] if self.vectorized else None
        out = []
        for k, codec in enumerate(self.slots):
            X = Xs[k]
            h = _REL_STEP * _tangent_scale(codec, X)
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
                        # ⊞ of Rⁿ is +: skip the round trip through C++
                        step = sign * D
                        moved[k] = X + step if codec.value_type is Rn else codec.manifold.plus_batch(X, step)
                    E.append(self.errors(moved, views))
                J[:, :, j] = (E[0] - E[1]) / (2 * h[:, j : j + 1])
            self._check_finite(J, Xs, f"Jacobian (variable {k})")
            out.append(self._whiten(J))
        return out

    def _whiten(self, A: np.ndarray) -> np.ndarray:
        """W A row by row (A: (N, m) or (N, m, t)); one matrix product when W is shared."""
        _, _, W, _ = self._pack()
        if self._shared_W is not None:
            return A @ self._shared_W.T if A.ndim == 2 else np.einsum("ij,njt->nit", self._shared_W, A)
        return np.einsum("nij,nj->ni", W, A) if A.ndim == 2 else np.einsum("nij,njt->nit", W, A)


class OptimizationProblem:
    """A least-squares problem on manifolds (MTKM's OptimizationProblem).

    Examples
    --------
    >>> p = OptimizationProblem()
    >>> x = p.add_random_var(SO3())
    >>> p.add_measurement(SO3.exp([0, 0, 1]), lambda r: r, [x], sigma=0.1)
    >>> p.solve().termination
    'convergence'
    """

    def __init__(self) -> None:
        self._core = _core.Problem()
        self._codecs: List[Codec] = []
        self._groups: Dict[Tuple[Any, ...], _Group] = {}
        self._meas_group: Dict[int, str] = {}
        # C++ factors whose errors can be unwhitened: mid -> (W, dim of one error row)
        self._cpp_W: Dict[int, np.ndarray] = {}
        self._labels: Dict[int, List[str]] = {}

    # ---- variables -------------------------------------------------------------------
    def add_random_var(
        self, value: Any, fixed: bool = False, name: Optional[str] = None,
        labels: Optional[Sequence[str]] = None,
    ) -> int:
        """Adds a variable with initial value ``value``; returns its id.

        ``labels`` names the tangent directions (e.g. ``["fx", "fy", ...]``) in
        reports; by default they come from the value's type.
        """
        codec = codec_of(value)
        vid = self._core.add_variable(codec.manifold, codec.to_ambient(value), name or "")
        self._codecs.append(codec)
        if labels is not None:
            if len(labels) != codec.dof:
                raise ValueError(f"variable '{name}': {len(labels)} labels for {codec.dof} directions")
            self._labels[vid] = list(labels)
        if fixed:
            self._core.set_fixed(vid, True)
        return vid

    def variable_name(self, vid: int) -> str:
        self._codec(vid)
        return self._core.variable_name(int(vid))

    def labels(self, vid: int) -> List[str]:
        """Names of the tangent directions of variable ``vid`` (for reports)."""
        from boxplus.manifolds import SE3, _CompoundBase

        codec = self._codec(vid)
        if vid in self._labels:
            return self._labels[vid]
        t = codec.value_type
        if t is SE3:
            return ["p.x", "p.y", "p.z", "θ.x", "θ.y", "θ.z"]
        if isinstance(t, type) and issubclass(t, _CompoundBase):
            out = []
            for m in t.members():
                n = t.slice_of(m).stop - t.slice_of(m).start
                out += [m] if n == 1 else [f"{m}[{i}]" for i in range(n)]
            return out
        return [f"[{i}]" for i in range(codec.dof)]

    def _codec(self, vid: int) -> Codec:
        if not isinstance(vid, (int, np.integer)) or not 0 <= vid < len(self._codecs):
            raise IndexError(f"unknown variable id {vid!r} (the problem has {len(self._codecs)})")
        return self._codecs[int(vid)]

    def value(self, vid: int) -> Any:
        """Current value of variable ``vid`` (a copy)."""
        return self._codec(vid).from_ambient(self._core.value(int(vid)))

    __getitem__ = value

    def set_value(self, vid: int, value: Any) -> None:
        codec = self._codec(vid)
        if codec_of(value) is not codec:
            raise TypeError(f"variable {vid} holds a {codec.name}, got {type(value).__name__}")
        self._core.set_value(int(vid), codec.to_ambient(value))

    @property
    def X(self) -> List[Any]:
        """Current values of all variables, in id order."""
        return [self.value(i) for i in range(len(self._codecs))]

    @property
    def num_variables(self) -> int:
        return len(self._codecs)

    @property
    def num_measurements(self) -> int:
        return self._core.num_measurements

    def fix(self, vid: int) -> None:
        """Holds variable ``vid`` constant during solves."""
        self._codec(vid)
        self._core.set_fixed(int(vid), True)

    def unfix(self, vid: int) -> None:
        self._codec(vid)
        self._core.set_fixed(int(vid), False)

    def is_fixed(self, vid: int) -> bool:
        self._codec(vid)
        return self._core.is_fixed(int(vid))

    # ---- measurements ----------------------------------------------------------------
    def _check_ids(self, ids: Sequence[int], what: str) -> List[int]:
        out = []
        for k, v in enumerate(ids):
            if not isinstance(v, (int, np.integer)) or not 0 <= v < len(self._codecs):
                raise IndexError(f"{what}: unknown variable id {v!r} (argument {k})")
            out.append(int(v))
        if len(set(out)) != len(out):
            raise ValueError(f"{what}: a variable is listed twice in {out}")
        return out

    def _group(self, f, name, vectorized, z_codec, m, slots, shared=()) -> _Group:
        key = (f, vectorized, None if z_codec is None else z_codec.name, m,
               tuple(c.name for c in slots), shared)
        g = self._groups.get(key)
        if g is None:
            g = _Group(self, f, name, vectorized, z_codec, m, slots)
            self._groups[key] = g
        return g

    def add_measurement(
        self,
        z: Any,
        f: Callable,
        ids: Sequence[int],
        constants: Sequence[Any] = (),
        sigma: Any = 1.0,
        loss: LossSpec = None,
        name: Optional[str] = None,
    ) -> int:
        """Adds one measurement with residual L⁻¹ (f(Y) ⊟ z).

        Parameters
        ----------
        z : array_like or manifold value
            The measured value; ``f`` must return the same kind.
        f : callable
            ``f(*values, *constants)``, ``values`` being the current values of the
            variables ``ids`` in order.
        ids : sequence of int
            The variables f depends on (this is the sparsity of the problem).
        constants : sequence
            Passed to f unchanged after the values.
        sigma : float, array_like
            Noise: a scalar σ, a vector of σᵢ, or the full covariance Σ.
        loss : str or (str, float) or Loss, optional
            Robust loss, e.g. ``("huber", 2.0)`` (width in standard deviations).
        name : str, optional
            Name of the measurement; measurements are grouped by ``f.__name__``.

        Returns
        -------
        int
            The measurement id.
        """
        fname = getattr(f, "__name__", type(f).__name__)
        what = f"measurement '{name}'" if name else f"measurement #{self.num_measurements} ({fname})"
        if not callable(f):
            raise TypeError(f"{what}: f must be callable, got {type(f).__name__}")
        ids = self._check_ids(ids, what)
        constants = tuple(constants)
        z_codec, z_amb = self._z_parts(z, what)
        m = z_codec.dof if z_codec is not None else z_amb.size
        values = [self.value(v) for v in ids]
        try:
            y = f(*values, *constants)
        except Exception as e:
            _note(e, f"raised by the measurement function of {what} when it was added")
            raise
        if z_codec is None:
            y_arr = np.asarray(y, dtype=float) if not isinstance(y, (str, bytes)) else None
            if y_arr is None or y_arr.size != m:
                raise ValueError(
                    f"{what}: f returned {y!r} ({np.shape(y)}), expected a vector of {m} numbers like z"
                )
        elif codec_of_or_none(y) is not z_codec:
            raise TypeError(f"{what}: f returned a {type(y).__name__}, expected a {z_codec.name} like z")
        W = _sqrt_info(sigma, m, what)
        group = self._group(f, fname, False, z_codec, m, [self._codecs[v] for v in ids])
        mid = group.append([ids], [z_amb], [W], [constants], _make_loss(loss, what), [name or ""])[0]
        self._meas_group[mid] = fname
        return mid

    def add_measurements(
        self,
        Z: Any,
        f: Callable,
        ids: Any,
        constants: Sequence[Any] = (),
        sigma: Any = 1.0,
        loss: LossSpec = None,
        name: Optional[str] = None,
    ) -> np.ndarray:
        """Adds N measurements evaluated together by a vectorised function.

        Parameters
        ----------
        Z : array (N, m) or sequence of N manifold values
            The measured values.
        f : callable
            ``f(*batches, *constants)``: one batch per variable slot (see
            :mod:`boxplus.batch`; row i is measurement i), returns an (N, m) array
            (or a batch of manifold values when Z holds manifold values).
        ids : int array (N, K)
            Row i lists the K variables of measurement i (same kinds in every row).
        constants : sequence of arrays with first dimension N
            Per-measurement constants, passed to f after the batches.
        sigma : float, array_like
            σ, σᵢ (m,), a shared Σ (m, m), or one Σ per measurement (N, m, m).

        Returns
        -------
        numpy.ndarray
            The N measurement ids.
        """
        fname = getattr(f, "__name__", type(f).__name__)
        what = f"measurements '{name}'" if name else f"measurements of {fname}"
        ids = np.asarray(ids)
        if ids.ndim == 1:
            ids = ids[:, None]
        if ids.ndim != 2 or ids.shape[0] == 0:
            raise ValueError(f"{what}: ids must be an (N, K) integer array with N > 0")
        n, K = ids.shape
        rows = [self._check_ids(r, f"{what} (row {i})") for i, r in enumerate(ids.tolist())]
        slots = [self._codecs[v] for v in rows[0]]
        for i, r in enumerate(rows):
            if [self._codecs[v] for v in r] != slots:
                raise TypeError(f"{what}: row {i} refers to variables of other types than row 0")
        # Arrays (and lists) are per-measurement rows; anything else (a manifold
        # value, a scalar) is one constant shared by every row.
        constants = tuple(np.asarray(c) if isinstance(c, (np.ndarray, list)) else c for c in constants)
        shared = tuple(c for c in constants if not isinstance(c, np.ndarray))
        for j, c in enumerate(constants):
            if isinstance(c, np.ndarray) and (c.ndim == 0 or c.shape[0] != n):
                raise ValueError(
                    f"{what}: constant {j} must have first dimension N = {n}, got shape {c.shape}"
                )
        if isinstance(Z, np.ndarray) or (len(Z) and not _is_manifold_value(Z[0])):
            z_codec = None
            Zarr = np.asarray(Z, dtype=float)
            if Zarr.ndim == 1:
                Zarr = Zarr[:, None]
            if Zarr.shape[0] != n:
                raise ValueError(f"{what}: Z has {Zarr.shape[0]} rows, ids {n}")
            m = Zarr.shape[1]
        else:
            z_codec = codec_of(Z[0])
            if len(Z) != n or any(codec_of_or_none(z) is not z_codec for z in Z):
                raise TypeError(f"{what}: Z must hold {n} values of one type")
            Zarr = np.stack([z_codec.to_ambient(z) for z in Z])
            m = z_codec.dof
        s = np.asarray(sigma, dtype=float)
        if s.ndim == 3:
            if s.shape != (n, m, m):
                raise ValueError(f"{what}: per-measurement Σ must have shape ({n}, {m}, {m})")
            W = np.stack([_sqrt_info(s[i], m, f"{what} (row {i})") for i in range(n)])
        else:
            W = np.broadcast_to(_sqrt_info(s, m, what), (n, m, m))
        if not np.all(np.isfinite(Zarr)):
            raise ValueError(f"{what}: Z has non-finite entries")
        group = self._group(f, fname, True, z_codec, m, slots, tuple(id(c) for c in shared))
        group.keepalive.extend(shared)
        # Check the function on the new rows before they join the group.
        Xs = [self._core.values([r[k] for r in rows]) for k in range(K)]
        views = [batch.view(c, X) for c, X in zip(slots, Xs)]
        try:
            Y = f(*views, *constants)
        except Exception as e:
            _note(e, f"raised by the vectorised function of {what} when they were added")
            raise
        E = _batch_errors(fname, z_codec, m, Y, Zarr, n)
        if not np.all(np.isfinite(E)):
            i = int(np.argmax(~np.all(np.isfinite(E), axis=1)))
            raise EvaluationError(f"{what}: f gives a non-finite prediction for row {i} at the initial values")
        names = [f"{name}[{i}]" if name else "" for i in range(n)]
        mids = group.append(rows, list(Zarr), list(W), constants, _make_loss(loss, what), names)
        for mid in mids:
            self._meas_group[mid] = fname
        return np.asarray(mids)

    def _z_parts(self, z: Any, what: str) -> Tuple[Optional[Codec], np.ndarray]:
        if _is_manifold_value(z):
            c = codec_of(z)
            return c, np.asarray(c.to_ambient(z), dtype=float)
        try:
            arr = np.atleast_1d(np.asarray(z, dtype=float)).reshape(-1)
        except (TypeError, ValueError):
            raise TypeError(f"{what}: z must be a vector or a manifold value, got {type(z).__name__}") from None
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"{what}: z has non-finite entries")
        return None, arr

    def add_prior(
        self, vid: int, z: Any, sigma: Any = 1.0, loss: LossSpec = None, name: Optional[str] = None
    ) -> int:
        """Adds the C++ prior r = L⁻¹ (x ⊟ z) on a built-in kind (Rn, SO2, SO3, SE2, SE3, S2)."""
        codec = self._codec(vid)
        what = f"measurement '{name}'" if name else f"prior on variable {vid}"
        if codec_of_or_none(z) is not codec:
            raise TypeError(f"{what}: z must be a {codec.name}, got {type(z).__name__}")
        W = _sqrt_info(sigma, codec.dof, what)
        noise = _core.NoiseModel.sqrt_information(W, what)
        mid = self._core.add_prior(int(vid), codec.to_ambient(z), noise, name or "",
                                   _make_loss(loss, what))
        self._meas_group[mid] = "prior"
        return mid

    def add_projection(
        self,
        z: Any,
        intrinsics: int,
        x2world: int,
        x2cam: int,
        p_world: Any,
        sigma: Any = 1.0,
        model: str = "simple_radial",
        loss: LossSpec = None,
        name: Optional[str] = None,
    ) -> int:
        """Adds the C++ pinhole factor: z ≈ π(k, x2cam ∘ x2world⁻¹ ∘ p_world).

        ``intrinsics`` must hold ``camera_model_size(model)`` ambient numbers in the
        model's order (simple_radial: [f, cx, cy, k1]; pinhole: [fx, fy, cx, cy];
        radial2: + [k1, k2]; opencv5: + [k1, k2, p1, p2, k3]); ``x2world`` and
        ``x2cam`` are SE3 variables (fix ``x2cam`` to the identity for one camera).
        """
        what = f"measurement '{name}'" if name else f"projection #{self.num_measurements}"
        ids = self._check_ids([intrinsics, x2world, x2cam], what)
        W = _sqrt_info(sigma, 2, what)
        zz = np.asarray(z, dtype=float).reshape(2)
        pw = np.asarray(p_world, dtype=float).reshape(3)
        mid = self._core.add_pinhole_point(model, *ids, zz, W, pw, name or "", _make_loss(loss, what))
        self._meas_group[mid] = f"projection[{model}]"
        return mid

    # ---- built-in C++ factors (see cpp/include/boxplus/factors/) ----------------------
    def _cpp(self, mid: int, group: str, W: Optional[np.ndarray]) -> int:
        self._meas_group[mid] = group
        if W is not None:
            self._cpp_W[mid] = W
        return mid

    def add_board(
        self,
        z: Any,
        intrinsics: int,
        x2world: int,
        x2cam: int,
        p_world: Any,
        sigma: Any = 1.0,
        model: str = "opencv5",
        loss: LossSpec = None,
        name: Optional[str] = None,
        group: Optional[str] = None,
    ) -> int:
        """All visible points of a board in one C++ factor (see factors/board.h).

        r_j = L⁻¹ (π(k, x2cam ∘ x2world⁻¹ ∘ p_world_j) − z_j); ``z`` (N, 2) pixels,
        ``p_world`` (N, 3) the same points in the board ("world") frame, ``sigma``
        a 2×2 Σ (or σ) shared by the points. ``group`` names the measurement
        group in RMS reports (default ``board[model]``).
        """
        what = f"measurement '{name}'" if name else f"board #{self.num_measurements}"
        ids = self._check_ids([intrinsics, x2world, x2cam], what)
        zz = np.asarray(z, dtype=float)
        pw = np.asarray(p_world, dtype=float)
        if zz.ndim != 2 or zz.shape[1] != 2 or pw.shape != (len(zz), 3) or len(zz) == 0:
            raise ValueError(f"{what}: z must be (N, 2) and p_world (N, 3) with N >= 1, got "
                             f"{zz.shape} and {pw.shape}")
        if not (np.all(np.isfinite(zz)) and np.all(np.isfinite(pw))):
            raise ValueError(f"{what}: non-finite points (an undetected board?)")
        size = _core.camera_model_size(model)
        if self._codec(intrinsics).ambient_size != size:
            raise ValueError(f"{what}: camera model '{model}' needs {size} intrinsics, variable "
                             f"'{self.variable_name(intrinsics)}' has {self._codec(intrinsics).ambient_size}")
        W = _sqrt_info(sigma, 2, what)
        mid = self._core.add_pinhole_board(model, *ids, np.ascontiguousarray(zz), W,
                                           np.ascontiguousarray(pw), name or "", _make_loss(loss, what))
        return self._cpp(mid, group or f"board[{model}]", W)

    def add_marker(
        self, z: Any, intrinsics: int, x2base: int, p_in_hand: int, x2cam: int, hand2base: Any,
        sigma: Any = 1.0, model: str = "opencv5", loss: LossSpec = None,
        name: Optional[str] = None, group: Optional[str] = None,
    ) -> int:
        """A marker on a hand, ``hand2base`` (SE3) from forward kinematics (factors/marker.h)."""
        from boxplus.manifolds import SE3

        what = f"measurement '{name}'" if name else f"marker #{self.num_measurements}"
        ids = self._check_ids([intrinsics, x2base, p_in_hand, x2cam], what)
        if not isinstance(hand2base, SE3):
            raise TypeError(f"{what}: hand2base must be an SE3")
        W = _sqrt_info(sigma, 2, what)
        mid = self._core.add_marker(model, *ids, np.asarray(z, float).reshape(2), W,
                                    hand2base.ambient, name or "", _make_loss(loss, what))
        return self._cpp(mid, group or "marker", W)

    def add_dh_marker(
        self, z: Any, intrinsics: int, x2base: int, p_in_hand: int, x2cam: int, dh: int,
        joints: Any, base2chain: Any = None, flange2hand: Any = None, sigma: Any = 1.0,
        model: str = "opencv5", loss: LossSpec = None, name: Optional[str] = None,
        group: Optional[str] = None,
    ) -> int:
        """A marker through a DH chain with unknown link parameters ``dh`` (an Rn(4n)
        variable: per joint [θ offset, d, a, α]) and joint readings ``joints`` (rad)."""
        from boxplus.manifolds import SE3

        what = f"measurement '{name}'" if name else f"DH marker #{self.num_measurements}"
        ids = self._check_ids([intrinsics, x2base, p_in_hand, x2cam, dh], what)
        q = np.asarray(joints, float).reshape(-1)
        if self._codec(dh).ambient_size != 4 * len(q):
            raise ValueError(f"{what}: {len(q)} joint readings need a dh variable of {4 * len(q)} "
                             f"numbers, '{self.variable_name(dh)}' has {self._codec(dh).ambient_size}")
        pre = (base2chain or SE3()).ambient
        post = (flange2hand or SE3()).ambient
        W = _sqrt_info(sigma, 2, what)
        mid = self._core.add_dh_marker(model, *ids, np.asarray(z, float).reshape(2), W, q, pre, post,
                                       name or "", _make_loss(loss, what))
        return self._cpp(mid, group or "marker", W)

    def add_gravity(
        self, z: Any, x2world: int, x2imu: int, accel: Optional[int] = None,
        g_in_world: Any = (0.0, 0.0, -9.81), sigma: Any = 1.0, loss: LossSpec = None,
        name: Optional[str] = None, group: str = "gravity",
    ) -> int:
        """Gravity read by an accelerometer (factors/gravity.h): r = L⁻¹ (s R_imu_x
        R_x2worldᵀ g + b − z). ``accel``: None (rotation only), an Rn(1) [s] or an
        Rn(4) [s, bx, by, bz] variable."""
        what = f"measurement '{name}'" if name else f"gravity #{self.num_measurements}"
        ids = [x2world, x2imu] + ([] if accel is None else [accel])
        ids = self._check_ids(ids, what)
        if accel is None:
            model = "rotation"
        else:
            n = self._codec(accel).ambient_size
            model = {1: "scale", 4: "scale_bias"}.get(n)
            if model is None:
                raise ValueError(f"{what}: accel must be Rn(1) [s] or Rn(4) [s, b], got {n} numbers")
        W = _sqrt_info(sigma, 3, what)
        mid = self._core.add_gravity(model, ids[0], ids[1], ids[2] if accel is not None else -1,
                                     np.asarray(z, float).reshape(3), W,
                                     np.asarray(g_in_world, float).reshape(3), name or "",
                                     _make_loss(loss, what))
        return self._cpp(mid, group, W)

    def add_relative_pose(
        self, z_b2a: Any, a2world: int, b2world: int, sigma: Any = 1.0, loss: LossSpec = None,
        name: Optional[str] = None, group: str = "relative_pose",
    ) -> int:
        """r = L⁻¹ ((a2world⁻¹ ∘ b2world) ⊟ z_b2a), tangent [δp, δθ] (factors/relative_pose.h)."""
        from boxplus.manifolds import SE3

        what = f"measurement '{name}'" if name else f"relative pose #{self.num_measurements}"
        ids = self._check_ids([a2world, b2world], what)
        if not isinstance(z_b2a, SE3):
            raise TypeError(f"{what}: z_b2a must be an SE3")
        W = _sqrt_info(sigma, 6, what)
        mid = self._core.add_relative_pose(*ids, z_b2a.ambient, _core.NoiseModel.sqrt_information(W, what),
                                           name or "", _make_loss(loss, what))
        return self._cpp(mid, group, W)

    def add_point(
        self, z: Any, x2world: int, x2cam: int, p_world: Any, sigma: Any = 1.0,
        loss: LossSpec = None, name: Optional[str] = None, group: str = "point",
    ) -> int:
        """A 3-D point measured in a sensor (factors/point.h); ``p_world`` a known
        point (3,) or the id of an Rn(3) variable."""
        what = f"measurement '{name}'" if name else f"point #{self.num_measurements}"
        if isinstance(p_world, (int, np.integer)):
            ids = self._check_ids([x2world, x2cam, p_world], what)
            pw, pid = np.zeros(3), ids[2]
        else:
            ids = self._check_ids([x2world, x2cam], what)
            pw, pid = np.asarray(p_world, float).reshape(3), -1
        W = _sqrt_info(sigma, 3, what)
        mid = self._core.add_point(ids[0], ids[1], pid, np.asarray(z, float).reshape(3),
                                   _core.NoiseModel.sqrt_information(W, what), pw,
                                   name or "", _make_loss(loss, what))
        return self._cpp(mid, group, W)

    def add_disparity(
        self, d: float, x2world: int, x2cam: int, disparity_params: int, p_world: Any,
        sigma: float = 1.0, loss: LossSpec = None, name: Optional[str] = None,
        group: str = "disparity",
    ) -> int:
        """Kinect-style disparity d = a / Z + b of a board point (factors/disparity.h);
        ``disparity_params`` an Rn(2) variable [a, b]."""
        what = f"measurement '{name}'" if name else f"disparity #{self.num_measurements}"
        ids = self._check_ids([x2world, x2cam, disparity_params], what)
        W = _sqrt_info(sigma, 1, what)
        mid = self._core.add_disparity(*ids, float(d), 1.0 / W[0, 0],
                                       np.asarray(p_world, float).reshape(3), name or "",
                                       _make_loss(loss, what))
        return self._cpp(mid, group, W)

    def jacobian(self) -> Dict[str, Any]:
        """Whitened residuals and their dense Jacobian in the tangent spaces of the
        free variables (dict: residuals, jacobian, variables, column_offsets,
        row_offsets); for diagnostics such as :func:`boxplus.calib.report`."""
        return self._core.evaluate_jacobian()

    def measurement_group(self, mid: int) -> str:
        return self._meas_group[int(mid)]

    # ---- solving ---------------------------------------------------------------------
    def solve(
        self,
        method: str = "lm",
        max_iterations: int = 100,
        function_tolerance: float = 1e-10,
        gradient_tolerance: float = 1e-12,
        parameter_tolerance: float = 1e-10,
        num_threads: int = 1,
        verbose: bool = False,
        callback: Optional[Callable[[dict], Any]] = None,
    ) -> SolveResult:
        """Minimises ½ Σ ρ(‖rᵢ‖²) and writes the estimates back.

        Parameters
        ----------
        method : {'lm', 'gn', 'gn_ls', 'dogleg'}
            Levenberg–Marquardt (default), Gauss–Newton (trust region: a step
            that raises the cost is rejected), Gauss–Newton with a backtracking
            line search along x ⊞ αδ, or Powell's dogleg.
        verbose : bool
            Print one line per iteration (cost, change, gradient, step, time).
        callback : callable, optional
            ``callback(info: dict)`` after each iteration; return False to stop.

        Returns
        -------
        SolveResult
            Summary and estimates. Ctrl-C stops the solve and keeps the best
            estimate so far (termination 'interrupted').
        """
        cb = callback
        if verbose:
            print(f"{'iter':>4}  {'cost':>14}  {'change':>10}  {'|gradient|':>10}  {'|step|':>10}  {'time':>8}")

            def cb(info: dict) -> Any:
                print(
                    f"{info['iteration']:4d}  {info['cost']:14.8e}  {-info['cost_change']:+10.3e}  "
                    f"{info['gradient_max_norm']:10.3e}  {info['step_norm']:10.3e}  "
                    f"{info['cumulative_time_s']:7.3f}s",
                    flush=True,
                )
                return callback(info) if callback is not None else None

        s = self._core.solve(
            method=method,
            max_iterations=max_iterations,
            function_tolerance=function_tolerance,
            gradient_tolerance=gradient_tolerance,
            parameter_tolerance=parameter_tolerance,
            num_threads=num_threads,
            verbose=False,
            callback=cb,
        )
        result = SolveResult(
            s.initial_cost, s.final_cost, s.iterations, s.time_s, s.termination, s.message,
            s.usable, s.report, self.X,
        )
        if verbose:
            print(result, file=sys.stdout, flush=True)
        return result

    # ---- after a solve ---------------------------------------------------------------
    def covariance(self, vid: int) -> np.ndarray:
        """Marginal covariance of variable ``vid`` in its tangent space."""
        self._codec(vid)
        return self._core.covariance(int(vid))

    def joint_covariance(self, ids: Sequence[int]) -> np.ndarray:
        ids = self._check_ids(ids, "joint_covariance")
        return self._core.joint_covariance(ids)

    def std(self, vid: int) -> np.ndarray:
        """Standard deviations of variable ``vid`` along its tangent directions."""
        return np.sqrt(np.diag(self.covariance(vid)))

    def residual(self, mid: int) -> np.ndarray:
        """Whitened residual of measurement ``mid`` at the current values."""
        return self._core.residual(int(mid))

    def errors(self) -> Dict[str, np.ndarray]:
        """Unwhitened errors f(Y) ⊟ z of the Python measurements, per function name."""
        out: Dict[str, List[np.ndarray]] = {}
        for g in self._groups.values():
            out.setdefault(g.name, []).append(g.errors(g.current_values()))
        for mid, e in self._cpp_errors().items():
            out.setdefault(self._meas_group[mid], []).append(e)
        return {k: np.concatenate(v) for k, v in out.items()}

    def _cpp_errors(self, mids: Optional[Sequence[int]] = None) -> Dict[int, np.ndarray]:
        """Unwhitened errors of the built-in factors with a known W: rows of W's size."""
        out = {}
        for mid in (self._cpp_W if mids is None else mids):
            W = self._cpp_W[mid]
            r = self._core.residual(mid).reshape(-1, W.shape[0])
            out[mid] = np.linalg.solve(W, r.T).T
        return out

    def measurement_errors(self, mid: int) -> np.ndarray:
        """Unwhitened errors of one built-in factor (rows: one per point/vector)."""
        return self._cpp_errors([int(mid)])[int(mid)]

    def residuals(self) -> Dict[str, np.ndarray]:
        """Whitened residuals of every measurement, grouped by function name (C++
        measurements: by their kind, e.g. 'prior')."""
        out: Dict[str, List[np.ndarray]] = {}
        for g in self._groups.values():
            _, _, W, _ = g._pack()
            out.setdefault(g.name, []).append(np.einsum("nij,nj->ni", W, g.errors(g.current_values())))
        python_mids = {mid for g in self._groups.values() for mid in g.meas_ids}
        for mid, gname in self._meas_group.items():
            if mid not in python_mids:
                r = self._core.residual(mid)
                m = self._cpp_W[mid].shape[0] if mid in self._cpp_W else r.size
                out.setdefault(gname, []).append(r.reshape(-1, m))
        return {k: np.concatenate(v) for k, v in out.items()}

    def rms(self, whitened: bool = False) -> Dict[str, float]:
        """RMS error per measurement group: sqrt(mean over measurements of ‖e‖²).

        Unwhitened (in the measurement's units, e.g. pixels) for Python
        measurements unless ``whitened``; C++ measurements are always whitened.
        """
        res = self.residuals() if whitened else {**self.residuals(), **self.errors()}
        return {k: float(np.sqrt(np.mean(np.sum(v**2, axis=1)))) for k, v in res.items()}

    def cost(self) -> float:
        """½ Σ ρ(‖rᵢ‖²) at the current values."""
        return self._core.cost()


def _is_manifold_value(v: Any) -> bool:
    return codec_of_or_none(v) is not None


def codec_of_or_none(v: Any) -> Optional[Codec]:
    try:
        return codec_of(v)
    except TypeError:
        return None
