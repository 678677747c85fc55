"""OptimizationProblem: least squares on manifolds, written like the maths.

A problem has random variables (manifold values) and measurements
(z, Σ, f, Y): the residual of a measurement is r = W (f(Y) ⊟ z) with
WᵀW = Σ⁻¹ (:mod:`boxplus.noise`), and ``solve()`` minimises ½ Σ ρ(‖r‖²) with
⊞-steps. All book-keeping — stacking, indices, sparsity, whitening,
Jacobians — happens here and in :mod:`boxplus.measurements`.

Measurement functions written in Python are differentiated by central finite
differences through ⊞ in the tangent space of each variable. They come in two
forms:

* ``add_measurement(z, f, ids, constants)``: ``f(*values, *constants)`` for one
  measurement, called once per measurement (simple, slow for thousands);
* ``add_measurements(Z, f, ids, constants)``: ``f(*batches, *constants)`` for a
  whole batch at once (numpy in, numpy out; see :mod:`boxplus.batch`), the fast
  form.

Measurements written in C++ mix freely with both: the generic ones here
(``add_prior``, ``add_relative_pose``, ``add_point``) and those of the domain
packages (``boxplus.calib.add_board`` and the other sensor factors,
``boxplus.joint``), which all enter through :meth:`add_factor`. Every
``add_*`` takes the noise as ``sigma=`` (σ or σᵢ), ``covariance=`` (Σ),
``information=`` (Ω) or ``noise=`` (a NoiseModel); the NoiseModel lives in
C++ with the measurement, Python measurements included, so ``errors()`` and
``rms()`` un-whiten every measurement on one path.

The calls that build a problem are journalled (:mod:`boxplus._journal`), so a
problem pickles, copies and rebuilds itself for parallel work.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from typing import Any, Callable

import numpy as np

from boxplus import _core, _journal, batch, solver
from boxplus._journal import journalled
from boxplus.losses import LossSpec, make_loss
from boxplus.manifolds import SE2, SE3, Codec, Rn, codec_of
from boxplus.measurements import EvaluationError, Group, batch_errors, note, vector_error
from boxplus.noise import NoiseModel, noise_model, noise_models


class UndeterminedWarning(UserWarning):
    """A solve ended where the measurements leave some directions free (a rank test
    of the Jacobian, :meth:`OptimizationProblem.check_determined`): the values along
    them are arbitrary and their covariances are refused."""

__all__ = ["EvaluationError", "OptimizationProblem", "UndeterminedWarning"]


def _codec_or_none(v: Any) -> Codec | None:
    try:
        return codec_of(v)
    except TypeError:
        return None


def _is_id(v: Any) -> bool:
    return isinstance(v, (int, np.integer)) and not isinstance(v, (bool, np.bool_))


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
        self._codecs: list[Codec] = []
        self._groups: dict[tuple[Any, ...], Group] = {}
        self._meas_group: dict[int, str] = {}
        self._group_dims: dict[str, int] = {}  # group -> rows' width (the noise's dimension)
        self._names: dict[str, int] = {}  # variable name -> id
        self._labels: dict[int, list[str]] = {}
        self._touched: set[int] = set()  # variables some measurement depends on
        self._touched_upto = 0  # measurements already counted in _touched

    def __repr__(self) -> str:
        def counts(names: Sequence[str]) -> str:
            tally: dict[str, int] = {}
            for k in names:
                tally[k] = tally.get(k, 0) + 1
            return ", ".join(f"{k} x{n}" for k, n in tally.items())

        fixed = sum(self._core.is_fixed(i) for i in range(len(self._codecs)))
        var = counts([c.name for c in self._codecs]) + (f"; {fixed} fixed" if fixed else "")
        meas = counts([self._meas_group[m] for m in sorted(self._meas_group)])
        return (f"<OptimizationProblem: {len(self._codecs)} variables"
                + (f" ({var})" if var else "") + f", {self.num_measurements} measurements"
                + (f" ({meas})" if meas else "") + ">")

    # ---- variables -------------------------------------------------------------------
    @journalled
    def add_random_var(
        self, value: Any, fixed: bool = False, name: str | None = None,
        labels: Sequence[str] | None = None,
    ) -> int:
        """Adds a variable with initial value ``value``; returns its id.

        ``labels`` names the tangent directions (e.g. ``["fx", "fy", ...]``) in
        reports; by default they come from the value's type (``Codec.labels``).
        """
        what = f"variable '{name}'" if name else f"variable #{len(self._codecs)}"
        if name is not None and not isinstance(name, str):
            raise TypeError(f"{what}: name must be a str, got {type(name).__name__}")
        if name and name in self._names:
            raise ValueError(f"{what}: a variable of this name exists already (id "
                             f"{self._names[name]}); names identify variables in reports")
        codec = codec_of(value)
        init = np.asarray(codec.to_ambient(value), dtype=float)
        if not np.all(np.isfinite(init)):
            raise ValueError(f"{what}: the initial value has non-finite entries")
        if labels is not None and len(labels) != codec.dof:
            raise ValueError(f"{what}: {len(labels)} labels for {codec.dof} directions")
        vid = self._core.add_variable(codec.manifold, init, name or "")
        self._codecs.append(codec)
        if name:
            self._names[name] = vid
        if labels is not None:
            self._labels[vid] = list(labels)
        # For messages that name an undetermined direction ("'R': θ.z").
        self._core.set_direction_labels(vid, self._labels.get(vid) or codec.labels())
        if fixed:
            self._core.set_fixed(vid, True)
        return vid

    def codec(self, vid: int) -> Codec:
        """How variable ``vid``'s values map to the solver (raises IndexError)."""
        if not _is_id(vid) or not 0 <= vid < len(self._codecs):
            raise IndexError(f"unknown variable id {vid!r} (the problem has {len(self._codecs)})")
        return self._codecs[int(vid)]

    def variable_name(self, vid: int) -> str:
        self.codec(vid)
        return self._core.variable_name(int(vid))

    def labels(self, vid: int) -> list[str]:
        """Names of the tangent directions of variable ``vid`` (for reports)."""
        codec = self.codec(vid)
        return self._labels.get(int(vid)) or codec.labels()

    def value(self, vid: int) -> Any:
        """Current value of variable ``vid`` (a copy)."""
        return self.codec(vid).from_ambient(self._core.value(int(vid)))

    __getitem__ = value

    @journalled
    def set_value(self, vid: int, value: Any) -> None:
        codec = self.codec(vid)
        if _codec_or_none(value) is not codec:
            raise TypeError(f"variable {vid} holds a {codec.name}, got {type(value).__name__}")
        self._core.set_value(int(vid), codec.to_ambient(value))

    @property
    def X(self) -> list[Any]:
        """Current values of all variables, in id order."""
        return [self.value(i) for i in range(len(self._codecs))]

    @property
    def num_variables(self) -> int:
        return len(self._codecs)

    @property
    def num_measurements(self) -> int:
        return self._core.num_measurements

    @journalled
    def fix(self, vid: int) -> None:
        """Holds variable ``vid`` constant during solves."""
        self.codec(vid)
        self._core.set_fixed(int(vid), True)

    @journalled
    def unfix(self, vid: int) -> None:
        self.codec(vid)
        self._core.set_fixed(int(vid), False)

    def is_fixed(self, vid: int) -> bool:
        self.codec(vid)
        return self._core.is_fixed(int(vid))

    # ---- what the measurement kinds share (here and in the domain packages) -------------
    def check_ids(self, ids: Any, what: str) -> list[int]:
        """The variable ids of a measurement as ints: one id or a sequence of distinct ids."""
        if _is_id(ids):
            ids = [ids]
        if isinstance(ids, (str, bytes, dict)) or not hasattr(ids, "__iter__"):
            raise TypeError(f"{what}: ids must be a variable id or a sequence of them, "
                            f"got {type(ids).__name__}")
        out = []
        for k, v in enumerate(ids):
            if not _is_id(v) or not 0 <= v < len(self._codecs):
                raise IndexError(f"{what}: unknown variable id {v!r} (argument {k})")
            out.append(int(v))
        if not out:
            raise ValueError(f"{what}: ids is empty (a measurement depends on at least one variable)")
        if len(set(out)) != len(out):
            raise ValueError(f"{what}: a variable is listed twice in {out}")
        return out

    def _register(self, mid: int, group: str) -> int:
        """Records the group of measurement ``mid`` for errors()/rms(); returns mid.

        A group's error rows have one width (its noise's dimension); a
        measurement of another width joins the group ``"<group>[<width>]"``.
        """
        dim = self._core.noise(int(mid)).dim
        width = self._group_dims.setdefault(group, dim)
        if width != dim:
            group = f"{group}[{dim}]"
            self._group_dims.setdefault(group, dim)
        self._meas_group[int(mid)] = group
        return int(mid)

    @journalled
    def add_factor(self, factor: _core.Factor, loss: LossSpec = None, name: str | None = None,
                   group: str = "factor") -> int:
        """Adds a C++ factor (one of the ``*_factor`` functions of ``boxplus._core``);
        returns its measurement id.

        This is the one way C++ measurements enter a problem: ``add_prior`` and the
        factor functions of :mod:`boxplus.calib` and :mod:`boxplus.joint` validate their
        input, build the factor and call this. ``group`` names the RMS group of
        :meth:`errors`. A problem that a bare ``add_factor`` call changed cannot be
        pickled (a factor holds a cost function, not its inputs): add factors inside a
        function decorated with :func:`boxplus._journal.journalled`, as the domain
        packages do.
        """
        what = f"measurement '{name}'" if name else f"{group} #{self.num_measurements}"
        if not isinstance(factor, _core.Factor):
            raise TypeError(f"{what}: add_factor takes a boxplus._core.Factor, got "
                            f"{type(factor).__name__}")
        self.check_ids(factor.variables, what)
        mid = self._core.add_factor(factor, make_loss(loss, what), name or "")
        return self._register(mid, group)

    def _group(self, f, name, vectorized, z_codec, m, slots, shared=()) -> Group:
        key = (f, vectorized, None if z_codec is None else z_codec.name, m,
               tuple(c.name for c in slots), shared)
        g = self._groups.get(key)
        if g is None:
            g = Group(self, f, name, vectorized, z_codec, m, slots)
            self._groups[key] = g
        return g

    # ---- measurements ----------------------------------------------------------------
    @journalled(by_reference=("z", "constants"))
    def add_measurement(
        self,
        z: Any,
        f: Callable,
        ids: Any,
        constants: Sequence[Any] = (),
        sigma: Any = None,
        covariance: Any = None,
        information: Any = None,
        noise: NoiseModel | None = None,
        loss: LossSpec = None,
        name: str | None = None,
    ) -> int:
        """Adds one measurement with residual r = W (f(Y) ⊟ z).

        Parameters
        ----------
        z : array_like or manifold value
            The measured value; ``f`` must return the same kind.
        f : callable
            ``f(*values, *constants)``, ``values`` being the current values of the
            variables ``ids`` in order.
        ids : int or sequence of int
            The variables f depends on (this is the sparsity of the problem).
        constants : sequence
            Passed to f unchanged after the values.
        sigma, covariance, information, noise
            The noise (:func:`boxplus.noise.noise_model`): σ or σᵢ, Σ, Ω = Σ⁻¹,
            or a NoiseModel; none of them: σ = 1.
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
        ids = self.check_ids(ids, what)
        constants = _constants(constants, what)
        z_codec, z_amb = self._z_parts(z, what)
        m = z_codec.dof if z_codec is not None else z_amb.size
        nm = noise_model(m, sigma, covariance, information, noise, what)
        lf = make_loss(loss, what)
        values = [self.value(v) for v in ids]
        try:
            y = f(*values, *constants)
        except Exception as e:
            note(e, f"raised by the measurement function of {what} when it was added")
            raise
        if z_codec is None:
            vector_error(y, z_amb, what)
        elif _codec_or_none(y) is not z_codec:
            raise TypeError(f"{what}: f returned a {type(y).__name__}, expected a {z_codec.name} like z")
        group = self._group(f, fname, False, z_codec, m, [self._codecs[v] for v in ids])
        mid = group.append([ids], [z_amb], [nm], [constants], lf, [name or ""])[0]
        return self._register(mid, fname)

    @journalled(by_reference=("Z", "constants"))
    def add_measurements(
        self,
        Z: Any,
        f: Callable,
        ids: Any,
        constants: Sequence[Any] = (),
        sigma: Any = None,
        covariance: Any = None,
        information: Any = None,
        noise: NoiseModel | None = None,
        loss: LossSpec = None,
        name: str | None = None,
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
        sigma, covariance, information, noise
            As for add_measurement, shared by the rows; ``covariance`` or
            ``information`` may also be a stack (N, m, m), one per measurement.

        Returns
        -------
        numpy.ndarray
            The N measurement ids.
        """
        fname = getattr(f, "__name__", type(f).__name__)
        what = f"measurements '{name}'" if name else f"measurements of {fname}"
        if not callable(f):
            raise TypeError(f"{what}: f must be callable, got {type(f).__name__}")
        try:
            ids = np.asarray(ids)
        except ValueError:
            raise ValueError(f"{what}: ids must be an (N, K) integer array") from None
        if ids.ndim == 1:
            ids = ids[:, None]
        if ids.ndim != 2 or ids.shape[0] == 0 or ids.shape[1] == 0:
            raise ValueError(f"{what}: ids must be an (N, K) integer array with N, K > 0, got "
                             f"shape {ids.shape}")
        n, K = ids.shape
        rows = [self.check_ids(r, f"{what} (row {i})") for i, r in enumerate(ids.tolist())]
        slots = [self._codecs[v] for v in rows[0]]
        for i, r in enumerate(rows):
            if [self._codecs[v] for v in r] != slots:
                raise TypeError(f"{what}: row {i} refers to variables of other types than row 0")
        # Arrays (and lists) are per-measurement rows; anything else (a manifold
        # value, a scalar) is one constant shared by every row.
        constants = tuple(np.asarray(c) if isinstance(c, (np.ndarray, list)) else c
                          for c in _constants(constants, what))
        shared = tuple(c for c in constants if not isinstance(c, np.ndarray))
        for j, c in enumerate(constants):
            if isinstance(c, np.ndarray) and (c.ndim == 0 or c.shape[0] != n):
                raise ValueError(
                    f"{what}: constant {j} must have first dimension N = {n}, got shape {c.shape}"
                )
        z_codec, Zarr, m = self._Z_parts(Z, n, what)
        noises = noise_models(n, m, sigma, covariance, information, noise, what)
        lf = make_loss(loss, what)
        group = self._group(f, fname, True, z_codec, m, slots, tuple(id(c) for c in shared))
        # Check the function on the new rows before they join the group.
        Xs = [self._core.values([r[k] for r in rows]) for k in range(K)]
        views = [batch.view(c, X) for c, X in zip(slots, Xs)]
        try:
            Y = f(*views, *constants)
        except Exception as e:
            note(e, f"raised by the vectorised function of {what} when they were added")
            raise
        E = batch_errors(fname, z_codec, m, Y, Zarr, n)
        if not np.all(np.isfinite(E)):
            i = int(np.argmax(~np.all(np.isfinite(E), axis=1)))
            raise EvaluationError(f"{what}: f gives a non-finite prediction for row {i} at the initial values")
        group.keepalive.extend(shared)
        names = [f"{name}[{i}]" if name else "" for i in range(n)]
        mids = group.append(rows, list(Zarr), noises, constants, lf, names)
        for mid in mids:
            self._register(mid, fname)
        return np.asarray(mids)

    def _z_parts(self, z: Any, what: str) -> tuple[Codec | None, np.ndarray]:
        c = _codec_or_none(z)
        if c is not None:
            return c, np.asarray(c.to_ambient(z), dtype=float)
        if isinstance(z, (str, bytes, dict)) or np.iscomplexobj(z):
            raise TypeError(f"{what}: z must be a real vector or a manifold value, got {type(z).__name__}")
        try:
            arr = np.atleast_1d(np.asarray(z, dtype=float)).reshape(-1)
        except (TypeError, ValueError):
            raise TypeError(f"{what}: z must be a vector or a manifold value, got {type(z).__name__}") from None
        if arr.size == 0:
            raise ValueError(f"{what}: z is empty")
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"{what}: z has non-finite entries")
        return None, arr

    def _Z_parts(self, Z: Any, n: int, what: str) -> tuple[Codec | None, np.ndarray, int]:
        """(codec of the values or None, Z as ambient rows (n, ·), error size m)."""
        if isinstance(Z, (str, bytes, dict)) or np.iscomplexobj(Z):
            raise TypeError(f"{what}: Z must be an (N, m) array or a sequence of manifold values, "
                            f"got {type(Z).__name__}")
        try:
            first = Z[0] if len(Z) else None
        except TypeError:
            raise TypeError(f"{what}: Z must be an (N, m) array or a sequence of manifold values, "
                            f"got {type(Z).__name__}") from None
        z_codec = None if isinstance(Z, np.ndarray) or first is None else _codec_or_none(first)
        if z_codec is None:
            try:
                Zarr = np.asarray(Z, dtype=float)
            except (TypeError, ValueError):
                raise TypeError(f"{what}: Z must be an (N, m) array of numbers") from None
            if Zarr.ndim == 1:
                Zarr = Zarr[:, None]
            if Zarr.ndim != 2 or Zarr.shape[0] != n or Zarr.shape[1] == 0:
                raise ValueError(f"{what}: Z has shape {Zarr.shape}, expected ({n}, m) like ids")
            m = Zarr.shape[1]
        else:
            if len(Z) != n or any(_codec_or_none(z) is not z_codec for z in Z):
                raise TypeError(f"{what}: Z must hold {n} values of one type")
            Zarr = np.stack([z_codec.to_ambient(z) for z in Z])
            m = z_codec.dof
        if not np.all(np.isfinite(Zarr)):
            raise ValueError(f"{what}: Z has non-finite entries")
        return z_codec, Zarr, m

    # ---- generic C++ factors ---------------------------------------------------------
    @journalled
    def add_prior(
        self, vid: int, z: Any, sigma: Any = None, covariance: Any = None,
        information: Any = None, noise: NoiseModel | None = None, loss: LossSpec = None,
        name: str | None = None, group: str = "prior", coordinates: Sequence[int | str] | None = None,
    ) -> int:
        """Adds the C++ prior r = W (x ⊟ z) on a built-in kind (Rn, SO2, SO3, SE2, SE3, S2;
        a compound's prior is a measurement ``add_measurement(z, lambda x: x, [vid])``);
        ``group`` names its RMS group (:meth:`errors`).

        ``coordinates`` (indices or labels of an Rn variable) puts the prior on those
        coordinates only, r = W (x[coordinates] − z) with z an Rn of their number: the
        other coordinates are left to the data (e.g. a lens's distortion coefficients
        pulled towards 0, its focal lengths not)."""
        codec = self.codec(vid)
        what = f"measurement '{name}'" if name else f"prior on variable {vid}"
        if coordinates is not None:
            index = self._coordinate_indices(vid, coordinates, what)
            zv = np.asarray(z.vec if isinstance(z, Rn) else z, dtype=float).reshape(-1)
            nm = noise_model(len(index), sigma, covariance, information, noise, what)
            f = _core.coordinate_prior_factor(self._core, int(vid), index, zv, nm, what)
            return self.add_factor(f, loss, name, group)
        if _codec_or_none(z) is not codec:
            raise TypeError(f"{what}: z must be a {codec.name}, got {type(z).__name__}")
        nm = noise_model(codec.dof, sigma, covariance, information, noise, what)
        f = _core.prior_factor(self._core, int(vid), codec.to_ambient(z), nm, what)
        return self.add_factor(f, loss, name, group)

    def _coordinate_indices(self, vid: int, coordinates: Sequence[int | str], what: str) -> list[int]:
        """The indices of ``coordinates`` (indices or labels) of Rn variable ``vid``;
        TypeError for another kind, ValueError naming the variable for an unknown one."""
        codec = self.codec(vid)
        name = self.variable_name(vid) or str(vid)
        if not codec.name.startswith("Rn"):
            raise TypeError(f"{what}: variable '{name}' is a {codec.name}; coordinates= needs an "
                            f"Rn variable")
        labels = self.labels(vid)
        index = []
        for c in coordinates:
            if isinstance(c, str):
                if c not in labels:
                    raise ValueError(f"{what}: variable '{name}' has no coordinate '{c}' "
                                     f"(labels: {', '.join(labels)})")
                index.append(labels.index(c))
            else:
                k = int(c)
                if not 0 <= k < len(labels):
                    raise ValueError(f"{what}: variable '{name}' has coordinates "
                                     f"0..{len(labels) - 1}, got {k}")
                index.append(k)
        return index

    @journalled
    def add_relative_pose(
        self, a_from_b: SE2 | SE3, world_from_a: int, world_from_b: int, sigma: Any = None,
        covariance: Any = None, information: Any = None, noise: NoiseModel | None = None,
        loss: LossSpec = None, name: str | None = None, group: str = "relative_pose",
    ) -> int:
        """A measured relative pose of two SE2 or two SE3 variables (odometry, a loop
        closure, a robot's forward kinematics; factors/pose/relative_pose.h).

        r = W ((world_from_a⁻¹ ∘ world_from_b) ⊟ a_from_b) with the compound ⊟ of
        Rᵈ × SO(d): [δp, δθ], 3-dim noise for SE2, 6-dim for SE3, in that order.
        """
        what = f"measurement '{name}'" if name else f"relative pose #{self.num_measurements}"
        ids = self.check_ids([world_from_a, world_from_b], what)
        if not isinstance(a_from_b, (SE2, SE3)):
            raise TypeError(f"{what}: a_from_b must be an SE2 or an SE3, got {type(a_from_b).__name__}")
        kind = type(a_from_b).__name__
        for v in ids:
            if self.codec(v).name != kind:
                raise TypeError(f"{what}: a_from_b is an {kind}, variable "
                                f"'{self.variable_name(v) or v}' is a {self.codec(v).name}")
        nm = noise_model(len(a_from_b), sigma, covariance, information, noise, what)
        f = _core.relative_pose_factor(ids[0], ids[1], a_from_b.ambient, nm, what)
        return self.add_factor(f, loss, name, group)

    @journalled
    def add_point(
        self, z: Any, world_from_rig: int, cam_from_rig: int | None, p_in_world: Any,
        sigma: Any = None, covariance: Any = None, information: Any = None,
        noise: NoiseModel | None = None, loss: LossSpec = None, name: str | None = None,
        group: str = "point",
    ) -> int:
        """A point measured by a sensor on a rig (factors/pose/observed_point.h).

        3-D: r = W (cam_from_rig · world_from_rig⁻¹ · p_in_world − z) with SE3 poses;
        ``p_in_world`` is a constant 3-vector or the id of an Rn(3) variable (a landmark);
        noise 3-dim. 2-D: an SE2 ``world_from_rig`` (the sensor at the pose:
        ``cam_from_rig=None``) and an Rn(2) landmark variable, r = W (x⁻¹ · l − z), noise
        2-dim (a known 2-D point is a fixed landmark variable).
        """
        what = f"measurement '{name}'" if name else f"point #{self.num_measurements}"
        if cam_from_rig is None:
            ids = self.check_ids([world_from_rig, p_in_world], what)
            if self.codec(ids[0]).name != "SE2" or self.codec(ids[1]).name != "Rn(2)":
                raise TypeError(f"{what}: without cam_from_rig, world_from_rig must be an SE2 and "
                                f"p_in_world an Rn(2) variable, got a {self.codec(ids[0]).name} "
                                f"and a {self.codec(ids[1]).name}")
            nm = noise_model(2, sigma, covariance, information, noise, what)
            z2 = np.asarray(z, dtype=float).reshape(-1)
            if z2.size != 2 or not np.all(np.isfinite(z2)):
                raise ValueError(f"{what}: z must be 2 finite numbers for a 2-D point")
            f = _core.landmark_2d_factor(ids[0], ids[1], z2, nm, what)
            return self.add_factor(f, loss, name, group)
        landmark = _is_id(p_in_world)
        ids = self.check_ids([world_from_rig, cam_from_rig] + ([p_in_world] if landmark else []), what)
        for v in ids[:2]:
            if self.codec(v).name != "SE3":
                raise TypeError(f"{what}: variable {v} must be an SE3, got a {self.codec(v).name}")
        constant = np.zeros(3) if landmark else _vector3(p_in_world, "p_in_world", what)
        nm = noise_model(3, sigma, covariance, information, noise, what)
        f = _core.point_factor(ids[0], ids[1], ids[2] if landmark else -1, _vector3(z, "z", what),
                               nm, constant, what)
        return self.add_factor(f, loss, name, group)

    def jacobian(self) -> dict[str, Any]:
        """Whitened residuals and their dense Jacobian in the tangent spaces of the
        free variables (dict: residuals, jacobian, variables, column_offsets,
        row_offsets); for diagnostics such as :func:`boxplus.calib.report`."""
        return self._core.evaluate_jacobian()

    def measurement_group(self, mid: int) -> str:
        return self._meas_group[int(mid)]

    def groups(self) -> dict[str, list[int]]:
        """Measurement ids per group (a Python function's name or a C++ factor's
        kind, e.g. 'prior', 'board[opencv5]'), in id order."""
        out: dict[str, list[int]] = {}
        for mid, g in sorted(self._meas_group.items()):
            out.setdefault(g, []).append(mid)
        return out

    # ---- solving ---------------------------------------------------------------------
    def solve(
        self,
        options: _core.SolverOptions | None = None,
        callback: Callable[[_core.IterationInfo], Any] | None = None,
        verbose: bool = False,
        check_determined: bool = True,
        **overrides: Any,
    ) -> _core.SolveSummary:
        """Minimises ½ Σ ρ(‖rᵢ‖²) and writes the estimates back (``self.X``).

        Parameters
        ----------
        options : SolverOptions, optional
            The settings; any of its fields may also be given as keywords
            (``method='gn_ls'``, ``max_iterations=50``, ``initial_trust_region_radius``,
            ``damping``, ``jacobi_scaling``, ``nonmonotonic_steps``, ...), which
            override ``options``.
        callback : callable, optional
            ``callback(info: IterationInfo)`` after each iteration; return False to stop.
        verbose : bool
            Print (with Python's ``print``, so ``contextlib.redirect_stdout`` and
            notebooks capture it) one line per iteration in the C++ progress
            format (χ² = 2 × cost, see ``_core.format_progress``) and a summary.
        check_determined : bool
            After the solve, run the rank test (:meth:`check_determined`, about one
            factorisation) and warn with :class:`UndeterminedWarning` naming what the
            data leave free. False skips it: for loops that solve one problem many
            times (restarts, staged solves), where one check suffices.

        Returns
        -------
        SolveSummary
            Termination, χ² before and after, iterations, time. Ctrl-C stops the
            solve and keeps the best estimate so far (termination 'interrupted').
            A Python exception raised by a measurement function, a manifold's ⊞
            or the callback is re-raised with its traceback. The summary is
            also logged at INFO on the ``boxplus`` logger (:mod:`boxplus.log`).
        """
        from boxplus.log import log_summary

        summary = solver.run(self._core, options, callback, verbose, **overrides)
        log_summary(summary, "solve")
        if check_determined and summary.usable and summary.termination != "interrupted":
            free = self.describe_undetermined()
            if free:
                warnings.warn(UndeterminedWarning(
                    f"the measurements do not determine {free}: covariances of these "
                    f"variables are refused (add measurements or priors, or fix a variable)"),
                    stacklevel=2)
        return summary

    # ---- after a solve ---------------------------------------------------------------
    def _undetermined(self, vid: int) -> bool:
        """Whether no measurement depends on variable ``vid`` (counted incrementally)."""
        n = self._core.num_measurements
        for mid in range(self._touched_upto, n):
            self._touched.update(self._core.measurement_variables(mid))
        self._touched_upto = n
        return vid not in self._touched

    def _check_determined(self, vid: int) -> None:
        if not self.is_fixed(vid) and self._undetermined(vid):
            name = self._core.variable_name(int(vid))
            raise ValueError(
                f"variable {name or vid!r} is undetermined: no measurement depends on it, so "
                f"its covariance is unbounded (add a measurement or a prior, or fix it)"
            )

    def covariance(self, vid: int) -> np.ndarray:
        """Marginal covariance of variable ``vid`` in its tangent space.

        Raises ValueError when the problem does not determine the variable (no
        measurement depends on it, or the data leaves one of its directions
        free). An undetermined *other* variable does not prevent it: the message
        then names the undetermined variables, and the determined ones keep
        their covariance (:meth:`joint_covariance`).
        """
        return self.joint_covariance([vid])

    def joint_covariance(self, ids: Sequence[int]) -> np.ndarray:
        """Joint covariance of distinct variables ``ids`` (blocks in that order), in
        their tangent spaces; raises ValueError as :meth:`covariance`."""
        ids = self.check_ids(ids, "joint_covariance")
        for v in ids:
            self._check_determined(v)
        return self._core.joint_covariance(ids)

    def check_determined(self) -> _core.Determinedness:
        """Which tangent directions the measurements leave free at the current values.

        A rank test of the whitened Jacobian with equilibrated columns (a direction
        whose singular value is below 10⁻⁹ of the largest is free; one sparse
        factorisation, kept until the problem or its values change). Its
        ``undetermined`` lists each variable moved by the null space, its free
        tangent directions and the variables they are tied to;
        :meth:`describe_undetermined` says it in words.
        """
        return self._core.check_determined()

    def describe_undetermined(self) -> str:
        """"'b': p.x, p.y (tied to 'a'); ..." — the free directions, or "" when the
        measurements determine every free variable."""
        d = self._core.check_determined()
        return "" if d.determined else self._core.describe_undetermined(d)

    def std(self, vid: int) -> np.ndarray:
        """Standard deviations of variable ``vid`` along its tangent directions."""
        return np.sqrt(np.diag(self.covariance(vid)))

    def profile(self, vid: int, coordinate: int | str, level: float = 1.0,
                options: _core.SolverOptions | None = None, search: float = 3.0) -> Any:
        """The profile-likelihood interval of one coordinate of an Rn variable: the
        values the data allow when every other variable re-adjusts, asymmetric where
        the parameters trade along a curved valley (:func:`boxplus.profile.profile_interval`;
        one solve of a copy per point, the problem itself is not changed)."""
        from boxplus.profile import profile_interval

        return profile_interval(self, vid, coordinate, level, options, search)

    def residual(self, mid: int) -> np.ndarray:
        """Whitened residual of measurement ``mid`` at the current values."""
        return self._core.residual(int(mid))

    def _rows(self, mids: list[int], whitened: bool) -> np.ndarray:
        """Errors (or residuals) of measurements of one group as rows of its width."""
        width = self._group_dims[self._meas_group[mids[0]]]
        return np.asarray(self._core.errors(mids, whitened)).reshape(-1, width)

    def _by_group(self, whitened: bool) -> dict[str, np.ndarray]:
        return {g: self._rows(mids, whitened) for g, mids in self.groups().items()}

    def errors(self) -> dict[str, np.ndarray]:
        """Unwhitened errors f(Y) ⊟ z of every measurement, per group, in the
        measurements' own units (rows: one per measured vector or point; a group is
        a Python function's name or a C++ factor's kind, e.g. 'prior', 'board[opencv5]')."""
        return self._by_group(whitened=False)

    def measurement_errors(self, mids: int | Sequence[int]) -> np.ndarray:
        """Unwhitened errors of one measurement or of several of one group, as rows
        (one per point/vector), all measurements evaluated once."""
        ids = [int(mids)] if isinstance(mids, (int, np.integer)) else [int(m) for m in mids]
        for m in ids:
            if m not in self._meas_group:
                raise IndexError(f"unknown measurement id {m} (the problem has {self.num_measurements})")
        width = {self._group_dims[self._meas_group[m]] for m in ids}
        if len(width) > 1:
            raise ValueError(f"measurement_errors: measurements of different widths {sorted(width)}")
        return self._rows(ids, whitened=False)

    def residuals(self) -> dict[str, np.ndarray]:
        """Whitened residuals of every measurement, grouped as :meth:`errors`."""
        return self._by_group(whitened=True)

    def rms(self, whitened: bool = False) -> dict[str, float]:
        """RMS error per measurement group: sqrt(mean over rows of ‖e‖²), in the
        measurements' own units (e.g. pixels), or of the whitened residuals."""
        res = self.residuals() if whitened else self.errors()
        return {k: float(np.sqrt(np.mean(np.sum(v**2, axis=1)))) for k, v in res.items()}

    def cost(self) -> float:
        """½ Σ ρ(‖rᵢ‖²) at the current values."""
        return self._core.cost()

    # ---- pickling --------------------------------------------------------------------
    def __getstate__(self) -> dict[str, Any]:
        """The problem's description: its journalled building calls, values and fixed
        flags (:mod:`boxplus._journal`); functions by reference."""
        return _journal.state_of(self)

    def __setstate__(self, state: dict[str, Any]) -> None:
        """Rebuilds the problem by replaying its journal on a new C++ problem."""
        OptimizationProblem.__init__(self)
        _journal.rebuild(self, state)

    def copy(self) -> OptimizationProblem:
        """A new problem built by the same calls, at the current values (same ids)."""
        new = OptimizationProblem.__new__(type(self))
        new.__setstate__(self.__getstate__())
        return new


def _constants(constants: Any, what: str) -> tuple[Any, ...]:
    """The extra arguments of f as a tuple (a str or a scalar is a slip, not a sequence)."""
    if isinstance(constants, (str, bytes, dict)) or not isinstance(constants, (tuple, list)):
        raise TypeError(f"{what}: constants must be a tuple or list of f's extra arguments "
                        f"(e.g. constants=(p,)), got {type(constants).__name__}")
    return tuple(constants)


def _vector3(value: Any, keyword: str, what: str) -> np.ndarray:
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"{what}: {keyword} must be 3 numbers, got {type(value).__name__}") from None
    if a.size != 3 or not np.all(np.isfinite(a)):
        raise ValueError(f"{what}: {keyword} must be 3 finite numbers, got shape {a.shape}")
    return a.reshape(3)
