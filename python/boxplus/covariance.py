"""Covariances of the variables a problem determines, when others it does not.

The covariance of the estimate is (JᵀJ)⁻¹ for the whitened Jacobian J at the
solution, in the tangent spaces of the free variables. Ceres' covariance
needs J to have full column rank. When it does not (a variable the data
leave partly free: the yaw of an IMU seen only through gravity, a gauge left
unfixed), the determined variables still have a covariance: a column with no
weight in J's null space has the same block of (JᵀJ)⁺ whatever gauge fixes
the free directions. This module finds those columns and their covariance
(:func:`determined_covariance`) and names the variables left free
(:func:`determined_block`, what ``OptimizationProblem.covariance`` falls back
to).
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["determined_block", "determined_covariance", "scaled_svd"]


def scaled_svd(J: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(column norms, observed-column mask, s, Vt, indices of the observed columns)
    of the column-scaled Jacobian J D⁻¹ = U S Vᵀ (unobserved = zero columns)."""
    norms = np.linalg.norm(J, axis=0)
    observed = norms > 0
    idx = np.flatnonzero(observed)
    if idx.size == 0:
        return norms, observed, np.zeros(0), np.zeros((0, 0)), idx
    _, s, Vt = np.linalg.svd(J[:, observed] / norms[observed], full_matrices=False)
    return norms, observed, s, Vt, idx


def determined_covariance(J: np.ndarray, rank_tol: float = 1e-9,
                          null_tol: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """(covariance, undetermined mask) over the columns of a whitened Jacobian J.

    The directions the data does not determine are the right singular vectors
    of J D⁻¹ with s < ``rank_tol``·s_max, plus the zero columns. A column with
    an entry above ``null_tol`` in such a vector is undetermined (NaN rows,
    ∞ on the diagonal). Every other column has zero weight in the null space,
    so its block of the pseudo-inverse (JᵀJ)⁺ is its covariance whatever gauge
    fixes the undetermined ones: determined parameters keep their σ when an
    unrelated parameter (e.g. the translation of an IMU seen only through
    gravity) is undetermined.
    """
    n = J.shape[1]
    norms, observed, s, Vt, idx = scaled_svd(J)
    cov = np.full((n, n), np.nan)
    undetermined = ~observed
    if s.size:
        good = s >= rank_tol * s[0]
        null = Vt[~good]
        if null.size:
            undetermined[idx[np.any(np.abs(null) > null_tol, axis=0)]] = True
        Cs = (Vt[good].T / s[good] ** 2) @ Vt[good]
        cov[np.ix_(idx, idx)] = Cs / np.outer(norms[idx], norms[idx])
    cov[undetermined, :] = np.nan
    cov[:, undetermined] = np.nan
    cov[undetermined, undetermined] = np.inf
    return cov, undetermined


def determined_block(problem: Any, ids: list[int], error: Exception) -> np.ndarray:
    """The joint covariance of variables ``ids`` of ``problem`` when its Jacobian is
    rank-deficient elsewhere; raises ValueError naming the variables the data leave
    free when one of ``ids`` is among them (``error``: Ceres' own, re-raised when the
    problem is too large for a dense decomposition)."""
    jac = problem.jacobian()
    J = np.asarray(jac["jacobian"])
    if J.shape[1] > 5000:  # a dense SVD beyond this takes minutes
        raise error
    cols: dict[int, list[int]] = {}
    for vid, off in zip(jac["variables"], jac["column_offsets"]):
        cols[int(vid)] = list(range(int(off), int(off) + problem.codec(vid).dof))
    cov, undetermined = determined_covariance(J)
    free = sorted({problem.variable_name(v) or str(v) for v, c in cols.items()
                   if undetermined[c].any()})
    bad = [problem.variable_name(v) or str(v) for v in ids if undetermined[cols[v]].any()]
    if bad:
        raise ValueError(f"covariance of {', '.join(map(repr, bad))} is undefined: the "
                         f"measurements do not determine {', '.join(map(repr, free))} (add "
                         f"measurements or priors, or fix them)")
    idx = [c for v in ids for c in cols[v]]
    return cov[np.ix_(idx, idx)]
