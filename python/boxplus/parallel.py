"""Many independent solves at once: on threads, processes, Ray or Dask.

:func:`solve_many` solves a list of problems, or the problems a builder makes
from a list of inputs (one per robot of a fleet, per fold, per restart), on
any executor:

* ``None``: serially, in this thread (the reference every executor matches);
* any :class:`concurrent.futures.Executor`: ``ThreadPoolExecutor`` (the GIL
  is released while C++ measurements are solved, so threads scale for them),
  ``ProcessPoolExecutor``;
* a Dask ``distributed.Client`` (or its ``client.get_executor()``);
* Ray: :class:`RayExecutor` below, or ``ray.util.multiprocessing.Pool``
  (anything with ``apply_async``).

Each task is deterministic: it gets its problem (or its input and, with
``seed``, its own random generator ``numpy.random.default_rng([seed, index])``)
whatever worker runs it, and a task (build, solve, ``extract``) caps BLAS at
the solve's ``num_threads`` (:mod:`boxplus.blas_threads`), so tasks side by
side do not oversubscribe the cores and every executor returns the serial
answer to the last bit. A task whose *code* raises reports the error (its traceback as
text) in its :class:`TaskResult`; a task whose *worker* fails (a process that
died, a lost connection, a cancelled future) is submitted again, at most
``retries`` times, and reported as failed if it still does not come back.

Ray and Dask are optional (``pip install boxplus[ray]`` / ``boxplus[dask]``);
this module imports neither until :class:`RayExecutor` is created.
"""

from __future__ import annotations

import concurrent.futures
import traceback
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from boxplus import blas_threads, solver
from boxplus._plain import fields_todict, plain

__all__ = ["RayExecutor", "TaskError", "TaskResult", "map_tasks", "map_values", "solve_many"]


@dataclass
class TaskResult:
    """What one task of :func:`solve_many` (or :func:`map_tasks`) gave.

    Attributes
    ----------
    index : int
        The task's position in the list of problems or inputs.
    value : Any
        The solved problem, or what ``extract(problem, summary)`` returned
        (:func:`map_tasks`: the function's return value); None on error.
    summary : SolveSummary or None
        The solve's summary (None on error and for :func:`map_tasks`).
    error : str or None
        None on success; else the exception and its traceback as text (an
        error of the task's code) or the last worker failure.
    worker_failed : bool
        Whether ``error`` is a worker failure (after ``attempts`` attempts)
        rather than an error of the task itself.
    attempts : int
        How many times the task was submitted.
    """

    index: int
    value: Any = None
    summary: Any = None
    error: str | None = None
    worker_failed: bool = False
    attempts: int = 1

    @property
    def ok(self) -> bool:
        """Whether the task ran to the end without an error."""
        return self.error is None

    def todict(self) -> dict[str, Any]:
        """Plain Python values (``json.dumps`` takes them). ``value`` is converted when it
        is plain data or a result (an OptimizationProblem becomes None: it is not data)."""
        out = fields_todict(self, skip=("value",))
        try:
            out["value"] = plain(self.value)
        except TypeError:
            out["value"] = None
        return out


def _run(fn: Callable, index: int, args: tuple) -> TaskResult:
    """Runs one task on a worker; its own errors come back as text, not as exceptions,
    so that an exception out of ``future.result()`` always means a worker failure."""
    try:
        value = fn(*args)
    except Exception as e:
        text = "".join(traceback.format_exception(type(e), e, e.__traceback__))
        return TaskResult(index, error=text)
    if isinstance(value, TaskResult):
        value.index = index
        return value
    return TaskResult(index, value=value)


class _Pending:
    """A submitted task: ``result()`` whatever the executor's kind of future."""

    def __init__(self, handle: Any, get: Callable[[Any], Any]) -> None:
        self.handle, self.get = handle, get

    def result(self) -> Any:
        return self.get(self.handle)


def _submit(executor: Any, fn: Callable, *args: Any) -> _Pending:
    if executor is None:  # serially, now; a raise here is the task's own, not a worker's
        done: concurrent.futures.Future = concurrent.futures.Future()
        done.set_result(fn(*args))
        return _Pending(done, lambda f: f.result())
    kind = type(executor)
    if kind.__name__ == "Client" and kind.__module__.startswith("distributed"):
        # pure=False: a resubmission must run again, not return the failed key's result.
        return _Pending(executor.submit(fn, *args, pure=False), lambda f: f.result())
    if hasattr(executor, "submit"):
        return _Pending(executor.submit(fn, *args), lambda f: f.result())
    if hasattr(executor, "apply_async"):  # multiprocessing-style pools (ray.util.multiprocessing)
        return _Pending(executor.apply_async(fn, args), lambda r: r.get())
    raise TypeError(f"executor must be None, a concurrent.futures.Executor, a dask Client or a "
                    f"pool with apply_async, got {kind.__name__}")


def map_tasks(fn: Callable, tasks: Sequence[tuple], executor: Any = None,
              retries: int = 2) -> list[TaskResult]:
    """Runs ``fn(*task)`` for every tuple of ``tasks`` on ``executor``; results in task order.

    Parameters
    ----------
    fn : callable
        A picklable function (module-level, or anything cloudpickle takes for
        Ray and Dask).
    tasks : sequence of tuple
        The arguments of each call.
    executor : None, concurrent.futures.Executor, dask Client or pool, optional
        Where the calls run (module docstring); None: serially, here.
    retries : int
        How many times a task whose worker failed is submitted again.

    Returns
    -------
    list of TaskResult
        One per task; ``value`` is what ``fn`` returned (or, if ``fn``
        returned a TaskResult, that one with its index set).
    """
    if int(retries) != retries or retries < 0:
        raise ValueError(f"retries must be a non-negative integer, got {retries!r}")
    tasks = [tuple(t) for t in tasks]
    pending = [_submit(executor, _run, fn, i, t) for i, t in enumerate(tasks)]
    out: list[TaskResult] = []
    for i, p in enumerate(pending):
        attempts = 1
        while True:
            try:
                r = p.result()
                break
            except Exception as e:  # the worker, not the task (_run returns the task's errors)
                if attempts > retries:
                    r = TaskResult(i, error=f"worker failure after {attempts} attempts: "
                                   f"{type(e).__name__}: {e}", worker_failed=True)
                    break
                attempts += 1
                try:
                    p = _submit(executor, _run, fn, i, tasks[i])
                except Exception as e2:  # e.g. a broken process pool refuses new work
                    r = TaskResult(i, error=f"worker failure after {attempts - 1} attempts, "
                                   f"resubmission refused: {type(e2).__name__}: {e2}",
                                   worker_failed=True)
                    break
        r.attempts = attempts
        out.append(r)
    return out


def _solve_task(problem: Any, builder: Callable | None, item: Any, rng_key: Any,
                extract: Callable | None, options: Any, overrides: dict[str, Any]) -> TaskResult:
    """One task of solve_many, on a worker: build (if asked), solve, extract, all with
    BLAS capped at the solve's num_threads (the tasks beside it have the other cores)."""
    with blas_threads.limit(solver._num_threads(options, overrides)):
        if builder is not None:
            problem = builder(item) if rng_key is None else builder(item, np.random.default_rng(rng_key))
        summary = problem.solve(options, **overrides)
        value = problem if extract is None else extract(problem, summary)
    return TaskResult(0, value=value, summary=summary)


class TaskError(RuntimeError):
    """A task of :func:`map_values` failed; the message holds its traceback (the task's own
    exception, raised on the worker) or the worker failure."""


def map_values(fn: Callable, tasks: Sequence[tuple], executor: Any, what: str,
               retries: int = 2) -> list[Any]:
    """``[fn(*task) for task in tasks]`` on ``executor`` (:func:`map_tasks`: any executor
    kind, worker failures retried), raising :class:`TaskError` for the first task that
    failed, with ``what`` and the task's index and traceback in the message. The one
    fan-out of boxplus' own parallel loops (restarts, cross-validation folds)."""
    results = map_tasks(fn, tasks, executor=executor, retries=retries)
    for r in results:
        if not r.ok:
            raise TaskError(f"{what}: task {r.index} failed:\n{r.error}")
    return [r.value for r in results]


def solve_many(
    problems: Any,
    inputs: Iterable[Any] | None = None,
    *,
    executor: Any = None,
    options: Any = None,
    extract: Callable[[Any, Any], Any] | None = None,
    seed: int | None = None,
    retries: int = 2,
    **overrides: Any,
) -> list[TaskResult]:
    """Solves many independent problems, serially or on an executor.

    Parameters
    ----------
    problems : sequence of problems, or callable
        Problems with a ``solve(options, **overrides)`` method
        (:class:`boxplus.OptimizationProblem`, a pose graph), or a *builder*
        ``builder(input)`` that makes one problem per entry of ``inputs``
        (``builder(input, rng)`` when ``seed`` is given). A pair
        ``(builder, inputs)`` is accepted too.
    inputs : iterable, optional
        The builder's inputs (one task each); only with a builder.
    executor : None, concurrent.futures.Executor, dask Client, pool with apply_async
        Where the tasks run (module docstring). None: serially, in this
        thread, the problems solved in place. On other processes the
        problems travel pickled (:meth:`OptimizationProblem.__getstate__`)
        and the solved copies come back.
    options : SolverOptions, optional
        The settings of every solve; ``**overrides`` replace its fields.
    extract : callable, optional
        ``extract(problem, summary)`` runs on the worker after the solve and
        its return value comes back instead of the problem (say, the few
        estimates a fleet needs: less to send than a whole problem).
    seed : int, optional
        With a builder: task i gets ``numpy.random.default_rng([seed, i])``,
        the same on every executor and worker.
    retries : int
        How many times a task whose worker failed is submitted again (errors
        raised by the task's own code are reported, not retried: they would
        happen again).

    Returns
    -------
    list of TaskResult
        In task order: ``value`` (the solved problem or ``extract``'s
        result), ``summary``, ``error`` (None on success), ``attempts``.

    Examples
    --------
    >>> from concurrent.futures import ThreadPoolExecutor
    >>> with ThreadPoolExecutor(2) as pool:                      # doctest: +SKIP
    ...     results = solve_many(build_rig, rigs, executor=pool, seed=7)
    >>> [r.index for r in results if not r.ok]                  # doctest: +SKIP
    """
    if isinstance(problems, tuple) and len(problems) == 2 and callable(problems[0]) and inputs is None:
        problems, inputs = problems
    if callable(problems) and not hasattr(problems, "solve"):
        if inputs is None:
            raise TypeError("solve_many(builder, inputs): a builder needs its inputs")
        items = list(inputs)
        tasks = [(None, problems, x, None if seed is None else [int(seed), i], extract, options,
                  overrides) for i, x in enumerate(items)]
    else:
        if inputs is not None:
            raise TypeError("solve_many(problems, inputs): inputs go with a builder, not with "
                            "ready problems")
        if seed is not None:
            raise TypeError("solve_many(problems, seed=...): the seed is for a builder's inputs")
        items = list(problems)
        for i, p in enumerate(items):
            if not hasattr(p, "solve"):
                raise TypeError(f"solve_many: problem {i} is a {type(p).__name__}, which has no "
                                f"solve()")
        if executor is None or isinstance(executor, concurrent.futures.ThreadPoolExecutor):
            ids = [id(p) for p in items]
            if len(set(ids)) != len(ids):
                raise ValueError("solve_many: the same problem object is listed twice (two "
                                 "solves of one problem cannot run at once)")
        tasks = [(p, None, None, None, extract, options, overrides) for p in items]
    return map_tasks(_solve_task, tasks, executor, retries)


class RayExecutor(concurrent.futures.Executor):
    """A :class:`concurrent.futures.Executor` over Ray tasks.

    Each ``submit(fn, *args)`` runs ``fn(*args)`` as one Ray task and returns
    Ray's own :class:`concurrent.futures.Future` of it. Ray must be
    initialised (``ray.init(...)``, locally or with ``address=`` of a cluster)
    before the first submit.

    Parameters
    ----------
    num_cpus : float
        CPUs Ray reserves per task (1: as many tasks at once as cores).
    max_retries : int
        Ray's own retries of a task whose worker process died, before the
        failure reaches :func:`solve_many` (which retries too).
    """

    def __init__(self, num_cpus: float = 1, max_retries: int = 0) -> None:
        from boxplus._optional import require

        self._ray = require("ray", "RayExecutor")
        self._options = dict(num_cpus=num_cpus, max_retries=max_retries)
        self._remote: Any = None

    def submit(self, fn: Callable, /, *args: Any, **kwargs: Any) -> concurrent.futures.Future:
        """``fn(*args, **kwargs)`` as one Ray task; its result or exception in a Future."""
        if self._remote is None:
            self._remote = self._ray.remote(_call).options(**self._options)
        return self._remote.remote(fn, args, kwargs).future()


def _call(fn: Callable, args: tuple, kwargs: dict[str, Any]) -> Any:
    return fn(*args, **kwargs)
