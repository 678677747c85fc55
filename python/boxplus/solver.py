"""One solve loop for every front end: the bound solver vocabulary and its printer.

:class:`SolverOptions`, :class:`IterationInfo` and :class:`SolveSummary` are the
C++ types (``boxplus/solver_options.h``) bound as classes; :func:`run` is the
one place a Python front end (:class:`boxplus.OptimizationProblem`,
:class:`boxplus.slam.PoseGraph`) starts a solve, so options, callbacks and the
progress lines (χ² = 2 × cost, the C++ format of ``boxplus/progress.h``) are
the same everywhere.

Every solve runs with the BLAS libraries of the process capped at the solve's
``num_threads`` (:func:`boxplus.blas_threads.limit`, restored afterwards), so
a default single-threaded solve does not also start a BLAS thread per core.
"""

from __future__ import annotations

from typing import Any, Callable

from boxplus import _core, blas_threads

__all__ = ["IterationInfo", "SolveSummary", "SolverOptions", "run"]

SolverOptions = _core.SolverOptions
IterationInfo = _core.IterationInfo
SolveSummary = _core.SolveSummary


def run(
    problem: Any,
    options: SolverOptions | None = None,
    callback: Callable[[IterationInfo], Any] | None = None,
    verbose: bool = False,
    **overrides: Any,
) -> SolveSummary:
    """Solves ``problem`` with ``options`` (fields overridden by keyword).

    ``problem`` is anything with the C++ ``solve(options, callback,
    **overrides)`` of :class:`boxplus._core.Problem` (also the C++ pose graph,
    whose solve may restart from other starts).

    ``verbose`` prints one line per iteration and a summary with Python's
    ``print`` (C++ would write to stderr, which notebooks and
    ``contextlib.redirect_stdout`` do not see).

    BLAS (CHOLMOD's kernels, numpy) runs with at most ``num_threads``
    threads during the solve (:func:`boxplus.blas_threads.limit`).
    """
    if callback is not None and not callable(callback):
        raise TypeError(f"callback must be callable, got {type(callback).__name__}")
    verbose = bool(verbose or overrides.pop("verbose", False) or getattr(options, "verbose", False))
    cb = callback
    if verbose:
        print(_core.progress_header(), flush=True)

        def cb(info: IterationInfo) -> Any:
            print(_core.format_progress(info), flush=True)
            return callback(info) if callback is not None else None

    with blas_threads.limit(_num_threads(options, overrides)):
        summary = problem.solve(options, cb, **overrides, verbose=False)
    if verbose:
        print(_core.format_summary(summary), flush=True)
    return summary


def _num_threads(options: SolverOptions | None, overrides: dict[str, Any]) -> int:
    """The solve's ``num_threads`` (a bad value is left for the C++ check to name)."""
    n = overrides.get("num_threads", getattr(options, "num_threads", None))
    if n is None:
        n = SolverOptions().num_threads
    try:
        return max(1, int(n))
    except (TypeError, ValueError):
        return 1
