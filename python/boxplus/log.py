"""What boxplus says, through Python's :mod:`logging`, and progress of long runs.

boxplus writes nothing to the process' stdout or stderr by itself (the
``verbose=True`` of the solves prints with Python's ``print``, so
``contextlib.redirect_stdout`` and notebooks capture it). Everything else goes
to two loggers:

``boxplus``
    Load reports of pose-graph files (INFO), their warnings (WARNING, also
    issued as Python warnings), solve summaries (INFO) and, at DEBUG, one line
    per iteration of a pose-graph solve.
``boxplus.ceres``
    Ceres' own glog messages (its INFO at DEBUG, WARNING, ERROR), with Ceres'
    file and line. glog itself writes neither files nor stderr (below FATAL).
    boxplus initialises glog when it is imported, unless the process already
    has (then only the routing is added); a library imported later that
    initialises glog without asking ``IsGoogleLoggingInitialized()`` first
    would stop the process with glog's "called InitGoogleLogging() twice":
    import such a library before boxplus.

Like every library, boxplus only adds a :class:`logging.NullHandler`: nothing
is shown until the application configures logging, e.g.
``logging.basicConfig(level=logging.INFO)`` or :func:`enable`.

Per-iteration lines and the χ² of summaries use the one format of
``boxplus/progress.h`` (χ² = Σ ρ(‖rᵢ‖²) = 2 × Ceres' cost).
:class:`Progress` is a solve callback that sends them to a logger and/or
shows a ``tqdm`` progress bar (an optional dependency: without tqdm there is
no bar, and no error)::

    with boxplus.log.Progress(bar=True) as progress:
        problem.solve(callback=progress)
"""

from __future__ import annotations

import logging
import sys
from typing import IO, Any, Callable

from boxplus import _core

__all__ = ["LoadProgress", "Progress", "enable", "flush_native", "logger", "log_summary"]

logger = logging.getLogger("boxplus")
logger.addHandler(logging.NullHandler())
ceres_logger = logging.getLogger("boxplus.ceres")

# glog severities → logging levels. Ceres' INFO messages are internals.
_GLOG_LEVELS = {0: logging.DEBUG, 1: logging.WARNING, 2: logging.ERROR, 3: logging.CRITICAL}


def flush_native() -> int:
    """Emits the queued glog messages of Ceres on the ``boxplus.ceres`` logger.

    The C++ side schedules this call itself (``Py_AddPendingCall``) as soon as
    a message is queued, so it runs once the interpreter executes Python code
    again; calling it directly is harmless.

    Returns
    -------
    int
        The number of messages emitted.
    """
    records = _core._native_log_drain()
    for severity, file, line, message in records:
        level = _GLOG_LEVELS.get(int(severity), logging.ERROR)
        if ceres_logger.isEnabledFor(level):
            ceres_logger.handle(
                ceres_logger.makeRecord(ceres_logger.name, level, file, line, message, (), None)
            )
    return len(records)


def enable(level: int = logging.INFO, stream: IO[str] | None = None) -> logging.Handler:
    """Shows boxplus' messages: adds a stream handler to the ``boxplus`` logger.

    A convenience for scripts and notebooks; applications may configure
    :mod:`logging` themselves instead.

    Parameters
    ----------
    level : int
        The lowest level shown (``logging.DEBUG`` adds per-iteration lines of
        pose-graph solves and Ceres' internals).
    stream : file, optional
        Where to write; ``sys.stderr`` when not given (looked up at each
        message, so redirections apply).

    Returns
    -------
    logging.Handler
        The handler added; ``logger.removeHandler(handler)`` undoes the call.
    """
    handler: logging.Handler = (
        logging.StreamHandler(stream) if stream is not None else _StderrHandler()
    )
    handler.setFormatter(logging.Formatter("%(name)s %(levelname)s: %(message)s"))
    logger.addHandler(handler)
    logger.setLevel(level)
    return handler


class _StderrHandler(logging.StreamHandler):
    """A StreamHandler on whatever ``sys.stderr`` is when a record is written."""

    def __init__(self) -> None:
        super().__init__(sys.stderr)

    def emit(self, record: logging.LogRecord) -> None:
        self.setStream(sys.stderr)
        super().emit(record)


def log_summary(summary: Any, what: str = "solve", log: logging.Logger | None = None) -> None:
    """Logs a SolveSummary at INFO in the one format (``what: termination: chi2 a -> b ...``)."""
    log = log or logger
    if log.isEnabledFor(logging.INFO):
        log.info("%s: %s", what, _core.format_summary(summary))


def _tqdm() -> Any:
    """``tqdm.auto.tqdm`` (a widget in notebooks, text elsewhere), or None without tqdm."""
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return None
    return tqdm


class _WithBar:
    """Owns an optional tqdm bar: ``has_bar``, :meth:`close`, and the context
    manager that closes it."""

    _bar: Any = None

    @property
    def has_bar(self) -> bool:
        """Whether a tqdm bar is shown (False without tqdm)."""
        return self._bar is not None

    def close(self) -> None:
        """Closes the bar (if any)."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    def __enter__(self) -> Any:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


class Progress(_WithBar):
    """A solve callback that reports each iteration to a logger and/or a bar.

    Parameters
    ----------
    log : logging.Logger or None
        Where the per-iteration lines go (the ``boxplus/progress.h`` format,
        header before iteration 0); None: no lines.
    level : int
        Their level (default INFO: shown by ``logging.basicConfig(level=INFO)``).
    bar : bool
        Show a ``tqdm`` bar of iterations with the current χ² (nothing when
        tqdm is not installed).
    total : int, optional
        The bar's length: the solve's ``max_iterations``.
    callback : callable, optional
        Called after the reporting with the same ``IterationInfo``; its return
        value is returned (False stops the solve).
    file : file, optional
        The bar's stream (tqdm's default, stderr, when not given).

    Notes
    -----
    Use it as a context manager, or call :meth:`close`, to close the bar.
    """

    def __init__(
        self,
        log: logging.Logger | None = logger,
        level: int = logging.INFO,
        bar: bool = False,
        total: int | None = None,
        callback: Callable[[Any], Any] | None = None,
        file: IO[str] | None = None,
    ) -> None:
        if callback is not None and not callable(callback):
            raise TypeError(f"callback must be callable, got {type(callback).__name__}")
        self.log, self.level, self.callback = log, level, callback
        self.iterations = 0
        self.chi2 = float("nan")
        tqdm = _tqdm() if bar else None
        self._bar = None
        if tqdm is not None:
            kw: dict[str, Any] = {"total": total, "unit": "it", "desc": "solve", "leave": False}
            if file is not None:
                kw["file"] = file
            self._bar = tqdm(**kw)

    def __call__(self, info: Any) -> Any:
        self.iterations = int(info.iteration)
        self.chi2 = 2.0 * float(info.cost)
        if self.log is not None and self.log.isEnabledFor(self.level):
            if info.iteration == 0:
                self.log.log(self.level, "%s", _core.progress_header())
            self.log.log(self.level, "%s", _core.format_progress(info))
        if self._bar is not None:
            if info.iteration > 0:
                self._bar.update(1)
            self._bar.set_postfix_str(f"chi2={self.chi2:.6g}", refresh=False)
        return self.callback(info) if self.callback is not None else None


class LoadProgress(_WithBar):
    """A ``progress(lines, bytes_read, bytes_total)`` callback of a file load:
    a tqdm bar of bytes (nothing without tqdm).

    Parameters
    ----------
    name : str
        The bar's label (the file's name).
    file : file, optional
        The bar's stream (tqdm's default, stderr, when not given).
    """

    def __init__(self, name: str, file: IO[str] | None = None) -> None:
        self.name, self.file = name, file
        self.lines = 0
        self._bar = None
        self._done = 0

    def __call__(self, lines: int, bytes_read: int, bytes_total: int) -> None:
        self.lines = int(lines)
        if self._bar is None and self._done == 0:
            tqdm = _tqdm()
            if tqdm is None:
                self._done = -1  # no tqdm: count lines only
                return
            kw: dict[str, Any] = {"total": int(bytes_total), "unit": "B", "unit_scale": True,
                                  "desc": self.name, "leave": False}
            if self.file is not None:
                kw["file"] = self.file
            self._bar = tqdm(**kw)
        if self._bar is not None:
            self._bar.update(int(bytes_read) - self._done)
            self._done = int(bytes_read)

