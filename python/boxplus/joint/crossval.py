"""k-fold cross-validation of calibration methods (Le & Ng, Sec. XI-C, Table II).

The data are items of several kinds (e.g. checkerboard views and plane
views); each kind is split into k folds separately, so that every fold
trains on (k−1)/k of every kind. Each method is trained on the training
items of a fold and scored on its validation items; the table reports the
mean ± standard deviation over the folds of each fold's mean error.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

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


def cross_validate(
    methods: Mapping[str, Callable[[Split], Any]],
    validate: Callable[[Any, Split], np.ndarray],
    sizes: Mapping[str, int],
    k: int = 5,
    seed: int | None = 0,
    scale: float = 1000.0,
    unit: str = "mm",
) -> CrossValidation:
    """Trains every method on every fold and scores it on the held-out items.

    Parameters
    ----------
    methods : mapping name -> train(train_split) -> model
    validate : callable(model, validation_split) -> errors
        Errors of the model on the held-out items (e.g. distances in metres).
    sizes : mapping kind -> number of items
    k, seed : folds and the seed of the shuffle
    scale, unit : errors are multiplied by ``scale`` and reported in ``unit``
    """
    splits = kfold(sizes, k, seed)
    cv = CrossValidation(unit=unit)
    for name, train in methods.items():
        errs = []
        for tr, va in splits:
            model = train(tr)
            e = np.asarray(validate(model, va), dtype=float)
            errs.append(float(np.mean(e)) * scale)
        cv.fold_errors[name] = errs
    return cv
