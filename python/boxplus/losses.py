"""Robust losses: the one Python spelling of a loss for every ``add_*``.

A loss is None (least squares), a name (``"huber"``, ``"cauchy"``, …, width 1),
a ``(name, width)`` pair (width in standard deviations of the whitened
residual), or a ready :class:`boxplus.Loss`. The names are parsed once, in C++
(``boxplus/loss.h``).
"""

from __future__ import annotations

from typing import Optional, Tuple, Union

from boxplus import _core

__all__ = ["LossSpec", "make_loss"]

LossSpec = Union[None, str, Tuple[str, float], "_core.Loss"]


def make_loss(loss: LossSpec, what: str) -> Optional["_core.Loss"]:
    """The :class:`boxplus.Loss` of ``loss``; raises ValueError naming ``what``."""
    if loss is None:
        return None
    if isinstance(loss, _core.Loss):
        return loss
    try:
        if isinstance(loss, str):
            return _core.Loss(loss, 1.0)
        name, width = loss
        return _core.Loss(str(name), float(width))
    except (TypeError, ValueError) as e:
        raise ValueError(f"{what}: bad loss {loss!r}: {e}") from None
