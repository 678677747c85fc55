"""Geometric constraints of intrinsic calibration (Le & Ng, Sec. VI).

* distance preservation: two data with known true distance d̄ᵢⱼ,
  ‖I(α, uᵢ) − I(α, uⱼ)‖ − d̄ᵢⱼ ~ N(0, σ²) (eq. 5);
* coplanarity: points of one group lie on a plane P, n·p − d ~ N(0, σ²);
* collinearity: points of one group lie on a line L, the component of p − c
  orthogonal to the direction ~ N(0, σ² I) (its norm is the distance, eq. 6).

Instead of refitting the plane or line by SVD at every step (as the paper
does), the plane or line is a variable estimated jointly with α: the same
optimum, a smooth objective and a sparse problem. The manifolds:

* :data:`Plane` = compound (normal: S2, distance: Rn(1)), {p : n·p = d}, 3 DOF;
* :data:`Line` = compound (direction: S2, point: Rn(3)), {c + s·v}, 5 DOF of
  which one (sliding c along v) is fixed by the extra residual v·c = 0 (c is
  the point of the line closest to the origin).

Planes and lines alone do not fix scale (all points shrinking to one point
satisfies them): a system needs at least one distance constraint or a link
to another system.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from boxplus.manifolds import S2, Rn, make_compound

__all__ = ["Line", "Plane", "fit_line", "fit_plane", "point_line_residual", "point_plane_residual"]

Plane = make_compound("Plane", normal=S2([0.0, 0.0, 1.0]), distance=Rn(1))
Line = make_compound("Line", direction=S2([1.0, 0.0, 0.0]), point=Rn(3))


def fit_plane(points: np.ndarray) -> Any:  # a Plane (a class made at run time)
    """Total-least-squares plane through ≥ 3 points (SVD), as a :data:`Plane`."""
    p = np.asarray(points, dtype=float)
    c = p.mean(axis=0)
    n = np.linalg.svd(p - c)[2][-1]
    return Plane(normal=S2(n), distance=[n @ c])


def fit_line(points: np.ndarray) -> Any:  # a Line (a class made at run time)
    """Total-least-squares line through ≥ 2 points (SVD), as a :data:`Line`."""
    p = np.asarray(points, dtype=float)
    c = p.mean(axis=0)
    v = np.linalg.svd(p - c)[2][0]
    return Line(direction=S2(v), point=c - (v @ c) * v)


def point_plane_residual(plane, p: np.ndarray) -> np.ndarray:
    """n·p − d, (N, 1), for a batch of planes and points (N, 3)."""
    return np.sum(plane.normal.vec * p, axis=1, keepdims=True) - plane.distance.vec


def point_line_residual(line, p: np.ndarray) -> np.ndarray:
    """(I − v vᵀ)(p − c), (N, 3): its norm is the distance of p to the line."""
    v = line.direction.vec
    q = p - line.point.vec
    return q - np.sum(q * v, axis=1, keepdims=True) * v
