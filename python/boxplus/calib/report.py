"""Calibration report: RMS per measurement group, every parameter with its
standard deviation, and a warning naming the parameters the data cannot
determine.

The diagnosis works on the whitened Jacobian J of all residuals w.r.t. the
tangent coordinates of the free variables (what the solver sees). Columns are
scaled to unit norm (so units do not matter) and decomposed, J D⁻¹ = U S Vᵀ.
A singular value below ``rank_tol``·s_max is a direction the data does not
determine (rank deficiency: e.g. the yaw of an IMU seen only through gravity);
below ``cond_tol``·s_max it is badly conditioned. Each such direction is
named by the parameters with the largest entries in its singular vector. The
covariance is (JᵀJ)⁻¹ (the pseudo-inverse over the determined directions;
undetermined parameters get an infinite σ), optionally rescaled by the
a-posteriori variance factor σ̂² = ‖r‖² / (m − n) when the given Σ is only a
guess (``rescale=True``, what OpenCV reports).

σ convention (every report of :mod:`boxplus.calib`): σ is computed from the
noise Σ the measurements were given, not rescaled (``rescale=False``, the
default of :func:`report`, :meth:`Calibration.report` and the command line);
the printed report shows both figures side by side — σ and σ·σ̂ — and
:meth:`CalibrationReport.std_other` returns the other one.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from boxplus.covariance import determined_covariance, scaled_svd

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
    jac = o.jacobian()
    J = np.asarray(jac["jacobian"])
    r = np.asarray(jac["residuals"])
    columns: list[tuple[int, int]] = []
    names: list[str] = []
    for vid in jac["variables"]:
        labels = o.labels(vid)
        vname = o.variable_name(vid)
        for t, lab in enumerate(labels):
            columns.append((vid, t))
            names.append(f"{vname}.{lab}")
    n = J.shape[1]
    norms, observed, s, Vt, idx = scaled_svd(J)
    undetermined: list[tuple[float, list[str]]] = []
    ill: list[tuple[float, list[str]]] = []
    if (~observed).any():
        undetermined.append((0.0, [names[i] for i in np.flatnonzero(~observed)]))
    cov = np.full((n, n), np.nan)
    cond = np.inf
    if s.size:
        rel = s / s[0]
        cond = s[0] / s[-1] if s[-1] > 0 else np.inf
        for k in np.flatnonzero(rel < cond_tol):
            v = Vt[k] / np.abs(Vt[k]).max()
            involved = idx[np.abs(v) >= name_tol]
            entry = (float(rel[k]), [names[i] for i in involved])
            if rel[k] < rank_tol:
                undetermined.append(entry)
            else:
                ill.append(entry)
        cov, _ = determined_covariance(J, rank_tol)
    dof = max(J.shape[0] - n, 1)
    sigma_factor = float(np.sqrt(r @ r / dof))
    if rescale:
        cov = cov * sigma_factor**2
    params = []
    for vid in jac["variables"]:
        vals = _display_values(o, vid)
        for t, lab in enumerate(o.labels(vid)):
            col = columns.index((vid, t))
            params.append(Parameter(o.variable_name(vid), lab, float(vals[t]), float(np.sqrt(cov[col, col]))))
    errs = o.errors()
    rms = {g: float(np.sqrt(np.mean(np.sum(e**2, axis=1)))) for g, e in errs.items()}
    count = {g: len(e) for g, e in errs.items()}
    return CalibrationReport(rms, count, params, undetermined, ill, float(cond), sigma_factor,
                             rescale, cov, columns)
