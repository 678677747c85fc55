"""The pose graph of a g2o/TORO file: boxplus.slam.PoseGraph (see boxplus.slam)."""

from __future__ import annotations

import logging
import os
import warnings
from os import PathLike
from typing import Any, Callable, SupportsIndex, SupportsInt, Union, cast

import numpy as np

from boxplus import _core, blas_threads, solver
from boxplus._core import pose_graph_implausible_chi2_per_dof as IMPLAUSIBLE_CHI2_PER_DOF
from boxplus._core import pose_graph_solver_defaults as _solver_defaults
from boxplus.log import LoadProgress, Progress, flush_native, log_summary, logger

__all__ = ["IMPLAUSIBLE_CHI2_PER_DOF", "SOLVER_DEFAULTS", "PoseGraph", "load_g2o", "save_g2o"]

PathType = Union[str, bytes, "PathLike[str]", "PathLike[bytes]"]


#: Solver settings used by :meth:`PoseGraph.solve` (and ``boxplus-g2o``),
#: from C++ ``boxplus::slam::DefaultSolverOptions``.
SOLVER_DEFAULTS = dict(_solver_defaults())


class PoseGraph(_core.PoseGraph):
    """A pose graph loaded from a file, ready to extend, solve and save.

    Attributes
    ----------
    problem : boxplus.Problem
        The underlying problem (variables ``x<vertex id>``, one measurement per
        edge). Add measurements or fix variables on it directly; ids of vertices
        map to variable ids through :meth:`variable`.
    report : boxplus._core.LoadReport
        What loading did: ``unknown_skipped``, ``unknown_tags``,
        ``repaired_information``, ``repaired_lines``, ``warnings``,
        ``estimates_from_file``, the times ``read_s``, ``init_s``, ``build_s``.

    The C++ class (``boxplus::slam::PoseGraph``, bound as
    ``boxplus._core.PoseGraph``) holds the graph, the problem and ``chi2``,
    ``poses``, ``landmarks``, ``variable``, ``fix``, ``save``; this subclass
    adds the Python conveniences (``solve`` with keywords, ``positions``,
    ``add_prior``, ``plot``).
    """

    @classmethod
    def load(cls, path: PathType, progress: Any = False, **options: Any) -> PoseGraph:
        """Reads, initialises and builds a graph (:func:`load_g2o`'s keywords)."""
        mode = options.pop("outliers", "auto")
        probability = options.pop("inlier_probability", 0.99)
        graph = _load(cls, path, progress, options, stacklevel=3)
        graph.outlier_mode = mode
        graph.inlier_probability = probability
        return graph

    # -- structure ----------------------------------------------------------
    def value(self, vertex_id: int) -> np.ndarray:
        """Current ambient value of a vertex (copy)."""
        return self.problem.value(self.variable(vertex_id))

    # -- extending ----------------------------------------------------------
    # The ids take what the binding's int conversion takes (the base class's signature).
    def add_vertex(self, vertex_id: SupportsInt | SupportsIndex, kind: str, estimate) -> int:
        """Adds a vertex ``kind`` in {'SE2', 'SE3', 'XY', 'XYZ'}; returns its variable id."""
        return super().add_vertex(vertex_id, kind, np.asarray(estimate, float))

    def add_edge(self, kind: str, from_id: SupportsInt | SupportsIndex, to_id: SupportsInt | SupportsIndex,
                 measurement, information) -> int:
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
        return super().add_edge(
            kind,
            from_id,
            to_id,
            np.asarray(measurement, float),
            np.asarray(information, float),
        )

    def add_prior(self, vertex_id: int, z: Any, sigma: Any = None, covariance: Any = None,
                  information: Any = None, noise: _core.NoiseModel | None = None) -> int:
        """Adds a prior ``W (x ⊟ z)`` on a vertex, ``z`` its ambient value (as in the file),
        the noise in the tangent order ([translation, rotation]) with the vocabulary of
        every ``add_*`` (:mod:`boxplus.noise`: ``sigma``, ``covariance``,
        ``information`` or ``noise``; as :meth:`boxplus.OptimizationProblem.add_prior`)."""
        from boxplus.noise import noise_model

        vid = self.variable(vertex_id)
        what = f"prior on vertex {vertex_id}"
        ambient = len(np.asarray(self.problem.value(vid)))
        dof = {3: 3, 7: 6, 2: 2}.get(ambient, ambient)  # SE2, SE3 (quaternion), points
        nm = noise_model(dof, sigma, covariance, information, noise, what)
        factor = _core.prior_factor(self.problem, vid, np.asarray(z, float), nm, what)
        return self.problem.add_factor(factor, name=what)

    # -- solving and results ------------------------------------------------
    def solve(
        self,
        options: _core.SolverOptions | None = None,
        callback: Callable[[_core.IterationInfo], Any] | None = None,
        verbose: bool = False,
        progress: bool = False,
        **overrides: Any,
    ) -> _core.SolveSummary:
        """Solves in place (the C++ solver, GIL released); returns a SolveSummary.

        The same vocabulary as :meth:`boxplus.OptimizationProblem.solve`
        (:func:`boxplus.solver.run`): ``options`` a :class:`boxplus.SolverOptions`,
        any field overridden by keyword, ``callback(info)`` per iteration,
        ``verbose`` prints χ² per iteration. Defaults are those measured best on
        pose graphs (:data:`SOLVER_DEFAULTS`, ``boxplus::slam::DefaultSolverOptions``):
        method ``'gn_lm'`` (alias ``'auto'``), Gauss–Newton with a line search
        while its full steps hold, then Levenberg–Marquardt; the trust-region
        fields (λI damping, no Jacobi scaling, up to 5 nonmonotonic steps) are
        those ``method='lm'`` then uses.
        ``summary.final_chi2`` is the objective (Σ ρ(eᵀΩe)).

        ``progress=True`` shows a tqdm bar of the iterations (nothing without
        tqdm). The summary is logged at INFO on the ``boxplus`` logger, each
        iteration at DEBUG (:mod:`boxplus.log`).
        """
        # The defaults are applied in C++ (PoseGraph::Solve) to every field not given here,
        # whether by keyword or in ``options``: method="lm" solves the same either way.
        given = set(getattr(options, "given", ()))
        base = options if options is not None and "max_iterations" in given else _core.SolverOptions()
        total = overrides.get("max_iterations", base.max_iterations)
        # Per-iteration lines at DEBUG on the boxplus logger, and the bar.
        log = logger if logger.isEnabledFor(logging.DEBUG) else None
        with Progress(log=log, level=logging.DEBUG, bar=bool(progress), total=total,
                      callback=callback) as report:
            cb = report if (log is not None or report.has_bar) else callback
            # The C++ PoseGraph.solve (from more starts when the solution is
            # implausible; boxplus::slam::PoseGraph::Solve).
            try:
                summary = solver.run(super(), options, cb, verbose, **overrides)
            finally:
                flush_native()
        log_summary(summary, "pose graph solve")
        report = self.outlier_report
        if report.ran:
            logger.info("pose graph solve: %d of %d loop closures judged wrong (%s)",
                        len(report.outliers), report.candidates, report.method)
        return summary

    @property
    def outliers(self) -> list[_core.EdgeVerdict]:
        """The edges the last :meth:`solve` judged wrong loop closures (file
        order; each with ``line``, ``from_id``, ``to_id``, ``chi2``); empty when
        none was or the judging did not run (``outlier_report.ran``)."""
        return list(self.outlier_report.outliers)

    def chi2(self, convention: str | None = None) -> float:
        """``Σ eᵀΩe`` at the current values ('g2o', 'log', 'compound' or 'sesync'; default: the graph's)."""
        return super().chi2(convention or "")

    def positions(self) -> np.ndarray:
        """Pose positions, shape (N, 2) or (N, 3)."""
        return self.poses()[:, : self.dimension]

    def save_g2o(self, path: PathType) -> None:
        """Writes the graph with the current estimates; ids, order and tags kept. The
        file is written atomically: a failed write keeps the previous file."""
        native = _native_path(path, "save_g2o")
        _named(lambda: self.save(_as_arg(native)), native)

    def plot(self, path: str | os.PathLike[str] | None = None, before: np.ndarray | None = None,
             title: str = "", ax: Any = None, unit: str = "m") -> Any:
        """Plots the trajectory; returns the Figure (see :func:`boxplus.slam.plot_trajectory`)."""
        from .plot import plot_trajectory

        return plot_trajectory(self, path, before=before, title=title, ax=ax, unit=unit)


def load_g2o(
    path: PathType,
    *,
    convention: str = "g2o",
    robust: str = "none",
    robust_width: float = 1.0,
    init: str = "best",
    skip_unknown: bool = False,
    repair_information: bool = False,
    progress: Any = False,
    outliers: str = "auto",
    inlier_probability: float = 0.99,
) -> PoseGraph:
    """Reads a g2o or TORO file and builds its problem in C++.

    Parameters
    ----------
    convention : {'g2o', 'log', 'compound', 'sesync'}
        Relative-pose error (module docstring); 'chordal' is 'sesync'.
    robust : {'none', 'huber', 'cauchy', 'tukey', 'arctan', 'softl1', 'dcs', 'geman_mcclure'}
    robust_width : float
        Kernel width on ``sqrt(eᵀΩe)``.
    init : {'best', 'file', 'spanning-tree', 'chordal'}
        Initial estimate: the better of the file's and the chordal one by the
        objective (``'best'``, the default here and in ``boxplus-g2o``;
        ``report.start`` says which was chosen, and when it was the chordal one
        a solution that is implausible, χ²/dof > 10, is also sought from the
        file's), the file's as it is (``'file'``), composition along a spanning
        tree, or the chordal rotation relaxation followed by linear
        translations. Files without vertices start from the spanning tree where
        the file's estimate would be used.
    skip_unknown : bool
        Skip unknown tags (counted in ``report.unknown_tags`` and a warning)
        instead of raising.
    repair_information : bool
        Replace information matrices that are not positive definite by the
        nearest positive-definite one (counted, with a warning).
    progress : bool or callable
        True: a tqdm bar of the bytes read (nothing without tqdm); a callable:
        ``progress(lines, bytes_read, bytes_total)`` every 4096 lines.
    outliers : {'auto', 'gnc-tls', 'gnc-gm', 'off'}
        Wrong loop closures (:attr:`PoseGraph.outlier_mode`): 'auto' judges the
        loop closures by graduated non-convexity when the least-squares
        solution is implausible (χ²/dof > 10, or a loop closure far beyond
        its χ² bound: docs/guide/slam.md) and returns the inliers' optimum; 'gnc-tls' / 'gnc-gm' always; 'off' never (the lowest
        least-squares minimum). After :meth:`PoseGraph.solve`,
        :attr:`PoseGraph.outliers` lists the edges judged wrong.
    inlier_probability : float
        An inlier's ``eᵀΩe`` is below the quantile of χ²(d) at this probability.

    Returns
    -------
    PoseGraph
        The graph. The load is reported at INFO on the ``boxplus`` logger, its
        warnings at WARNING there and as a Python ``UserWarning``
        (:mod:`boxplus.log`).

    Raises
    ------
    boxplus.ParseError
        Malformed input; the message names the file and the line.
    """
    options = dict(convention=convention, robust=robust, robust_width=robust_width, init=init,
                   skip_unknown=skip_unknown, repair_information=repair_information)
    graph = _load(PoseGraph, path, progress, options, stacklevel=3)
    graph.outlier_mode = outliers
    graph.inlier_probability = inlier_probability
    return graph


def _load(cls: type[PoseGraph], path: PathType, progress: Any, options: dict[str, Any],
          stacklevel: int) -> PoseGraph:
    """Builds ``cls`` from a file, with a progress bar or callback, and reports
    the load on the ``boxplus`` logger (warnings also as Python warnings, at
    ``stacklevel``: the caller of the public function)."""
    native = _native_path(path, "load_g2o")
    # The load's linear algebra (the chordal start's factorisations) on one BLAS
    # thread, as a solve's: OpenBLAS called from two threads at once splits its work
    # differently than from one, and concurrent loads would differ from serial ones
    # in the last bits (boxplus.blas_threads).
    with blas_threads.limit(1):
        if progress is True:
            with LoadProgress(os.path.basename(os.fsdecode(native))) as bar:
                graph = _named(lambda: cls(_as_arg(native), progress=bar, **options), native)
        else:
            graph = _named(lambda: cls(_as_arg(native), progress=progress or None, **options), native)
    flush_native()
    r = graph.report
    if logger.isEnabledFor(logging.INFO):
        logger.info(
            "%s: %d lines, %d %dD poses, %d landmarks, %d edges, start '%s' (read %.3f s, "
            "initialise %.3f s, build %.3f s)", path, r.lines, len(graph.poses()), graph.dimension,
            len(graph.landmarks()), graph.num_edges, r.start, r.read_s, r.init_s, r.build_s)
    if r.warnings:
        for line in r.warnings.strip().splitlines():
            logger.warning("%s", line)
        warnings.warn(r.warnings.strip(), stacklevel=stacklevel)
    return graph


def _native_path(path: Any, what: str) -> bytes:
    """The file system's bytes of a path (str, bytes or PathLike): non-UTF-8 names work."""
    try:
        return os.fsencode(os.fspath(path))
    except TypeError:
        raise TypeError(f"{what}: path must be a str, bytes or os.PathLike, got "
                        f"{type(path).__name__}") from None


def _as_arg(native: bytes) -> str:
    """``native`` for a binding whose stub says ``str``: pybind's std::string takes the
    bytes as they are, so a name that is not UTF-8 reaches the file system intact."""
    return cast(str, native)


def _named(call: Callable[[], Any], native: bytes) -> Any:
    """``call()``, with an error message that names a non-UTF-8 file readably."""
    try:
        return call()
    except UnicodeDecodeError:  # the C++ message held the raw bytes of the name
        raise OSError(f"cannot read or write '{os.fsdecode(native)}'") from None


def save_g2o(graph: PoseGraph, path: PathType) -> None:
    """Writes ``graph`` with its current estimates (see :meth:`PoseGraph.save_g2o`)."""
    graph.save_g2o(path)
