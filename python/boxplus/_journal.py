"""The journal an :class:`boxplus.OptimizationProblem` is rebuilt from when it
is copied or unpickled.

The C++ problem holds cost functions, not their inputs, so a problem cannot be
copied from its solver state. Instead every public call that builds one is
*journalled* with its arguments: a function that adds variables or
measurements to a problem (a method of the problem, or a free function of a
domain package such as ``boxplus.calib.add_board`` or the joint terms of
``boxplus.joint``) is decorated with :func:`journalled`, and each top-level
call appends ``(function, args, kwargs)`` to the problem's journal. There is
no list of names to keep in step: a new factor function is journalled by its
own decorator, wherever it lives.

Functions are stored by reference (pickle stores a module-level function or
method as its qualified name; cloudpickle, which Ray and Dask use, also
stores lambdas and closures by value); so are the measurement functions,
noise models (exact W) and constants passed to them. Unpickling replays the
journal on a new problem, then sets the current values and fixed flags, so
the copy solves to the same result bit for bit.

Arrays passed to a journalled call are copied (a caller may fill the same
buffer for the next call), except the arguments a call keeps by reference
(``by_reference=``: a Python measurement's ``z`` and ``constants``), which
stay shared as in the problem itself. Calls made inside a journalled call are
not journalled again. A problem changed around the journalled calls (``_core``
used directly, or ``add_factor`` called with a C++ factor, which cannot be
pickled) is refused with a :class:`pickle.PicklingError` naming the call.
"""

from __future__ import annotations

import copy
import functools
import inspect
import pickle
from collections.abc import Sequence
from typing import Any, Callable, TypeVar

import numpy as np

from boxplus import _core
from boxplus.manifolds import ManifoldValue

__all__ = ["journalled", "rebuild", "state_of"]

_VERSION = 2
F = TypeVar("F", bound=Callable[..., Any])


def _frozen(arg: Any) -> Any:
    """``arg`` with its writeable arrays and Python manifold values copied (in lists,
    tuples and dicts too)."""
    if isinstance(arg, np.ndarray):
        return arg.copy() if arg.flags.writeable else arg
    if isinstance(arg, ManifoldValue):
        return copy.deepcopy(arg)
    if isinstance(arg, (list, tuple)):
        out = [_frozen(a) for a in arg]
        return out if isinstance(arg, list) else type(arg)(out) if type(arg) is tuple else arg
    if isinstance(arg, dict):
        return {k: _frozen(v) for k, v in arg.items()}
    return arg


def _counts(problem: Any) -> tuple[int, int]:
    return problem._core.num_variables, problem._core.num_measurements


def journalled(fn: F | None = None, *, by_reference: Sequence[str] = ()) -> Any:
    """Decorates ``fn(problem, ...)`` so that its top-level calls are journalled.

    Parameters
    ----------
    fn : callable
        A method of an OptimizationProblem or a module-level function whose
        first argument is the problem. It must be reachable by its qualified
        name (pickle stores it by reference).
    by_reference : sequence of str
        Names of the arguments the problem keeps by reference (not copied into
        the journal), so that a later change by the caller reaches the copy as
        it reaches the problem.
    """
    if fn is None:
        return lambda f: journalled(f, by_reference=by_reference)
    signature = inspect.signature(fn)
    kept = tuple(by_reference)

    def entry(problem: Any, args: tuple, kwargs: dict[str, Any]) -> tuple[Any, tuple, dict]:
        if not kept:
            return call, tuple(_frozen(a) for a in args), {k: _frozen(v) for k, v in kwargs.items()}
        try:
            bound = signature.bind(problem, *args, **kwargs)
        except TypeError:  # the call itself will raise the same error
            return call, args, kwargs
        first = next(iter(signature.parameters))
        for key, value in bound.arguments.items():
            if key != first and key not in kept:
                bound.arguments[key] = _frozen(value)
        return call, bound.args[1:], bound.kwargs

    @functools.wraps(fn)
    def call(problem: Any, *args: Any, **kwargs: Any) -> Any:
        d = problem.__dict__
        if d.get("_journal_depth", 0):
            return fn(problem, *args, **kwargs)
        record = entry(problem, args, kwargs)
        d["_journal_depth"] = 1
        before = _counts(problem)
        try:
            result = fn(problem, *args, **kwargs)
        except BaseException:
            if _counts(problem) != before:  # a partial change the journal cannot replay
                d["_journal_broken"] = f"{fn.__qualname__} failed after changing the problem"
            raise
        finally:
            d["_journal_depth"] = 0
        d.setdefault("_journal", []).append(record)
        d["_journal_counts"] = _counts(problem)
        return result

    call.__boxplus_journalled__ = True  # type: ignore[attr-defined]
    return call


def _exact(kind: str, ambient: np.ndarray) -> Any:
    return _core.exact_value(kind, ambient)


class _ExactValue:
    """Pickles an SO3, SE3 or S2 with its exact ambient bits: their own pickling
    goes through ``from_ambient``, whose normalisation can move the last bit of a
    measured value, and then the copy would not solve bit for bit like the original."""

    def __init__(self, value: Any) -> None:
        self.kind = type(value).__name__
        self.ambient = np.array(value.ambient, dtype=float)

    def __reduce__(self) -> tuple[Any, tuple[str, np.ndarray]]:
        return _exact, (self.kind, self.ambient)


_UNIT_KINDS = (_core.SO3, _core.SE3, _core.S2)


def _exact_values(arg: Any, memo: dict[int, _ExactValue]) -> Any:
    """``arg`` with its SO3, SE3 and S2 values (in lists, tuples and dicts too) wrapped
    in :class:`_ExactValue`, one wrapper per value (``memo``), so that a value passed
    twice is still one object in the copy."""
    if type(arg) in _UNIT_KINDS:
        if id(arg) not in memo:
            memo[id(arg)] = _ExactValue(arg)
        return memo[id(arg)]
    if isinstance(arg, list):
        return [_exact_values(a, memo) for a in arg]
    if type(arg) is tuple:
        return tuple(_exact_values(a, memo) for a in arg)
    if isinstance(arg, dict):
        return {k: _exact_values(v, memo) for k, v in arg.items()}
    return arg


def _unwrapped(arg: Any) -> Any:
    """``arg`` with :class:`_ExactValue` wrappers replaced by their values (a state
    used without a pickle round trip: :meth:`OptimizationProblem.copy`)."""
    if isinstance(arg, _ExactValue):
        return _exact(arg.kind, arg.ambient)
    if isinstance(arg, list):
        return [_unwrapped(a) for a in arg]
    if type(arg) is tuple:
        return tuple(_unwrapped(a) for a in arg)
    if isinstance(arg, dict):
        return {k: _unwrapped(v) for k, v in arg.items()}
    return arg


def _find(args: Any, kinds: tuple[type, ...]) -> Any:
    """The first object of one of ``kinds`` in args (lists, tuples, dicts searched)."""
    if isinstance(args, kinds):
        return args
    if isinstance(args, (list, tuple)):
        for a in args:
            found = _find(a, kinds)
            if found is not None:
                return found
    if isinstance(args, dict):
        return _find(list(args.values()), kinds)
    return None


def state_of(problem: Any) -> dict[str, Any]:
    """The picklable description of ``problem`` (see the module docstring)."""
    d = problem.__dict__
    broken = d.get("_journal_broken")
    if broken:
        raise pickle.PicklingError(f"OptimizationProblem cannot be described: {broken}")
    journal = d.get("_journal", [])
    expected = d.get("_journal_counts", (0, 0))
    have = _counts(problem)
    if have != expected:
        raise pickle.PicklingError(
            f"OptimizationProblem cannot be described: it has {have[0]} variables and {have[1]} "
            f"measurements, its journalled calls made {expected[0]} and {expected[1]} (were "
            f"some added through _core directly?)")
    for k, (fn, args, kwargs) in enumerate(journal):
        found = _find((args, kwargs), (_core.Loss, _core.Factor))
        if isinstance(found, _core.Loss):
            raise pickle.PicklingError(
                f"OptimizationProblem cannot be described: call {k} ({fn.__qualname__}) was given "
                f"a boxplus.Loss object, whose width is not kept exactly; pass the loss as a name "
                f"or a (name, width) pair to make the problem picklable")
        if found is not None:
            raise pickle.PicklingError(
                f"OptimizationProblem cannot be described: call {k} ({fn.__qualname__}) was given "
                f"a C++ Factor, which holds a cost function, not its inputs; add factors through "
                f"a function decorated with boxplus._journal.journalled, which is journalled "
                f"with its arguments")
    core = problem._core
    memo: dict[int, _ExactValue] = {}
    return {
        "version": _VERSION,
        "journal": [(fn, _exact_values(args, memo), _exact_values(kwargs, memo))
                    for fn, args, kwargs in journal],
        "values": [core.value(i) for i in range(have[0])],
        "fixed": [core.is_fixed(i) for i in range(have[0])],
        "counts": have,
    }


def rebuild(problem: Any, state: dict[str, Any]) -> None:
    """Replays ``state`` (from :func:`state_of`) on a freshly initialised ``problem``."""
    if not isinstance(state, dict) or state.get("version") != _VERSION:
        raise pickle.UnpicklingError("not the state of a boxplus.OptimizationProblem of this "
                                     f"version (expected version {_VERSION})")
    for fn, args, kwargs in state["journal"]:
        fn(problem, *_unwrapped(args), **_unwrapped(kwargs))
    if _counts(problem) != tuple(state["counts"]):
        raise pickle.UnpicklingError(
            f"the rebuilt problem has {_counts(problem)} (variables, measurements), the pickled "
            f"one had {tuple(state['counts'])}")
    core = problem._core
    for vid, (value, fixed) in enumerate(zip(state["values"], state["fixed"])):
        core.restore_value(vid, value)  # the same bits, not renormalised
        core.set_fixed(vid, bool(fixed))
