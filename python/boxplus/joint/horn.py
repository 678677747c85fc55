"""Horn's closed-form absolute orientation with unit quaternions.

B. K. P. Horn, "Closed-form solution of absolute orientation using unit
quaternions", J. Opt. Soc. Am. A 4(4), 1987: the rotation that best maps the
centred points a'ᵢ onto b'ᵢ is the eigenvector of the largest eigenvalue of
the symmetric 4×4 matrix N built from M = Σ wᵢ a'ᵢ b'ᵢᵀ (Sec. 4), and the
translation is t = b̄ − R ā (Sec. 2.C). No scale is estimated. The maths is
:func:`boxplus.geometry.absolute_orientation`; this is joint's name for it.

Frames: the result is ``b_from_a``, an SE3 with ``b_from_a.fromlocal(a) ≈ b``
(SE(3) = R³ × SO(3), tangent [translation, rotation]).
"""

from __future__ import annotations

import numpy as np

from boxplus.geometry import absolute_orientation
from boxplus.manifolds import SE3

__all__ = ["horn"]


def horn(p_in_a: np.ndarray, p_in_b: np.ndarray, weights: np.ndarray | None = None) -> SE3:
    """The rigid transform b_from_a minimising Σ wᵢ ‖R aᵢ + t − bᵢ‖².

    Parameters
    ----------
    p_in_a, p_in_b : (N, 3) arrays
        The same N ≥ 3 points in frames a and b, not all on one line.
    weights : (N,) array, optional
        Non-negative weights (default: all 1).

    Returns
    -------
    SE3
        ``b_from_a``: ``b_from_a.fromlocal(p_in_a[i]) ≈ p_in_b[i]``.

    Raises
    ------
    ValueError
        On bad shapes, fewer than 3 points, or points on one line (the rotation
        about that line is then undetermined).
    """
    b_from_a = absolute_orientation(p_in_a, p_in_b, weights, what="horn")
    assert isinstance(b_from_a, SE3)  # without scale= it is a pose, not (pose, scale)
    return b_from_a
