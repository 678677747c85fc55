"""todict() of every result type: plain Python values ``json.dumps`` takes.

One conversion for the C++ result classes (their read-only properties, found on
the class; python/bindings/bindings.h ``DefPropertiesToDict``) and for the Python
result dataclasses (their fields), so that a result nested in another (an
``EdgeVerdict`` in an ``OutlierReport``, a ``SolveSummary`` in a ``RestartResult``)
comes out the same way everywhere.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np


def plain(value: Any) -> Any:
    """``value`` as None, bool, int, float, str, list or dict (recursively).

    Results convert through their own ``todict()``; manifold values become their
    ambient vector ([p, q] for poses, q = [x, y, z, w]); arrays nested lists; a
    non-finite float stays a float (``json.dumps`` writes NaN/Infinity)."""
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value)
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, dict):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    todict = getattr(value, "todict", None)
    if callable(todict):
        return todict()
    ambient = getattr(value, "ambient", None)
    if ambient is not None:
        return np.asarray(ambient, dtype=float).tolist()
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return fields_todict(value)
    raise TypeError(f"todict: cannot convert a {type(value).__name__} to plain values")


def properties_todict(obj: Any) -> dict[str, Any]:
    """Every public read-only property of ``obj``'s class, converted by :func:`plain`."""
    return {name: plain(getattr(obj, name)) for name, attr in sorted(vars(type(obj)).items())
            if isinstance(attr, property) and not name.startswith("_")}


def fields_todict(obj: Any, skip: tuple[str, ...] = ()) -> dict[str, Any]:
    """Every field of the dataclass ``obj`` but ``skip``, converted by :func:`plain`."""
    return {f.name: plain(getattr(obj, f.name)) for f in dataclasses.fields(obj)
            if f.name not in skip}
