"""BLAS threads during a solve: they follow boxplus' own ``num_threads``.

The sparse Cholesky factorisation under a solve (CHOLMOD's supernodal
kernels) and numpy's linear algebra call BLAS, which is usually OpenBLAS with
its own pool of threads, one per core by default. A solve with
``num_threads=1`` therefore still ran on every core, and two solves side by
side (threads, processes, a fleet on Ray or Dask workers) each asked every
core for its BLAS calls: on a busy machine that oversubscription made solves
3–40× slower until ``OPENBLAS_NUM_THREADS=1`` was set by hand.

:func:`limit` caps every loaded BLAS library at ``num_threads`` for the
duration of a block and restores the previous counts afterwards;
:func:`boxplus.solver.run` wraps every solve in it. It uses ``threadpoolctl``
when it is installed and otherwise OpenBLAS' own ``openblas_set_num_threads``,
found at run time among the libraries already loaded into the process.

The count is process-wide, so concurrent blocks share it: while any block is
open, BLAS runs with the largest count requested by the open blocks, never
more than what was set before the first one opened (a smaller
``OPENBLAS_NUM_THREADS`` or an outer ``threadpoolctl`` limit is never raised),
and the last block to close restores it. A block opened inside another on
the same thread asks for no more than the outer one.

Bit-for-bit equality of threads and serial solves (the rule, tested): a solve
whose sparse factor is supernodal (CHOLMOD's BLAS kernels; large or dense
graphs) gives the same bits on any thread when OpenBLAS is single-threaded
from the process' start (``OPENBLAS_NUM_THREADS=1``, as ``make test`` and the
benchmarks run). With OpenBLAS' thread pool capped to one thread at run time
(this module), OpenBLAS still computes differently on the main thread than
on the others (measured: 1.3e-11 after one Gauss–Newton step of a 1500-pose
sphere, 1e-13 at convergence), so such solves agree to rounding, not to the
last bit. Small problems (simplicial factorisation, no BLAS) are
bit-identical either way.
"""

from __future__ import annotations

import ctypes
import os
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

__all__ = ["backend", "current", "limit"]

# The setter and getter spellings OpenBLAS is built with: the plain one
# (Debian's libopenblas), the 64-bit-integer suffix, and the prefixed one
# numpy and scipy wheels bundle.
_OPENBLAS_SYMBOLS = (
    ("openblas_set_num_threads", "openblas_get_num_threads"),
    ("openblas_set_num_threads64_", "openblas_get_num_threads64_"),
    ("scipy_openblas_set_num_threads64_", "scipy_openblas_get_num_threads64_"),
    ("scipy_openblas_set_num_threads", "scipy_openblas_get_num_threads"),
)


class _Pool:
    """One BLAS library's thread count: get() and set(n)."""

    def __init__(self, name: str, get: Any, set_: Any) -> None:
        self.name, self.get, self.set = name, get, set_


def _threadpoolctl_pools() -> list[_Pool] | None:
    try:
        import threadpoolctl
    except ImportError:
        return None
    controller = threadpoolctl.ThreadpoolController().select(user_api="blas")
    return [
        _Pool(lib.filepath, lambda lib=lib: int(lib.num_threads),
              lambda n, lib=lib: lib.set_num_threads(n))
        for lib in controller.lib_controllers
    ]


def _loaded_paths() -> list[str]:
    """Paths of the shared libraries mapped into this process whose name says OpenBLAS."""
    try:
        with open("/proc/self/maps", encoding="utf-8", errors="replace") as f:
            paths = {line.split(None, 5)[-1].strip() for line in f if "openblas" in line.lower()}
    except OSError:  # not Linux: only the global namespace is searched
        return []
    return sorted(p for p in paths if p.startswith("/"))


def _openblas_pools() -> list[_Pool]:
    pools: list[_Pool] = []
    seen: set[int] = set()
    handles: list[tuple[str, Any]] = []
    for path in _loaded_paths():
        try:
            handles.append((path, ctypes.CDLL(path, mode=os.RTLD_NOLOAD | os.RTLD_LOCAL)
                            if hasattr(os, "RTLD_NOLOAD") else ctypes.CDLL(path)))
        except OSError:
            continue
    if sys.platform != "win32":
        handles.append(("global namespace", ctypes.CDLL(None)))
    for where, lib in handles:
        for set_name, get_name in _OPENBLAS_SYMBOLS:
            setter = getattr(lib, set_name, None)
            getter = getattr(lib, get_name, None)
            if setter is None or getter is None:
                continue
            address = ctypes.cast(setter, ctypes.c_void_p).value or 0
            if address in seen:  # the same library reached twice
                continue
            seen.add(address)
            setter.argtypes, setter.restype = [ctypes.c_int], None
            getter.argtypes, getter.restype = [], ctypes.c_int
            pools.append(_Pool(f"{where}:{set_name}", lambda g=getter: int(g()),
                               lambda n, s=setter: s(int(n))))
    return pools


_lock = threading.Lock()
_active: list[int] = []  # the counts requested by the open blocks
_saved: list[tuple[_Pool, int]] = []  # each pool's count before the first block opened
_nested = threading.local()  # n: the count of this thread's innermost open block
_backend = "none"
_prefer_threadpoolctl = True  # False: OpenBLAS' own call even when threadpoolctl is installed


_cache: tuple[tuple[int, bool], list[_Pool]] | None = None


def _pools() -> list[_Pool]:
    """The BLAS pools of the process, scanned again only after an import.

    Scanning the loaded libraries costs about 1 ms, more than a small solve;
    a new BLAS comes into the process with a Python import (numpy, scipy,
    boxplus' own extension), so the number of imported modules tells when
    to look again.
    """
    global _cache
    key = (len(sys.modules), _prefer_threadpoolctl)
    if _cache is None or _cache[0] != key:
        _cache = (key, _scan_pools())
    return _cache[1]


def _scan_pools() -> list[_Pool]:
    global _backend
    pools = _threadpoolctl_pools() if _prefer_threadpoolctl else None
    if pools is not None:
        _backend = "threadpoolctl"
        return pools
    pools = _openblas_pools()
    _backend = "openblas" if pools else "none"
    return pools


def _apply() -> None:
    """Sets every saved pool to max(open requests), capped by its own count before."""
    want = max(_active)
    for pool, before in _saved:
        n = min(want, before)
        if pool.get() != n:
            pool.set(n)


@contextmanager
def limit(num_threads: int) -> Iterator[None]:
    """Caps the BLAS libraries loaded in this process at ``num_threads`` threads.

    Parameters
    ----------
    num_threads : int
        Threads BLAS may use inside the block (``SolverOptions.num_threads``
        for a solve), at least 1.

    Notes
    -----
    The libraries are looked up when the first of the concurrent blocks
    opens (again only after a Python import since the last look), so a BLAS
    loaded later (say scipy's, imported during a solve) is not capped by that
    block.
    """
    n = int(num_threads)
    if n < 1:
        raise ValueError(f"num_threads must be >= 1, got {num_threads}")
    outer = getattr(_nested, "n", None)
    if outer is not None:  # a block inside a block of this thread never raises its count
        n = min(n, outer)
    _nested.n = n
    with _lock:
        if not _active:
            _saved[:] = [(p, p.get()) for p in _pools()]
        _active.append(n)
        _apply()
    try:
        yield
    finally:
        _nested.n = outer
        with _lock:
            _active.remove(n)
            if _active:
                _apply()
            else:
                for pool, before in _saved:
                    if pool.get() != before:
                        pool.set(before)
                _saved.clear()


def current() -> dict[str, int]:
    """The thread count of every BLAS library found now, by library."""
    with _lock:
        return {p.name: p.get() for p in _pools()}


def backend() -> str:
    """How counts are set: ``'threadpoolctl'``, ``'openblas'`` (its own call) or ``'none'``."""
    with _lock:
        _pools()
        return _backend
