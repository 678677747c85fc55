"""Graph SLAM: g2o/TORO pose graphs on boxplus.

>>> import boxplus.slam as slam
>>> graph = slam.load_g2o("parking-garage.g2o")      # read and built in C++
>>> before = graph.positions()
>>> summary = graph.solve(method="lm")
>>> graph.save_g2o("parking-garage-opt.g2o")          # ids and order kept
>>> slam.plot_trajectory(graph, "trajectory.png", before=before)

Poses: SE2 ambient ``[x, y, θ]``; SE3 ambient ``[px, py, pz, qx, qy, qz, qw]``
with tangent ``[δp, δθ]`` (translation first, ⊞ the compound R³ × SO(3)).
Relative-pose errors (see ``cpp/include/boxplus/factors/relative_pose3d.h``),
with ``Δ = z⁻¹ (xᵢ⁻¹ xⱼ)``:

* ``convention="g2o"`` (default): ``e = [t(Δ), vec(q(Δ))]`` with ``w ≥ 0``,
  g2o's ``EdgeSE3``; 2D ``e = [t(Δ), θ(Δ)]`` (g2o and GTSAM alike);
* ``convention="log"``: ``e = [u, ω]`` from ``(ω, u) = Pose3::Logmap(Δ)``,
  GTSAM's ``BetweenFactor<Pose3>``;
* ``convention="sesync"`` (alias ``"chordal"``): SE-Sync's objective (Rosen et
  al., IJRR 2019), residual ``[√τ (tⱼ − tᵢ − Rᵢt̃ᵢⱼ), √κ vec(Rⱼ − RᵢR̃ᵢⱼ)]``
  with isotropic precisions τ, κ from Ω as SE-Sync's ``read_g2o_file``
  computes them (``factors/relative_pose_sesync.h``); its chi2 is SE-Sync's
  ``f`` (``chi2_sesync``).

The objective is ``chi2 = Σ eᵀΩe`` with the file's information matrices Ω
(twice Ceres' cost, twice GTSAM's ``graph.error``); ``Σ‖r‖²`` in the sesync
convention.
"""

from __future__ import annotations

from os import PathLike
from typing import Callable, Optional, Union

import numpy as np

from boxplus._core import PoseGraph as _CorePoseGraph
from boxplus._core import pose_graph_solver_defaults as _solver_defaults
from boxplus._core import pose_graph_default_method as _default_method

from .reference import chi2_g2o, chi2_log, chi2_sesync, read_g2o_arrays

__all__ = [
    "SOLVER_DEFAULTS",
    "SlamProblem",
    "load_g2o",
    "save_g2o",
    "plot_trajectory",
    "chi2_g2o",
    "chi2_log",
    "chi2_sesync",
    "read_g2o_arrays",
]

PathType = Union[str, "PathLike[str]"]


#: Trust-region settings used by :meth:`SlamProblem.solve` (and ``boxplus-g2o``),
#: from C++ ``boxplus::slam::DefaultSolverOptions``.
SOLVER_DEFAULTS = dict(_solver_defaults())


class SlamProblem:
    """A pose graph loaded from a file, ready to extend, solve and save.

    Attributes
    ----------
    problem : boxplus.Problem
        The underlying problem (variables ``x<vertex id>``, one measurement per
        edge). Add measurements or fix variables on it directly; ids of vertices
        map to variable ids through :meth:`variable`.
    report : dict
        What the reader did: ``unknown_skipped``, ``unknown_tags``,
        ``repaired_information``, ``repaired_lines``, ``warnings``,
        ``estimates_from_file``.
    """

    def __init__(self, core: _CorePoseGraph, report: dict):
        self._core = core
        self.report = report

    # -- structure ----------------------------------------------------------
    @property
    def problem(self):
        return self._core.problem

    @property
    def dimension(self) -> int:
        """2 or 3 (the poses' dimension)."""
        return self._core.dimension

    @property
    def vertex_ids(self) -> list:
        return self._core.vertex_ids

    @property
    def gauge_vertex(self) -> int:
        """The vertex held fixed for the gauge (first FIX id, else the first vertex)."""
        return self._core.gauge_vertex

    @property
    def convention(self) -> str:
        return self._core.convention

    @property
    def num_edges(self) -> int:
        return self._core.num_edges

    def variable(self, vertex_id: int) -> int:
        """Variable id in :attr:`problem` of a vertex id."""
        return self._core.variable(vertex_id)

    def value(self, vertex_id: int) -> np.ndarray:
        """Current ambient value of a vertex (copy)."""
        return self._core.problem.value(self._core.variable(vertex_id))

    def fix(self, vertex_id: int, fixed: bool = True) -> None:
        """Holds a vertex constant (or releases it)."""
        self._core.fix(vertex_id, fixed)

    # -- extending ----------------------------------------------------------
    def add_vertex(self, vertex_id: int, kind: str, estimate) -> int:
        """Adds a vertex ``kind`` in {'SE2', 'SE3', 'XY', 'XYZ'}; returns its variable id."""
        return self._core.add_vertex(vertex_id, kind, np.asarray(estimate, float))

    def add_edge(self, kind: str, from_id: int, to_id: int, measurement, information) -> int:
        """Adds an edge (saved with the graph); returns its measurement id.

        Parameters
        ----------
        kind : {'SE2', 'SE3', 'SE2_XY', 'SE3_XYZ', 'SE2_BEARING_RANGE'}
        measurement : array_like
            SE2 ``[x, y, θ]``, SE3 ``[t, qx, qy, qz, qw]``, points, or
            ``[bearing, range]``.
        information : array_like
            Full symmetric information matrix, in the error's order.
        """
        return self._core.add_edge(
            kind,
            from_id,
            to_id,
            np.asarray(measurement, float),
            np.asarray(information, float),
        )

    def add_prior(self, vertex_id: int, value, information) -> int:
        """Adds a prior ``U (x ⊟ z)`` with ``UᵀU = information`` (tangent order)."""
        from boxplus.noise import noise_model

        vid = self._core.variable(vertex_id)
        info = np.asarray(information, float)
        noise = noise_model(info.shape[0] if info.ndim == 2 else -1, information=info,
                            what=f"prior on vertex {vertex_id}")
        return self._core.problem.add_prior(vid, np.asarray(value, float), noise)

    # -- solving and results ------------------------------------------------
    def solve(
        self,
        method: str = "auto",
        max_iterations: int = 100,
        num_threads: int = 1,
        verbose: bool = False,
        callback: Optional[Callable[[dict], Optional[bool]]] = None,
        function_tolerance: float = 1e-10,
        gradient_tolerance: float = 1e-12,
        parameter_tolerance: float = 1e-10,
        **trust_region,
    ):
        """Solves in place (the C++ solver, GIL released); returns a SolveSummary.

        ``summary.final_cost`` is half the chi2 (Ceres' cost). ``method`` 'auto'
        is the strategy measured best for the graph's dimension (dogleg for 2D,
        'lm' for 3D; ``boxplus::slam::DefaultMethod``), else 'lm', 'gn', 'gn_ls'
        (Gauss–Newton with a line search), 'dogleg'.

        The trust-region settings default to those measured best on pose
        graphs (:data:`SOLVER_DEFAULTS`: LM that starts as Gauss–Newton, λI
        damping, no Jacobi scaling, up to 5 nonmonotonic steps); override any of
        ``initial_trust_region_radius``, ``damping`` ('levenberg' or
        'marquardt'), ``jacobi_scaling``, ``nonmonotonic_steps`` by keyword
        (``boxplus.Problem.solve`` documents them).
        """
        unknown = set(trust_region) - set(SOLVER_DEFAULTS)
        if unknown:
            raise TypeError(f"solve() got unexpected keyword arguments {sorted(unknown)}")
        if method == "auto":
            method = _default_method(self.dimension)
        return self._core.problem.solve(
            **{**SOLVER_DEFAULTS, **trust_region},
            method=method,
            max_iterations=max_iterations,
            function_tolerance=function_tolerance,
            gradient_tolerance=gradient_tolerance,
            parameter_tolerance=parameter_tolerance,
            num_threads=num_threads,
            verbose=verbose,
            callback=callback,
        )

    def chi2(self, convention: Optional[str] = None) -> float:
        """``Σ eᵀΩe`` at the current values ('g2o', 'log' or 'sesync'; default: the graph's)."""
        return self._core.chi2(convention or "")

    def poses(self) -> np.ndarray:
        """Pose estimates, one ambient row per pose vertex (file order)."""
        return self._core.poses()

    def positions(self) -> np.ndarray:
        """Pose positions, shape (N, 2) or (N, 3)."""
        return self._core.poses()[:, : self.dimension]

    def landmarks(self) -> np.ndarray:
        return self._core.landmarks()

    def save_g2o(self, path: PathType) -> None:
        """Writes the graph with the current estimates; ids, order and tags kept."""
        self._core.save(str(path))

    def to_string(self) -> str:
        return self._core.to_string()

    def plot(self, path: PathType, before: Optional[np.ndarray] = None, title: str = "") -> None:
        """PNG of the trajectory (see :func:`plot_trajectory`)."""
        plot_trajectory(self, path, before=before, title=title)


def load_g2o(
    path: PathType,
    *,
    convention: str = "g2o",
    robust: str = "none",
    robust_width: float = 1.0,
    init: str = "file",
    skip_unknown: bool = False,
    repair_information: bool = False,
) -> SlamProblem:
    """Reads a g2o or TORO file and builds its problem in C++.

    Parameters
    ----------
    convention : {'g2o', 'log', 'sesync'}
        Relative-pose error (module docstring); 'chordal' is 'sesync'.
    robust : {'none', 'huber', 'cauchy', 'tukey', 'arctan', 'softl1'}
    robust_width : float
        Kernel width on ``sqrt(eᵀΩe)``.
    init : {'file', 'spanning-tree', 'chordal'}
        Initial estimate: the file's, composition along a spanning tree, or the
        chordal rotation relaxation followed by linear translations. Files
        without vertices always start from the spanning tree.
    skip_unknown : bool
        Skip unknown tags (counted in ``report['unknown_tags']`` and a warning)
        instead of raising.
    repair_information : bool
        Replace information matrices that are not positive definite by the
        nearest positive-definite one (counted, with a warning).

    Raises
    ------
    boxplus.ParseError
        Malformed input; the message names the file and the line.
    """
    import warnings

    core, report = _CorePoseGraph.load(
        str(path),
        convention=convention,
        robust=robust,
        robust_width=robust_width,
        init=init,
        skip_unknown=skip_unknown,
        repair_information=repair_information,
    )
    if report["warnings"]:
        warnings.warn(report["warnings"].strip(), stacklevel=2)
    return SlamProblem(core, report)


def save_g2o(graph: SlamProblem, path: PathType) -> None:
    """Writes ``graph`` with its current estimates (see :meth:`SlamProblem.save_g2o`)."""
    graph.save_g2o(path)


def plot_trajectory(
    graph: SlamProblem,
    path: PathType,
    before: Optional[np.ndarray] = None,
    title: str = "",
) -> None:
    """Writes a PNG of the pose positions (x–y plane), optionally over ``before``.

    Parameters
    ----------
    before : ndarray, optional
        Positions (N, 2 or 3) before optimisation, e.g. ``graph.positions()``
        taken before :meth:`SlamProblem.solve`.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    after = graph.positions()
    fig, ax = plt.subplots(figsize=(7, 7))
    if before is not None:
        before = np.asarray(before)
        ax.plot(before[:, 0], before[:, 1], "-", color="0.6", lw=0.7, label="before")
    ax.plot(after[:, 0], after[:, 1], "-", color="C0", lw=0.9, label="after")
    lm = graph.landmarks()
    if len(lm):
        ax.plot(lm[:, 0], lm[:, 1], "+", color="C3", ms=4, label="landmarks")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.legend(loc="best")
    ax.set_title(title or f"chi2 = {graph.chi2():.6g}")
    fig.tight_layout()
    fig.savefig(str(path), dpi=120)
    plt.close(fig)
