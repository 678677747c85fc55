"""Manifold values: the built-in kinds, user-defined ones, and named compounds.

Every value ``x`` of a manifold S behaves like a vector from outside:

* ``x + delta`` is x ⊞ δ, with ``delta`` a vector of ``x.dof`` numbers;
* ``y - x`` is y ⊟ x, a vector of ``x.dof`` numbers (same type on both sides);
* ``len(x) == x.dof`` is the tangent dimension.

The built-in kinds (:class:`Rn`, :class:`SO2`, :class:`SO3`, :class:`SE2`,
:class:`SE3`, :class:`S2`) are implemented in C++. A new kind is a subclass of
:class:`ManifoldValue` written in Python; :func:`make_compound` builds named
Cartesian products of any of them.

The solver stores each variable as an *ambient* vector (a quaternion for SO3,
``[p, q]`` for SE3, ...). A :class:`Codec` says how a type maps to that storage
and which ⊞/⊟ the solver uses for it.
"""

from __future__ import annotations

import abc
import sys
from dataclasses import dataclass
from typing import Any, Callable, ClassVar

import numpy as np

from boxplus import _core
from boxplus._core import S2, SE2, SE3, SO2, SO3, Rn

__all__ = [
    "Codec",
    "CodecPart",
    "ManifoldValue",
    "Rn",
    "S2",
    "SE2",
    "SE3",
    "SO2",
    "SO3",
    "codec_of",
    "make_compound",
]


class ManifoldValue(abc.ABC):
    """Base class of manifold types written in Python.

    A subclass defines ``dof`` and four methods; everything else (``+``, ``-``,
    ``len``, use as a variable or measurement of an OptimizationProblem) follows.

    Examples
    --------
    A plane as a unit normal and a distance (3 DOF)::

        class Plane(boxplus.ManifoldValue):
            dof = 3

            def __init__(self, normal, d):
                self.normal, self.d = boxplus.S2(normal), float(d)

            def boxplus(self, delta):
                return Plane((self.normal + delta[:2]).vec, self.d + delta[2])

            def boxminus(self, other):
                return np.r_[self.normal - other.normal, self.d - other.d]

            def to_ambient(self):
                return np.r_[self.normal.vec, self.d]

            @classmethod
            def from_ambient(cls, a):
                return cls(a[:3], a[3])
    """

    dof: ClassVar[int]

    @abc.abstractmethod
    def boxplus(self, delta: np.ndarray) -> ManifoldValue:
        """x ⊞ δ."""

    @abc.abstractmethod
    def boxminus(self, other: ManifoldValue) -> np.ndarray:
        """self ⊟ other, a vector of ``dof`` numbers."""

    @abc.abstractmethod
    def to_ambient(self) -> np.ndarray:
        """The value as a flat vector of fixed length (the solver's storage)."""

    @classmethod
    @abc.abstractmethod
    def from_ambient(cls, a: np.ndarray) -> ManifoldValue:
        """Inverse of :meth:`to_ambient`."""

    @property
    def ambient(self) -> np.ndarray:
        return np.asarray(self.to_ambient(), dtype=float)

    def __len__(self) -> int:
        return self.dof

    def __add__(self, delta: Any) -> ManifoldValue:
        d = np.asarray(delta, dtype=float)
        if d.shape != (self.dof,):
            raise ValueError(
                f"{type(self).__name__} ⊞ δ: expected a vector of {self.dof} numbers, "
                f"got shape {d.shape}"
            )
        return self.boxplus(d)

    def __sub__(self, other: Any) -> np.ndarray:
        if type(other) is not type(self):
            raise TypeError(
                f"{type(self).__name__} - x: x must be a {type(self).__name__}, "
                f"got {type(other).__name__}"
            )
        return np.asarray(self.boxminus(other), dtype=float)

    def isclose(self, other: Any, atol: float = 1e-9) -> bool:
        """Whether every coordinate of ``self ⊟ other`` is at most ``atol`` in magnitude.

        Parameters
        ----------
        other : same type as self
        atol : float
            Tolerance in the tangent's units.

        Returns
        -------
        bool
        """
        if not atol >= 0:
            raise ValueError("isclose: atol must be >= 0")
        if type(other) is type(self) and self == other:
            return True  # also where x ⊟ x rounds to a few ulps
        d = self - other
        return bool(d.size == 0 or np.max(np.abs(d)) <= atol)

    def __array__(self, dtype: Any = None, copy: bool | None = None) -> np.ndarray:
        """The ambient vector as a new float array (``numpy.asarray(x)``)."""
        if copy is False:
            raise ValueError("a copy of the ambient vector is always made: copy=False is impossible")
        a = np.array(self.to_ambient(), dtype=float)
        return a if dtype is None else a.astype(dtype)


# --------------------------------------------------------------------------------------
# Codecs: how a value type is stored by the solver
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Codec:
    """How values of one type map to the solver's storage, and what callers
    need to know about that type without switching on it.

    Subclasses carry the kind-specific behaviour (Rⁿ, the C++ built-ins,
    compounds); the base class is the behaviour of a Python
    :class:`ManifoldValue`.

    Attributes
    ----------
    name : str
        Type name, for messages.
    manifold : boxplus.Manifold
        The ⊞/⊟ the solver uses (C++ for built-in kinds and their compounds).
    value_type : type
        The Python type of the values.
    from_ambient : callable
        Ambient vector → value.
    to_ambient : callable
        Value → ambient vector.
    """

    name: str
    manifold: Any
    value_type: type
    from_ambient: Callable[[np.ndarray], Any]
    to_ambient: Callable[[Any], np.ndarray]

    @property
    def dof(self) -> int:
        return self.manifold.tangent_size

    @property
    def ambient_size(self) -> int:
        return self.manifold.ambient_size

    @property
    def is_euclidean(self) -> bool:
        """True when ⊞ is + and ⊟ is − on the ambient vector (Rⁿ)."""
        return False

    def parts(self) -> tuple[CodecPart, ...]:
        """The members of a compound with their slices; () for other kinds."""
        return ()

    def tangent_scale(self, X: np.ndarray) -> np.ndarray:
        """Magnitudes (N, dof) of the values in the rows of X (N, ambient size),
        per tangent direction, that size finite-difference steps: max(1, abs(x))
        for Rⁿ coordinates, member by member for compounds, 1 for directions of
        rotation-like kinds (their tangent is already scale-free)."""
        return np.ones((X.shape[0], self.dof))

    def labels(self) -> list[str]:
        """Names of the tangent directions, for reports: "[i]" unless the kind
        names them (SE3: p.x … θ.z, compounds: their members)."""
        return [f"[{i}]" for i in range(self.dof)]

    def plus_batch(self, X: np.ndarray, D: np.ndarray) -> np.ndarray:
        """Rows X ⊞ D (N, ambient size) for steps D (N, dof)."""
        return self.manifold.plus_batch(X, D)

    def view(self, X: np.ndarray) -> Any:
        """The batch of the values stored in the rows of X (:mod:`boxplus.batch`)."""
        return [self.from_ambient(row) for row in X]

    def perturbed_view(self, base: Any, direction: int, h: np.ndarray) -> Any:
        """The batch of ``base`` ⊞ (h · e_direction) built from the unperturbed batch
        without a round trip through the ambient storage, where the batch kind
        allows it; None otherwise (then use :meth:`plus_batch`)."""
        perturbed = getattr(base, "perturbed", None)
        return perturbed(direction, h) if perturbed is not None else None

    def display(self, value: Any) -> np.ndarray:
        """Numbers shown beside the tangent directions in reports (dof,): the
        coordinates where the ambient vector is the tangent, NaN otherwise."""
        a = np.asarray(self.to_ambient(value), dtype=float)
        return a if a.size == self.dof else np.full(self.dof, np.nan)


@dataclass(frozen=True, eq=False)  # slices are unhashable: identity semantics
class CodecPart:
    """A member of a compound: its name, codec and slices of the stacked
    ambient and tangent vectors."""

    name: str
    codec: Codec
    ambient: slice
    tangent: slice


@dataclass(frozen=True)
class _RnCodec(Codec):
    @property
    def is_euclidean(self) -> bool:
        return True

    def tangent_scale(self, X: np.ndarray) -> np.ndarray:
        return np.maximum(1.0, np.abs(X))

    def plus_batch(self, X: np.ndarray, D: np.ndarray) -> np.ndarray:
        return X + D  # ⊞ of Rⁿ is +: no round trip through C++

    def view(self, X: np.ndarray) -> Any:
        from boxplus.batch import RnBatch

        return RnBatch(X)

    def display(self, value: Any) -> np.ndarray:
        return np.asarray(value.vec, dtype=float)


@dataclass(frozen=True)
class _BuiltinCodec(Codec):
    tangent_labels: tuple[str, ...] = ()
    chart: Callable[[Any], np.ndarray] | None = None  # value → tangent at the identity

    def labels(self) -> list[str]:
        return list(self.tangent_labels) or super().labels()

    def view(self, X: np.ndarray) -> Any:
        from boxplus.batch import builtin_view

        return builtin_view(self.value_type, X)

    def display(self, value: Any) -> np.ndarray:
        return self.chart(value) if self.chart is not None else super().display(value)


@dataclass(frozen=True)
class _CompoundCodec(Codec):
    members: tuple[CodecPart, ...] = ()

    def parts(self) -> tuple[CodecPart, ...]:
        return self.members

    def tangent_scale(self, X: np.ndarray) -> np.ndarray:
        return np.concatenate([m.codec.tangent_scale(X[:, m.ambient]) for m in self.members], axis=1)

    def labels(self) -> list[str]:
        out: list[str] = []
        for m in self.members:
            n = m.codec.dof
            out += [m.name] if n == 1 else [f"{m.name}[{i}]" for i in range(n)]
        return out

    def view(self, X: np.ndarray) -> Any:
        from boxplus.batch import CompoundBatch

        return CompoundBatch(self.value_type, X)

    def display(self, value: Any) -> np.ndarray:
        return np.concatenate([m.codec.display(getattr(value, m.name)) for m in self.members])


_BUILTIN = (SO2, SO3, SE2, SE3, S2)
_codec_cache: dict[tuple[Any, ...], Codec] = {}
_LABELS: dict[type, tuple[str, ...]] = {
    SE3: ("p.x", "p.y", "p.z", "θ.x", "θ.y", "θ.z"),
    SE2: ("p.x", "p.y", "θ"),
    SO3: ("θ.x", "θ.y", "θ.z"),
    SO2: ("θ",),
}
_CHARTS: dict[type, Callable[[Any], np.ndarray]] = {
    SE3: lambda v: np.concatenate([v.pos, v.rot.log()]),
    SO3: lambda v: v.log(),
}


def _builtin_codec(cls: Any) -> Codec:  # a bound class: SO3, SE3, S2, ...
    key = (cls,)
    if key not in _codec_cache:
        _codec_cache[key] = _BuiltinCodec(
            cls.__name__, cls.manifold(), cls, cls.from_ambient, lambda v: v.ambient,
            _LABELS.get(cls, ()), _CHARTS.get(cls),
        )
    return _codec_cache[key]


def _rn_codec(n: int) -> Codec:
    key = (Rn, n)
    if key not in _codec_cache:
        _codec_cache[key] = _RnCodec(
            f"Rn({n})", _core.make_manifold("Rn", n), Rn, Rn, lambda v: v.vec
        )
    return _codec_cache[key]


def _python_codec(cls: type[ManifoldValue], ambient_size: int) -> Codec:
    key = (cls, ambient_size)
    if key not in _codec_cache:
        dof = getattr(cls, "dof", None)
        if isinstance(dof, bool) or not isinstance(dof, (int, np.integer)) or not 1 <= dof <= ambient_size:
            raise TypeError(f"{cls.__name__}.dof must be an int from 1 to the ambient size "
                            f"{ambient_size} (len(to_ambient())), got {dof!r}")

        def plus(x: np.ndarray, d: np.ndarray) -> np.ndarray:
            y = cls.from_ambient(x).boxplus(d)
            if not isinstance(y, ManifoldValue):  # a common slip: returning the ambient vector
                raise TypeError(f"{cls.__name__}.boxplus returned a {type(y).__name__}, "
                                f"expected a {cls.__name__}")
            return y.to_ambient()

        def minus(y: np.ndarray, x: np.ndarray) -> np.ndarray:
            return cls.from_ambient(y).boxminus(cls.from_ambient(x))

        manifold = _core.make_python_manifold(ambient_size, int(cls.dof), plus, minus, cls.__name__)
        _codec_cache[key] = Codec(
            cls.__name__, manifold, cls, cls.from_ambient, lambda v: np.asarray(v.to_ambient(), float)
        )
    return _codec_cache[key]


def codec_of(value: Any) -> Codec:
    """The codec of a manifold value (raises TypeError for anything else)."""
    if isinstance(value, _BUILTIN):
        return _builtin_codec(type(value))
    if isinstance(value, Rn):
        return _rn_codec(value.dof)
    if isinstance(value, _CompoundBase):
        return type(value)._codec()
    if isinstance(value, ManifoldValue):
        a = np.asarray(value.to_ambient(), dtype=float)
        if a.ndim != 1 or a.size == 0:
            raise TypeError(f"{type(value).__name__}.to_ambient() must return a non-empty vector")
        return _python_codec(type(value), a.size)
    raise TypeError(
        f"expected a manifold value (Rn, SO2, SO3, SE2, SE3, S2, a compound or a "
        f"boxplus.ManifoldValue), got {type(value).__name__}"
    )


# --------------------------------------------------------------------------------------
# Named compounds
# --------------------------------------------------------------------------------------


class _CompoundBase(ManifoldValue):
    """Base of the classes made by :func:`make_compound`."""

    _members: ClassVar[tuple[str, ...]] = ()
    _prototypes: ClassVar[dict[str, Any]] = {}
    _member_codecs: ClassVar[dict[str, Codec]] = {}
    _tangent_offsets: ClassVar[dict[str, int]] = {}
    _ambient_offsets: ClassVar[dict[str, int]] = {}
    _compound_codec: ClassVar[Codec | None] = None
    dof: ClassVar[int] = 0

    def __init__(self, **members: Any) -> None:
        unknown = set(members) - set(self._members)
        if unknown:
            raise TypeError(
                f"{type(self).__name__}: unknown member(s) {sorted(unknown)}; "
                f"members are {list(self._members)}"
            )
        for name in self._members:
            proto = self._prototypes[name]
            v = members.get(name, proto)
            object.__setattr__(self, name, _coerce_member(type(self).__name__, name, proto, v))

    def __reduce__(self) -> tuple[Any, ...]:
        # The class is made at run time: pickled by reference when its module holds
        # it under its name (``Plane = make_compound("Plane", ...)``), else by its
        # definition, rebuilt on loading. The members pickle as themselves, bit for
        # bit (values unpickle their exact stored numbers).
        cls = type(self)
        members = {n: getattr(self, n) for n in self._members}
        if getattr(sys.modules.get(cls.__module__), cls.__qualname__, None) is cls:
            return (_compound_with_members, (cls, members))
        return (_rebuilt_compound, (cls.__name__, cls._prototypes, members))

    @classmethod
    def idx_of(cls, name: str) -> int:
        """Start of member ``name`` in the stacked tangent vector."""
        if name not in cls._tangent_offsets:
            raise KeyError(f"{cls.__name__} has no member '{name}' (members: {list(cls._members)})")
        return cls._tangent_offsets[name]

    @classmethod
    def slice_of(cls, name: str) -> slice:
        """Slice of member ``name`` in the stacked tangent vector."""
        start = cls.idx_of(name)
        return slice(start, start + cls._member_codecs[name].dof)

    @classmethod
    def members(cls) -> tuple[str, ...]:
        return cls._members

    def boxplus(self, delta: np.ndarray) -> _CompoundBase:
        return type(self)(
            **{n: getattr(self, n) + delta[self.slice_of(n)] for n in self._members}
        )

    def boxminus(self, other: ManifoldValue) -> np.ndarray:
        return np.concatenate([getattr(self, n) - getattr(other, n) for n in self._members])

    def to_ambient(self) -> np.ndarray:
        return np.concatenate(
            [self._member_codecs[n].to_ambient(getattr(self, n)) for n in self._members]
        )

    @classmethod
    def from_ambient(cls, a: np.ndarray) -> _CompoundBase:
        a = np.asarray(a, dtype=float)
        out = {}
        for n in cls._members:
            c = cls._member_codecs[n]
            start = cls._ambient_offsets[n]
            out[n] = c.from_ambient(a[start : start + c.ambient_size])
        return cls(**out)

    @classmethod
    def _codec(cls) -> Codec:
        if cls._compound_codec is None:
            manifold = _core.make_product_manifold([cls._member_codecs[n].manifold for n in cls._members])
            parts = tuple(
                CodecPart(n, c, slice(cls._ambient_offsets[n], cls._ambient_offsets[n] + c.ambient_size),
                          cls.slice_of(n))
                for n, c in ((n, cls._member_codecs[n]) for n in cls._members)
            )
            cls._compound_codec = _CompoundCodec(cls.__name__, manifold, cls, cls.from_ambient, cls.to_ambient,
                                                 parts)
        return cls._compound_codec

    def __setattr__(self, name: str, value: Any) -> None:
        if name in self._members:
            value = _coerce_member(type(self).__name__, name, self._prototypes[name], value)
        object.__setattr__(self, name, value)

    def __repr__(self) -> str:
        inner = ", ".join(f"{n}={getattr(self, n)!r}" for n in self._members)
        return f"{type(self).__name__}({inner})"

    def __eq__(self, other: object) -> bool:
        """Same compound type and every member equal (members compare by value)."""
        if type(other) is not type(self):
            return NotImplemented
        return all(getattr(self, n) == getattr(other, n) for n in self._members)

    # Members can be reassigned (mutable), so compounds are not hashable.
    __hash__ = None  # type: ignore[assignment]


def _coerce_member(owner: str, name: str, proto: Any, v: Any) -> Any:
    """Accepts a value of the prototype's type, or plain numbers for an Rn member."""
    if type(v) is type(proto):
        if isinstance(proto, Rn) and v.dof != proto.dof:
            raise ValueError(f"{owner}.{name}: expected Rn({proto.dof}), got Rn({v.dof})")
        return v
    if isinstance(proto, Rn):
        arr = np.atleast_1d(np.asarray(v, dtype=float))
        if arr.shape != (proto.dof,):
            raise ValueError(f"{owner}.{name}: expected {proto.dof} numbers, got shape {arr.shape}")
        return Rn(arr)
    if isinstance(proto, _CompoundBase) and isinstance(v, dict):
        return type(proto)(**v)
    raise TypeError(f"{owner}.{name}: expected a {type(proto).__name__}, got {type(v).__name__}")


def make_compound(_name: str = "Compound", **members: Any) -> type[_CompoundBase]:
    """Declares a named compound (Cartesian product) manifold from prototypes.

    Parameters
    ----------
    _name : str
        Name of the new type (for messages and ``repr``).
    **members
        ``member_name=prototype`` in order; a prototype is a value of the member's
        type (``Rn(2)``, ``SO3()``, another compound, a ManifoldValue) and is also
        the member's default value.

    Returns
    -------
    type
        A class whose instances have the members as attributes, ⊞/⊟ member-wise
        (tangent vector = members' tangent vectors stacked in declaration order),
        and ``idx_of(name)`` giving where a member starts in that vector.

    Examples
    --------
    >>> intrinsic_t = make_compound("intrinsic_t", focal_length=Rn(1), offset=Rn(2),
    ...                             distortion=Rn(1))
    >>> intr = intrinsic_t(focal_length=[530.0], offset=[320, 240], distortion=[0.0])
    >>> intr.offset.vec, intrinsic_t.idx_of("offset"), intr.dof
    (array([320., 240.]), 1, 4)
    """
    if not members:
        raise ValueError("make_compound needs at least one member")
    codecs, toff, aoff = {}, {}, {}
    t = a = 0
    if not isinstance(_name, str) or not _name.isidentifier():
        raise ValueError(f"make_compound: the type name must be an identifier, got {_name!r}")
    for name, proto in members.items():
        if name.startswith("_"):
            raise ValueError(f"make_compound('{_name}'): member name '{name}' must not start with '_'")
        if name == "dof" or hasattr(_CompoundBase, name):  # would shadow boxplus, idx_of, ...
            raise ValueError(f"make_compound('{_name}'): member name '{name}' is taken by the "
                             f"compound's own interface ({name} of every compound); choose another")
        c = codec_of(proto)
        codecs[name], toff[name], aoff[name] = c, t, a
        t += c.dof
        a += c.ambient_size
    # The caller's module: where ``Plane = make_compound("Plane", ...)`` puts it, so
    # that pickle finds the class by reference.
    caller = sys._getframe(1).f_globals.get("__name__", __name__)
    return type(
        _name,
        (_CompoundBase,),
        {
            "_members": tuple(members),
            "_prototypes": dict(members),
            "_member_codecs": codecs,
            "_tangent_offsets": toff,
            "_ambient_offsets": aoff,
            "_compound_codec": None,
            "dof": t,
            "__module__": caller,
        },
    )


def _compound_with_members(cls: type[_CompoundBase], members: dict[str, Any]) -> _CompoundBase:
    """A compound of class ``cls`` holding exactly ``members`` (unpickling)."""
    out = cls.__new__(cls)
    for name, value in members.items():
        object.__setattr__(out, name, value)
    return out


_REBUILT: dict[tuple[str, bytes], type[_CompoundBase]] = {}


def _rebuilt_compound(name: str, prototypes: dict[str, Any], members: dict[str, Any]) -> _CompoundBase:
    """Unpickling a compound whose class no module holds: the class made again from
    its definition (once per definition in a process), then the value."""
    import pickle

    key = (name, pickle.dumps(prototypes))
    if key not in _REBUILT:
        _REBUILT[key] = make_compound(name, **prototypes)
    return _compound_with_members(_REBUILT[key], members)


# --------------------------------------------------------------------------------------
# Interoperability with scipy.spatial.transform.Rotation (both use [x, y, z, w])
# --------------------------------------------------------------------------------------


def _so3_from_scipy(rotation: Any) -> SO3:
    """SO3 from a single ``scipy.spatial.transform.Rotation``."""
    return SO3.from_quat(np.asarray(rotation.as_quat(), dtype=float).reshape(4))


def _so3_as_scipy(self: SO3) -> Any:
    """This rotation as a ``scipy.spatial.transform.Rotation``."""
    from scipy.spatial.transform import Rotation

    return Rotation.from_quat(self.quat)


# The stub lists these two as methods of the bound class (stubgen imports the package, so
# it sees them); mypy forbids assigning to a method, which is what this patch does.
SO3.from_scipy = staticmethod(_so3_from_scipy)  # type: ignore[method-assign]
SO3.as_scipy = _so3_as_scipy  # type: ignore[method-assign]
