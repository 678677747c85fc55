"""Measurement noise: one vocabulary for every ``add_*``.

Every measurement takes exactly one of

``sigma``
    a standard deviation σ (scalar, the same in every direction) or a vector
    of σᵢ (independent errors);
``covariance``
    the covariance Σ (d × d, symmetric positive definite);
``information``
    the information matrix Ω = Σ⁻¹ (d × d, SPD), as g2o/TORO files store it;
``noise``
    a ready :class:`boxplus.NoiseModel`.

With none of them, σ = 1 (the residual is the error). The residual is
r = W e with WᵀW = Ω (:mod:`boxplus.noise` builds W once, in C++, through
:class:`boxplus.NoiseModel`), and errors are un-whitened with the same model,
so every RMS is in the measurement's own units.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from boxplus import _core

__all__ = ["NoiseModel", "noise_model", "noise_models"]

NoiseModel = _core.NoiseModel


def _array(value: Any, keyword: str, what: str) -> np.ndarray:
    if isinstance(value, (str, bytes, dict)) or np.iscomplexobj(value):
        raise TypeError(f"{what}: {keyword} must be real numbers, got {type(value).__name__}")
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"{what}: {keyword} must be numbers, got {type(value).__name__}") from None
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{what}: {keyword} has non-finite entries")
    return a


def noise_model(
    dim: int,
    sigma: Any = None,
    covariance: Any = None,
    information: Any = None,
    noise: NoiseModel | None = None,
    what: str = "measurement",
) -> NoiseModel:
    """The NoiseModel of one measurement with a ``dim``-entry error.

    Exactly one of ``sigma``, ``covariance``, ``information`` and ``noise`` may
    be given (none: σ = 1). Raises ValueError or TypeError naming ``what``.
    """
    if isinstance(dim, bool) or not isinstance(dim, (int, np.integer)) or dim < 1:
        raise ValueError(f"{what}: an error has at least one entry, got dimension {dim!r}")
    given = [k for k, v in (("sigma", sigma), ("covariance", covariance),
                            ("information", information), ("noise", noise)) if v is not None]
    if len(given) > 1:
        raise ValueError(f"{what}: give one of sigma, covariance, information or noise, "
                         f"not {' and '.join(given)}")
    if noise is not None:
        if not isinstance(noise, NoiseModel):
            raise TypeError(f"{what}: noise must be a boxplus.NoiseModel, "
                            f"got {type(noise).__name__}")
        if noise.dim != dim:
            raise ValueError(f"{what}: noise of dimension {noise.dim} for an error of "
                             f"{dim} entries")
        return noise
    if covariance is not None:
        S = _array(covariance, "covariance", what)
        if S.shape != (dim, dim):
            raise ValueError(f"{what}: covariance must be {dim}×{dim}, got shape {S.shape}")
        return NoiseModel.covariance(S, what)
    if information is not None:
        O = _array(information, "information", what)
        if O.shape != (dim, dim):
            raise ValueError(f"{what}: information must be {dim}×{dim}, got shape {O.shape}")
        return NoiseModel.information(O, what)
    if sigma is None:
        return NoiseModel.unit(dim)
    s = _array(sigma, "sigma", what)
    if s.ndim == 0:
        return NoiseModel.isotropic(dim, float(s), what)
    if s.shape == (dim,):
        return NoiseModel.sigmas(s, what)
    if s.shape == (dim, dim):
        raise ValueError(f"{what}: sigma is a {dim}×{dim} matrix; a full covariance is "
                         f"given as covariance=")
    raise ValueError(f"{what}: sigma must be a scalar or a vector of {dim} standard "
                     f"deviations, got shape {s.shape}")


def noise_models(
    n: int,
    dim: int,
    sigma: Any = None,
    covariance: Any = None,
    information: Any = None,
    noise: NoiseModel | None = None,
    what: str = "measurements",
) -> list:
    """One NoiseModel per row of a batch of ``n`` measurements.

    ``covariance`` or ``information`` may also be a stack (n, dim, dim), one
    matrix per measurement; otherwise one model is shared by all rows.
    """
    for keyword, value in (("covariance", covariance), ("information", information)):
        if value is not None and np.ndim(value) == 3:
            A = _array(value, keyword, what)
            if A.shape != (n, dim, dim):
                raise ValueError(f"{what}: per-measurement {keyword} must have shape "
                                 f"({n}, {dim}, {dim}), got {A.shape}")
            return [noise_model(dim, **{keyword: A[i]}, what=f"{what} (row {i})")
                    for i in range(n)]
    shared = noise_model(dim, sigma, covariance, information, noise, what)
    return [shared] * n
