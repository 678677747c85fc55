"""Calibration report: RMS per measurement group, every parameter with its
standard deviation, and a warning naming the parameters the data cannot
determine.

The diagnosis works on the whitened Jacobian J of all residuals w.r.t. the
tangent coordinates of the free variables (what the solver sees), with its
columns scaled to unit norm (J D⁻¹, so units do not matter). The directions
the data do not determine come from the problem's rank test
(:meth:`boxplus.OptimizationProblem.check_determined`: singular values of
J D⁻¹ below ``rank_tol``·s_max, found on J itself with one sparse
factorisation, whatever the number of rows; e.g. the yaw of an IMU seen only
through gravity), each named by its variable's parameters. Directions whose
singular value is below ``cond_tol``·s_max are badly conditioned, named by the
parameters with the largest entries in the eigenvector of D⁻¹JᵀJD⁻¹ (formed
sparse, decomposed dense: n × n, never the m × n Jacobian). The covariance is
(JᵀJ)⁺ (the pseudo-inverse over the determined directions, which no choice
of the free ones changes; undetermined parameters get an infinite σ),
optionally rescaled by the a-posteriori variance factor σ̂² = ‖r‖² / (m − n)
when the given Σ is only a guess (``rescale=True``, what OpenCV reports).
The linear algebra runs on one BLAS thread, as the solves do.

σ convention (every report of :mod:`boxplus.calib`): σ is computed from the
noise Σ the measurements were given, not rescaled (``rescale=False``, the
default of :func:`report`, :meth:`Calibration.report` and the command line);
the printed report shows both figures side by side — σ and σ·σ̂ — and
:meth:`CalibrationReport.std_other` returns the other one.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from boxplus import blas_threads

__all__ = ["CalibrationReport", "Parameter", "report"]


@dataclass
class Parameter:
    variable: str
    label: str
    value: float
    std: float

    @property
    def name(self) -> str:
        return f"{self.variable}.{self.label}"


@dataclass
class CalibrationReport:
    rms: dict[str, float]            # per group, unwhitened (pixels, m/s², ...)
    count: dict[str, int]            # error rows per group
    parameters: list[Parameter]
    undetermined: list[tuple[float, list[str]]]   # (s / s_max, parameter names), rank-deficient
    ill_conditioned: list[tuple[float, list[str]]]  # (s / s_max, parameter names)
    condition: float                 # s_max / s_min of the column-scaled Jacobian
    sigma_factor: float              # σ̂ (1 when the given Σ fit the residuals)
    rescaled: bool
    covariance: np.ndarray = field(repr=False)  # tangent covariance over the free variables
    columns: list[tuple[int, int]] = field(repr=False)  # per column: (variable id, tangent index)

    def std(self, variable: str) -> np.ndarray:
        return np.array([p.std for p in self.parameters if p.variable == variable])

    def value(self, variable: str) -> np.ndarray:
        return np.array([p.value for p in self.parameters if p.variable == variable])

    def todict(self) -> dict:
        """Plain Python types only (``json.dumps`` takes it): every field, the
        parameters as {variable, label, value, std}, and the warnings."""
        return {
            "rms": {k: float(v) for k, v in self.rms.items()},
            "count": {k: int(v) for k, v in self.count.items()},
            "parameters": [{"variable": p.variable, "label": p.label, "value": float(p.value),
                            "std": float(p.std)} for p in self.parameters],
            "undetermined": [[float(s), list(n)] for s, n in self.undetermined],
            "ill_conditioned": [[float(s), list(n)] for s, n in self.ill_conditioned],
            "condition": float(self.condition),
            "sigma_factor": float(self.sigma_factor),
            "rescaled": bool(self.rescaled),
            "warnings": self.warnings,
            "covariance": np.asarray(self.covariance, dtype=float).tolist(),
            "columns": [[int(v), int(i)] for v, i in self.columns],
        }

    @property
    def warnings(self) -> list[str]:
        out = []
        for s, names in self.undetermined:
            out.append(f"NOT DETERMINED by the data (singular value {s:.1e} of the largest): "
                       + ", ".join(names))
        for s, names in self.ill_conditioned:
            out.append(f"badly conditioned (singular value {s:.1e} of the largest): " + ", ".join(names))
        return out

    def std_other(self, variable: str) -> np.ndarray:
        """The σ of the other convention: rescaled by σ̂ when this report is not, and
        the reverse (see :func:`report`)."""
        f = 1 / self.sigma_factor if self.rescaled else self.sigma_factor
        return self.std(variable) * f

    def __str__(self) -> str:
        lines = ["calibration report", "  RMS per measurement group:"]
        for g, r in self.rms.items():
            lines.append(f"    {g:24s} {r:.5f}  ({self.count[g]} errors)")
        given, scaled = ("σ·σ̂", "σ") if self.rescaled else ("σ", "σ·σ̂")
        f = 1 / self.sigma_factor if self.rescaled else self.sigma_factor
        lines.append(f"  parameters: value ± 1σ from the given noise Σ, and σ·σ̂ rescaled by the "
                     f"fit's residual σ̂ = {self.sigma_factor:.4f} (OpenCV's); this report's std() "
                     f"is the {'rescaled' if self.rescaled else 'unrescaled'} one")
        lines.append(f"    {'parameter':32s} {'value':>14s}   {given:>12s} {scaled:>12s}")
        for p in self.parameters:
            lines.append(f"    {p.name:32s} {p.value:+14.6f} ± {p.std:12.6f} {p.std * f:12.6f}")
        lines.append(f"  condition number (scaled Jacobian): {self.condition:.3g}")
        for w in self.warnings:
            lines.append("  WARNING: " + w)
        return "\n".join(lines)


def _display_values(o, vid: int) -> np.ndarray:
    """Values shown beside the tangent directions: Rⁿ coordinates, for a pose its
    position and rotation vector (the tangent at the identity); :meth:`Codec.display`."""
    return o.codec(vid).display(o.value(vid))


def report(o, rescale: bool = False, rank_tol: float = 1e-9, cond_tol: float = 1e-5,
           name_tol: float = 0.3) -> CalibrationReport:
    """Builds the report of a solved :class:`~boxplus.OptimizationProblem`.

    σ convention: ``rescale=False`` (the default, here and in
    :meth:`boxplus.calib.Calibration.report`) gives σ from the noise the
    measurements were given (Σ); ``rescale=True`` multiplies them by σ̂, the
    fit's residual scale (OpenCV's convention). The report prints both
    (``sigma_factor`` is σ̂), so either figure is at hand.
    """
    with blas_threads.limit(1):
        return _report(o, rescale, rank_tol, cond_tol, name_tol)


def _direction_names(v: np.ndarray, names: list[str], name_tol: float) -> list[str]:
    """The parameters with the largest entries of direction ``v``."""
    top = np.abs(v).max()
    return [names[i] for i in np.flatnonzero(np.abs(v) >= name_tol * top)] if top > 0 else []


def _report(o, rescale: bool, rank_tol: float, cond_tol: float,
            name_tol: float) -> CalibrationReport:
    det = o._core.check_determined(relative_tolerance=rank_tol)
    nm = o._core.normal_matrix()
    H = np.asarray(nm["normal_matrix"])
    r = np.asarray(nm["residuals"])
    columns: list[tuple[int, int]] = []
    names: list[str] = []
    for vid in nm["variables"]:
        vname = o.variable_name(vid)
        for t, lab in enumerate(o.labels(vid)):
            columns.append((vid, t))
            names.append(f"{vname}.{lab}")
    n = H.shape[0]
    norms = np.asarray(det.column_norms)
    scale = np.divide(1.0, norms, out=np.zeros(n), where=norms > 0)
    Hs = H * np.outer(scale, scale)
    N = np.asarray(det.null_space).reshape(n, -1)
    undetermined: list[tuple[float, list[str]]] = []
    for u in det.undetermined:
        vname = o.variable_name(u.variable)
        labels = o.labels(u.variable)
        D = np.asarray(u.directions)
        for j in range(D.shape[1]):
            undetermined.append((0.0, _direction_names(D[:, j], [f"{vname}.{lab}" for lab in labels],
                                                       name_tol)))
    ill: list[tuple[float, list[str]]] = []
    cond = np.inf
    cov = np.full((n, n), np.nan)
    if n:
        # The null space found on J is set aside; the rest of the spectrum of
        # D⁻¹JᵀJD⁻¹ gives the condition number and the weak directions.
        w, V = np.linalg.eigh(Hs)
        k = N.shape[1]
        w, V = w[k:], V[:, k:]
        if w.size and w[-1] > 0:
            rel = np.sqrt(np.clip(w, 0, None) / w[-1])
            cond = float(1 / rel[0]) if rel[0] > 0 else np.inf
            for i in np.flatnonzero(rel < cond_tol):
                ill.append((float(rel[i]), _direction_names(V[:, i], names, name_tol)))
        # (JᵀJ)⁺ = (JᵀJ + N Nᵀ)⁻¹ − N Nᵀ for an orthonormal basis N of its null space.
        NNt = N @ N.T
        Cs = np.linalg.solve(Hs + NNt, np.eye(n)) - NNt
        cov = Cs * np.outer(scale, scale)
        free = np.linalg.norm(N, axis=1) > 1e-6
        cov[free, :] = np.nan
        cov[:, free] = np.nan
        cov[free, free] = np.inf
        cov = 0.5 * (cov + cov.T)
    dof = max(r.size - n, 1)
    sigma_factor = float(np.sqrt(r @ r / dof))
    if rescale:
        cov = cov * sigma_factor**2
    params = []
    for vid in nm["variables"]:
        vals = _display_values(o, vid)
        for t, lab in enumerate(o.labels(vid)):
            col = columns.index((vid, t))
            params.append(Parameter(o.variable_name(vid), lab, float(vals[t]), float(np.sqrt(cov[col, col]))))
    errs = o.errors()
    rms = {g: float(np.sqrt(np.mean(np.sum(e**2, axis=1)))) for g, e in errs.items()}
    count = {g: len(e) for g, e in errs.items()}
    return CalibrationReport(rms, count, params, undetermined, ill, float(cond), sigma_factor,
                             rescale, cov, columns)
