"""k-fold cross-validation of calibration methods (Le & Ng, Sec. XI-C, Table II).

The data are items of several kinds (e.g. checkerboard views and plane
views); folds are given by the user, or each kind is split into k folds separately, so that every fold
trains on (k−1)/k of every kind. Each method is trained on the training
items of a fold and scored on its validation items; the table reports the
mean ± standard deviation over the folds of each fold's mean error.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from boxplus._plain import fields_todict
from boxplus.parallel import map_values

__all__ = ["CrossValidation", "cross_validate", "kfold"]

Split = dict[str, np.ndarray]


def kfold(sizes: Mapping[str, int], k: int, seed: int | None = 0) -> list[tuple[Split, Split]]:
    """k (train, validation) splits; each maps a kind to item indices.

    Items of each kind are shuffled with ``seed`` and dealt into k folds.
    """
    if k < 2:
        raise ValueError(f"k-fold cross-validation needs k >= 2, got {k}")
    rng = np.random.default_rng(seed)
    folds = {}
    for kind, n in sizes.items():
        if n < k:
            raise ValueError(f"cross-validation: {n} items of kind '{kind}' cannot make {k} folds")
        folds[kind] = np.array_split(rng.permutation(n), k)
    out = []
    for i in range(k):
        val = {kind: np.sort(f[i]) for kind, f in folds.items()}
        train = {kind: np.sort(np.concatenate([f[j] for j in range(k) if j != i])) for kind, f in folds.items()}
        out.append((train, val))
    return out


@dataclass
class CrossValidation:
    """Per method, the mean validation error of every fold (in the error's units ×
    ``scale``, by default metres → millimetres)."""

    fold_errors: dict[str, list[float]] = field(default_factory=dict)
    unit: str = "mm"
    # per method and fold, every metric (when ``validate`` returns rows of several
    # metrics, an (N, m) array; fold_errors then holds the first)
    fold_metrics: dict[str, list[np.ndarray]] = field(default_factory=dict)

    def todict(self) -> dict[str, Any]:
        """Plain Python values (``json.dumps`` takes them): the fields, and the mean and
        standard deviation over the folds per method."""
        summary = {m: {"mean": self.mean(m), "std": self.std(m)} for m in self.fold_errors}
        return {**fields_todict(self), "summary": summary}

    def mean(self, method: str) -> float:
        return float(np.mean(self.fold_errors[method]))

    def std(self, method: str) -> float:
        return float(np.std(self.fold_errors[method]))

    def table(self) -> str:
        w = max(len(m) for m in self.fold_errors) if self.fold_errors else 6
        lines = [f"{'method':<{w}}  validation error ({self.unit}), mean ± std over folds   per fold"]
        for m, e in self.fold_errors.items():
            folds = " ".join(f"{x:.2f}" for x in e)
            lines.append(f"{m:<{w}}  {self.mean(m):8.3f} ± {self.std(m):.3f}                        [{folds}]")
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.table()


def _fold_error(train: Callable[[Split], Any], validate: Callable[[Any, Split], np.ndarray],
                tr: Split, va: Split, scale: float) -> float:
    model = train(tr)
    e = np.asarray(validate(model, va), dtype=float)
    if e.ndim == 2:  # rows of several metrics: their means
        return np.mean(e, axis=0) * scale
    return float(np.mean(e)) * scale


def cross_validate(
    methods: Mapping[str, Callable[[Split], Any]],
    validate: Callable[[Any, Split], np.ndarray],
    sizes: Mapping[str, int] | None = None,
    k: int = 5,
    seed: int | None = 0,
    scale: float = 1000.0,
    unit: str = "mm",
    folds: Sequence[tuple[Split, Split]] | None = None,
    executor: Any = None,
) -> CrossValidation:
    """Trains every method on every fold and scores it on the held-out items.

    Parameters
    ----------
    methods : mapping name -> train(train_split) -> model
    validate : callable(model, validation_split) -> errors
        Errors of the model on the held-out items (e.g. distances in metres), (N,);
        or (N, m) rows of m metrics, averaged per metric (``fold_metrics``).
    sizes : mapping kind -> number of items
        For folds made here by :func:`kfold` (with ``k`` and ``seed``).
    folds : sequence of (train, validation) splits, optional
        Folds given by the user (each maps a kind to item indices); replaces
        ``sizes``/``k``/``seed``.
    scale, unit : errors are multiplied by ``scale`` and reported in ``unit``
    executor : concurrent.futures.Executor, dask Client or pool, optional
        Runs the (method, fold) fits in parallel through
        :func:`boxplus.parallel.map_values` (a fit that raises ends the call with
        :class:`boxplus.parallel.TaskError` and its traceback); the results are collected in
        order, so the table is the same as the serial one, bit for bit, when the
        methods are deterministic. A process pool needs picklable ``methods``
        and ``validate`` (module-level functions or ``functools.partial``).
    """
    if folds is None:
        if sizes is None:
            raise ValueError("cross_validate: give sizes (folds made here) or folds")
        splits = kfold(sizes, k, seed)
    else:
        splits = list(folds)
        if not splits:
            raise ValueError("cross_validate: no folds")
        for i, (tr, va) in enumerate(splits):
            for kind in set(tr) | set(va):
                both = np.intersect1d(np.asarray(tr.get(kind, []), int), np.asarray(va.get(kind, []), int))
                if both.size:
                    raise ValueError(f"cross_validate: fold {i} trains and validates on items "
                                     f"{both.tolist()} of kind '{kind}'")
    jobs = [(name, tr, va) for name in methods for tr, va in splits]
    if executor is None:
        errs = [_fold_error(methods[n], validate, tr, va, scale) for n, tr, va in jobs]
    else:
        errs = map_values(_fold_error, [(methods[n], validate, tr, va, scale) for n, tr, va in jobs],
                          executor, "cross_validate")
    cv = CrossValidation(unit=unit)
    for i, name in enumerate(methods):
        per_fold = errs[i * len(splits):(i + 1) * len(splits)]
        cv.fold_metrics[name] = [np.atleast_1d(e) for e in per_fold]
        cv.fold_errors[name] = [float(np.atleast_1d(e)[0]) for e in per_fold]
    return cv
