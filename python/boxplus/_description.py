"""What an :class:`boxplus.OptimizationProblem` is rebuilt from when it is unpickled.

The C++ problem holds cost functions, not their inputs, so a problem cannot be
copied from its solver state. Instead every public call that builds one
(``add_random_var``, every ``add_*`` measurement, ``fix``, ``unfix``,
``set_value``) is journalled with its arguments: variables with their initial
values, measurements with their functions *by reference* (pickle stores a
module-level function as its qualified name; cloudpickle, which Ray and Dask
use, also stores lambdas and closures by value), noise, losses and constants.
Unpickling replays the journal on a new problem, then sets the current values
and fixed flags, so the copy solves to the same result bit for bit.

Arrays passed to a journalled call are copied (a caller may fill the same
buffer for the next call), except those a Python measurement keeps by
reference (its ``z`` and ``constants``), which stay shared as in the problem
itself. Calls made inside a journalled call are not
journalled again. A problem changed around the public calls (``_core`` used
directly) is refused with a :class:`pickle.PicklingError` instead of being
rebuilt wrongly.
"""

from __future__ import annotations

import copy
import functools
import inspect
import pickle
from typing import Any, Callable

import numpy as np

from boxplus import _core
from boxplus.manifolds import ManifoldValue

__all__ = ["JOURNALLED", "journal_calls", "state_of", "rebuild"]

# The calls that build a problem; a name missing from a class is skipped.
JOURNALLED = (
    "add_random_var", "add_measurement", "add_measurements", "add_prior", "add_projection",
    "add_board", "add_marker", "add_dh_marker", "add_gravity", "add_relative_pose", "add_point",
    "add_disparity", "fix", "unfix", "set_value",
)
_VERSION = 1


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


# The arguments a Python measurement keeps by reference (its z rows may be views
# of the caller's array, its constants are the caller's objects): a later change
# reaches the problem, so it must reach the copy alike, and pickle keeps one
# object passed twice as one. Everything else is converted when added: frozen.
_BY_REFERENCE = {"add_measurement": ("z", "constants"), "add_measurements": ("Z", "constants")}


def _entry(name: str, signature: inspect.Signature, self: Any, args: tuple,
           kwargs: dict[str, Any]) -> tuple[str, tuple, dict[str, Any]]:
    """The journal entry of a call: its arguments frozen, but those the problem keeps
    by reference (:data:`_BY_REFERENCE`)."""
    kept = _BY_REFERENCE.get(name)
    if kept is None:  # everything frozen: no need to know which argument is which
        return name, tuple(_frozen(a) for a in args), {k: _frozen(v) for k, v in kwargs.items()}
    try:
        bound = signature.bind(self, *args, **kwargs)
    except TypeError:  # the call itself will raise the same error
        return name, args, kwargs
    for key, value in bound.arguments.items():
        if key != "self" and key not in kept:
            bound.arguments[key] = _frozen(value)
    return name, bound.args[1:], bound.kwargs


def _journalled(method: Callable) -> Callable:
    name = method.__name__
    signature = inspect.signature(method)

    @functools.wraps(method)
    def call(self: Any, *args: Any, **kwargs: Any) -> Any:
        d = self.__dict__
        depth = d.get("_journal_depth", 0)
        if depth:
            return method(self, *args, **kwargs)
        entry = _entry(name, signature, self, args, kwargs)
        d["_journal_depth"] = 1
        before = _counts(self)
        try:
            result = method(self, *args, **kwargs)
        except BaseException:
            if _counts(self) != before:  # a partial change the journal cannot replay
                d["_journal_broken"] = f"{name} failed after changing the problem"
            raise
        finally:
            d["_journal_depth"] = 0
        d.setdefault("_journal", []).append(entry)
        d["_journal_counts"] = _counts(self)
        return result

    return call


def journal_calls(cls: type) -> type:
    """Journals the building calls of ``cls`` (:data:`JOURNALLED`); returns ``cls``."""
    for name in JOURNALLED:
        method = getattr(cls, name, None)
        if method is not None and not getattr(method, "_boxplus_journalled", False):
            wrapped = _journalled(method)
            wrapped._boxplus_journalled = True  # type: ignore[attr-defined]
            setattr(cls, name, wrapped)
    return cls


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


def _loss_objects(args: Any) -> bool:
    if isinstance(args, _core.Loss):
        return True
    if isinstance(args, (list, tuple)):
        return any(_loss_objects(a) for a in args)
    if isinstance(args, dict):
        return any(_loss_objects(a) for a in args.values())
    return False


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
            f"measurements, its public add_* calls made {expected[0]} and {expected[1]} (were "
            f"some added through _core directly?)")
    for k, (name, args, kwargs) in enumerate(journal):
        if _loss_objects((args, kwargs)):
            raise pickle.PicklingError(
                f"OptimizationProblem cannot be described: call {k} ({name}) was given a "
                f"boxplus.Loss object, whose width is not kept exactly; pass the loss as a name "
                f"or a (name, width) pair to make the problem picklable")
    core = problem._core
    memo: dict[int, _ExactValue] = {}
    return {
        "version": _VERSION,
        "journal": [(name, _exact_values(args, memo), _exact_values(kwargs, memo))
                    for name, args, kwargs in journal],
        "values": [core.value(i) for i in range(have[0])],
        "fixed": [core.is_fixed(i) for i in range(have[0])],
        "counts": have,
    }


def rebuild(problem: Any, state: dict[str, Any]) -> None:
    """Replays ``state`` (from :func:`state_of`) on a freshly initialised ``problem``."""
    if not isinstance(state, dict) or state.get("version") != _VERSION:
        raise pickle.UnpicklingError("not the state of a boxplus.OptimizationProblem of this "
                                     f"version (expected version {_VERSION})")
    for name, args, kwargs in state["journal"]:
        getattr(problem, name)(*args, **kwargs)
    if _counts(problem) != tuple(state["counts"]):
        raise pickle.UnpicklingError(
            f"the rebuilt problem has {_counts(problem)} (variables, measurements), the pickled "
            f"one had {tuple(state['counts'])}")
    core = problem._core
    for vid, (value, fixed) in enumerate(zip(state["values"], state["fixed"])):
        core.restore_value(vid, value)  # the same bits, not renormalised
        core.set_fixed(vid, bool(fixed))
