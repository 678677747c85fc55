"""Robust losses by name: the one Python spelling of a loss argument.

A loss is given as ``None`` (least squares), a name (``"huber"``), a
``(name, width)`` pair (width in standard deviations of the whitened
residual) or a ready :class:`boxplus.Loss`. Names are parsed in C++
(``boxplus::MakeLoss``; :func:`boxplus._core.loss_names` lists them).
"""

from __future__ import annotations

from typing import Union

from boxplus import _core

__all__ = ["LossSpec", "make_loss"]

LossSpec = Union[None, str, tuple[str, float], "_core.Loss"]


def make_loss(spec: LossSpec, what: str) -> _core.Loss | None:
    """The :class:`boxplus.Loss` of ``spec`` (None: least squares).

    Raises ValueError naming ``what`` for an unknown name or a bad width.
    """
    if spec is None or isinstance(spec, _core.Loss):
        return spec
    try:
        if isinstance(spec, str):
            return _core.Loss(spec, 1.0)
        name, width = spec
        if not isinstance(name, str):
            raise TypeError(f"the name must be a str, got {type(name).__name__}")
        return _core.Loss(name, float(width))
    except (TypeError, ValueError) as e:
        raise ValueError(f"{what}: bad loss {spec!r}: {e}") from None
